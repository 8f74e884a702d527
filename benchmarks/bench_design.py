"""Benchmark: ``design sensor`` tables (critical tolerances and every length step).

Targets: the whole sensor design table (every pair's exact critical tolerance, the mix's,
and the optimal plan length's steps with all their breakpoints up to the critical
tolerance, each step's plan verified) for a 20-part mix in under 10 s, for a 50-part mix in
under 60 s. Two families of mixes: random convex 6- to 10-gons on one 60 x 40 mm ellipse
(as benchmarks/bench_planners.py: similar parts, small critical tolerances) and random
convex 3- to 10-gons of 20-100 mm (as benchmarks/bench_mix.py: varied sizes, larger
critical tolerances, so longer plans to prove).

Run: ``python benchmarks/bench_design.py [--quick]``
"""

from __future__ import annotations

import argparse
import math
import random
import resource
import signal
import sys
import time

import numpy as np

from feederkit.design.sensor import design_tolerance
from feederkit.design.steps import mix_breakpoints
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part


def ellipse_part(n: int, seed: int, name: str):
    """Random angles on a 60 x 40 mm ellipse: every point is a hull vertex."""
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]
    return push_function(make_part(make_outline(name, pts)))


def ellipse_mix(count: int):
    return [
        ellipse_part(random.Random(s).randint(6, 10), 100 + s, f"mix-{s}") for s in range(count)
    ]


def varied_part(rng: np.random.Generator, name: str):
    """A random convex polygon (3-10 vertices, 20-100 mm) with a random COM inside."""
    while True:
        k = int(rng.integers(3, 11))
        size = float(rng.uniform(20.0, 100.0))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, k))
        r = rng.uniform(0.6, 1.0, k) * size / 2.0
        pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
        try:
            part = make_part(make_outline(name, pts.tolist()))
            hull = np.asarray(part.hull)
            w = rng.dirichlet(np.ones(len(hull)))
            com = 0.5 * (w @ hull) + 0.5 * hull.mean(axis=0)
            return push_function(make_part(part.outline, (float(com[0]), float(com[1]))))
        except InputError:
            continue


def varied_mix(count: int, seed: int = 1):
    rng = np.random.default_rng(seed)
    return [varied_part(rng, f"p{i}") for i in range(count)]


class GaveUp(Exception):
    """A case ran past its cap."""


def _alarm(signum, frame):
    raise GaveUp


CAP = 3.0
"""A case is stopped after this many times its target (and counts as slow)."""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the 20-part mixes only")
    args = ap.parse_args()
    cases = [
        ("20-part mix, 6-10-gons on one ellipse", lambda: ellipse_mix(20), 10.0),
        ("20-part mix, 3-10-gons of 20-100 mm", lambda: varied_mix(20), 10.0),
    ]
    if not args.quick:
        cases += [
            ("50-part mix, 6-10-gons on one ellipse", lambda: ellipse_mix(50), 60.0),
            ("50-part mix, 3-10-gons of 20-100 mm", lambda: varied_mix(50), 60.0),
        ]
    print(
        "| case | states | breakpoints | critical mm | steps (length) | s | target | |\n"
        "| --- | ---: | ---: | ---: | --- | ---: | ---: | --- |"
    )
    failed = 0
    for name, build, target in cases:
        pfs = build()
        states = sum(pf.n for pf in pfs)
        signal.signal(signal.SIGALRM, _alarm)
        signal.alarm(int(CAP * target))
        t = time.perf_counter()
        try:
            design = design_tolerance(pfs)
        except GaveUp:
            failed += 1
            print(
                f"| {name} | {states} | {len(mix_breakpoints(pfs))} | - | - | "
                f"> {CAP * target:g} (gave up) | {target:g} | SLOW |",
                flush=True,
            )
            continue
        finally:
            signal.alarm(0)
        wall = time.perf_counter() - t
        lengths = ",".join(str(s.length) for s in design.steps)
        x = design.critical_tolerance
        ok = wall < target
        failed += not ok
        print(
            f"| {name} | {states} | {len(mix_breakpoints(pfs))} | "
            f"{'none' if x is None else f'{x:.4g}'} | {len(design.steps)} ({lengths}) | "
            f"{wall:.2f} | {target:g} | {'ok' if ok else 'SLOW'} |",
            flush=True,
        )
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"peak memory {peak:.0f} MB")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
