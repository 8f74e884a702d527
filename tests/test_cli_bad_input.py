"""Bad input to every command of design.md's list: one ``error: ...`` line on stderr, exit 2.

Unknown names, missing files, impossible numbers and folders that do not exist are refused
before any planning, so each case is quick; a warning about the part must not come first.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cli.app import main

ROOT = Path(__file__).resolve().parents[1]
PART = str(ROOT / "catalog" / "l-bracket.json")
PLAN = str(ROOT / "tests" / "golden" / "isosceles-right-triangle.tolerance.json")

CASES = [
    ["demo", "--catalog-dir", "/nonexistent-feederkit"],
    ["demo", "--tolerance-percent", "-1"],
    ["part", "analyze", "no-such-part"],
    ["part", "analyze", PART, "--tolerance", "0"],
    ["part", "plot", PART, "-o", "picture.bmp"],
    ["plan", "no-such-part.json"],
    ["plan", PART, "--led-pitch", "-1"],
    ["plan", PART, "--noise", "0.1"],
    ["plan", PART, "--led-pitch", "0.5", "--noise", "1e7"],
    ["plan", PART, "--rotation-error", "200"],
    ["plan", PART, "--shape-tolerance", "-1"],
    ["plan", PART, "--shape-tolerance", "1e9"],
    ["plan", PART, "--com-tolerance", "1e9"],
    ["plan", PART, "--landings", "sideways"],
    ["plan", PART, "--accept", "pose-9"],
    ["plan", PART, "--objective", "fastest"],
    ["plan", PART, "--objective", "time"],
    ["plan", PART, "--time-limit", "nan"],
    ["plan", PART, "--memory-limit", "0"],
    ["plan", PART, "--grouping", "foo"],
    ["plan", PART, "--lumping", "foo"],
    ["plan", PART, "--cell", "no-such-cell.toml"],
    ["plan", PART, "-o", "/nonexistent-feederkit/dir/plan.json"],
    ["plan", PART, "--report", "/nonexistent-feederkit/r.html"],
    ["plan", PART, PART],
    ["plan"],
    ["plan", PART, "--bogus"],
    ["run", "no-such-plan.json"],
    ["run", PLAN, "--start-deg", "inf"],
    ["run", PLAN, PART],
    ["run", PLAN, "--start-deg", "10", "--all"],
    ["design", "sensor"],
    ["design", "sensor", "no-such-part"],
    ["design", "sensor", PART, PART, "--time-limit", "0"],
    ["design", "sensor", PART, PART, "--memory-limit", "0"],
    ["catalog", "list"],
    ["catalog", "add", "no-such-part.json"],
    ["catalog", "import", "/nonexistent-feederkit"],
    ["catalog", "show", "l-bracket"],
    ["changeover", "compile", "x", "--mix", "l-bracket:2,t-clip:-1"],
    ["changeover", "compile", "x", "--mix", "a,b", "-o", "/nonexistent-feederkit/a.json"],
    ["changeover", "show", "nosuch"],
    ["lookalike", PART, "--keep", "shape"],
    ["report", "no-such-plan.json", "-o", "r.html"],
    ["report", PLAN, "-o", "r.html", "--seconds-per-op", "-1"],
    ["simulate", "no-such-plan.json"],
    ["simulate", PLAN, "--require-success", "2"],
    ["no-such-command"],
]


@pytest.mark.parametrize("args", CASES, ids=lambda a: " ".join(Path(x).name for x in a))
def test_bad_input_is_one_error_line_and_exit_2(args, tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)  # no ./feederkit.db, no ./feederkit.toml
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    code = main(args)
    captured = capsys.readouterr()
    lines = [ln for ln in captured.err.splitlines() if ln.strip()]
    assert code == 2, captured.err
    assert len(lines) == 1 and lines[0].startswith("error: "), captured.err
    assert "Traceback" not in captured.err
    assert not list(tmp_path.iterdir()), "bad input wrote a file"


def test_a_memory_limit_below_what_the_command_holds_is_bad_input(capsys, tmp_path) -> None:
    # 50 MB: Python and feederkit alone hold about 100; every search ran out at once and
    # answered "no plan found within the memory limit" after loading the parts.
    assert main(["plan", PART, "--memory-limit", "50", "-o", str(tmp_path / "p.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--memory-limit 50 MB is no more than the command already" in err[0]
    assert not (tmp_path / "p.json").exists()
