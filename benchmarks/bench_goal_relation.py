"""Benchmark: the goal relation (``inseparable_masks``, the planner's first long stage)
against the plain greatest fixpoint, on the machines the planner builds.

    python benchmarks/bench_goal_relation.py              # every case
    python benchmarks/bench_goal_relation.py mix          # cases whose name has "mix"
    python benchmarks/bench_goal_relation.py --plain-limit 30

Each case is one of ``bench_deadline.py``'s, its machine split at wandering states and
numbered by diameter as ``plan`` does (``planning.wandering.twinned``,
``planning.reindex.by_diameter``). Timed, CPU seconds, on fresh copies of that machine:
``inseparable_masks``, then the plain fixpoint: every pair that can read alike (each pair
asked), each pair's cases from ``pair_outcomes``, passes over all pairs until none is
dropped, a pair dropped when some case merges it (ideal model) or some outcome of either
state has no live partner among the other's (outcome sets). The plain one gives up after
``--plain-limit`` seconds (default 60). Exit code 1 when both finish and disagree.
"""

from __future__ import annotations

import sys
import time

from bench_deadline import CASES
from bench_planners import GaveUp, circle_cut, fresh, mix, near_round, random_outline  # noqa: F401

from feederkit.machine import PushAlignMachine, build_machine, members
from feederkit.machine.inseparable import inseparable_masks, pair_outcomes
from feederkit.planning.reindex import by_diameter
from feederkit.planning.wandering import twinned
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

PLAIN_LIMIT_S = 60.0

NAMES = (
    "near-round 64-gon 1%, 0.3 mm",
    "near-round 64-gon 1%, 3%",
    "near-round 200-gon 0.1%, 3%",
    "50-part mix, 5%",
    "100-part mix, 5%",
    "200-part mix, 0.5%",
    "200-part mix, 1%, ideal",
)
"""The deadline cases whose goal relation takes a share of a 10 s limit."""


def planner_machine(spec: str) -> PushAlignMachine:
    """The case's machine as ``plan`` searches it (split, numbered by diameter)."""
    expr, tol, unc = spec.split("|")
    pfs = eval(expr)
    size = max(pf.part.size for pf in pfs)
    mm = float(tol[:-1]) / 100.0 * size if tol.endswith("%") else float(tol)
    machine = build_machine(pfs, ToleranceSensor(mm), IDEAL if unc == "ideal" else Uncertainty())
    split, _twins = twinned(machine, None)
    return by_diameter(split)[0]


def plain_fixpoint(machine: PushAlignMachine, limit_s: float) -> tuple[int, ...]:
    """The greatest fixpoint by passes over every pair (module docstring); GaveUp past
    ``limit_s`` seconds of CPU."""
    end = time.process_time() + limit_s
    n, sensor = machine.n, machine.sensor
    d = [s.sensed for s in machine.states]
    alive = {(i, j) for i in range(n) for j in range(i + 1, n) if sensor.can_read_alike(d[i], d[j])}
    cases = {}
    for p in alive:
        if time.process_time() > end:
            raise GaveUp
        cases[p] = pair_outcomes(machine, *p)

    def linked(x: int, y: int) -> bool:
        return x != y and (min(x, y), max(x, y)) in alive

    def holds(p: tuple[int, int]) -> bool:
        for a, b in cases[p]:
            if machine.deterministic:
                if not linked(a, b):
                    return False
                continue
            xs, ys = members(a), members(b)
            if not all(any(linked(x, y) for y in ys) for x in xs):
                return False
            if not all(any(linked(x, y) for x in xs) for y in ys):
                return False
        return True

    changed = True
    while changed:
        changed = False
        for p in sorted(alive):
            if time.process_time() > end:
                raise GaveUp
            if not holds(p):
                alive.discard(p)
                changed = True
    masks = [0] * n
    for i, j in alive:
        masks[i] |= 1 << j
        masks[j] |= 1 << i
    return tuple(masks)


def main(argv: list[str]) -> int:
    plain_s = PLAIN_LIMIT_S
    if "--plain-limit" in argv:
        at = argv.index("--plain-limit")
        plain_s = float(argv[at + 1])
        argv = argv[:at] + argv[at + 2 :]
    print(f"the plain fixpoint gives up after {plain_s:g} s of CPU")
    rows, bad = [], 0
    for name in NAMES:
        if argv and not any(w in name for w in argv):
            continue
        machine = planner_machine(CASES[name][1])
        c = time.process_time()
        ours = inseparable_masks(fresh(machine))
        ours_s = time.process_time() - c
        c = time.process_time()
        try:
            plain = plain_fixpoint(fresh(machine), plain_s)
            plain_s_used = time.process_time() - c
            ratio = f"{plain_s_used / max(ours_s, 1e-9):.1f}x"
            plain_text = f"{plain_s_used:.2f}"
            same = "yes" if plain == ours else "NO"
            bad += plain != ours
        except GaveUp:
            ratio = f"> {plain_s / max(ours_s, 1e-9):.0f}x"
            plain_text, same = f"> {plain_s:g}", "-"
        pairs = sum(m.bit_count() for m in ours) // 2
        row = [name, str(machine.n), f"{ours_s:.2f}", plain_text, ratio, str(pairs), same]
        rows.append(row)
        print("  ".join(row), flush=True)
    print("\n| case | states | fixpoint cpu s | plain cpu s | ratio | inseparable pairs | same |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | --- |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
