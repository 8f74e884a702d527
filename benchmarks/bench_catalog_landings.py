"""Catalog analysis over landings at scale: ``bench_catalog_scale.py``'s random parts, each
face up and face down (``landings_of_outline``), the members ``feederkit catalog analyze``
analyzes (docs/mixes.md).

    python benchmarks/bench_catalog_landings.py [PARTS]     # default 50,000 parts

Prints the generation and push-function times, then ``analyze_mix`` over the landings (wall
and CPU seconds, candidate pairs, unrecognizable pairs, its stages) and the process's peak
resident memory (the parts and their push functions included). Targets (issue 12, item 6,
set for parts): under 300 s and 1 GB; exit code 1 when one is missed (both met since
2026-12-03: 861 MB, docs/performance.md).
"""

from __future__ import annotations

import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_catalog_scale import TARGET_MB, TARGET_S, catalog  # noqa: E402

from feederkit.landing.model import landings_of_outline  # noqa: E402
from feederkit.mechanics.push import push_function  # noqa: E402
from feederkit.mix.analyze import analyze_mix  # noqa: E402
from feederkit.sensors import ToleranceSensor  # noqa: E402


def main(argv: list[str]) -> int:
    n = int(argv[0]) if argv else 50_000
    t = time.perf_counter()
    parts = catalog(n, 5, 0.02)
    t_gen = time.perf_counter() - t
    t = time.perf_counter()
    pfs = [push_function(x.part) for p in parts for x in landings_of_outline(p)]
    t_pf = time.perf_counter() - t
    sizes = sorted(p.size for p in parts)
    sensor = ToleranceSensor(0.01 * sizes[len(sizes) // 2])
    cpu, t = time.process_time(), time.perf_counter()
    result = analyze_mix(pfs, sensor)
    wall, cpu = time.perf_counter() - t, time.process_time() - cpu
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    stages = ", ".join(f"{k} {v:.1f} s" for k, v in result.seconds.items())
    print(
        f"{n} parts, {len(pfs)} landings (generated in {t_gen:.0f} s, push functions "
        f"{t_pf:.0f} s); tolerance {sensor.tolerance:.3f} mm"
    )
    print(
        f"analyze_mix over the landings: {wall:.1f} s wall, {cpu:.1f} s CPU ({stages}); "
        f"{result.candidates} candidate pairs, {len(result.pairs or ())} unrecognizable"
    )
    ok_t, ok_m = min(wall, cpu) <= TARGET_S, peak <= TARGET_MB
    print(f"time target {TARGET_S:.0f} s: {'met' if ok_t else 'MISSED'}")
    print(f"peak memory {peak:.0f} MB, target {TARGET_MB:.0f} MB: {'met' if ok_m else 'MISSED'}")
    return 0 if ok_t and ok_m else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
