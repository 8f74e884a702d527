"""The SQLite parts catalog: schema, revisions by SHA-256, changeovers, all-or-nothing writes."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import fixtures_cad as fx
import pytest
from shared import catalog_snapshot as snapshot

from feederkit import catalog as cat
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.outline import load_outline_json, make_outline, save_outline_json
from feederkit.sources import load_part, load_part_with_warnings


def square(name: str = "sq", side: float = 10.0):
    return make_outline(name, [(0, 0), (side, 0), (side, side), (0, side)])


def write_square(path: Path, side: float = 10.0, name: str | None = None) -> Path:
    save_outline_json(square(name or path.stem, side), path)
    return path


def test_schema_wal_foreign_keys_and_version(tmp_path):
    db = tmp_path / "c.db"
    conn = cat.open_catalog(db, create=True)
    try:
        assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert conn.execute("PRAGMA foreign_keys").fetchone()[0] == 1
        assert cat.schema_version(conn) == cat.SCHEMA_VERSION
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        assert {"parts", "revisions", "changeovers", "changeover_parts"} <= tables
    finally:
        conn.close()


def test_missing_foreign_and_future_catalogs(tmp_path):
    with pytest.raises(InputError, match="no catalog there"):
        cat.list_parts(tmp_path / "none.db")
    junk = tmp_path / "junk.db"
    junk.write_bytes(b"this is not sqlite" * 100)
    with pytest.raises(InputError, match="not a feederkit catalog"):
        cat.list_parts(junk)
    other = tmp_path / "other.db"
    conn = sqlite3.connect(other)
    conn.execute("CREATE TABLE t (x)")
    conn.commit()
    conn.close()
    with pytest.raises(InputError, match="not a feederkit catalog"):
        cat.list_parts(other)
    future = tmp_path / "future.db"
    cat.open_catalog(future, create=True).close()
    conn = sqlite3.connect(future)
    conn.execute(f"PRAGMA user_version = {cat.SCHEMA_VERSION + 1}")
    conn.close()
    with pytest.raises(InputError, match="newer than this feederkit"):
        cat.list_parts(future)


def test_migration_from_an_empty_file(tmp_path):
    db = tmp_path / "empty.db"
    sqlite3.connect(db).close()  # an empty SQLite file is version 0: no catalog until made one
    with pytest.raises(InputError, match="no catalog there"):
        cat.list_parts(db)
    conn = cat.open_catalog(db, create=True)
    assert cat.schema_version(conn) == cat.SCHEMA_VERSION
    conn.close()
    assert cat.list_parts(db) == []


def test_revisions_by_sha256(tmp_path):
    db = tmp_path / "c.db"
    src = write_square(tmp_path / "plate.json")
    (first,) = cat.add_file(db, src)
    assert (first.name, first.revision, first.status) == ("plate", 1, "added")
    (again,) = cat.add_file(db, src)
    assert (again.revision, again.status) == (1, "unchanged")
    write_square(src, side=12.0, name="plate")
    (changed,) = cat.add_file(db, src)
    assert (changed.revision, changed.status) == (2, "revised")
    assert cat.get_part(db, "plate").revision == "2"
    assert cat.get_part(db, "plate", 1).hull[2] == (10.0, 10.0)
    assert cat.get_part(db, "plate", 2).hull[2] == (12.0, 12.0)
    rev = cat.get_revision(db, "plate")
    assert rev.source_path == str(src.resolve())
    import hashlib

    assert rev.source_sha256 == hashlib.sha256(src.read_bytes()).hexdigest()
    assert [h[0] for h in cat.revision_history(db, "plate")] == [1, 2]
    (summary,) = cat.list_parts(db)
    assert (summary.revision, summary.revisions, summary.area) == (2, 2, 144.0)
    with pytest.raises(InputError, match="has no revision 3"):
        cat.get_part(db, "plate", 3)


def test_changed_options_make_a_revision(tmp_path):
    db = tmp_path / "c.db"
    src = fx.write_rotated_block(tmp_path / "blk.dxf")
    assert cat.add_file(db, src)[0].revision == 1
    assert cat.add_file(db, src, ImportOptions(units="mm"))[0].status == "revised"
    assert cat.add_file(db, src, ImportOptions(units="mm"))[0].status == "unchanged"


def test_duplicate_name_from_another_file(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "a.json", name="part"))
    other = write_square(tmp_path / "b.json", side=5.0, name="part")
    before = snapshot(db)
    with pytest.raises(InputError, match="duplicate name.*--revise"):
        cat.add_file(db, other)
    assert snapshot(db) == before
    assert cat.add_file(db, other, revise=True)[0].revision == 2


def test_stored_part_is_exactly_the_imported_one(tmp_path):
    db = tmp_path / "c.db"
    src = fx.write_plate(tmp_path / "plate.dxf")
    cat.add_file(db, src)
    direct = load_part(str(src))
    stored = cat.get_part(db, "plate")
    assert stored.hull == direct.hull and stored.com == direct.com
    assert stored.outline == direct.outline
    assert stored.revision == "1"
    rev = cat.get_revision(db, "plate")
    assert rev.source_kind == "dxf" and rev.source_units == "mm" and rev.hull_tolerance == 0.05
    assert rev.orientable and rev.not_orientable_reason is None


def test_mesh_pose_is_recorded(tmp_path):
    import trimesh

    db = tmp_path / "c.db"
    src = fx.write_mesh(trimesh.creation.box((10, 20, 30)), tmp_path / "box.stl")
    cat.add_file(db, src, ImportOptions(pose=4))
    rev = cat.get_revision(db, "box")
    assert rev.mesh_pose["index"] == 4 and rev.mesh_pose["count"] == 6
    assert len(rev.mesh_pose["transform"]) == 4
    assert rev.area == pytest.approx(200.0)


def test_disk_is_recorded_not_orientable(tmp_path):
    db = tmp_path / "c.db"
    (out,) = cat.add_file(db, fx.write_disk(tmp_path / "disk.dxf"))
    assert not out.orientable
    assert any("not orientable by pushing" in w for w in out.warnings)
    rev = cat.get_revision(db, "disk")
    assert rev.orientable is False and "disk-like" in rev.not_orientable_reason
    assert cat.list_parts(db)[0].orientable is False


def test_all_parts_of_a_drawing(tmp_path):
    db = tmp_path / "c.db"
    outs = cat.add_file(db, fx.write_two_parts(tmp_path / "two.dxf"), ImportOptions(all_parts=True))
    assert [o.name for o in outs] == ["two", "two-2"]
    assert [p.area for p in cat.list_parts(db)] == [800.0, 100.0]


def test_add_outline_and_export_round_trip(tmp_path):
    db = tmp_path / "c.db"
    outline = make_outline("tri", [(0, 0), (4, 0), (0, 3)], com=(1.0, 1.0))
    out = cat.add_outline(db, outline)
    assert (out.revision, out.status) == (1, "added")
    assert cat.add_outline(db, outline).status == "unchanged"
    path = tmp_path / "tri.json"
    cat.export_part(db, "tri", path)
    back = load_outline_json(path)
    assert back == outline
    data = json.loads(path.read_text())
    assert data["units"] == "mm" and data["com"] == [1.0, 1.0]


def test_remove_part(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "a.json"))
    cat.remove_part(db, "a")
    assert cat.list_parts(db) == []
    with pytest.raises(InputError, match="no part named 'a'"):
        cat.remove_part(db, "a")
    conn = sqlite3.connect(db)
    assert conn.execute("SELECT count(*) FROM revisions").fetchone()[0] == 0  # cascaded
    conn.close()


def test_names_are_checked(tmp_path):
    db = tmp_path / "c.db"
    for bad in ("", " x", "a@b", "a/b", "-x"):
        with pytest.raises(InputError, match="invalid part name"):
            cat.add_outline(db, square("ok"), name=bad)


# ---- changeovers --------------------------------------------------------------------------


def test_changeovers(tmp_path):
    db = tmp_path / "c.db"
    src_a = write_square(tmp_path / "a.json")
    cat.add_file(db, src_a)
    cat.add_file(db, write_square(tmp_path / "b.json", side=7.0))
    write_square(src_a, side=11.0, name="a")
    cat.add_file(db, src_a)  # a is now at revision 2
    plan = json.dumps({"format": "feederkit-plan", "version": 1})
    info = cat.save_changeover(
        db, "line-3", [("a", 1), ("b", 1)], {"model": "tolerance", "e": 0.1}, plan
    )
    assert info.parts == (("a", 1), ("b", 1))
    got = cat.get_changeover(db, "line-3")
    assert got.name == "line-3" and got.plan_json == plan
    assert got.info.sensor == {"model": "tolerance", "e": 0.1}
    assert got.info.parts == (("a", 1), ("b", 1))  # the exact revisions, not the latest
    assert [c.name for c in cat.list_changeovers(db)] == ["line-3"]
    with pytest.raises(InputError, match="already exists"):
        cat.save_changeover(db, "line-3", [("a", 2)], {}, plan)
    cat.save_changeover(db, "line-3", [("a", 2)], {}, plan, replace=True)
    assert cat.get_changeover(db, "line-3").info.parts == (("a", 2),)
    with pytest.raises(InputError, match="no part 'a' revision 9"):
        cat.save_changeover(db, "x", [("a", 9)], {}, plan)
    with pytest.raises(InputError, match="not valid JSON"):
        cat.save_changeover(db, "x", [("a", 1)], {}, "{not json")
    with pytest.raises(InputError, match="listed twice"):
        cat.save_changeover(db, "x", [("a", 1), ("a", 2)], {}, plan)
    before = snapshot(db)
    with pytest.raises(InputError, match="used by changeover"):
        cat.remove_part(db, "a")
    assert snapshot(db) == before
    assert cat.remove_part(db, "a", force=True) == ["line-3"]
    assert cat.list_changeovers(db) == []
    with pytest.raises(InputError, match="no changeover named"):
        cat.get_changeover(db, "line-3")


def test_foreign_keys_protect_changeover_revisions(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "a.json"))
    cat.save_changeover(db, "co", [("a", 1)], {}, "{}")
    conn = cat.open_catalog(db)
    with pytest.raises(sqlite3.IntegrityError):
        conn.execute("DELETE FROM revisions")
    conn.close()


# ---- sources: catalog names -------------------------------------------------------------


def test_sources_resolve_catalog_names(tmp_path, monkeypatch):
    db = tmp_path / "c.db"
    src = write_square(tmp_path / "a.json")
    cat.add_file(db, src)
    write_square(src, side=3.0, name="a")
    cat.add_file(db, src)
    monkeypatch.chdir(tmp_path / "..")
    assert load_part("a", catalog=str(db)).revision == "2"
    assert load_part("a@1", catalog=str(db)).hull[2] == (10.0, 10.0)
    monkeypatch.setenv("FEEDERKIT_CATALOG", str(db))
    loaded = load_part_with_warnings("a")
    assert loaded.part.revision == "2" and loaded.orientability.orientable
    assert load_part("a", com=(1.0, 1.0)).com == (1.0, 1.0)
    with pytest.raises(InputError, match="no such file or catalog part"):
        load_part("zzz")
    monkeypatch.setenv("FEEDERKIT_CATALOG", str(tmp_path / "missing.db"))
    with pytest.raises(InputError, match="no such file or catalog part"):
        load_part("a")


def test_sources_read_cad_files(tmp_path):
    part = load_part(str(fx.write_plate(tmp_path / "plate.dxf")))
    assert part.outline.polygon().area == pytest.approx(fx.PLATE_AREA, rel=2e-4)
    loaded = load_part_with_warnings(str(fx.write_disk(tmp_path / "disk.dxf")))
    assert not loaded.orientability.orientable


# ---- all or nothing ---------------------------------------------------------------------


def make_dir(tmp_path: Path, n: int = 6) -> Path:
    d = tmp_path / "parts"
    (d / "sub").mkdir(parents=True)
    for k in range(n):
        write_square((d if k % 2 else d / "sub") / f"p{k}.json", side=5.0 + k)
    fx.write_plate(d / "plate.dxf")
    (d / "notes.txt").write_text("not a part")
    return d


def test_import_directory(tmp_path):
    db = tmp_path / "c.db"
    d = make_dir(tmp_path)
    seen = []
    result = cat.import_directory(db, d, progress=lambda *a: seen.append(a))
    assert sorted(o.name for o in result.outcomes) == ["p0", "p1", "p2", "p3", "p4", "p5", "plate"]
    assert all(o.status == "added" for o in result.outcomes)
    assert [Path(p).name for p in result.ignored] == ["notes.txt"]
    assert {a[0] for a in seen} == {"read", "write"}
    again = cat.import_directory(db, d)
    assert all(o.status == "unchanged" for o in again.outcomes)


def test_directory_with_one_bad_file_adds_nothing(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "keep.json"))
    d = make_dir(tmp_path)
    (d / "sub" / "broken.dxf").write_text("0\nSECTION\n2\nENTITIES\n0\nLINE\n")
    before = snapshot(db)
    with pytest.raises(InputError, match="broken.dxf"):
        cat.import_directory(db, d)
    assert snapshot(db) == before


def test_directory_with_duplicate_names_adds_nothing(tmp_path):
    db = tmp_path / "c.db"
    cat.open_catalog(db, create=True).close()
    d = make_dir(tmp_path)
    write_square(d / "sub" / "p1.json", side=2.0)
    before = snapshot(db)
    with pytest.raises(InputError, match="duplicate name 'p1'"):
        cat.import_directory(db, d)
    assert snapshot(db) == before


def test_write_failure_in_the_middle_rolls_back(tmp_path):
    db = tmp_path / "c.db"
    d = make_dir(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    cat.add_file(db, write_square(elsewhere / "p3.json"))
    before = snapshot(db)
    with pytest.raises(InputError, match="duplicate name: part 'p3'"):
        cat.import_directory(db, d)  # p3 exists from another file: found while writing
    assert snapshot(db) == before


KILL_SCRIPT = textwrap.dedent(
    """
    import os, signal, sys
    from feederkit.catalog import import_directory

    def progress(phase, done, total, item):
        if phase == "write" and done == int(sys.argv[3]):
            os.kill(os.getpid(), signal.SIGKILL)

    import_directory(sys.argv[1], sys.argv[2], progress=progress)
    """
)


def test_killed_import_leaves_the_catalog_as_it_was(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "keep.json"))
    d = make_dir(tmp_path, n=12)
    before = snapshot(db)
    script = tmp_path / "kill.py"
    script.write_text(KILL_SCRIPT)
    proc = subprocess.run([sys.executable, str(script), str(db), str(d), "8"], capture_output=True)
    assert proc.returncode == -signal.SIGKILL
    assert snapshot(db) == before
    conn = sqlite3.connect(db)
    assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
    conn.close()
    # the catalog still works and the import can be run again
    assert len(cat.import_directory(db, d).outcomes) == 13


def test_cli_import_killed_from_outside_is_all_or_nothing(tmp_path):
    db = tmp_path / "c.db"
    cat.add_file(db, write_square(tmp_path / "keep.json"))
    d = make_dir(tmp_path, n=40)
    before = snapshot(db)
    env = dict(os.environ, FEEDERKIT_CATALOG=str(db))
    cmd = [
        sys.executable,
        "-c",
        "from feederkit.cli.app import run; run()",
        "catalog",
        "import",
        str(d),
    ]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        proc.wait(timeout=0.8)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    after = snapshot(db)
    assert after == before or len(cat.list_parts(db)) == 42
