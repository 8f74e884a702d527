"""A revision's own shape and COM tolerances (design.md, "Uncertainty"): schema 3 stores
them, ``catalog add`` and ``import`` set them, ``show`` and ``list`` print them, and the plan
commands declare the largest their parts store unless a flag is given."""

from __future__ import annotations

import json
import math
import sqlite3
from pathlib import Path

import pytest
from shared import catalog_snapshot as snapshot
from shared import no_stray_profile  # noqa: F401 - autouse: a clean working folder
from shared import run_cli as run

import feederkit.catalog as cat
from feederkit.catalog.schema import SCHEMA_V1, SCHEMA_V2
from feederkit.catalog.tolerances import (
    PartTolerances,
    RevisionTolerances,
    declared_tolerances,
)
from feederkit.errors import InputError
from feederkit.landing.model import landings_of_outline
from feederkit.outline import make_outline, outline_to_dict, save_outline_json
from feederkit.part import make_part


def run_json(capsys, *args: str):
    code, out, err = run(capsys, *args, "--json")
    assert code == 0, err
    return json.loads(out)


def rect(folder: Path, name: str, w: float, h: float) -> Path:
    """A ``w`` x ``h`` mm rectangle's outline file (mirror-symmetric: one landing)."""
    path = folder / f"{name}.json"
    save_outline_json(make_outline(name, [(0, 0), (w, 0), (w, h), (0, h)]), path)
    return path


def add(capsys, db: Path, path: Path, *flags: str) -> dict:
    (outcome,) = run_json(capsys, "catalog", "add", str(path), "--catalog", str(db), *flags)
    return outcome


@pytest.fixture
def mix(tmp_path, capsys) -> Path:
    """ra stores t 0.02; rb stores t 0.05 and c 0.03; rc stores none (NULL)."""
    db = tmp_path / "c.db"
    add(capsys, db, rect(tmp_path, "ra", 40, 20), "--shape-tolerance", "0.02")
    add(
        capsys,
        db,
        rect(tmp_path, "rb", 50, 30),
        "--shape-tolerance",
        "0.05",
        "--com-tolerance",
        "0.03",
    )
    add(capsys, db, rect(tmp_path, "rc", 30, 12))
    return db


# -- schema 3 -------------------------------------------------------------------------------


def _v2_catalog(path: Path) -> None:
    """A catalog as schema 2 wrote it: one flat part with its landings, no tolerance columns."""
    conn = sqlite3.connect(path)
    for statement in (SCHEMA_V1 + SCHEMA_V2).split(";"):
        if statement.strip():
            conn.execute(statement)
    conn.execute("PRAGMA user_version = 2")
    part = make_part(make_outline("ell", [(0, 0), (30, 0), (30, 8), (8, 8), (8, 20), (0, 20)]))
    dumps = json.dumps
    conn.execute("INSERT INTO parts VALUES (1, 'ell', 'then', 'me')")
    conn.execute(
        "INSERT INTO revisions (id, part_id, revision, source_path, source_sha256, source_kind, "
        "source_units, options_json, outline_json, hull_json, com_x, com_y, hull_tolerance, "
        "mesh_pose_json, orientable, not_orientable_reason, warnings_json, area, n_holes, "
        "n_hull, created_at, created_by) "
        "VALUES (1, 1, 1, '/old/ell.json', ?, 'outline', 'mm', '{}', ?, ?, ?, ?, NULL, NULL, "
        "1, NULL, '[]', ?, 0, ?, 'then', 'me')",
        (
            "0" * 64,
            dumps(outline_to_dict(part.outline)),
            dumps([list(p) for p in part.hull]),
            part.com[0],
            part.com[1],
            part.outline.polygon().area,
            len(part.hull),
        ),
    )
    for k, x in enumerate(landings_of_outline(part)):
        conn.execute(
            "INSERT INTO landings VALUES (1, ?, ?, ?, ?, ?, ?, ?, '[]')",
            (
                k,
                x.name,
                x.probability,
                dumps(outline_to_dict(x.part.outline)),
                dumps([list(p) for p in x.part.hull]),
                x.part.com[0],
                x.part.com[1],
            ),
        )
    conn.commit()
    conn.close()


