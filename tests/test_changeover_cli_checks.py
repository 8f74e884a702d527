"""``changeover compile`` and ``changeover remove`` as catalog writers: ``--wait`` for a busy
catalog (the busy message advises it, catalog.md "Busy"), and a bad changeover name refused
before any planning (it used to be refused by the store, after the plan and its report)."""

from __future__ import annotations

import json
import sqlite3
import time
import unicodedata
from pathlib import Path

import pytest
from shared import catalog_snapshot as snapshot
from shared import one_line_error

import feederkit.cli.changeover as cli_changeover
from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


@pytest.fixture
def db(tmp_path, capsys) -> Path:
    path = tmp_path / "cat.db"
    for part in ("octagon", "rectangle-2x1"):
        assert main(["catalog", "add", str(CATALOG / f"{part}.json"), "--catalog", str(path)]) == 0
    capsys.readouterr()
    return path


COMPILE = ["changeover", "compile", "line", "--mix", "octagon,rectangle-2x1", "--tolerance", "0.1"]


@pytest.mark.parametrize(
    "args",
    [[*COMPILE, "--rotation-error", "0"], ["changeover", "remove", "line"]],
    ids=["compile", "remove"],
)
def test_a_busy_catalog_is_waited_for_as_long_as_wait_says(db, capsys, args):
    if args[1] == "remove":
        # Stored; exit 1: the ideal plan holds no rotation error on a feeder that vibrates.
        assert main([*COMPILE, "--rotation-error", "0", "--catalog", str(db)]) == 1
        capsys.readouterr()
    before = snapshot(db)
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")
    try:
        t0 = time.monotonic()
        code = main([*args, "--catalog", str(db), "--wait", "0.3"])
        waited = time.monotonic() - t0
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    err = capsys.readouterr().err
    assert code == 2, err
    assert "waiting up to 0.3 s" in err
    assert "still busy after 0.3 s" in err and "--wait SECONDS" in err
    assert waited >= 0.3
    assert snapshot(db) == before


def test_a_bad_changeover_name_is_refused_before_the_plan(db, capsys, monkeypatch, tmp_path):
    def no_plan(*args, **kwargs):
        raise AssertionError("planned for a name the store refuses")

    monkeypatch.setattr(cli_changeover, "compile_changeover", no_plan)
    monkeypatch.setattr(cli_changeover, "load_parts", no_plan)
    report = tmp_path / "r.html"
    args = ["changeover", "compile", "bad/name", "--mix", "octagon,rectangle-2x1"]
    err = one_line_error(capsys, [*args, "--report", str(report), "--catalog", str(db)])
    assert "invalid changeover name 'bad/name'" in err
    assert not report.exists()


def test_a_changeover_name_is_one_name_however_it_is_spelled(db, capsys):
    """'Linie Ü' typed on Linux (NFC) and pasted from a macOS file name (NFD) look the same:
    one changeover, as one part (catalog.md, names)."""
    nfc, nfd = unicodedata.normalize("NFC", "Linie Ü"), unicodedata.normalize("NFD", "Linie Ü")
    assert nfc != nfd
    args = ["--mix", "octagon,rectangle-2x1", "--tolerance", "0.1", "--rotation-error", "0"]
    assert main(["changeover", "compile", nfd, *args, "--catalog", str(db)]) == 1  # stored
    capsys.readouterr()
    err = one_line_error(capsys, ["changeover", "compile", nfc, *args, "--catalog", str(db)])
    assert "already exists" in err
    assert main(["changeover", "show", nfc, "--catalog", str(db)]) == 0
    capsys.readouterr()
    assert main(["changeover", "remove", nfc, "--catalog", str(db)]) == 0
    capsys.readouterr()
    assert main(["changeover", "list", "--json", "--catalog", str(db)]) == 0
    assert json.loads(capsys.readouterr().out) == []
