"""``feederkit plan`` answers within its time limit, its own plan's verification and file
included: the command end to end in a fresh process, as a user runs it
(benchmarks/bench_command_deadline.py measures more cases; docs/planning.md, "The command's
limit")."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

LIMIT_S = 10.0
SLACK_S = 3.0
"""What the command may take past its limit: the planner's own overshoot and the first
plan's grace (``FIRST_PLAN_GRACE_S``, not needed by this case), and the start of the
subprocess before Python runs. It was 2.5 s: in CI's parallel slow run the command answered
after 12.6 and 12.7 s at a 10 s limit, when the limit was counted from the command's call
(about 0.8 s after Python's start); it now counts from the process's start."""


def _mix(folder: Path, count: int, monkeypatch) -> list[str]:
    """The benchmark's mix (bench_command_deadline.mix) written as outline files."""
    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from bench_command_deadline import mix

    paths = []
    for s, outline in enumerate(mix(count)):
        path = folder / f"{s:03d}-{outline['name']}.json"
        path.write_text(json.dumps(outline))
        paths.append(str(path))
    return paths


@pytest.mark.slow  # about 10 s
def test_a_large_optimal_plan_gives_way_to_one_the_limit_can_verify(tmp_path, monkeypatch):
    # The 100-part mix at 0.5 % under 1 degree: its exact tie-breaks make a 47,000-node plan
    # whose file, verification and output take about 5 s after the planner; under a 10 s
    # limit the command ended 4-6 s late with it. Now the plan's verification is committed
    # to the planner's deadline as it is built, and a smaller plan of the same proven
    # length is written in time.
    out = tmp_path / "plan.json"
    command = [sys.executable, "-c", "from feederkit.cli.app import run; run()"]
    args = [*command, "plan", *_mix(tmp_path, 100, monkeypatch)]
    args += ["--tolerance", "0.3", "--landings", "up", "--time-limit", f"{LIMIT_S:g}"]
    start = time.perf_counter()
    proc = subprocess.run([*args, "-o", str(out)], capture_output=True, text=True, timeout=120)
    wall = time.perf_counter() - start
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert wall <= LIMIT_S + SLACK_S, f"answered after {wall:.1f} s"
    stats = json.loads(out.read_text())["stats"]
    assert stats["length"] == 4 and stats["lower_bound"] == 4 and stats["optimal"]
