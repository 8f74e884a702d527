"""The catalog never tracebacks or half-writes: busy, read-only, full and damaged catalogs,
edited rows and hostile names are each one InputError naming the file or part (docs/catalog.md).

The damaged-row cases edit a real SQLite file with ``UPDATE``; the busy case holds a real
``BEGIN IMMEDIATE`` on a second connection.
"""

from __future__ import annotations

import gc
import os
import sqlite3
import threading
from pathlib import Path

import pytest
from shared import catalog_snapshot as snapshot

from feederkit import catalog as cat
from feederkit.catalog.schema import CatalogConnection
from feederkit.errors import InputError
from feederkit.outline import make_outline


def square(name: str = "l-bracket", side: float = 10.0):
    return make_outline(name, [(0, 0), (side, 0), (side, side), (0, side)])


@pytest.fixture
def db(tmp_path: Path) -> Path:
    path = tmp_path / "cat.db"
    cat.add_outline(cat.open_catalog(path, create=True), square())
    return path


def edit(db: Path, sql: str, *args: object) -> None:
    """Change the catalog file behind feederkit's back, as a user with sqlite3 would."""
    conn = sqlite3.connect(db)
    conn.execute(sql, args)
    conn.commit()
    conn.close()


def one_line(exc: pytest.ExceptionInfo[InputError]) -> str:
    text = str(exc.value)
    assert "\n" not in text
    return text


# --- the catalog path ------------------------------------------------------------------


def test_one_rule_resolves_the_catalog_path(tmp_path, monkeypatch):
    monkeypatch.delenv(cat.CATALOG_ENV, raising=False)
    assert cat.resolve_catalog_path(None) == Path("feederkit.db")
    monkeypatch.setenv(cat.CATALOG_ENV, str(tmp_path / "env.db"))
    assert cat.resolve_catalog_path(None) == tmp_path / "env.db"
    assert cat.resolve_catalog_path(tmp_path / "arg.db") == tmp_path / "arg.db"
    assert cat.default_catalog_path() == tmp_path / "env.db"


# --- names -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "why"),
    [
        (".", "folders"),
        ("..", "folders"),
        ("evil\u202egnp.exe", "U+202E"),  # right-to-left override
        ("l-\u200bbracket", "U+200B"),  # zero-width space
        ("a\u2066b", "U+2066"),  # left-to-right isolate
        ("tab\there", "U+0009"),
        ("del\x7f", "U+007F"),
        ("nb\u00a0space", "U+00A0"),
        ("\u0436" * 150, "240"),  # 150 characters, 300 bytes of UTF-8
    ],
)
def test_hostile_names_are_refused(tmp_path, name, why):
    with pytest.raises(InputError) as exc:
        cat.add_outline(tmp_path / "c.db", square(), name=name)
    assert why in one_line(exc)
    assert not (tmp_path / "c.db").exists() or cat.list_parts(tmp_path / "c.db") == []


def test_long_names_within_the_file_name_limit_are_fine(tmp_path):
    db = tmp_path / "c.db"
    ascii_name = "p" * 200
    cyrillic = "\u0436" * 120  # 240 bytes
    cat.add_outline(db, square(), name=ascii_name)
    cat.add_outline(db, square(), name=cyrillic, source_path="other")
    assert cat.part_names(db) == sorted([ascii_name, cyrillic])


# --- unknown names: the nearest ones are suggested --------------------------------------------


def test_unknown_name_suggests_the_nearest(db):
    with pytest.raises(InputError) as exc:
        cat.get_revision(db, "l-brakcet")
    assert "did you mean 'l-bracket'?" in one_line(exc)
    assert cat.similar_names(db, "L-Bracket") == ["l-bracket"]
    assert cat.similar_names(db, "zzzz") == []
    with pytest.raises(InputError) as exc:
        cat.remove_part(db, "lbracket")
    assert "did you mean 'l-bracket'?" in one_line(exc)


# --- busy, read-only, unwritable, full -----------------------------------------------------


