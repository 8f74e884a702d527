"""Planner performance against issue 3's and issue 5's targets, with the plain search as baseline.

    python benchmarks/bench_planners.py           # everything (a few minutes: the baseline)
    python benchmarks/bench_planners.py --quick   # skip the slowest baseline runs
    python benchmarks/bench_planners.py "12-gon"  # the cases whose name holds "12-gon"

For each case: the time of ``feederkit.planning.plan`` (proven optimal, default options),
split into the length proof (everything but the tie-breaking stages) and the tie-breaking
stages (``refine.stage`` and the tree build that breaks ties, docs/planning.md "Which plan
among the shortest"), the time of the plain exhaustive AND/OR search over sets
(``baseline_length`` below: iterative deepening, every overlap range, readings branching
exactly, a memo of (set, depth) results and nothing else), their ratio, and the target.
Times are wall-clock seconds and CPU seconds, each the best of the same number of runs for
the planner and the baseline (a few for fast cases), each on a fresh copy of the machine
(no tables cached from an earlier run); the ratio is baseline CPU over planner
CPU, since other work on the machine inflates wall time, printed with two decimals below
10x so that a planner slower than the plain search shows as such; ``proof x`` is the same
ratio for the length proof alone (the plan's CPU less its tie-breaking stages), the work the
plain search does. Peak memory is the
process's maximum resident set size. Exit code 1 when a target is missed.

Every machine is the paper's ideal model (``IDEAL``: exact push functions and diameters),
which the plain search of section 6.1 also assumes; under the default 1 degree rotation
error the random parts have no strong plan. The last case is a mix whose readings carry no
information once they name the part (a triangle and both landings of an off-centre
octagon, all octagon states reading one diameter): the planner solves that branch as a
sensorless problem (docs/planning.md), the plain search takes minutes. The very last is
both landings of a near-round 12-gon under a sensor whose one reading fits every state:
the planner's A* over sets (feederkit.planning.quiet) against a plain search that gives up.
"""

from __future__ import annotations

import math
import random
import resource
import sys
import time
from pathlib import Path

import feederkit.planning.api as planning_api
from feederkit.landing.model import landings_of_outline
from feederkit.machine import (
    PushAlignMachine,
    branches,
    build_machine,
    inseparable,
    is_goal,
    overlap_ranges,
)
from feederkit.mechanics import push_function
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

HERE = Path(__file__).resolve().parent
BASELINE_LIMIT_S = 60.0
"""The baseline gives up after this long (its time is then reported as '>')."""


class GaveUp(Exception):
    pass


def baseline_length(machine, limit_s: float = BASELINE_LIMIT_S) -> int:
    """The plain exhaustive AND/OR search (section 6.1): the first alignment counted."""
    insep = inseparable(machine)
    memo: dict[tuple[int, int], bool] = {}
    end = time.perf_counter() + limit_s

    def within(mask: int, k: int) -> bool:
        if is_goal(insep, mask):
            return True
        if k == 0:
            return False
        key = (mask, k)
        if key in memo:
            return memo[key]
        if time.perf_counter() > end:
            raise GaveUp
        ok = any(
            all(within(b.mask, k - 1) for b in branches(machine, a.image))
            for a in overlap_ranges(machine, mask)
        )
        memo[key] = ok
        return ok

    worst = 0
    for b in branches(machine, machine.all_states):
        k = 0
        while not within(b.mask, k):
            k += 1
        worst = max(worst, k)
    return 1 + worst


def regular(n: int, com: tuple[float, float]):
    pts = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    return push_function(make_part(make_outline(f"regular-{n}", pts, com=com)))


def random_convex(n: int, seed: int, name: str):
    """Random angles on a 60 x 40 mm ellipse: every point is a hull vertex."""
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]
    return push_function(make_part(make_outline(name, pts)))


def random_outline(n: int, seed: int):
    """The hull of ``n`` points at random angles and radii 21-30 mm (10-32 stable states)."""
    rng = random.Random(seed)
    pts = []
    for t in sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n)):
        f = 30.0 * rng.uniform(0.7, 1.0)
        pts.append((f * math.cos(t), f * math.sin(t)))
    return push_function(make_part(make_outline(f"rand-{n}-{seed}", pts)))


def near_round(n: int, noise: float, seed: int = 0, r: float = 10.0):
    """A regular ``n``-gon of radius ``r`` mm with relative radial noise ``noise``."""
    rng = random.Random(seed)
    pts = []
    for k in range(n):
        a, f = 2 * math.pi * k / n, 1 + rng.uniform(-noise, noise)
        pts.append((r * f * math.cos(a), r * f * math.sin(a)))
    return push_function(make_part(make_outline(f"round-{n}", pts)))


