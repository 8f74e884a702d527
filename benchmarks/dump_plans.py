"""Dump the planner's plans on many machines with a sensor, to compare two versions byte for byte.

    python benchmarks/dump_plans.py OUT.txt           # every case (about a minute)
    python benchmarks/dump_plans.py OUT.txt --quick   # without the benchmark's largest mixes

A tool for changes that must not change any plan (the tie-breaking stages made faster,
docs/planning.md "Which plan among the shortest"): run it before and after, then
``cmp`` the two files. Cases: every case of ``bench_planners.py`` with a sensor, and a few
dozen random parts and mixes (the tests' generators) under every objective, with tolerance
and LED sensors, with a margin floor and under the default rotation error. Per case: the
length, the smallest margin, the expected operations (``repr``), ``tie_breaks``,
``optimal``, the lower bound, and the plan's nodes in a canonical walk (structurally equal
subplans numbered once, in the order a depth-first walk meets them, so how the planner
shares nodes in memory does not show). The tie-breaking budget is lifted
(``api.TIE_SHARE``, ``api.EXPECTED_SHARE``), so every tie-break is compared in full (a
change that makes the stages poll less would otherwise move where a budget of polls cuts
them).
"""

from __future__ import annotations

import math
import random
import sys
import time
from pathlib import Path

import shapely

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import bench_planners as bp  # noqa: E402
from shared import small_mix  # noqa: E402  (tests/test_deadline.py's mix)

import feederkit.planning.api as api  # noqa: E402
from feederkit.errors import PlanningError  # noqa: E402
from feederkit.machine import build_machine  # noqa: E402
from feederkit.mechanics import push_function  # noqa: E402
from feederkit.outline import make_outline  # noqa: E402
from feederkit.part import make_part  # noqa: E402
from feederkit.planning.options import ActionCosts, PlanningOptions  # noqa: E402
from feederkit.planning.tree import Leaf  # noqa: E402
from feederkit.sensors import LedSensor, ToleranceSensor  # noqa: E402
from feederkit.uncertainty import IDEAL, Uncertainty  # noqa: E402

COSTS = ActionCosts(pick_place_s=1.2, rotation_speed_deg_s=60.0, drift_s=0.5)


def random_part(seed: int, n: int):
    """tests/test_planners.py's random convex part (radii 0.8-1 on a 60 x 40 mm ellipse)."""
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    radii = [rng.uniform(0.8, 1.0) for _ in angles]
    pts = [(30 * r * math.cos(t), 20 * r * math.sin(t)) for r, t in zip(radii, angles, strict=True)]
    hull = shapely.MultiPoint(pts).convex_hull.exterior.coords[:-1]
    return push_function(make_part(make_outline(f"random-{seed}", hull)))


