"""``feederkit catalog ...`` on busy, damaged or mistyped input: one line, exit 2, catalog as
it was; and the commands a new user expects (remove NAME@REV, what changed, did you mean)."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
from shared import catalog_snapshot as snapshot

from feederkit.cli.app import main
from feederkit.outline import make_outline, save_outline_json


@pytest.fixture
def db(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    path = tmp_path / "cat.db"
    assert main(["catalog", "init", "--catalog", str(path)]) == 0
    return path


def square(path: Path, side: float = 10.0, name: str | None = None) -> Path:
    save_outline_json(
        make_outline(name or path.stem, [(0, 0), (side, 0), (side, side), (0, side)]), path
    )
    return path


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err
    assert lines[-1].startswith("error: "), err
    return lines[-1]


def test_busy_catalog_waits_then_one_line(tmp_path, db, capsys):
    part = square(tmp_path / "l-bracket.json")
    before = snapshot(db)
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")
    try:
        code, _, err = run(
            capsys, "catalog", "add", str(part), "--catalog", str(db), "--wait", "0.2"
        )
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    assert code == 2
    assert "busy" in err and "waiting up to 0.2 s" in err
    assert "--wait" in error_line(err) and str(db) in error_line(err)
    assert snapshot(db) == before
    assert run(capsys, "catalog", "add", str(part), "--catalog", str(db), "--wait", "-1")[0] == 2


def test_damaged_row_is_one_line_with_the_fix(tmp_path, db, capsys):
    assert (
        main(["catalog", "add", str(square(tmp_path / "l-bracket.json")), "--catalog", str(db)])
        == 0
    )
    conn = sqlite3.connect(db)
    conn.execute("UPDATE revisions SET com_x = 99.0")
    conn.commit()
    conn.close()
    code, _, err = run(capsys, "catalog", "show", "l-bracket", "--catalog", str(db))
    assert code == 2
    line = error_line(err)
    assert "l-bracket@1" in line and "center of mass" in line
    assert "feederkit catalog remove l-bracket@1" in line
    assert run(capsys, "catalog", "remove", "l-bracket@1", "--catalog", str(db))[0] == 0
    assert json.loads(run(capsys, "catalog", "list", "--json", "--catalog", str(db))[1]) == []


def test_remove_one_revision_and_what_changed(tmp_path, db, capsys):
    part = square(tmp_path / "l-bracket.json")
    assert main(["catalog", "add", str(part), "--catalog", str(db)]) == 0
    code, out, _ = run(
        capsys, "catalog", "add", str(part), "--hull-tolerance", "0.5", "--catalog", str(db)
    )
    assert code == 0
    assert "revision 2 (revised: hull_tolerance: default -> 0.5)" in out
    square(part, side=12.0)
    code, out, _ = run(
        capsys,
        "catalog",
        "add",
        str(part),
        "--hull-tolerance",
        "0.5",
        "--json",
        "--catalog",
        str(db),
    )
    (outcome,) = json.loads(out)
    assert outcome["revision"] == 3 and outcome["changes"][0].startswith("file changed")
    code, out, _ = run(capsys, "catalog", "remove", "l-bracket@2", "--catalog", str(db))
    assert code == 0 and "removed l-bracket revision 2" in out
    shown = json.loads(
        run(capsys, "catalog", "show", "l-bracket", "--json", "--catalog", str(db))[1]
    )
    assert [r["revision"] for r in shown["revisions"]] == [1, 3]
    shown = json.loads(
        run(capsys, "catalog", "show", "l-bracket@1", "--json", "--catalog", str(db))[1]
    )
    assert shown["revision"] == 1
    code, _, err = run(capsys, "catalog", "remove", "l-bracket@2", "--catalog", str(db))
    assert code == 2 and "no revision 2" in error_line(err)


def test_unknown_name_and_missing_file(tmp_path, db, capsys):
    assert (
        main(["catalog", "add", str(square(tmp_path / "l-bracket.json")), "--catalog", str(db)])
        == 0
    )
    code, _, err = run(capsys, "catalog", "show", "l-brackt", "--catalog", str(db))
    assert code == 2 and "did you mean 'l-bracket'?" in error_line(err)
    code, _, err = run(capsys, "catalog", "add", "missing/part.dxf", "--catalog", str(db))
    assert code == 2 and error_line(err) == "error: missing/part.dxf: no such file"
    long_name = "\u0436" * 150 + ".json"  # 150 characters, over 255 bytes
    code, _, err = run(capsys, "catalog", "add", long_name, "--catalog", str(db))
    assert code == 2 and "File name too long" in error_line(err)
    code, _, err = run(capsys, "catalog", "list", "--catalog", str(db) + "x" * 300)
    assert code == 2 and "File name too long" in error_line(err)


@pytest.mark.parametrize("name", [".", "..", "a\u202eb", "a\u200bb", "\u0436" * 130])
def test_hostile_names_from_the_command_line(tmp_path, db, capsys, name):
    part = square(tmp_path / "p.json")
    before = snapshot(db)
    code, _, err = run(capsys, "catalog", "add", str(part), "--name", name, "--catalog", str(db))
    assert code == 2 and "invalid part name" in error_line(err)
    assert snapshot(db) == before


def test_analyze_exits_1_when_pairs_cannot_be_told_apart(tmp_path, db, capsys):
    for name in ("twin-a", "twin-b"):
        path = tmp_path / f"{name}.json"
        save_outline_json(make_outline(name, [(0, 0), (12, 0), (9, 7), (2, 5)]), path)
        assert main(["catalog", "add", str(path), "--catalog", str(db)]) == 0
    capsys.readouterr()
    code, out, err = run(
        capsys, "catalog", "analyze", "--tolerance", "0.01", "--json", "--catalog", str(db)
    )
    assert code == 1, err
    # Each landing is a member (face up and face down, as plan plans the two parts).
    pairs = {frozenset((p["part_a"], p["part_b"])) for p in json.loads(out)["unrecognizable_pairs"]}
    assert pairs == {
        frozenset(("twin-a/up", "twin-b/up")),
        frozenset(("twin-a/down", "twin-b/down")),
    }
    last = [line for line in err.splitlines() if line.strip()][-1]
    # A result to act on (exit 1) is not an error of the input: no "error:" prefix.
    assert last.startswith("result: 2 pairs of landings") and "twin-a/up & twin-b/up" in last, err
    assert "error:" not in err
    # Without a sensor no pair is told apart (section 8.6): a result to act on too (rev53 #6).
    code, _, err = run(capsys, "catalog", "analyze", "--json", "--catalog", str(db))
    assert code == 1 and err.strip().splitlines()[-1].startswith("result: without a sensor")


def test_a_missing_catalog_is_worded_alike_by_every_command(tmp_path, capsys):
    missing = str(tmp_path / "none.db")
    lines = set()
    for args in (
        ["list"],
        ["show", "x"],
        ["analyze"],
        ["export", "x", "-o", str(tmp_path / "p.json")],
    ):
        assert main(["catalog", *args, "--catalog", missing]) == 2
        lines.add(capsys.readouterr().err.strip())
    want = f"error: {missing}: no catalog there (create one with 'feederkit catalog init')"
    assert lines == {want}


@pytest.mark.parametrize("command", ["show", "export"])
def test_a_revision_given_twice_and_differently_is_refused(tmp_path, db, capsys, command):
    part = square(tmp_path / "clip.json")
    assert main(["catalog", "add", str(part), "--catalog", str(db)]) == 0
    square(part, side=12.0)
    assert main(["catalog", "add", str(part), "--catalog", str(db)]) == 0
    capsys.readouterr()
    out = ["-o", str(tmp_path / "x.json")] if command == "export" else []
    args = ["catalog", command, "clip@1", *out, "--catalog", str(db)]
    code, _, err = run(capsys, *args, "--revision", "2")
    assert code == 2 and error_line(err) == (
        "error: clip@1: the revision is given twice (1 and --revision 2)"
    )
    assert not (tmp_path / "x.json").exists()
    code, stdout, _ = run(capsys, *args, "--revision", "1", "--json")
    assert code == 0 and json.loads(stdout)["revision"] == 1
