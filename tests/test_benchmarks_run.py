"""The quick benchmarks run to the end on the current code (a benchmark that crashes measures
nothing: bench_plans and bench_import_catalog both did once the library moved on).

Only the scripts that finish in seconds; each is its own process, as docs/performance.md runs
it. A missed target is exit 1 and is the benchmark's business on its own machine, not a
failure here; a traceback (exit 1 with one on stderr) or any other code is.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"

QUICK = [
    ("bench_plans.py",),
    ("bench_analysis.py",),
    ("bench_mix.py",),
    ("bench_import_catalog.py", "--parts", "300"),
    ("bench_goal_relation.py", "64-gon 1%, 3%"),
]


@pytest.mark.slow
@pytest.mark.parametrize("args", QUICK, ids=[a[0] for a in QUICK])
def test_the_quick_benchmark_runs_to_the_end(args):
    done = subprocess.run(
        [sys.executable, str(BENCH / args[0]), *args[1:]],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=BENCH.parent,
    )
    assert "Traceback" not in done.stderr, done.stderr[-2000:]
    assert done.returncode in (0, 1), done.stderr[-2000:]
    assert done.stdout.strip(), "the benchmark printed no figures"
