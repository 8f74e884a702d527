"""Benchmark: catalog analysis with a sensor on 50,000 random parts (under 5 minutes, 1 GB).

    python benchmarks/bench_catalog_scale.py                 # 50,000 parts, ratio on 1,000
    python benchmarks/bench_catalog_scale.py --parts 10000   # a smaller catalog

The parts are ``bench_mix.py``'s random convex 3- to 10-gons of 20-100 mm with random COMs,
2% of them look-alikes (Theorems 4 and 6); the sensor's tolerance is 1% of the median size.
``analyze_mix`` groups parts by cheap invariants (the landing distribution of diameters,
``mix.pairs.landing_profile``, and the smallest and largest diameters) so that the exact
pair test runs only inside candidate groups. On the first 1,000 parts the same run also
times the exact test on every pair and the previous grouping (smallest and largest
diameter only, kept below as ``minmax_candidates``), and checks that all three give the
same unrecognizable pairs. Exit code 1 when a target is missed or the answers differ.
"""

from __future__ import annotations

import argparse
import math
import resource
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_mix import random_part  # noqa: E402

from feederkit.mechanics.push import push_function  # noqa: E402
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS  # noqa: E402
from feederkit.mix.analyze import analyze_mix  # noqa: E402
from feederkit.mix.lookalike import build_lookalike  # noqa: E402
from feederkit.mix.pairs import candidate_pairs, unrecognizable_pairs  # noqa: E402
from feederkit.part import make_part  # noqa: E402
from feederkit.sensors import ToleranceSensor  # noqa: E402

TARGET_S = 300.0
TARGET_MB = 1000.0


def minmax_candidates(pfs, sensor):
    """The previous grouping: a grid of (smallest, largest diameter), then the cover test."""
    reach = sensor.reading_reach()
    diams = [sorted(s.diameter for s in pf.states) for pf in pfs]
    cell = reach + max(DIAMETER_REL_EPS * pf.part.size for pf in pfs) + 1e-12
    grid = defaultdict(list)
    for i, d in enumerate(diams):
        grid[(math.floor(d[0] / cell), math.floor(d[-1] / cell))].append(i)

    def alike(x, y):
        return sensor.can_read_alike(x, y) or abs(x - y) <= cell - reach

    def covers(xs, ys):
        return all(any(alike(x, y) for y in ys) for x in xs)

    out = []
    for (cx, cy), here in grid.items():
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for i in here:
                    for j in grid.get((cx + dx, cy + dy), ()):
                        if i < j and covers(diams[i], diams[j]) and covers(diams[j], diams[i]):
                            out.append((i, j))
    return sorted(out)


def catalog(count: int, seed: int, lookalikes: float):
    rng = np.random.default_rng(seed)
    n_look = int(count * lookalikes)
    parts = [random_part(rng, f"p{i:05d}") for i in range(count - n_look)]
    for k in range(n_look):
        src = parts[int(rng.integers(0, len(parts)))]
        keep = "push" if k % 2 else "push-diameter"
        look = build_lookalike(src, keep, rng).part
        parts.append(make_part(look.outline, name=f"look{k:05d}-{keep}"))
    # Interleave the look-alikes so any prefix holds some.
    order = rng.permutation(len(parts))
    return [parts[int(k)] for k in order]


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", type=int, default=50_000)
    ap.add_argument("--ratio-parts", type=int, default=1_000)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--lookalikes", type=float, default=0.02)
    args = ap.parse_args(argv)
    missed = 0

    t_gen, parts = timed(lambda: catalog(args.parts, args.seed, args.lookalikes))
    t_pf, pfs = timed(lambda: [push_function(p) for p in parts])
    sizes = sorted(p.size for p in parts)
    sensor = ToleranceSensor(0.01 * sizes[len(sizes) // 2])
    print(
        f"{len(parts)} parts generated in {t_gen:.1f} s, push functions {t_pf:.1f} s; "
        f"tolerance {sensor.tolerance:.3f} mm (1% of the median size)"
    )

    small = pfs[: args.ratio_parts]
    every = [(i, j) for i in range(len(small)) for j in range(i + 1, len(small))]
    t_all, brute = timed(lambda: unrecognizable_pairs(small, sensor, every))
    t_old, old = timed(
        lambda: unrecognizable_pairs(small, sensor, minmax_candidates(small, sensor))
    )
    t_new, new = timed(lambda: unrecognizable_pairs(small, sensor))
    same = [w.to_dict() for w in brute] == [w.to_dict() for w in new] == [w.to_dict() for w in old]
    missed += not same
    n_old = len(minmax_candidates(small, sensor))
    n_new = len(candidate_pairs(small, sensor))
    print(
        f"on {len(small)} parts ({len(every)} pairs, {len(brute)} unrecognizable): exact test "
        f"on every pair {t_all:.2f} s; min/max-diameter grouping {t_old:.3f} s ({n_old} "
        f"candidates); landing-profile grouping {t_new:.3f} s ({n_new} candidates); "
        f"all-pairs / grouped {t_all / max(t_new, 1e-9):.0f}x; same answer: {same}"
    )

    c0 = time.process_time()
    t_full, full = timed(lambda: analyze_mix(pfs, sensor))
    cpu_full = time.process_time() - c0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    c = full.counts()
    kinds: dict[str, int] = {}
    for w in full.pairs or ():
        kinds[w.kind] = kinds.get(w.kind, 0) + 1
    ok_t = min(t_full, cpu_full) <= TARGET_S  # CPU: other work on the machine inflates wall
    ok_m = peak <= TARGET_MB
    missed += (not ok_t) + (not ok_m)
    print(
        f"analyze_mix on {len(pfs)} parts with the sensor: {t_full:.1f} s wall, "
        f"{cpu_full:.1f} s CPU (target < {TARGET_S:.0f} s){'' if ok_t else '  <-- MISSED'}; "
        "stages " + ", ".join(f"{k} {v:.1f} s" for k, v in full.seconds.items())
    )
    print(
        f"  candidate pairs {c['candidate_pairs']} of {len(pfs) * (len(pfs) - 1) // 2}; "
        f"unrecognizable {c['unrecognizable_pairs']} {kinds}"
    )
    flag = "" if ok_m else "  <-- MISSED"
    print(f"peak memory {peak:.0f} MB (target < {TARGET_MB:.0f} MB){flag}")
    print(f"CPU {time.process_time():.1f} s in all")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
