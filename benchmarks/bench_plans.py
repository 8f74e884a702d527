"""Benchmark: the plan file and its verification on the kinematic model (issue 3, items 4-5).

    python benchmarks/bench_plans.py

Every plan is verified before it is written, so verification must stay small next to
planning. For each case: the planner's time (for comparison), then ``plan_to_dict`` and
``verify_plan`` (rebuild the parts from hull and COM, every start, every reading extreme and
branch endpoint, every branch, rotations at both ends of each margin). Figures are medians
of repeated runs on this machine. Targets (ours): verification under 50 ms for a sample part,
under 1 s for the offset regular n-gons, random 64-gons and a 20-part mix, and never more than the
planner's own time plus 0.1 s. Exit code 1 when a target is missed.
"""

from __future__ import annotations

import json
import math
import random
import statistics
import sys
import time
from pathlib import Path

from feederkit.machine import build_machine
from feederkit.mechanics.push import push_function
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.plans import plan_to_dict, verify_plan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

REPEATS = 5
HERE = Path(__file__).resolve().parent


def regular(n: int, com: tuple[float, float]):
    pts = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    return push_function(make_part(make_outline(f"regular-{n}", pts, com=com)))


def random_convex(n: int, seed: int, name: str):
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]  # on an ellipse: all convex
    return push_function(make_part(make_outline(name, pts)))


def median_s(fn, repeats: int = REPEATS):
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def cases():
    for path in sorted((HERE.parent / "catalog").glob("*.json")):
        pf = push_function(make_part(load_outline_json(path)))
        yield f"sample {path.stem}, tolerance 3%", [pf], ToleranceSensor(0.03 * pf.part.size), 0.05
    for n in (12, 32, 64):
        yield (
            f"regular {n}-gon, COM (0.13, 0.05), sensorless",
            [regular(n, (0.13, 0.05))],
            NoSensor(),
            1.0,
        )
    yield (
        "regular 32-gon, COM (0.02, 0.008): 32 states, sensorless",
        [regular(32, (0.02, 0.008))],
        NoSensor(),
        1.0,
    )
    for seed in range(3):
        pf = random_convex(64, seed, f"random-64-{seed}")
        yield (
            f"random convex 64-gon #{seed}, tolerance 3%",
            [pf],
            ToleranceSensor(0.03 * pf.part.size),
            1.0,
        )
    mix = [random_convex(random.Random(s).randint(6, 10), 100 + s, f"mix-{s}") for s in range(20)]
    yield "20-part mix of 6- to 10-gons, tolerance 2%", mix, ToleranceSensor(0.02 * 30), 1.0


def main() -> int:
    missed = 0
    print(f"{'case':58} {'plan s':>8} {'file s':>8} {'verify s':>9} {'paths':>12} {'len':>4}")
    for name, pfs, sensor, target in cases():
        # The kinematic model the file's verification runs on (build_machine's default is the
        # strong model under 1 degree, whose physical states the plan file does not list).
        machine = build_machine(pfs, sensor, IDEAL)
        t_plan, result = median_s(lambda m=machine: plan(m), 1)
        t_file, data = median_s(lambda r=result, p=pfs: plan_to_dict(r, p))
        json.dumps(data)
        t_verify, report = median_s(lambda d=data: verify_plan(d))
        ok = report.ok and t_verify <= target and t_verify <= t_plan + 0.1
        missed += not ok
        flag = "" if ok else "  <-- MISSED" if report.ok else "  <-- FAILED VERIFICATION"
        print(
            f"{name:58} {t_plan:8.4f} {t_file:8.4f} {t_verify:9.4f} {report.paths:12.3g} "
            f"{data['stats']['length']:4d}{flag}"
        )
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
