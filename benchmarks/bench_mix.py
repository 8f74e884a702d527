"""Benchmark: ``catalog analyze`` on 10,000 random parts (issue 5).

Targets: behaviour classes alone under 10 s; classes plus the exact pair test for a 1% sensor
under 60 s; peak memory under 1 GB. The parts are random convex 3- to 10-gons of 20-100 mm
with random centers of mass, plus look-alikes (Theorems 4 and 6) of some of them so the
classes and pairs are not all trivial. The pair test prunes by diameters (no all-pairs pass);
the figure "all-pairs" estimates what the exact test on every pair would cost.

Run: ``python benchmarks/bench_mix.py [--parts N] [--seed S]``
"""

from __future__ import annotations

import argparse
import math
import resource
import time

import numpy as np

from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.mix.analyze import analyze_mix
from feederkit.mix.lookalike import build_lookalike
from feederkit.mix.pairs import inseparable_cross_pairs
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import ToleranceSensor


def random_part(rng: np.random.Generator, name: str):
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
            return make_part(part.outline, (float(com[0]), float(com[1])))
        except InputError:
            continue


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--lookalikes", type=float, default=0.02, help="share of look-alike parts")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)

    n_look = int(args.parts * args.lookalikes)
    t0 = time.perf_counter()
    parts = [random_part(rng, f"p{i:05d}") for i in range(args.parts - n_look)]
    for k in range(n_look):
        src = parts[int(rng.integers(0, len(parts)))]
        keep = "push" if k % 2 else "push-diameter"
        look = build_lookalike(src, keep, rng).part
        parts.append(make_part(look.outline, name=f"look{k:04d}-{keep}-{src.name}"))
    t_gen = time.perf_counter() - t0
    print(f"generated {len(parts)} parts ({n_look} look-alikes) in {t_gen:.1f} s")

    t0 = time.perf_counter()
    pfs = [push_function(p) for p in parts]
    t_pf = time.perf_counter() - t0
    sizes = sorted(p.size for p in parts)
    tol = 0.01 * sizes[len(sizes) // 2]
    sensor = ToleranceSensor(tol)

    from feederkit.sensors import NoSensor

    t0 = time.perf_counter()
    analyze_mix(pfs, NoSensor())
    t_classes = time.perf_counter() - t0
    t0 = time.perf_counter()
    full = analyze_mix(pfs, sensor)
    t_full = time.perf_counter() - t0

    # Cost of the exact test on one random pair, times the number of pairs: the all-pairs estimate.
    sample = 300
    t0 = time.perf_counter()
    for _ in range(sample):
        i, j = rng.integers(0, len(pfs), 2)
        inseparable_cross_pairs(pfs[int(i)], pfs[int(j)], sensor)
    per_pair = (time.perf_counter() - t0) / sample
    all_pairs = per_pair * len(pfs) * (len(pfs) - 1) / 2

    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    c = full.counts()
    kinds: dict[str, int] = {}
    for w in full.pairs or ():
        kinds[w.kind] = kinds.get(w.kind, 0) + 1
    print(f"push functions of {len(pfs)} parts: {t_pf:.2f} s")
    print(
        f"classes alone (signatures + classes): {t_classes:.2f} s  (target < 10 s; "
        f"+ push functions {t_pf + t_classes:.2f} s)  "
        f"{c['push_classes']} push classes, {c['push_diameter_classes']} push-diameter classes"
    )
    print(
        f"classes + exact pair test, tolerance {tol:.3f} mm (1% of the median size): "
        f"{t_full:.2f} s  (target < 60 s; + push functions {t_pf + t_full:.2f} s)"
    )
    print(
        f"  candidate pairs {c['candidate_pairs']} of {len(pfs) * (len(pfs) - 1) // 2}; "
        f"unrecognizable {c['unrecognizable_pairs']} {kinds}; stages {full.seconds}"
    )
    print(f"  all-pairs exact test (estimated from {sample} pairs): {all_pairs:.0f} s")
    print(f"peak memory (max RSS): {peak_mb:.0f} MB  (target < 1024 MB)")


if __name__ == "__main__":
    main()