def _columns(conn: sqlite3.Connection) -> list[str]:
    return [r[1] for r in conn.execute("PRAGMA table_info(revisions)")]


def test_a_schema_2_catalog_migrates_and_keeps_its_parts(tmp_path, capsys):
    db = tmp_path / "v2.db"
    _v2_catalog(db)
    conn = cat.open_catalog(db)
    assert cat.schema_version(conn) == cat.SCHEMA_VERSION == 3
    assert _columns(conn)[-2:] == ["shape_tolerance_mm", "com_tolerance_mm"]
    rev = cat.get_revision(conn, "ell")
    assert (rev.revision, rev.source_path, rev.area) == (1, "/old/ell.json", pytest.approx(336))
    assert [x.name for x in rev.landings] == ["up", "down"] and rev.landings_note is None
    assert (rev.shape_tolerance_mm, rev.com_tolerance_mm) == (None, None)
    # NULL is stored; a negative value is refused by the column's check.
    row = conn.execute("SELECT shape_tolerance_mm, com_tolerance_mm FROM revisions").fetchone()
    assert row == (None, None)
    for column in ("shape_tolerance_mm", "com_tolerance_mm"):
        with pytest.raises(sqlite3.IntegrityError):
            conn.execute(f"UPDATE revisions SET {column} = -0.1")
    conn.close()
    listed = run_json(capsys, "catalog", "list", "--catalog", str(db))
    assert [(p["name"], p["shape_tolerance_mm"], p["com_tolerance_mm"]) for p in listed] == [
        ("ell", None, None)
    ]


# -- setting them ---------------------------------------------------------------------------


def test_add_stores_them_and_show_and_list_print_them(tmp_path, capsys, mix):
    shown = run_json(capsys, "catalog", "show", "rb", "--catalog", str(mix))
    assert (shown["shape_tolerance_mm"], shown["com_tolerance_mm"]) == (0.05, 0.03)
    none = run_json(capsys, "catalog", "show", "rc", "--catalog", str(mix))
    assert (none["shape_tolerance_mm"], none["com_tolerance_mm"]) == (None, None)
    listed = run_json(capsys, "catalog", "list", "--catalog", str(mix))
    assert [(p["name"], p["shape_tolerance_mm"], p["com_tolerance_mm"]) for p in listed] == [
        ("ra", 0.02, None),
        ("rb", 0.05, 0.03),
        ("rc", None, None),
    ]
    code, out, _ = run(capsys, "catalog", "show", "rb", "--catalog", str(mix))
    assert code == 0
    assert any("shape tolerance" in x and "0.05 mm" in x for x in out.splitlines())
    assert any("COM tolerance" in x and "0.03 mm" in x for x in out.splitlines())
    code, out, _ = run(capsys, "catalog", "show", "rc", "--catalog", str(mix))
    assert code == 0 and "shape tolerance" not in out and "COM tolerance" not in out
    code, out, _ = run(
        capsys, "catalog", "add", str(rect(tmp_path, "rd", 20, 10)), "--catalog", str(mix),
        "--com-tolerance", "0.1",
    )  # fmt: skip
    assert code == 0 and out == "rd: revision 1 (added); stores COM tolerance 0.1 mm\n"


def test_a_new_tolerance_makes_a_revision_and_one_not_given_is_kept(tmp_path, capsys, mix):
    src = tmp_path / "rb.json"
    again = add(capsys, mix, src, "--shape-tolerance", "0.05")
    assert (again["status"], again["revision"]) == ("unchanged", 1)
    new = add(capsys, mix, src, "--shape-tolerance", "0.04")
    assert (new["status"], new["revision"]) == ("revised", 2)
    assert new["changes"] == ["shape tolerance: 0.05 mm -> 0.04 mm"]
    assert (new["shape_tolerance_mm"], new["com_tolerance_mm"]) == (0.04, 0.03)
    rect(tmp_path, "rb", 52, 30)  # a changed drawing, no flags: both tolerances kept
    changed = add(capsys, mix, src)
    assert (changed["revision"], changed["shape_tolerance_mm"], changed["com_tolerance_mm"]) == (
        3,
        0.04,
        0.03,
    )
    rev = cat.get_revision(mix, "rb")
    assert (rev.revision, rev.shape_tolerance_mm, rev.com_tolerance_mm) == (3, 0.04, 0.03)
    assert cat.get_revision(mix, "rb", 1).shape_tolerance_mm == 0.05


