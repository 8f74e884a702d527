"""``--time-limit`` counts from the command's start: the process's own start when run as the
console script (Python's start and the imports are part of what a user times), else the
call of ``main`` (tests run many commands in one process)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from feederkit.cli import app, common
from feederkit.cli.common import COMMAND_START, PROCESS_AGE_MAX_S, process_age_s

HEPTAGON = Path(__file__).resolve().parents[1] / "catalog" / "heptagon-fig17.json"
CUT = "left no time for the whole certificate"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="no /proc (not Linux)")
def test_a_fresh_process_knows_its_age():
    code = "from feederkit.cli.common import process_age_s; print(process_age_s())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    age = float(out.stdout)  # None would fail here: the age is known on Linux
    assert 0.0 < age < 10.0  # Python's start and the imports, a second or so
    # This long-lived test process is too old to be a command just started.
    assert process_age_s() is None or process_age_s() <= PROCESS_AGE_MAX_S


def test_the_clock_starts_at_the_process_start_only_when_asked(monkeypatch):
    monkeypatch.setattr(common, "process_age_s", lambda: 5.0)
    COMMAND_START.mark(True)
    assert time.monotonic() - COMMAND_START.started() == pytest.approx(5.0, abs=0.5)
    COMMAND_START.mark(False)
    assert time.monotonic() - COMMAND_START.started() == pytest.approx(0.0, abs=0.5)
    monkeypatch.setattr(common, "process_age_s", lambda: None)  # not known: now
    COMMAND_START.mark(True)
    assert time.monotonic() - COMMAND_START.started() == pytest.approx(0.0, abs=0.5)
    COMMAND_START.reset()
    assert COMMAND_START.at is None


def test_the_console_script_counts_from_the_process_start(monkeypatch):
    seen: list[bool] = []
    monkeypatch.setattr(
        app, "main", lambda argv=None, *, from_process=False: seen.append(from_process) or 0
    )
    with pytest.raises(SystemExit):
        app.run()
    assert seen == [True]


@pytest.mark.parametrize(("age", "cut"), [(None, False), (9.9, True)])
def test_the_plan_command_counts_its_limit_from_the_process_start(monkeypatch, capsys, age, cut):
    # A process already 9.9 s old at a 10 s limit leaves the certificate no time: the
    # command says so; counted from the call of main, the same plan gets its certificate.
    monkeypatch.setattr(common, "process_age_s", lambda: age)
    args = ["plan", str(HEPTAGON), "--tolerance", "0.5", "--time-limit", "10"]
    assert app.main(args, from_process=True) == 1  # its landings read alike (section 8.4)
    assert (CUT in capsys.readouterr().err) is cut
    assert COMMAND_START.at is None  # the run is over: a later command starts afresh
