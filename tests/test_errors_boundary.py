"""The command line's one error boundary (feederkit.cli.app.main): every error is one line on
stderr with an exit code (design.md), never a traceback; a bug says so and names its log."""

from __future__ import annotations

import errno
import re
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

import feederkit
from feederkit.cli import catalog as catalog_cli
from feederkit.cli.app import main


@pytest.fixture
def db(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    path = tmp_path / "cat.db"
    assert main(["catalog", "init", "--catalog", str(path)]) == 0
    return path


def fail_with(monkeypatch, exc: BaseException) -> None:
    """Make ``catalog list`` raise ``exc`` from inside the library."""

    def boom(*args, **kwargs):
        raise exc

    monkeypatch.setattr(catalog_cli, "list_parts", boom)


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith("error: ")
    return lines[0]


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"feederkit {feederkit.__version__}"


def test_a_bug_says_so_and_names_its_log(db, capsys, monkeypatch):
    fail_with(monkeypatch, ZeroDivisionError("division by zero"))
    assert main(["catalog", "list", "--catalog", str(db)]) == 70
    line = one_error_line(capsys.readouterr().err)
    assert "this is a bug in feederkit" in line and "ZeroDivisionError" in line
    log = Path(re.search(r"details in (\S+\.log)", line)[1])
    try:
        text = log.read_text()
        assert "Traceback" in text and "ZeroDivisionError" in text and "boom" in text
    finally:
        log.unlink()


@pytest.mark.parametrize(
    ("exc", "expected"),
    [
        (
            OSError(errno.ENOSPC, "No space left on device", "out/plan.json"),
            "out/plan.json: the disk is full",
        ),
        (OSError(errno.EACCES, "Permission denied", "/etc/x.db"), "/etc/x.db: permission denied"),
        (OSError(errno.ENAMETOOLONG, "File name too long", "a" * 300), "255 bytes"),
        (OverflowError("int too large to convert to float"), "a number is too large"),
        (RecursionError("maximum recursion depth exceeded"), "nested too deeply"),
        (UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte"), "not UTF-8 text"),
        (sqlite3.OperationalError("disk I/O error"), "catalog error (disk I/O error"),
    ],
    ids=["ENOSPC", "EACCES", "ENAMETOOLONG", "overflow", "recursion", "utf8", "sqlite"],
)
def test_system_errors_are_one_line_and_exit_2(db, capsys, monkeypatch, exc, expected):
    fail_with(monkeypatch, exc)
    assert main(["catalog", "list", "--catalog", str(db)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert expected in line
    log = re.search(r"details in (\S+\.log)", line)
    assert log is not None  # the traceback is kept in case it was a bug after all
    Path(log[1]).unlink()


def test_ctrl_c_in_a_command_is_one_line_and_130(db, capsys, monkeypatch):
    fail_with(monkeypatch, KeyboardInterrupt())
    assert main(["catalog", "list", "--catalog", str(db)]) == 130
    assert one_error_line(capsys.readouterr().err) == "error: interrupted"


STARTUP_CTRL_C = """
import sys

class CtrlC:
    def find_spec(self, name, path=None, target=None):
        if name == "feederkit.cli.common":
            raise KeyboardInterrupt
        return None

sys.meta_path.insert(0, CtrlC())
from feederkit.cli.app import run
run()
"""


def test_ctrl_c_during_start_up_is_one_line_and_130():
    proc = subprocess.run(
        [sys.executable, "-c", STARTUP_CTRL_C, "catalog", "list"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr.strip() == "error: interrupted"