def test_import_stores_them_on_every_new_revision(tmp_path, capsys):
    folder = tmp_path / "parts"
    folder.mkdir()
    rect(folder, "p", 40, 20)
    rect(folder, "q", 30, 10)
    db = tmp_path / "c.db"
    data = run_json(
        capsys, "catalog", "import", str(folder), "--catalog", str(db), "--shape-tolerance", "0.01"
    )
    assert [(p["name"], p["shape_tolerance_mm"], p["com_tolerance_mm"]) for p in data["parts"]] == [
        ("p", 0.01, None),
        ("q", 0.01, None),
    ]
    assert [p.shape_tolerance_mm for p in cat.list_parts(db)] == [0.01, 0.01]


@pytest.mark.parametrize(
    ("flags", "words"),
    [
        (("--shape-tolerance", "-0.1"), "shape tolerance must be a finite nonnegative number"),
        (("--shape-tolerance", "nan"), "shape tolerance must be a finite nonnegative number"),
        (("--com-tolerance", "inf"), "COM tolerance must be a finite nonnegative number"),
        (("--shape-tolerance", "6"), "shape tolerance 6 mm must be below half the smallest"),
        (("--com-tolerance", "6"), "COM tolerance 6 mm must be below the COM's distance"),
    ],
)
def test_bad_values_exit_2_and_write_nothing(tmp_path, capsys, mix, flags, words):
    """The 30 x 12 rectangle rc: half its smallest edge is 6 mm, its COM 6 mm from an edge."""
    folder = tmp_path / "folder"
    folder.mkdir()
    rect(folder, "fresh", 30, 12)
    before = snapshot(mix)
    fresh_db = tmp_path / "new.db"
    commands = [
        ("catalog", "add", str(tmp_path / "rc.json"), "--catalog", str(mix)),  # revises rc
        ("catalog", "add", str(folder / "fresh.json"), "--catalog", str(mix)),  # a new part
        ("catalog", "import", str(folder), "--catalog", str(mix)),
        ("catalog", "add", str(folder / "fresh.json"), "--catalog", str(fresh_db)),
    ]
    for command in commands:
        code, out, err = run(capsys, *command, *flags)
        assert code == 2, (command, err)
        assert out == "" and len(err.strip().splitlines()) == 1, err
        assert words in err and flags[0] in err, err
    assert snapshot(mix) == before
    assert not fresh_db.exists()


def test_a_kept_tolerance_too_large_for_the_new_drawing_is_refused(tmp_path, capsys, mix):
    add(capsys, mix, rect(tmp_path, "thin", 30, 12), "--shape-tolerance", "5")
    before = snapshot(mix)
    rect(tmp_path, "thin", 30, 8)  # half its smallest edge is now 4 mm
    code, _, err = run(capsys, "catalog", "add", str(tmp_path / "thin.json"), "--catalog", str(mix))
    assert code == 2 and "shape tolerance 5 mm must be below" in err
    assert "revision 1's, kept because not given" in err and len(err.strip().splitlines()) == 1
    assert snapshot(mix) == before


# -- the rule -------------------------------------------------------------------------------


