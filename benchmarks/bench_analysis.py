"""Benchmark: the analysis of one 1,000-vertex outline (issue 2: well under 50 ms).

    python benchmarks/bench_analysis.py

"Analysis" is what ``feederkit part analyze --tolerance E --json`` does after reading the file:
validate the outline, build the part (hull, COM), the exact push function, the symmetry of
the push and push-diameter functions, the Fig. 14 class, and the JSON object. Each figure is
the median and the best wall time of repeated runs, and the best CPU time of this process.
The verdict uses the best CPU time, the cost of the code itself: on a shared 2-core machine
wall times also measure whatever else is running (the load average is printed). Exit code 1
when it misses the target.
"""

from __future__ import annotations

import math
import os
import random
import statistics
import sys
import time
from collections.abc import Callable

from feederkit.mechanics.analysis import analysis_to_dict, analyze_part
from feederkit.mechanics.polygon_classes import polygon_class
from feederkit.mechanics.push import push_function
from feederkit.mechanics.symmetry import symmetry
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import ToleranceSensor

TARGET_MS = 50.0
REPEATS = 30
N = 1000


def regular(n: int) -> list[tuple[float, float]]:
    return [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]


def random_convex(n: int, seed: int) -> list[tuple[float, float]]:
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    a, b = 30.0, 20.0  # an ellipse, mm: every point is a hull vertex
    return [(a * math.cos(t), b * math.sin(t)) for t in angles]


def gear(n: int) -> list[tuple[float, float]]:
    """A non-convex outline (a 50-tooth gear, mm) whose hull keeps the tooth tips."""
    out = []
    for k in range(n):
        t = 2 * math.pi * k / n
        r = 20.0 + (1.5 if (k // 10) % 2 == 0 else 0.0)
        out.append((r * math.cos(t), r * math.sin(t)))
    return out


CASES: dict[str, tuple[list[tuple[float, float]], tuple[float, float] | None]] = {
    "regular 1000-gon, COM at the centre": (regular(N), None),
    "regular 1000-gon, COM at (0.13, 0.05)": (regular(N), (0.13, 0.05)),
    "random convex 1000-gon (ellipse)": (random_convex(N, 1), (1.0, -2.0)),
    "1000-vertex gear outline": (gear(N), None),
}


def timed(fn: Callable[[], object]) -> tuple[float, float, float]:
    """Median and best wall time and best CPU time (ms) of REPEATS calls."""
    fn()  # warm up
    wall, cpu = [], []
    for _ in range(REPEATS):
        start, start_cpu = time.perf_counter(), time.process_time()
        fn()
        cpu.append((time.process_time() - start_cpu) * 1000.0)
        wall.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(wall), min(wall), min(cpu)


def main() -> int:
    sensor = ToleranceSensor(0.01)
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"analysis of a {N}-vertex outline; target: under {TARGET_MS:.0f} ms (load {load})")
    print(f"{'case':40s} {'stage':18s} {'median ms':>10s} {'best ms':>9s} {'best CPU ms':>12s}")
    worst = 0.0
    for name, (vertices, com) in CASES.items():
        outline = make_outline("bench", vertices)
        part = make_part(outline, com)
        pf = push_function(part)
        stages: dict[str, Callable[[], object]] = {
            "outline": lambda v=vertices: make_outline("bench", v),
            "part (hull, COM)": lambda o=outline, c=com: make_part(o, c),
            "push function": lambda p=part: push_function(p),
            "symmetry": lambda f=pf: symmetry(f),
            "class": lambda f=pf: polygon_class(f, sensor),
            "total": lambda v=vertices, c=com: analysis_to_dict(
                analyze_part(make_part(make_outline("bench", v), c), sensor)
            ),
        }
        for stage, fn in stages.items():
            med, best, cpu = timed(fn)
            print(f"{name:40s} {stage:18s} {med:10.2f} {best:9.2f} {cpu:12.2f}")
            if stage == "total":
                worst = max(worst, cpu)
        print(f"{'':40s} hull {len(part.hull)} vertices, {pf.n} stable states")
    ok = worst < TARGET_MS
    verdict = "ok" if ok else "MISSED"
    print(f"slowest total (best CPU time): {worst:.2f} ms (target {TARGET_MS:.0f} ms): {verdict}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
