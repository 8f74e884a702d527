"""Simulator figures against issue 7's targets (run: ``python benchmarks/bench_sim.py``).

Targets: about 10 ms of wall time per simulated push-align operation on one core; 100
trials of a 3-step plan in under 10 s. Also printed: agreement of simulated pushes with
the push function for the issue's three parts across belt speeds and fence frictions, and
on random convex polygons (where misses are classified: a start within 1.5 deg of a
divergent orientation, or a predicted stable edge within 2 deg of one, a near-metastable
edge the part's momentum carries it past).

CPU time (``time.process_time``) is printed beside wall time because the machine may be
shared; the targets are judged on CPU time of this single-threaded process. Exit code 1
when a target is missed.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from test_sim_plans import (  # noqa: E402
    build_plan,
    offset_triangle,
    pentagon,
    rectangle,
    right_triangle,
)

from feederkit.errors import InputError  # noqa: E402
from feederkit.mechanics.push import push_function  # noqa: E402
from feederkit.outline import make_outline  # noqa: E402
from feederkit.part import make_part  # noqa: E402
from feederkit.sim import simulate_plan, simulate_push  # noqa: E402
from feederkit.sim.trial import divergent_distance  # noqa: E402

PARTS = {"rectangle": rectangle, "right triangle": right_triangle, "pentagon": pentagon}


def per_push(drops: int = 100) -> bool:
    print(f"push-align operations: {drops} random drops per part, default settings")
    walls, cpus, sims = [], [], []
    for name, make in PARTS.items():
        part = make()
        simulate_push(part, 0.0)  # build the model outside the timing
        rng = np.random.default_rng(1)
        agree, worst = 0, 0.0
        for theta in rng.uniform(0.0, 360.0, drops):
            w0, c0 = time.perf_counter(), time.process_time()
            check = simulate_push(part, float(theta))
            walls.append(time.perf_counter() - w0)
            cpus.append(time.process_time() - c0)
            sims.append(check.outcome.sim_time_s)
            agree += check.agrees
            if not check.agrees:
                worst = max(worst, check.divergent_distance_deg)
        misses = f"misses start <= {worst:.2f} deg from a divergent orientation"
        print(f"  {name:15s} agreement {agree}/{drops}" + (f"; {misses}" if agree < drops else ""))
    cpu_ms = 1000 * statistics.mean(cpus)
    print(
        f"  per operation: CPU mean {cpu_ms:.1f} ms (median {1000 * statistics.median(cpus):.1f}, "
        f"p95 {1000 * float(np.percentile(cpus, 95)):.1f}); wall mean "
        f"{1000 * statistics.mean(walls):.1f} ms; simulated {statistics.mean(sims):.2f} s "
        f"({statistics.mean(sims) / 0.002:.0f} steps of 2 ms)"
    )
    ok = cpu_ms <= 12.0
    print(f"  target ~10 ms per operation: {'met' if ok else 'MISSED'}")
    return ok


def three_step_plan(trials: int = 100) -> bool:
    plan = build_plan(offset_triangle(), 0.5)
    assert plan["stats"]["length"] == 3
    w0, c0 = time.perf_counter(), time.process_time()
    s = simulate_plan(plan, trials, seed=0)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    print(
        f"3-step plan (offset equilateral triangle, readings all equal): {trials} trials, "
        f"{s.pushes} operations: CPU {cpu:.2f} s, wall {wall:.2f} s; "
        f"{s.successes}/{s.trials} succeeded, {len(s.unsettled)} never settled, "
        f"push agreement {s.push_agreements}/{s.settled_pushes}"
    )
    ok = cpu < 10.0
    print(f"  target 100 trials in under 10 s: {'met' if ok else 'MISSED'}")
    return ok


def agreement_matrix(drops: int = 40) -> None:
    print(f"agreement across settings ({drops} drops per part; misses: max start distance)")
    settings = [
        {"belt_speed": 0.03},
        {"belt_speed": 0.1},
        {"belt_speed": 0.3},
        {"friction_fence": 0.0},
        {"friction_fence": 0.6},
        {"friction_belt": 0.3, "friction_fence": 0.5},
        {"friction_belt": 0.9, "friction_fence": 0.05},
    ]
    for kw in settings:
        cells = []
        for name, make in PARTS.items():
            part = make()
            rng = np.random.default_rng(2)
            checks = [simulate_push(part, float(t), **kw) for t in rng.uniform(0, 360, drops)]
            miss = [c.divergent_distance_deg for c in checks if not c.agrees]
            worst = f" <= {max(miss):.2f}" if miss else ""
            cells.append(f"{name} {drops - len(miss)}/{drops}{worst}")
        label = ", ".join(f"{k}={v}" for k, v in kw.items())
        print(f"  {label:40s} " + "; ".join(cells))


def random_polygons(count: int = 40, drops: int = 10) -> None:
    rng = np.random.default_rng(5)
    total = near_start = near_edge = other = 0
    for k in range(count):
        n = int(rng.integers(5, 11))
        ang = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(15, 40, n)
        try:
            part = make_part(
                make_outline(f"poly{k}", np.column_stack([r * np.cos(ang), r * np.sin(ang)]))
            )
            pf = push_function(part)
        except (InputError, AssertionError):
            continue
        for theta in rng.uniform(0, 360, drops):
            c = simulate_push(part, float(theta))
            total += 1
            if c.agrees:
                continue
            if c.divergent_distance_deg <= 1.5:
                near_start += 1
            elif divergent_distance(pf, c.predicted.normal_deg) <= 2.0:
                near_edge += 1
            else:
                other += 1
    agree = total - near_start - near_edge - other
    print(
        f"random convex 5-10-gons (15-40 mm radius): {agree}/{total} agree; misses: "
        f"{near_start} start within 1.5 deg of a divergent orientation, {near_edge} predicted "
        f"a stable edge within 2 deg of one (near-metastable), {other} other"
    )


def main() -> int:
    ok = per_push()
    ok = three_step_plan() and ok
    agreement_matrix()
    random_polygons()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