def test_the_rule_largest_stored_null_as_zero_flag_wins():
    a, b = RevisionTolerances("a", 1, 0.02, None), RevisionTolerances("b", 2, 0.05, 0.0)
    c = RevisionTolerances("c", 3)
    d = declared_tolerances([a, c, b])
    assert (d.shape_tolerance_mm, d.shape_from) == (0.05, "catalog: b r2")
    assert (d.com_tolerance_mm, d.com_from) == (0.0, "catalog: b r2") and d.warnings == ()
    nothing = declared_tolerances([c, RevisionTolerances("e", 1)])
    assert (nothing.shape_tolerance_mm, nothing.com_tolerance_mm) == (0.0, 0.0)
    assert nothing.sources() == {"shape_tolerance_mm": "default", "com_tolerance_mm": "default"}
    assert declared_tolerances([]).sources() == nothing.sources()
    given = declared_tolerances([a, b], shape_tolerance=0.03, com_tolerance=0.0)
    assert (given.shape_tolerance_mm, given.com_tolerance_mm) == (0.03, 0.0)
    assert given.sources() == {"shape_tolerance_mm": "given", "com_tolerance_mm": "given"}
    (warning,) = given.warnings  # only b stores more than given, and only a shape tolerance
    assert "b r2 stores 0.05 mm" in warning and "a r1" not in warning
    assert declared_tolerances([a, b], shape_tolerance=0.05).warnings == ()


def test_part_tolerances_are_checked():
    assert PartTolerances(0.1, None).over(PartTolerances(0.5, 0.2)) == PartTolerances(0.1, 0.2)
    for bad in (-1.0, math.nan, math.inf, "x"):
        with pytest.raises(InputError):
            PartTolerances(bad)  # type: ignore[arg-type]


# -- using them -----------------------------------------------------------------------------


def compile_json(capsys, db: Path, *flags: str) -> tuple[dict, str]:
    code, out, err = run(
        capsys, "changeover", "compile", "co", "--mix", "ra,rb,rc", "--tolerance", "0.5",
        "--catalog", str(db), "--json", *flags,
    )  # fmt: skip
    assert code == 0, err
    return json.loads(out), err


def test_the_largest_stored_wins_in_changeover_compile(capsys, mix):
    data, err = compile_json(capsys, mix)
    assert data["plan"]["uncertainty"] == {
        "rotation_error_deg": 1.0,
        "shape_tolerance_mm": 0.05,
        "com_tolerance_mm": 0.03,
    }
    assert data["uncertainty_from"] == {
        "shape_tolerance_mm": "catalog: rb r1",
        "com_tolerance_mm": "catalog: rb r1",
    }
    assert "warning" not in err
    stored = json.loads(cat.get_changeover(mix, "co").plan_json)
    assert stored["uncertainty"] == data["plan"]["uncertainty"]
    code, out, _ = run(
        capsys, "changeover", "compile", "co2", "--mix", "ra,rc", "--tolerance", "0.5",
        "--catalog", str(mix),
    )  # fmt: skip
    assert code == 0
    assert "shape tolerance 0.02 mm (catalog: ra r1), COM tolerance 0 mm" in " ".join(out.split())


def test_a_flag_overrides_the_catalog_with_one_warning(capsys, mix):
    data, err = compile_json(capsys, mix, "--shape-tolerance", "0.01")
    assert data["plan"]["uncertainty"]["shape_tolerance_mm"] == 0.01
    assert data["plan"]["uncertainty"]["com_tolerance_mm"] == 0.03  # not given: the catalog's
    assert data["uncertainty"] == data["plan"]["uncertainty"]  # as the exit-1 object has it
    assert data["uncertainty_from"] == {
        "shape_tolerance_mm": "given",
        "com_tolerance_mm": "catalog: rb r1",
    }
    warnings = [x for x in err.splitlines() if x.startswith("warning:")]
    assert len(warnings) == 1, err
    assert "rb r1 stores 0.05 mm" in warnings[0] and "ra r1 stores 0.02 mm" in warnings[0]
    assert "0.01 mm" in warnings[0] and "--shape-tolerance" in warnings[0]
    # At or above every stored value: no warning.
    data, err = compile_json(capsys, mix, "--replace", "--com-tolerance", "0.03")
    assert "warning" not in err and data["plan"]["uncertainty"]["com_tolerance_mm"] == 0.03


