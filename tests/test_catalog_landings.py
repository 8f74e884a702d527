"""Landings in the catalog: stored per revision, --side-probability, schema 1 catalogs migrated."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
import trimesh

import feederkit.catalog as cat
from feederkit.catalog.schema import SCHEMA_V1
from feederkit.catalog.store import NOTE_FLAT, NOTE_MESH
from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.importers.reader import file_sha256
from feederkit.landing import landings_of_outline
from feederkit.outline import make_outline, outline_to_dict, save_outline_json
from feederkit.part import make_part


def ell_outline(name: str = "ell"):
    return make_outline(
        name,
        [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)],
        [[(30, 3), (34, 3), (34, 7), (30, 7)]],
    )


@pytest.fixture
def box_stl(tmp_path) -> Path:
    path = tmp_path / "box.stl"
    trimesh.creation.box((10.0, 20.0, 30.0)).export(path)
    return path


def test_flat_revision_stores_both_sides(tmp_path):
    db = tmp_path / "c.db"
    cat.add_outline(db, ell_outline(), side_probability=0.7)
    rev = cat.get_revision(db, "ell")
    assert rev.landings_note is None
    assert [(x.name, x.probability) for x in rev.landings] == [
        ("up", pytest.approx(0.7)),
        ("down", pytest.approx(0.3)),
    ]
    fresh = landings_of_outline(make_part(ell_outline()), 0.7)
    for stored, made in zip(rev.landings, fresh, strict=True):
        assert stored.part.name == f"ell/{stored.name}" and stored.part.revision == "1"
        assert stored.part.com == pytest.approx(made.part.com, abs=1e-12)
        assert stored.part.hull == made.part.hull
        assert stored.part.outline == made.part.outline


def test_side_probability_is_an_option_of_the_revision(tmp_path):
    db = tmp_path / "c.db"
    assert cat.add_outline(db, ell_outline()).status == "added"
    assert cat.add_outline(db, ell_outline()).status == "unchanged"
    changed = cat.add_outline(db, ell_outline(), side_probability=0.6)
    assert changed.status == "revised"
    assert any("side_probability" in c for c in changed.changes)
    assert cat.get_revision(db, "ell").landings[0].probability == pytest.approx(0.6)
    with pytest.raises(InputError, match="strictly between 0 and 1"):
        cat.add_outline(db, ell_outline(), side_probability=1.0)


def test_symmetric_outline_stores_one_landing(tmp_path):
    db = tmp_path / "c.db"
    cat.add_outline(db, make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)]))
    (only,) = cat.get_revision(db, "bar").landings
    assert (only.name, only.probability, only.merged) == ("up", 1.0, ("down",))


def test_mesh_revision_stores_every_pose(tmp_path, box_stl):
    db = tmp_path / "c.db"
    cat.add_file(db, box_stl, ImportOptions(units="mm"))
    rev = cat.get_revision(db, "box")
    assert [x.name for x in rev.landings] == ["pose-0", "pose-2", "pose-4"]
    assert sum(x.probability for x in rev.landings) == pytest.approx(1.0, abs=1e-6)
    assert rev.landings[0].part.hull == rev.hull  # the imported pose is pose 0
    # A mesh has no sides: the side probability does not make a new revision.
    (again,) = cat.add_file(db, box_stl, ImportOptions(units="mm"), side_probability=0.7)
    assert again.status == "unchanged"


def test_directory_import_stores_landings(tmp_path, box_stl):
    save_outline_json(ell_outline(), tmp_path / "ell.json")
    db = tmp_path / "c.db"
    cat.import_directory(db, tmp_path, ImportOptions(units="mm"), side_probability=0.8)
    assert [x.name for x in cat.get_revision(db, "box").landings] == ["pose-0", "pose-2", "pose-4"]
    ups = cat.get_revision(db, "ell").landings
    assert [x.probability for x in ups] == pytest.approx([0.8, 0.2])


def _old_catalog(path: Path, box: Path) -> None:
    """A catalog as schema 1 wrote it: a flat part and a mesh part, no landings table."""
    conn = sqlite3.connect(path)
    for statement in SCHEMA_V1.split(";"):
        if statement.strip():
            conn.execute(statement)
    conn.execute("PRAGMA user_version = 1")
    dumps = json.dumps
    flat = make_part(ell_outline())
    box_part = make_part(make_outline("box", [(-15, -10), (15, -10), (15, 10), (-15, 10)]))
    rows = [
        ("ell", "/old/ell.json", "0" * 64, "outline", "{}", flat, None),
        (
            "box",
            str(box.resolve()),
            file_sha256(box),
            "mesh",
            json.dumps(ImportOptions(units="mm").as_key(), sort_keys=True, separators=(",", ":")),
            box_part,
            {"index": 0, "probability": 0.3225, "count": 6, "transform": []},
        ),
    ]
    for pid, (name, src, sha, kind, options, part, pose) in enumerate(rows, start=1):
        conn.execute(
            "INSERT INTO parts (id, name, created_at, created_by) VALUES (?, ?, 'then', 'me')",
            (pid, name),
        )
        conn.execute(
            "INSERT INTO revisions (part_id, revision, source_path, source_sha256, source_kind, "
            "source_units, options_json, outline_json, hull_json, com_x, com_y, hull_tolerance, "
            "mesh_pose_json, orientable, not_orientable_reason, warnings_json, area, n_holes, "
            "n_hull, created_at, created_by) "
            "VALUES (?, 1, ?, ?, ?, 'mm', ?, ?, ?, ?, ?, NULL, ?, 1, NULL, '[]', ?, ?, ?, "
            "'then', 'me')",
            (
                pid,
                src,
                sha,
                kind,
                options,
                dumps(outline_to_dict(part.outline)),
                dumps([list(p) for p in part.hull]),
                part.com[0],
                part.com[1],
                None if pose is None else dumps(pose),
                part.outline.polygon().area,
                len(part.outline.holes),
                len(part.hull),
            ),
        )
    conn.commit()
    conn.close()


def test_schema_1_catalog_is_migrated_and_stays_readable(tmp_path, box_stl):
    db = tmp_path / "old.db"
    _old_catalog(db, box_stl)
    conn = cat.open_catalog(db)
    assert cat.schema_version(conn) == cat.SCHEMA_VERSION
    assert conn.execute("SELECT count(*) FROM landings").fetchone()[0] == 0
    flat = cat.get_revision(conn, "ell")
    assert flat.landings_note == NOTE_FLAT
    assert [(x.name, x.probability) for x in flat.landings] == [("up", 0.5), ("down", 0.5)]
    assert flat.landings[1].part.com[0] == pytest.approx(-flat.com[0])
    mesh = cat.get_revision(conn, "box")
    assert mesh.landings_note == NOTE_MESH
    (pose,) = mesh.landings
    assert (pose.name, pose.probability) == ("pose-0", pytest.approx(0.3225))
    assert [p.name for p in cat.list_parts(conn)] == ["box", "ell"]
    # Adding the unchanged mesh file again stores all its poses as the next revision.
    (again,) = cat.add_file(conn, box_stl, ImportOptions(units="mm"))
    assert again.status == "revised" and any("resting poses" in c for c in again.changes)
    assert len(cat.get_revision(conn, "box").landings) == 3
    assert len(cat.get_revision(conn, "box", 1).landings) == 1
    # Removing a part removes its landings with it.
    cat.remove_part(conn, "box")
    assert conn.execute("SELECT count(*) FROM landings").fetchone()[0] == 0
    conn.close()


def test_damaged_landing_row_is_one_error_naming_the_revision(tmp_path):
    db = tmp_path / "c.db"
    cat.add_outline(db, ell_outline())
    conn = sqlite3.connect(db)
    conn.execute("UPDATE landings SET probability = 2.5 WHERE name = 'down'")
    conn.commit()
    conn.close()
    with pytest.raises(InputError, match=r"catalog part ell@1: .*landing down's probability"):
        cat.get_revision(db, "ell")


def test_cli_side_probability_and_show(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    save_outline_json(ell_outline(), tmp_path / "ell.json")
    db = str(tmp_path / "c.db")
    for bad in ("0", "1", "-0.2", "nan"):
        assert main(["catalog", "add", "ell.json", "--catalog", db, "--side-probability", bad]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "strictly between 0 and 1" in err
    assert not (tmp_path / "c.db").exists()
    assert main(["catalog", "add", "ell.json", "--catalog", db, "--side-probability", "0.25"]) == 0
    capsys.readouterr()
    assert main(["catalog", "show", "ell", "--catalog", db, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [(x["landing"], x["probability"]) for x in data["landings"]] == [
        ("up", 0.25),
        ("down", 0.75),
    ]
    assert data["landings"][1]["com"][0] == pytest.approx(-data["com"][0])
    assert main(["catalog", "show", "ell", "--catalog", db]) == 0
    out = capsys.readouterr().out
    assert "up: probability 0.250" in out and "down: probability 0.750" in out


def test_plan_of_a_catalog_part_covers_its_stored_landings(tmp_path, capsys):
    db = tmp_path / "c.db"
    cat.add_outline(db, ell_outline(), side_probability=0.25)
    out = tmp_path / "plan.json"
    args = ["plan", "ell", "--catalog", str(db), "--tolerance", "0.5", "-o", str(out)]
    assert main(args) == 0, capsys.readouterr().err
    plan = json.loads(out.read_text())
    parts = [(p["name"], p["revision"], p["landing"], p["share"]) for p in plan["parts"]]
    assert parts == [("ell", "1", "up", 0.25), ("ell", "1", "down", 0.75)]


def test_plan_of_a_catalog_mesh_picks_its_stored_poses(tmp_path, capsys, box_stl):
    db = tmp_path / "c.db"
    cat.add_file(db, box_stl, ImportOptions(units="mm"))
    out = tmp_path / "plan.json"
    box = ["plan", "box", "--catalog", str(db), "--tolerance", "0.5", "-o", str(out)]
    assert main([*box, "--landings", "0,4", "--json"]) == 0, capsys.readouterr().err
    plan = json.loads(capsys.readouterr().out)
    assert [p["landing"] for p in plan["parts"]] == ["pose-0", "pose-4"]
    shares = [p["share"] for p in plan["parts"]]
    stored = {x.name: x.probability for x in cat.get_revision(db, "box").landings}
    total = stored["pose-0"] + stored["pose-4"]
    assert shares == pytest.approx([stored["pose-0"] / total, stored["pose-4"] / total])


def test_exporting_a_mesh_part_says_the_file_holds_one_pose(tmp_path, box_stl, capsys):
    db = str(tmp_path / "c.db")
    assert main(["catalog", "add", str(box_stl), "--catalog", db]) == 0
    capsys.readouterr()
    out = tmp_path / "box.json"
    assert main(["catalog", "export", "box", "-o", str(out), "--json", "--catalog", db]) == 0
    [warning] = json.loads(capsys.readouterr().out)["warnings"]
    assert "mesh part of 3 landings" in warning and "covers that pose only" in warning
    flat = tmp_path / "ell.json"
    ring = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
    save_outline_json(make_outline("ell", ring), flat)
    assert main(["catalog", "add", str(flat), "--catalog", db]) == 0
    capsys.readouterr()
    assert main(["catalog", "export", "ell", "-o", str(out), "--json", "--catalog", db]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"] == []