def test_busy_catalog_waits_with_a_message_then_one_line(db):
    before = snapshot(db)
    heard: list[str] = []
    cat.set_busy_notifier(heard.append)
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")
    try:
        conn = cat.open_catalog(db, wait=0.3)
        with pytest.raises(InputError) as exc:
            cat.add_outline(conn, square("other"))
        conn.close()
    finally:
        holder.execute("ROLLBACK")
        holder.close()
        cat.set_busy_notifier(None)
    text = one_line(exc)
    assert str(db) in text and "busy" in text and "--wait" in text
    assert len(heard) == 1 and "waiting up to 0.3 s" in heard[0]
    assert snapshot(db) == before


def test_busy_catalog_that_frees_up_in_time_is_written(db):
    holder = sqlite3.connect(db, isolation_level=None, check_same_thread=False)
    holder.execute("BEGIN IMMEDIATE")
    conn = cat.open_catalog(db, wait=5.0)

    timer = threading.Timer(0.4, lambda: holder.execute("ROLLBACK"))
    timer.start()
    try:
        cat.add_outline(conn, square("other"))
    finally:
        timer.join()
        holder.close()
        conn.close()
    assert cat.part_names(db) == ["l-bracket", "other"]


def _read_only(db: Path) -> CatalogConnection:
    conn = sqlite3.connect(
        f"file:{db}?mode=ro", uri=True, isolation_level=None, factory=CatalogConnection
    )
    conn.path = db
    return conn


def test_read_only_catalog_is_named_as_such(db):
    before = snapshot(db)
    conn = _read_only(db)
    try:
        assert [p.name for p in cat.list_parts(conn)] == ["l-bracket"]  # reading works
        with pytest.raises(InputError) as exc:
            cat.remove_part(conn, "l-bracket")
    finally:
        conn.close()
    assert "read-only" in one_line(exc) and str(db) in one_line(exc)
    assert snapshot(db) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write read-only files")
def test_read_only_file_and_unwritable_folder(db, tmp_path):
    db.chmod(0o444)
    try:
        with pytest.raises(InputError) as exc:
            cat.add_outline(db, square("other"))
        assert "read-only" in one_line(exc)
    finally:
        db.chmod(0o644)
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with pytest.raises(InputError) as exc:
            cat.open_catalog(folder / "c.db", create=True)
        assert "not writable" in one_line(exc)
    finally:
        folder.chmod(0o755)


def test_unwritable_folder_is_not_called_a_foreign_file(tmp_path, monkeypatch):
    folder = tmp_path / "locked"
    folder.mkdir()
    real = os.access
    monkeypatch.setattr(
        "feederkit.catalog.schema.os.access",
        lambda p, mode: False if Path(p) == folder and mode == os.W_OK else real(p, mode),
    )
    with pytest.raises(InputError) as exc:
        cat.open_catalog(folder / "c.db", create=True)
    text = one_line(exc)
    assert "folder" in text and "not writable" in text and "not a feederkit catalog" not in text
    with pytest.raises(InputError) as exc:
        cat.open_catalog(tmp_path / "missing" / "c.db", create=True)
    assert "does not exist" in one_line(exc)
    with pytest.raises(InputError) as exc:
        cat.open_catalog(tmp_path / ("x" * 300 + ".db"), create=True)
    assert "too long" in one_line(exc)


def _folder_unwritable(monkeypatch, folder: Path) -> None:
    """The folder reads as not writable (as a read-only mount does; root may write anyway)."""
    real = os.access
    monkeypatch.setattr(
        "feederkit.catalog.schema.os.access",
        lambda p, mode: False if Path(p) == folder and mode == os.W_OK else real(p, mode),
    )


def test_catalog_in_a_read_only_folder_is_read_not_written(db, monkeypatch):
    gc.collect()  # the fixture's connection: closed, so the catalog has no -wal and -shm
    before, files = snapshot(db), sorted(db.parent.iterdir())
    assert files == [db]
    _folder_unwritable(monkeypatch, db.parent)
    # Reads work, without the -wal and -shm files SQLite could not make there.
    assert [p.name for p in cat.list_parts(db)] == ["l-bracket"]
    assert cat.get_part(db, "l-bracket").outline.name == "l-bracket"
    assert sorted(db.parent.iterdir()) == files
    # A write is refused with one line naming the folder; nothing changes.
    with pytest.raises(InputError) as exc:
        cat.add_outline(db, square("other"))
    assert "not writable" in one_line(exc) and str(db.parent) in one_line(exc)
    assert snapshot(db) == before