def circle_cut(n: int = 360, cut: float = 0.9, r: float = 10.0):
    """A circle of ``n`` facets, radius ``r`` mm, with a flat cut at ``cut * r`` below its
    centre."""
    pts = [
        (r * math.cos(2 * math.pi * k / n), max(r * math.sin(2 * math.pi * k / n), -cut * r))
        for k in range(n)
    ]
    return push_function(make_part(make_outline("cut", pts)))


def mix(count: int):
    return [
        random_convex(random.Random(s).randint(6, 10), 100 + s, f"mix-{s}") for s in range(count)
    ]


def triangle_and_octagon():
    """A right triangle and both landings of an octagon with its COM off centre."""
    octagon = [(math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)) for k in range(8)]
    parts = [
        make_part(make_outline("tri", [(0, 0), (1, 0), (0, 1)])),
        make_part(make_outline("octagon", octagon, com=(0.13, 0.05))),
    ]
    return [push_function(x.part) for p in parts for x in landings_of_outline(p)]


class StageClock:
    """CPU seconds spent in the planner's tie-breaking stages during one call.

    Wraps ``api.stage`` and ``api._build`` (the margin stage, then the tree build that breaks
    the remaining ties) for the duration of a ``with`` block; ``ties`` is their sum.
    """

    NAMES = ("stage", "_build")

    def __init__(self) -> None:
        self.ties = 0.0
        self._saved: dict[str, object] = {}

    def __enter__(self) -> StageClock:
        for name in self.NAMES:
            fn = getattr(planning_api, name)
            self._saved[name] = fn

            def clocked(*args, _fn=fn, **kwargs):
                start = time.process_time()
                try:
                    return _fn(*args, **kwargs)
                finally:
                    self.ties += time.process_time() - start

            setattr(planning_api, name, clocked)
        return self

    def __exit__(self, *exc) -> None:
        for name, fn in self._saved.items():
            setattr(planning_api, name, fn)


def fresh(machine: PushAlignMachine) -> PushAlignMachine:
    """An equal machine with nothing cached (its search space's tables are per machine), so
    that every timed run, the planner's and the baseline's, starts cold."""
    m = machine
    return PushAlignMachine(m.part_names, m.states, m.action_maps, m.sensor, m.uncertainty)


def timed_plan(machine, repeats: int):
    """Best wall and CPU seconds of ``plan`` over ``repeats`` runs, the tie-breaking CPU
    seconds of the fastest run, and the last result."""
    wall, cpu, ties, out = math.inf, math.inf, 0.0, None
    for _ in range(repeats):
        m = fresh(machine)
        with StageClock() as clock:
            t, c = time.perf_counter(), time.process_time()
            out = plan(m)
            dc = time.process_time() - c
            wall = min(wall, time.perf_counter() - t)
        if dc < cpu:
            cpu, ties = dc, clock.ties
    return wall, cpu, ties, out


def ratio_text(ratio: float, bound: bool = False) -> str:
    """A speed-up in words: two decimals below 10x (a planner slower than the plain search
    shows as such), whole numbers above; ``bound``: at least that (the baseline gave up)."""
    text = f"{ratio:.2f}x" if ratio < 10 else f"{ratio:.0f}x"
    return (">" if bound else "") + text


def timed(fn, repeats: int, machine: PushAlignMachine | None = None):
    """Best wall and CPU seconds over ``repeats`` runs, and the last result; with a
    ``machine``, each run is ``fn`` of a fresh copy of it (made before the clock starts)."""
    wall, cpu, out = math.inf, math.inf, None
    for _ in range(repeats):
        args = () if machine is None else (fresh(machine),)
        t, c = time.perf_counter(), time.process_time()
        out = fn(*args)
        cpu = min(cpu, time.process_time() - c)
        wall = min(wall, time.perf_counter() - t)
    return wall, cpu, out