def cases(quick: bool):
    """(name, machine, options) for every case."""
    worst = PlanningOptions()
    for name, machine, _target, _base in bp.cases(quick=False):
        if machine.sensor.informative and not (quick and "50-part" in name):
            yield name, machine, worst
    objectives = (
        ("worst", PlanningOptions()),
        ("expected", PlanningOptions(objective="expected")),
        ("worst+costs", PlanningOptions(costs=COSTS)),
        ("time", PlanningOptions(objective="time", costs=COSTS)),
        ("worst-time", PlanningOptions(objective="worst-time", costs=COSTS)),
    )
    rng = random.Random(12)
    for seed in range(24):
        n = rng.randint(7, 14)
        rel = rng.choice((0.01, 0.02, 0.03, 0.05))
        pf = random_part(seed, n)
        m = build_machine([pf], ToleranceSensor(rel * pf.part.size), IDEAL)
        label, options = objectives[seed % len(objectives)]
        yield f"random {n}-gon #{seed} at {rel:.0%}, {label}", m, options
        if seed % 4 == 0:
            yield (
                f"random {n}-gon #{seed} at {rel:.0%}, min margin 2",
                m,
                PlanningOptions(min_margin_deg=2.0),
            )
    for count in range(3, 9):
        for tol in (1.0, 2.0):
            m = build_machine(small_mix(count, 100 + 7 * count), ToleranceSensor(tol), IDEAL)
            label, options = objectives[(count + int(tol)) % len(objectives)]
            yield f"{count}-part mix at {tol:g} mm, {label}", m, options
    for seed in range(24, 36):
        n = rng.randint(16, 30)
        rel = rng.choice((0.01, 0.02, 0.03))
        pf = random_part(seed, n)
        m = build_machine([pf], ToleranceSensor(rel * pf.part.size), IDEAL)
        label, options = objectives[seed % len(objectives)]
        yield f"random {n}-gon #{seed} at {rel:.0%}, {label}", m, options
    for count, tol, many in ((10, 0.6, 2), (12, 1.5, 1), (15, 0.8, 2)):
        m = build_machine(small_mix(count, 200 + count), ToleranceSensor(tol), IDEAL)
        for label, options in objectives[:many]:
            yield f"{count}-part mix at {tol:g} mm, {label}", m, options
    for seed in range(4):
        pf = random_part(40 + seed, 9)
        m = build_machine([pf], LedSensor(0.5, 0.1), IDEAL)
        yield f"random 9-gon #{40 + seed}, LED 0.5/0.1", m, PlanningOptions()
    for seed in range(6):
        pf = random_part(60 + seed, 6 + seed % 3)
        m = build_machine([pf], ToleranceSensor(0.02 * pf.part.size), Uncertainty(1.0))
        label, options = objectives[seed % len(objectives)]
        yield f"random part #{60 + seed} at 2%, rotation error 1 deg, {label}", m, options
    for count in (3, 4, 6):
        m = build_machine(small_mix(count, 300), ToleranceSensor(1.0), Uncertainty(0.5))
        for label, options in objectives[:2]:
            yield f"{count}-part mix at 1 mm, rotation error 0.5 deg, {label}", m, options


def canonical(root) -> list[str]:
    """The plan's nodes, structurally equal subplans once, in depth-first order."""
    ids: dict[str, int] = {}
    lines: list[str] = []
    memo: dict[int, int] = {}

    def visit(node) -> int:
        hit = memo.get(id(node))
        if hit is not None:
            return hit
        if isinstance(node, Leaf):
            text = f"leaf {node.mask:x}"
        else:
            a = node.action
            head = (
                "root" if a is None else f"act {a.lo!r} {a.hi!r} {a.image:x} {a.representative!r}"
            )
            subs = [f"[{b.lo!r},{b.hi!r},{b.mask:x}]->{visit(sub)}" for b, sub in node.branches]
            text = head + " " + " ".join(subs)
        k = ids.get(text)
        if k is None:
            k = ids[text] = len(ids)
            lines.append(f"  n{k}: {text}")
        memo[id(node)] = k
        return k

    visit(root)
    return lines


def main(argv: list[str]) -> int:
    if not argv or argv[0].startswith("-"):
        print("usage: python benchmarks/dump_plans.py OUT.txt [--quick]", file=sys.stderr)
        return 2
    api.TIE_SHARE = api.EXPECTED_SHARE = 1e9  # every tie-break compared in full
    out = Path(argv[0])
    total = 0.0
    with out.open("w") as f:
        for name, machine, options in cases("--quick" in argv):
            start = time.process_time()
            try:
                r = api.plan(bp.fresh(machine), options)
            except PlanningError as exc:
                f.write(f"{name}: error {exc}\n")
                continue
            cpu = time.process_time() - start
            total += cpu
            f.write(
                f"{name}: length {r.length} margin {r.min_margin!r} expected "
                f"{r.expected_length!r} ties {r.tie_breaks} optimal {r.optimal} "
                f"lower {r.lower_bound}\n"
            )
            f.writelines(line + "\n" for line in canonical(r.root))
            print(f"{cpu:8.3f} CPU s  {name}", flush=True)
    print(f"total {total:.2f} CPU s; written {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