def test_old_catalog_in_a_read_only_folder_says_to_copy_it(db, monkeypatch):
    edit(db, "PRAGMA user_version = 1")
    _folder_unwritable(monkeypatch, db.parent)
    with pytest.raises(InputError) as exc:
        cat.list_parts(db)
    assert "schema version 1" in one_line(exc) and "copy" in one_line(exc)


def test_full_disk_leaves_the_catalog_intact(db):
    before = snapshot(db)
    conn = cat.open_catalog(db)
    pages = conn.execute("PRAGMA page_count").fetchone()[0]
    conn.execute(f"PRAGMA max_page_count = {pages}")
    big = make_outline("big", [(0, 0), *[(10 + k * 1e-3, k) for k in range(3000)], (0, 3000)])
    with pytest.raises(InputError) as exc:
        cat.add_outline(conn, big)
    conn.close()
    assert "disk is full" in one_line(exc) and "as it was" in one_line(exc)
    assert snapshot(db) == before
    assert cat.part_names(db) == ["l-bracket"]


class _FullAtCommit(CatalogConnection):
    """COMMIT fails as it does on a full disk (SQLITE_FULL); everything else is real."""

    def execute(self, sql, *args):  # type: ignore[override]
        if sql == "COMMIT":
            err = sqlite3.OperationalError("database or disk is full")
            err.sqlite_errorname = "SQLITE_FULL"  # type: ignore[attr-defined]
            raise err
        return super().execute(sql, *args)


def test_full_disk_at_commit_rolls_back(db):
    before = snapshot(db)
    conn = sqlite3.connect(db, isolation_level=None, factory=_FullAtCommit)
    conn.path = db
    with pytest.raises(InputError) as exc:
        cat.add_outline(conn, square("other"))
    assert not conn.in_transaction
    conn.close()
    assert "disk is full" in one_line(exc)
    assert snapshot(db) == before


# --- damaged rows and files --------------------------------------------------------------------

DAMAGE = [
    ("outline_json", "UPDATE revisions SET outline_json = '{\"vertices\": [[0, 0], [1'"),
    ("hull_json", "UPDATE revisions SET hull_json = '[[0, 0], [10, 0]]'"),
    ("hull_json", "UPDATE revisions SET hull_json = '[[0, 0], [10, 0], [\"a\", 10]]'"),
    ("outline_json", "UPDATE revisions SET outline_json = '{\"vertices\": [[0, 1e400]]}'"),
    ("center of mass", "UPDATE revisions SET com_x = 25.0"),
    ("com_x", "UPDATE revisions SET com_x = 'abc'"),
    ("revision", "UPDATE revisions SET revision = 'x'"),
    ("orientable", "UPDATE revisions SET orientable = 7"),
    ("warnings_json", "UPDATE revisions SET warnings_json = '{\"a\": 1}'"),
    ("source_path", "UPDATE revisions SET source_path = CAST(X'666fff6f' AS TEXT)"),
    ("options_json", "UPDATE revisions SET options_json = 12"),
]


@pytest.mark.parametrize(("field", "sql"), DAMAGE, ids=[d[1][22:60] for d in DAMAGE])
def test_damaged_rows_are_one_line_naming_the_part(db, field, sql):
    conn = sqlite3.connect(db)
    conn.execute("PRAGMA ignore_check_constraints = ON")
    conn.execute(sql)
    conn.commit()
    conn.close()
    with pytest.raises(InputError) as exc:
        cat.get_part(db, "l-bracket")
    text = one_line(exc)
    assert "l-bracket@" in text and field in text and "damaged" in text
    if "revision =" not in sql:
        assert "feederkit catalog remove l-bracket@1" in text


def test_damaged_list_row_and_bad_utf8_name(db):
    edit(db, "UPDATE revisions SET area = 'wide'")
    with pytest.raises(InputError) as exc:
        cat.list_parts(db)
    assert "l-bracket@1" in one_line(exc) and "area" in one_line(exc)
    edit(db, "UPDATE revisions SET area = 100.0")
    edit(db, "UPDATE parts SET name = CAST(X'6c2dff' AS TEXT)")
    with pytest.raises(InputError) as exc:
        cat.list_parts(db)
    text = one_line(exc)
    assert "\\udcff" in text and "backup" in text
    assert cat.part_names(db) == []


