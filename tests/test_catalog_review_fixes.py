"""Review fixes: an empty file is no catalog for reads, ``import --skip-bad`` skips a name
taken in the catalog, and ``demo`` gives advice that works for it (docs/catalog.md)."""

from __future__ import annotations

import json
import shutil
import sqlite3
from pathlib import Path

import pytest
from shared import catalog_snapshot as snapshot

from feederkit.catalog import SCHEMA_VERSION, list_parts, open_catalog, schema_version
from feederkit.cli.app import main
from feederkit.errors import InputError

CATALOG = Path(__file__).resolve().parents[1] / "catalog"

READS = (
    ("catalog", "list"),
    ("catalog", "show", "octagon"),
    ("catalog", "export", "octagon", "-o", "out.json"),
    ("catalog", "analyze"),
    ("catalog", "remove", "octagon"),
    ("changeover", "list"),
    ("changeover", "show", "line-1"),
    ("changeover", "remove", "line-1"),
    ("plan", "SOMENAME"),
)
"""Commands that must take an empty file for no catalog, as a missing one, and leave it empty."""


@pytest.fixture
def here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A clean working folder without $FEEDERKIT_CATALOG."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    return tmp_path


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    """Run the command line in process: exit code, stdout, stderr."""
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def plate(path: Path) -> Path:
    """An outline file of the bundled chamfered plate, named ``my-plate``."""
    data = json.loads((CATALOG / "chamfered-plate.json").read_text())
    data["name"] = "my-plate"
    path.write_text(json.dumps(data))
    return path


# 1. An existing empty file is no catalog, as a missing one, and a read never writes to it.

NO_CATALOG = "no catalog there"


@pytest.mark.parametrize("command", READS, ids=[" ".join(c[:2]) for c in READS])
def test_a_read_takes_an_empty_file_for_no_catalog(here, capsys, command) -> None:
    db = here / "zero.db"
    db.write_bytes(b"")
    got, out, err = run(capsys, *command, "--catalog", str(db))
    assert got == 2 and NO_CATALOG in err and "catalog init" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert db.stat().st_size == 0
    assert sorted(p.name for p in here.iterdir()) == ["zero.db"]  # no -wal, -shm or out.json


def test_open_catalog_refuses_an_empty_file_unless_it_creates(here) -> None:
    db = here / "zero.db"
    db.write_bytes(b"")
    with pytest.raises(InputError, match=f"{NO_CATALOG} \\(an empty file; create one with"):
        open_catalog(db)
    with pytest.raises(InputError, match=NO_CATALOG):
        list_parts(db)
    assert db.stat().st_size == 0
    conn = open_catalog(db, create=True)
    try:
        assert list_parts(conn) == [] and schema_version(conn) == SCHEMA_VERSION
    finally:
        conn.close()
    assert db.stat().st_size > 0


def test_a_read_takes_an_sqlite_file_without_tables_for_no_catalog(here, capsys) -> None:
    """An SQLite database with nothing in it is not a catalog either: a read leaves it so."""
    db = here / "blank.db"
    conn = sqlite3.connect(db)
    conn.execute("CREATE TABLE t (x)")
    conn.execute("DROP TABLE t")
    conn.commit()
    conn.close()
    before = db.read_bytes()
    code, _, err = run(capsys, "catalog", "list", "--catalog", str(db))
    assert code == 2 and NO_CATALOG in err and "without tables" in err
    assert db.read_bytes() == before
    code, out, _ = run(capsys, "catalog", "init", "--catalog", str(db))
    assert code == 0 and "ready" in out
    assert run(capsys, "catalog", "list", "--catalog", str(db))[0] == 0


def test_other_files_stay_refused_by_reads_and_init(here, capsys) -> None:
    """A file that is not SQLite, or another program's database, is never taken over."""
    text = here / "notes.db"
    text.write_text("not a database at all, just some words in a file " * 20)
    foreign = here / "other.db"
    conn = sqlite3.connect(foreign)
    conn.execute("CREATE TABLE t (x)")
    conn.commit()
    conn.close()
    for db, said in ((text, "not a feederkit catalog"), (foreign, "not a feederkit catalog")):
        before = db.read_bytes()
        for command in (("catalog", "list"), ("catalog", "init")):
            code, _, err = run(capsys, *command, "--catalog", str(db))
            assert code == 2 and said in err, (db, command, err)
        assert db.read_bytes() == before


@pytest.mark.parametrize("command", (("catalog", "init"), ("catalog", "add", "plate.json")))
def test_init_and_add_make_an_empty_file_a_catalog(here, capsys, command) -> None:
    plate(here / "plate.json")
    db = here / "zero.db"
    db.write_bytes(b"")
    code, out, err = run(capsys, *command, "--catalog", str(db))
    assert code == 0, err
    if command[1] == "init":
        assert "created" in out
    assert run(capsys, "catalog", "list", "--catalog", str(db))[0] == 0


# 2. import --skip-bad skips (and names) a part whose name the catalog has from another file.


def _clash(here: Path, capsys: pytest.CaptureFixture[str]) -> tuple[Path, Path]:
    db = here / "c.db"
    assert (
        run(capsys, "catalog", "add", str(plate(here / "plate.json")), "--catalog", str(db))[0] == 0
    )
    imp = here / "imp"
    imp.mkdir()
    shutil.copy(here / "plate.json", imp / "plate.json")
    shutil.copy(CATALOG / "octagon.json", imp / "octagon.json")
    return db, imp


def test_skip_bad_skips_a_name_taken_in_the_catalog(here, capsys) -> None:
    db, imp = _clash(here, capsys)
    args = ("catalog", "import", str(imp), "--skip-bad", "--catalog", str(db), "--json")
    code, out, err = run(capsys, *args)
    assert code == 0, err
    result = json.loads(out)
    assert [p["name"] for p in result["parts"]] == ["octagon"]
    (skipped,) = result["skipped"]
    assert "plate.json" in skipped and "'my-plate' already exists" in skipped
    assert "--name" not in skipped  # catalog import has no --name
    assert "skipped:" in err and "my-plate" in err
    listed = json.loads(run(capsys, "catalog", "list", "--catalog", str(db), "--json")[1])
    assert {(p["name"], p["revision"]) for p in listed} == {("my-plate", 1), ("octagon", 1)}


def test_without_skip_bad_a_name_clash_still_imports_nothing(here, capsys) -> None:
    db, imp = _clash(here, capsys)
    before = snapshot(db)
    code, _, err = run(capsys, "catalog", "import", str(imp), "--catalog", str(db))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "duplicate name: part 'my-plate' already exists" in err
    assert snapshot(db) == before


# 3. demo has no --skip-bad: its advice about bad files must work for it.


def test_demo_with_a_bad_file_gives_advice_that_works_for_demo(here, capsys) -> None:
    parts = here / "parts"
    parts.mkdir()
    shutil.copy(CATALOG / "octagon.json", parts / "octagon.json")
    (parts / "bad.dxf").write_text("garbage\n")
    code, _, err = run(capsys, "demo", "--catalog-dir", str(parts), "-o", str(here / "out"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "bad.dxf" in err and "--skip-bad" not in err
    assert "move them out of the folder" in err
