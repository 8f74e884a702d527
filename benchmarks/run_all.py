"""Run every benchmark script in this folder, one after another, and print their figures.

python benchmarks/run_all.py            # all
python benchmarks/run_all.py planners   # those whose file name contains "planners"
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    scripts = sorted(
        p for p in HERE.glob("bench_*.py") if not argv or any(a in p.name for a in argv)
    )
    failed = 0
    for script in scripts:
        print(f"=== {script.name}", flush=True)
        start = time.perf_counter()
        rc = subprocess.call([sys.executable, str(script)])
        print(f"=== {script.name}: exit {rc}, {time.perf_counter() - start:.1f} s", flush=True)
        failed += rc != 0
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