def test_damaged_row_can_be_removed_by_revision(db):
    cat.add_outline(db, square(side=12.0), source_path="<python:l-bracket>")
    edit(db, "UPDATE revisions SET hull_json = 'nope' WHERE revision = 2")
    with pytest.raises(InputError, match="l-bracket@2"):
        cat.get_part(db, "l-bracket")
    cat.remove_part(db, "l-bracket", revision=2)
    assert cat.get_part(db, "l-bracket").revision == "1"


def test_malformed_database_file(db):
    conn = sqlite3.connect(db)
    conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    page = conn.execute("PRAGMA page_size").fetchone()[0]
    conn.close()
    data = bytearray(db.read_bytes())
    data[page : 3 * page] = b"\xa5" * (2 * page)
    db.write_bytes(bytes(data))
    with pytest.raises(InputError) as exc:
        cat.list_parts(db)
    text = one_line(exc)
    assert str(db) in text and "damaged" in text and "backup" in text


def test_damaged_changeover_row(db):
    cat.save_changeover(db, "line-3", [("l-bracket", 1)], {"model": "none"}, "{}")
    edit(db, "UPDATE changeovers SET sensor_json = '{\"a\": [1'")
    with pytest.raises(InputError) as exc:
        cat.list_changeovers(db)
    assert "changeover line-3" in one_line(exc) and "damaged" in one_line(exc)


# --- a changeover's files are written inside its transaction --------------------------------------


def test_changeover_before_commit_failure_stores_nothing(db, tmp_path):
    before = snapshot(db)

    def write_files() -> None:
        raise InputError(f"{tmp_path / 'plan.json'}: cannot write the file (No space left)")

    with pytest.raises(InputError, match="No space left"):
        cat.save_changeover(
            db, "line-3", [("l-bracket", 1)], {"model": "none"}, "{}", before_commit=write_files
        )
    assert snapshot(db) == before
    written: list[bool] = []

    def write_ok() -> None:
        conn = sqlite3.connect(db, timeout=0)  # another reader sees nothing yet
        assert conn.execute("SELECT count(*) FROM changeovers").fetchone()[0] == 0
        conn.close()
        written.append(True)

    cat.save_changeover(
        db, "line-3", [("l-bracket", 1)], {"model": "none"}, "{}", before_commit=write_ok
    )
    assert written == [True]
    assert [c.name for c in cat.list_changeovers(db)] == ["line-3"]


# --- one revision, and what changed ------------------------------------------------------------


def test_remove_one_revision(db):
    cat.add_outline(db, square(side=12.0), source_path="<python:l-bracket>")
    cat.add_outline(db, square(side=14.0), source_path="<python:l-bracket>")
    cat.save_changeover(db, "line-3", [("l-bracket", 2)], {"model": "none"}, "{}")
    with pytest.raises(InputError, match="l-bracket@2.*--force"):
        cat.remove_part(db, "l-bracket", revision=2)
    with pytest.raises(InputError, match="no revision 9"):
        cat.remove_part(db, "l-bracket", revision=9)
    assert cat.remove_part(db, "l-bracket", revision=2, force=True) == ["line-3"]
    assert [r[0] for r in cat.revision_history(db, "l-bracket")] == [1, 3]
    cat.remove_part(db, "l-bracket", revision=1)
    cat.remove_part(db, "l-bracket", revision=3)  # the last one: the part goes
    assert cat.part_names(db) == []


def test_revised_outcome_says_what_changed(tmp_path):
    db = tmp_path / "c.db"
    src = "<python:l-bracket>"
    cat.add_outline(db, square(), source_path=src)
    out = cat.add_outline(db, square(), source_path=src, hull_tolerance=0.1)
    assert out.status == "revised"
    assert out.changes == ("hull_tolerance: default -> 0.1",)
    out = cat.add_outline(db, square(side=11.0), source_path=src, hull_tolerance=0.1)
    assert len(out.changes) == 1 and out.changes[0].startswith("file changed since revision 2")


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("l-bracket", True),
        ("l-bracket@2", True),
        ("bracket.v2", True),
        ("parts/l-bracket", False),
        ("l-bracket.dxf", False),
        ("L-BRACKET.JSON@3", False),
        ("..", False),
        ("p" * 300, False),
    ],
)
def test_sources_that_can_only_be_files(source, expected):
    assert cat.could_be_part_name(source) is expected
