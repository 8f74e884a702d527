"""Benchmark: ``plan`` with a time limit answers within it, on machines that run for minutes.

    python benchmarks/bench_deadline.py              # time limit 10 s, every case
    python benchmarks/bench_deadline.py 2 mix        # time limit 2 s, cases whose name has "mix"
    python benchmarks/bench_deadline.py 10 --memory 300   # and a memory limit of 300 MB

Each case runs in a fresh process (its machine built first, not timed) and calls
``feederkit.planning.api.plan`` with ``PlanningOptions(time_limit_s=T)``; the parent kills
it after ``3 T + 30`` s. Printed: wall and CPU seconds of ``plan``, the overshoot beyond the
limit (wall - T), peak memory, and the answer (length, proven lower bound, optimal or not,
or the one-line PlanningError). The cases are the hard ones of docs/performance.md: near-round
64- and 200-gons (radial noise 0.1-1 %) at a coarse tolerance, a 360-facet circle with a
flat cut, random outlines, mixes of 5-200 random 6-10-gons (60 x 40 mm) at 0.3 mm-5 %,
under the default uncertainty (rotation error 1 deg) and, marked "ideal", the ideal model.
Exit code 1 when some case overshoots by more than ``MAX_OVERSHOOT_S`` or crashes.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time

MAX_OVERSHOOT_S = 2.0

CASES = {
    "near-round 64-gon 1%, 0.3 mm": "[near_round(64, 0.01)]|0.3|unc",
    "near-round 64-gon 1%, 0.3 mm, ideal": "[near_round(64, 0.01)]|0.3|ideal",
    "near-round 200-gon 0.1%, 0.3 mm, ideal": "[near_round(200, 0.001)]|0.3|ideal",
    "near-round 200-gon 0.5%, 1%": "[near_round(200, 0.005)]|0.2|unc",
    "360-facet circle, flat cut, 0.3 mm, ideal": "[circle_cut()]|0.3|ideal",
    "random 50-point outline, 3%": "[random_convex(50, 7, 'r50')]|1.8|unc",
    "random 1000-point outline, 3%, ideal": "[random_convex(1000, 1, 'r1000')]|1.8|ideal",
    "5-part mix, 3%": "mix(5)|1.8|unc",
    "20-part mix, 5%": "mix(20)|3.0|unc",
    "50-part mix, 1%": "mix(50)|0.6|unc",
    "50-part mix, 1%, ideal": "mix(50)|0.6|ideal",
    "100-part mix, 0.3 mm": "mix(100)|0.3|unc",
    "200-part mix, 0.3 mm": "mix(200)|0.3|unc",
}

CHILD = r"""
import json, math, random, resource, sys, time
sys.path.insert(0, sys.argv[4])
from bench_planners import mix, random_convex
from feederkit.errors import PlanningError
from feederkit.machine import build_machine
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.planning.options import PlanningOptions
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

def near_round(n, noise, seed=0, r=10.0):
    rng = random.Random(seed)
    pts = []
    for k in range(n):
        a, f = 2 * math.pi * k / n, 1 + rng.uniform(-noise, noise)
        pts.append((r * f * math.cos(a), r * f * math.sin(a)))
    return push_function(make_part(make_outline(f"round-{n}", pts)))

def circle_cut(n=360, cut=0.9, r=10.0):
    pts = [(r * math.cos(2 * math.pi * k / n), max(r * math.sin(2 * math.pi * k / n), -cut * r))
           for k in range(n)]
    return push_function(make_part(make_outline("cut", pts)))

expr, tol, unc = sys.argv[1].split("|")
limit = float(sys.argv[2])
memory = None if sys.argv[3] == "none" else float(sys.argv[3])
model = IDEAL if unc == "ideal" else Uncertainty()
machine = build_machine(eval(expr), ToleranceSensor(eval(tol)), model)
t0, c0 = time.perf_counter(), time.process_time()
try:
    r = plan(machine, PlanningOptions(time_limit_s=limit, memory_limit_mb=memory))
    out = {"length": r.length, "lower": r.lower_bound, "optimal": r.optimal}
except PlanningError as e:
    out = {"error": str(e)}
out.update(states=machine.n, wall=time.perf_counter() - t0, cpu=time.process_time() - c0,
           peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
print(json.dumps(out))
"""


def main(argv: list[str]) -> int:
    memory = "none"
    if "--memory" in argv:
        k = argv.index("--memory")
        memory = argv[k + 1]
        argv = argv[:k] + argv[k + 2 :]
    limit = float(argv[0]) if argv else 10.0
    wanted = argv[1:]
    here = str(__import__("pathlib").Path(__file__).resolve().parent)
    print(f"time limit {limit:g} s, memory limit {memory} MB")
    head = ("case", "states", "wall s", "cpu s", "over s", "peak MB", "answer")
    print(f"{head[0]:42} {head[1]:>6} {head[2]:>7} {head[3]:>7} {head[4]:>7} {head[5]:>8}  answer")
    bad = 0
    worst = -1e9
    for name, spec in CASES.items():
        if wanted and not any(w in name for w in wanted):
            continue
        hard = 3 * limit + 30
        start = time.perf_counter()
        try:
            p = subprocess.run(
                [sys.executable, "-c", CHILD, spec, str(limit), memory, here],
                capture_output=True,
                text=True,
                timeout=hard,
            )
        except subprocess.TimeoutExpired:
            print(f"{name:42} killed after {hard:.0f} s  <-- MISSED", flush=True)
            bad += 1
            continue
        lines = p.stdout.strip().splitlines()
        if p.returncode != 0 or not lines:
            tail = (p.stderr.strip().splitlines() or ["?"])[-1]
            print(f"{name:42} crashed: {tail}  <-- MISSED", flush=True)
            bad += 1
            continue
        r = json.loads(lines[-1])
        over = r["wall"] - limit
        worst = max(worst, over)
        if "error" in r:
            answer = "PlanningError: " + r["error"][:70]
        else:
            answer = f"length {r['length']}, bound {r['lower']}, optimal {r['optimal']}"
        flag = "  <-- MISSED" if over > MAX_OVERSHOOT_S else ""
        bad += bool(flag)
        print(
            f"{name:42} {r['states']:6d} {r['wall']:7.2f} {r['cpu']:7.2f} {over:7.2f} "
            f"{r['peak_mb']:8.0f}  {answer}{flag}  ({time.perf_counter() - start:.0f} s in all)",
            flush=True,
        )
    print(f"largest overshoot {worst:.2f} s (allowed {MAX_OVERSHOOT_S:g} s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
