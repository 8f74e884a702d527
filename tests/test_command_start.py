"""``--time-limit`` counts from the command's start: the process's own start when run as the
console script (Python's start and the imports are part of what a user times), else the
call of ``main`` (tests run many commands in one process)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from feederkit.cli import app, common
from feederkit.cli.common import COMMAND_START, PROCESS_AGE_MAX_S, process_age_s

HEPTAGON = Path(__file__).resolve().parents[1] / "catalog" / "heptagon-fig17.json"
CUT = "left no time for the whole certificate"
TICKS = os.sysconf("SC_CLK_TCK")


@pytest.fixture(autouse=True)
def _unmarked():
    yield
    COMMAND_START.reset()  # whatever a test left: the next one starts unmarked


def _proc(tmp_path: Path, name: bytes, start_ticks: int, uptime_s: float) -> tuple[str, str]:
    """A /proc/self/stat line (fields 3-22 after the name, starttime last) and /proc/uptime."""
    stat = tmp_path / "stat"
    stat.write_bytes(b"4242 (" + name + b") S" + b" 0" * 18 + b" %d 0 0\n" % start_ticks)
    up = tmp_path / "uptime"
    up.write_text(f"{uptime_s:.2f} 100.00\n")
    return str(stat), str(up)


@pytest.mark.parametrize("name", [b"feederkit", b"a b) (c", "pyth\u00f6n".encode()])
def test_the_process_age_is_its_uptime_less_its_start(tmp_path, name):
    stat, up = _proc(tmp_path, name, 1000 * TICKS, 1001.25)
    assert process_age_s(stat, up) == pytest.approx(1.25, abs=1e-6)


@pytest.mark.parametrize(
    ("start_s", "uptime_s"), [(1000.0, 999.0), (1000.0, 1000.0 + PROCESS_AGE_MAX_S + 1.0)]
)
def test_an_implausible_age_is_not_known(tmp_path, start_s, uptime_s):
    # Started after now (another clock), or too old to be a command just started.
    stat, up = _proc(tmp_path, b"x", int(start_s * TICKS), uptime_s)
    assert process_age_s(stat, up) is None


def test_an_unreadable_proc_is_not_known(tmp_path):
    assert process_age_s(str(tmp_path / "missing"), str(tmp_path / "missing")) is None
    (tmp_path / "stat").write_bytes(b"4242 (x) S 1 2")  # cut short
    (tmp_path / "uptime").write_text("12.0 3.0\n")
    assert process_age_s(str(tmp_path / "stat"), str(tmp_path / "uptime")) is None


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="no /proc (not Linux)")
def test_a_fresh_process_knows_its_age():
    code = "from feederkit.cli.common import process_age_s; print(process_age_s())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    age = float(out.stdout)  # None would fail here: the age is known on Linux
    assert 0.0 < age <= PROCESS_AGE_MAX_S  # Python's start and the imports, a second or so


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

    def recording(argv=None, *, from_process=False):
        seen.append(from_process)
        return 0

    monkeypatch.setattr(app, "main", recording)
    with pytest.raises(SystemExit):
        app.run()
    assert seen == [True]


def test_a_run_that_fails_leaves_no_mark(monkeypatch):
    def broken(args):
        raise RuntimeError("the run's own machinery failed")

    monkeypatch.setattr(app, "_main", broken)
    with pytest.raises(RuntimeError):
        app.main(["plan", "--help"], from_process=True)
    assert COMMAND_START.at is None


@pytest.mark.parametrize(("age", "cut"), [(None, False), (29.9, True)])
def test_the_plan_command_counts_its_limit_from_the_process_start(monkeypatch, capsys, age, cut):
    # A process already 29.9 s old at a 30 s limit leaves the certificate no time: the
    # command says so; counted from the call of main, the same plan (0.2 s) gets its
    # certificate.
    monkeypatch.setattr(common, "process_age_s", lambda: age)
    args = ["plan", str(HEPTAGON), "--tolerance", "0.5", "--time-limit", "30"]
    assert app.main(args, from_process=True) == 1  # its landings read alike (section 8.4)
    assert (CUT in capsys.readouterr().err) is cut
    assert COMMAND_START.at is None  # the run is over: a later command starts afresh