def cases(quick: bool):
    """(name, machine, target seconds, run the baseline?)"""
    for path in sorted((HERE.parent / "catalog").glob("*.json")):
        pf = push_function(make_part(load_outline_json(path)))
        yield f"sample {path.stem}, sensorless", build_machine([pf], None, IDEAL), 0.01, True
        sensor = ToleranceSensor(0.03 * pf.part.size)
        yield f"sample {path.stem}, tolerance 3%", build_machine([pf], sensor, IDEAL), 0.01, True
    for n, target in ((12, 0.1), (32, 2.0), (64, 30.0)):
        m = build_machine([regular(n, (0.13, 0.05))], None, IDEAL)
        yield f"regular {n}-gon, COM (0.13, 0.05) [{m.n} states]", m, target, not quick or n == 12
    m = build_machine([regular(32, (0.02, 0.008))], None, IDEAL)
    yield f"regular 32-gon, COM (0.02, 0.008) [{m.n} states]", m, 2.0, not quick
    for seed in range(10):
        pf = random_convex(64, seed, f"random-64-{seed}")
        m = build_machine([pf], ToleranceSensor(0.03 * pf.part.size), IDEAL)
        yield f"random convex 64-gon #{seed}, 3% [{m.n} states]", m, 0.2, seed < 3
    # Issue 12's own sensor cases: a random part and a 10-part mix at 3 %.
    pf = random_outline(50, 2)
    m = build_machine([pf], ToleranceSensor(0.03 * pf.part.size), IDEAL)
    yield f"random 50-point outline, 3% [{m.n} states]", m, 0.2, True
    parts = mix(10)
    size = max(pf.part.size for pf in parts)
    m = build_machine(parts, ToleranceSensor(0.03 * size), IDEAL)
    yield f"10-part mix of 6-10-gons, 3% of {size:.0f} mm [{m.n} states]", m, 0.5, True
    for count, rel, target in ((20, 0.02, 0.5), (50, 0.01, 5.0)):
        parts = mix(count)
        size = max(pf.part.size for pf in parts)
        m = build_machine(parts, ToleranceSensor(rel * size), IDEAL)
        name = f"{count}-part mix of 6-10-gons, {rel:.0%} of {size:.0f} mm [{m.n} states]"
        yield name, m, target, not quick
        # benchmarks/bench_plans.py takes the percentage of 30 mm instead.
        m = build_machine(parts, ToleranceSensor(rel * 30.0), IDEAL)
        name = f"{count}-part mix of 6-10-gons, {rel:.0%} of 30 mm [{m.n} states]"
        yield name, m, target, not quick
    m = build_machine(triangle_and_octagon(), ToleranceSensor(0.01), IDEAL)
    yield f"triangle + octagon up/down, 0.01 mm [{m.n} states]", m, 2.0, not quick
    # Both landings of a near-round part whose every diameter fits one reading: A* over sets
    # (feederkit.planning.quiet); the plain search gives up.
    pfs = [push_function(x.part) for x in landings_of_outline(near_round(12, 0.03, 3).part)]
    m = build_machine(pfs, ToleranceSensor(2.0), IDEAL)
    name = f"near-round 12-gon up/down, 2 mm [{m.n} states]"
    yield name, m, 0.5, not quick


def main(argv: list[str]) -> int:
    quick = "--quick" in argv
    wanted = [a for a in argv if not a.startswith("--")]  # substrings of case names
    missed = 0
    head = ("case", "plan s", "cpu s", "proof", "ties", "target", "base s", "base cpu", "ratio",
            "proof x")  # fmt: skip
    print(f"{head[0]:58} " + " ".join(f"{h:>8}" for h in head[1:]) + "  len")
    for name, machine, target, with_baseline in cases(quick):
        if wanted and not any(w in name for w in wanted):
            continue
        repeats = 3 if target <= 0.5 else 1
        wall, cpu, ties, result = timed_plan(machine, repeats)
        assert result.optimal
        base = base_cpu = ratio = proof_ratio = ""
        proof = max(cpu - ties, 1e-9)
        if with_baseline:
            try:
                bw, bc, blen = timed(baseline_length, repeats, machine)
                assert blen == result.length, (name, blen, result.length)
                base, base_cpu = f"{bw:8.3f}", f"{bc:8.3f}"
                ratio = ratio_text(bc / max(cpu, 1e-9))
                proof_ratio = ratio_text(bc / proof)
            except GaveUp:
                base = f">{BASELINE_LIMIT_S:7.0f}"
                ratio = ratio_text(BASELINE_LIMIT_S / max(cpu, 1e-9), bound=True)
                proof_ratio = ratio_text(BASELINE_LIMIT_S / proof, bound=True)
        ok = min(wall, cpu) <= target
        missed += not ok
        flag = "" if ok else "  <-- MISSED"
        print(
            f"{name:58} {wall:8.4f} {cpu:8.4f} {cpu - ties:8.4f} {ties:8.4f} {target:8.2f} "
            f"{base:>8} {base_cpu:>8} {ratio:>8} {proof_ratio:>8} {result.length:4d}{flag}",
            flush=True,
        )
    for count, rel in ((20, 0.02), (50, 0.01)) if not wanted else ():
        parts = mix(count)
        size = max(pf.part.size for pf in parts)
        m = build_machine(parts, ToleranceSensor(rel * size), IDEAL)
        wall, cpu, _ = timed(inseparable, 3, m)
        print(f"inseparable() on the {count}-part mix [{m.n} states]: {wall:.4f} s ({cpu:.4f} CPU)")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    ok = peak < 500.0
    missed += not ok
    print(f"peak memory: {peak:.0f} MB (target 500 MB){'' if ok else '  <-- MISSED'}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