def test_a_revision_storing_nothing_counts_as_zero(tmp_path, capsys, mix):
    code, out, err = run(
        capsys, "changeover", "compile", "co", "--mix", "rc", "--tolerance", "0.5",
        "--catalog", str(mix), "--json",
    )  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert data["plan"]["uncertainty"]["shape_tolerance_mm"] == 0.0
    assert data["plan"]["uncertainty"]["com_tolerance_mm"] == 0.0
    assert data["uncertainty_from"] == {
        "shape_tolerance_mm": "default",
        "com_tolerance_mm": "default",
    }
    # ra stores only a shape tolerance: the COM tolerance is rc's and ra's NULL, 0.
    code, out, err = run(
        capsys, "plan", "ra", "rc", "--tolerance", "0.5", "--catalog", str(mix), "--json"
    )
    assert code == 0, err
    assert json.loads(out)["uncertainty"] == {
        "rotation_error_deg": 1.0,
        "shape_tolerance_mm": 0.02,
        "com_tolerance_mm": 0.0,
    }


def test_plan_names_the_revision_and_an_outline_file_counts_as_zero(tmp_path, capsys, mix):
    big = rect(tmp_path, "big", 80, 20)  # a file: stores nothing
    code, out, err = run(
        capsys, "plan", "rb", str(big), "--tolerance", "0.5", "--catalog", str(mix)
    )
    assert code == 0, err
    want = (
        "uncertainty: rotation error ±1°, shape tolerance 0.05 mm (catalog: rb r1), COM "
        "tolerance 0.03 mm (catalog: rb r1)"
    )
    assert want in " ".join(out.split())
    code, out, err = run(capsys, "plan", str(big), "--tolerance", "0.5", "--json")
    assert code == 0, err
    assert json.loads(out)["uncertainty"]["shape_tolerance_mm"] == 0.0


def test_a_stored_tolerance_too_large_for_another_part_names_its_revision(tmp_path, capsys, mix):
    add(capsys, mix, rect(tmp_path, "loose", 40, 30), "--shape-tolerance", "7")
    code, out, err = run(capsys, "plan", "loose", "rc", "--tolerance", "0.5", "--catalog", str(mix))
    assert code == 2 and out == ""
    (line,) = err.strip().splitlines()
    assert "rc: shape tolerance 7 mm must be below" in line
    assert "(catalog: loose r1)" in line and "--shape-tolerance MM" in line


def test_catalog_analyze_and_design_sensor_take_the_stored_values(capsys, mix):
    analysis = run_json(capsys, "catalog", "analyze", "--tolerance", "0.5", "--catalog", str(mix))
    assert analysis["uncertainty"]["shape_tolerance_mm"] == 0.05
    assert analysis["uncertainty"]["com_tolerance_mm"] == 0.03
    assert analysis["uncertainty_from"]["shape_tolerance_mm"] == "catalog: rb r1"
    design = run_json(capsys, "design", "sensor", "--mix", "ra,rc", "--catalog", str(mix))
    assert design["uncertainty"]["shape_tolerance_mm"] == 0.02
    assert design["uncertainty"]["com_tolerance_mm"] == 0.0
    assert design["uncertainty_from"] == {
        "shape_tolerance_mm": "catalog: ra r1",
        "com_tolerance_mm": "default",
    }


def test_no_strong_plan_under_a_stored_tolerance_names_its_revision(tmp_path, capsys, mix):
    # A 40 x 36 mm plate: at a 4 mm shape tolerance its sides may tilt enough that no strong
    # plan exists; the user gave no tolerance, so the answer says where 4 mm came from.
    path = tmp_path / "sq.json"
    save_outline_json(make_outline("sq", [(0, 0), (40, 0), (40, 36), (0, 36)]), path)
    add(capsys, mix, path, "--shape-tolerance", "4")
    code, _, err = run(capsys, "plan", "sq", "--tolerance", "0.5", "--catalog", str(mix))
    line = " ".join(err.split())
    assert code == 1 and "no strong plan exists" in line
    assert "the shape tolerance is the largest the planned parts' catalog revisions store" in line
    assert "(catalog: sq r1)" in line
    code, _, err = run(
        capsys, "plan", "sq", "--tolerance", "0.5", "--shape-tolerance", "4", "--catalog", str(mix)
    )
    assert code == 1 and "catalog revisions store" not in err  # given: the user knows
