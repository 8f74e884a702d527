"""A new user's import findings: source units, a tolerance checked on every pose, an outline
drawn twice inside itself, --com in a file not in mm, warnings of several parts, open ends."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from feederkit.importers import ImportOptions, import_parts


def write_inch_outline(path: Path) -> Path:
    """A 2 x 1 inch plate as an outline file that says its units are inches."""
    data = {"name": "plate-in", "units": "in", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]}
    path.write_text(json.dumps(data))
    return path


def test_outline_file_keeps_its_source_units(tmp_path):
    path = write_inch_outline(tmp_path / "plate-in.json")
    result, parts = import_parts(path, ImportOptions())
    assert parts[0].part.outline.vertices[1] == (50.8, 0.0)
    assert result.parts[0].source_units == "in"
    _, parts = import_parts(path, ImportOptions(units="cm"))
    assert parts[0].source.source_units == "cm"
    _, parts = import_parts(path, ImportOptions(units="Inches"))
    assert parts[0].source.source_units == "in"


def test_cad_files_name_an_override_unit_canonically(tmp_path):
    import ezdxf
    import trimesh

    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 0), (2, 0), (2, 1), (0, 1)], close=True)
    doc.saveas(tmp_path / "plate.dxf")
    trimesh.creation.box((2, 1, 0.2)).export(tmp_path / "plate.stl")
    for name in ("plate.dxf", "plate.stl"):
        _, parts = import_parts(tmp_path / name, ImportOptions(units="Inches"))
        assert parts[0].source.source_units == "in"


def test_catalog_refuses_a_tolerance_too_large_for_another_mesh_pose(tmp_path, capsys):
    """A 50 x 30 x 3 mm plate's pose 0 allows a shape tolerance below 15 mm, its poses on an
    edge below 1.5 mm: plans cover every landing, so the revision may store only the latter."""
    import trimesh
    from shared import run_cli

    trimesh.creation.box((50, 30, 3)).export(tmp_path / "plate.stl")
    db = str(tmp_path / "c.db")
    code, _, err = run_cli(
        capsys, "catalog", "add", str(tmp_path / "plate.stl"), "--catalog", db,
        "--shape-tolerance", "4.9",
    )  # fmt: skip
    assert code == 2
    assert "pose-" in err and "1.5 mm" in err and "--shape-tolerance" in err
    code, _, err = run_cli(
        capsys, "catalog", "add", str(tmp_path / "plate.stl"), "--catalog", db,
        "--com-tolerance", "2",
    )  # fmt: skip
    assert code == 2 and "pose-" in err and "--com-tolerance" in err
    code, _, err = run_cli(
        capsys, "catalog", "add", str(tmp_path / "plate.stl"), "--catalog", db,
        "--shape-tolerance", "1", "--com-tolerance", "1",
    )  # fmt: skip
    assert code == 0, err
    code, _, err = run_cli(capsys, "plan", "plate", "--catalog", db, "--tolerance", "0.5")
    assert "must be below" not in err


def test_an_outline_left_open_is_refused_naming_where(tmp_path):
    """A plate whose last LINE stops 0.3 mm short (more than the 0.1 mm import bridges): the
    refusal says where the outline is open and how far apart its ends are, so the user can
    find the gap in CAD."""
    import ezdxf
    import pytest

    from feederkit.errors import InputError

    doc = ezdxf.new("R2010", units=4)  # mm
    msp = doc.modelspace()
    msp.add_line((0, 0), (40, 0))
    msp.add_arc((40, 10), 10, -90, 90)
    msp.add_line((40, 20), (0, 20))
    msp.add_line((0, 20), (0, 0.3))
    doc.saveas(tmp_path / "open.dxf")
    with pytest.raises(InputError) as exc:
        import_parts(tmp_path / "open.dxf", ImportOptions())
    words = str(exc.value)
    assert "no closed outline" in words
    assert words.endswith("(2 open ends, 0.3 mm apart at (0, 0.3) and (0, 0))")


def test_com_given_for_a_file_in_inches_warns_that_it_is_read_in_mm(tmp_path):
    """--com is in mm (the part frame's unit); a user reading an inch drawing may give inches,
    which lands inside the part and is taken without a word."""
    path = write_inch_outline(tmp_path / "plate-in.json")
    _, parts = import_parts(path, ImportOptions(com=(1.1, 0.5)))
    assert parts[0].part.com == (1.1, 0.5)
    assert any("--com" in w and "mm" in w and " in " in w for w in parts[0].warnings)
    _, parts = import_parts(path, ImportOptions(units="mm", com=(1.1, 0.5)))
    assert not any("--com" in w for w in parts[0].warnings)


def write_plate_with_island(path: Path) -> Path:
    """A 60 x 30 mm plate with a square hole that holds a 6 mm square: two parts."""
    import ezdxf

    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (60, 0), (60, 30), (0, 30)], close=True)
    msp.add_lwpolyline([(10, 10), (20, 10), (20, 20), (10, 20)], close=True)
    msp.add_lwpolyline([(12, 12), (18, 12), (18, 18), (12, 18)], close=True)
    doc.saveas(path)
    return path


def test_all_parts_warnings_said_once_and_true_of_all_parts(tmp_path, capsys):
    """With --all-parts a drawing's own warnings are said once, under the file, not once per
    part under each part's name (the 6 mm square is no '60 x 30 mm rectangle'); and the
    nested part is imported, not left out."""
    from shared import run_cli

    path = str(write_plate_with_island(tmp_path / "sheet.dxf"))
    for args in (
        ["part", "analyze", path, "--all-parts"],
        ["plan", path, "--all-parts", "--tolerance", "0.3", "-o", "/dev/null"],
    ):
        _, _, err = run_cli(capsys, *args)
        lines = [ln for ln in err.splitlines() if "holes hold" in ln]
        assert len(lines) == 1, err
        assert lines[0].startswith(f"warning: {path}: ")
        assert "imported the outer part" not in lines[0]
        assert "sheet-2): the part is a 60 x 30" not in err


def test_an_outline_drawn_twice_with_an_inner_copy_is_no_drawing_frame(tmp_path):
    """A 50 x 30 mm plate whose outline is drawn twice, the copy 0.02 mm inside (more than
    the flatten tolerance, so not a repeat): it was taken for a double-line drawing frame
    and the plate's 8 mm hole imported as the part, with only 'skipped 1 drawing frame'."""
    import ezdxf
    import pytest

    from feederkit.errors import InputError

    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (50, 0), (50, 30), (0, 30)], close=True)
    msp.add_lwpolyline([(0.02, 0.02), (49.98, 0.02), (49.98, 29.98), (0.02, 29.98)], close=True)
    msp.add_circle((15, 15), 4)
    doc.saveas(tmp_path / "twice.dxf")
    with pytest.raises(InputError, match=r"the outline seems drawn twice, 0.028 mm apart"):
        import_parts(tmp_path / "twice.dxf", ImportOptions())


def test_an_outline_file_of_no_plausible_size_warns_of_its_units(tmp_path):
    # A plate drawn in metres in a file without units is read as mm: 0.07 mm across, a unit
    # mistake more likely than a part; drawings and meshes said so, outline files did not.
    ring = [[0, 0], [0.06, 0], [0.06, 0.04], [0, 0.04]]
    path = tmp_path / "plate.json"
    path.write_text(json.dumps({"name": "plate", "vertices": ring}))
    [part] = import_parts(path, ImportOptions())[1]
    [note] = [w for w in part.warnings if "check the units" in w]
    assert "0.07211 mm across" in note and "as the file carries no units" in note
    assert "72.11 mm in m" in note
    path.write_text(json.dumps({"name": "plate", "units": "m", "vertices": ring}))
    [part] = import_parts(path, ImportOptions())[1]
    assert not [w for w in part.warnings if "check the units" in w]  # 72 mm: plausible
    path.write_text(json.dumps({"name": "plate", "units": "mm", "vertices": ring}))
    [part] = import_parts(path, ImportOptions())[1]
    assert not [w for w in part.warnings if "check the units" in w]  # the file says mm
    path.write_text(json.dumps({"name": "plate", "vertices": ring}))
    [part] = import_parts(path, ImportOptions(units="mm"))[1]
    assert not [w for w in part.warnings if "check the units" in w]  # so does --units


def test_two_separate_parts_equal_in_size_are_not_called_the_largest(tmp_path):
    import fixtures_cad as fx

    def two(msp, x: float) -> None:
        msp.add_lwpolyline([(0, 0), (40, 0), (40, 20), (0, 20)], close=True)
        msp.add_lwpolyline([(100, 0), (100 + x, 0), (100 + x, 40), (100, 40)], close=True)

    equal = fx.write_entities(tmp_path / "equal.dxf", lambda msp: two(msp, 20.0))
    [part] = import_parts(equal, ImportOptions())[1]
    [note] = [w for w in part.warnings if "separate parts" in w]
    assert "imported one of the 2 largest, equal in size: area 800.0 mm2" in note
    bigger = fx.write_entities(tmp_path / "bigger.dxf", lambda msp: two(msp, 21.0))
    [part] = import_parts(bigger, ImportOptions())[1]
    [note] = [w for w in part.warnings if "separate parts" in w]
    assert "imported the one of the largest outline, area 840.0 mm2 at" in note
    assert note.endswith("(use --all-parts for all)")


def test_a_part_chosen_by_its_outline_says_how_much_its_holes_take(tmp_path):
    # A 50 x 30 plate with a D10 hole (1421.6 mm2 of material, flattened) beside a 48 x 31
    # plate (1488): the first is imported, by its outline; "the largest" then listed a
    # larger part left out.
    import fixtures_cad as fx

    def build(msp) -> None:
        msp.add_lwpolyline([(0, 0), (50, 0), (50, 30), (0, 30)], close=True)
        msp.add_circle((25, 15), 5)
        msp.add_lwpolyline([(100, 0), (148, 0), (148, 31), (100, 31)], close=True)

    path = fx.write_entities(tmp_path / "two.dxf", build)
    [part] = import_parts(path, ImportOptions())[1]
    [note] = [w for w in part.warnings if "separate parts" in w]
    assert "the one of the largest outline, area 1421.6 mm2 (1500.0 inside its outline)" in note


def test_a_mesh_whose_only_triangle_has_a_nan_says_why_none_is_left(tmp_path):
    import pytest

    from feederkit.errors import InputError

    path = tmp_path / "nan.stl"
    path.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 10 0 0\n"
        "vertex nan 10 0\nendloop\nendfacet\nendsolid t\n"
    )
    with pytest.raises(InputError, match="1 triangle of the mesh has a corner with a NaN"):
        import_parts(path, ImportOptions())


def test_a_hull_tolerance_that_is_infinite_or_not_small_against_the_part_is_refused(tmp_path):
    # It ended in "the center of mass lies on the boundary of the contact hull", naming
    # neither the option nor the cause.
    import fixtures_cad as fx
    import pytest

    from feederkit.errors import InputError

    path = fx.write_two_parts(tmp_path / "two.dxf")
    for bad, words in ((float("inf"), "finite number"), (1000.0, "not small against the part")):
        with pytest.raises(InputError, match=f"--hull-tolerance .*{words}"):
            import_parts(path, ImportOptions(hull_tolerance=bad))
    [part] = import_parts(path, ImportOptions(hull_tolerance=0.5))[1]
    assert part.hull_tolerance == 0.5


def test_an_outline_file_with_a_byte_order_mark_is_read(tmp_path):
    # Windows tools write a UTF-8 BOM; it was "not valid JSON (Unexpected UTF-8 BOM)".
    path = tmp_path / "bom.json"
    data = {"name": "bom", "units": "mm", "vertices": [[0, 0], [20, 0], [20, 10], [0, 10]]}
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(data).encode("utf-8"))
    [part] = import_parts(path, ImportOptions())[1]
    assert part.part.name == "bom" and part.part.outline.vertices[2] == (20.0, 10.0)


@pytest.mark.parametrize(("side", "word"), [(1e-6, "smaller than 1 mm"), (1e9, "larger than 2 m")])
def test_a_file_that_says_mm_still_warns_at_a_size_no_part_has(tmp_path, side, word):
    ring = [[0, 0], [side, 0], [side, side], [0, side]]
    path = tmp_path / "plate.json"
    path.write_text(json.dumps({"name": "plate", "units": "mm", "vertices": ring}))
    [part] = import_parts(path, ImportOptions())[1]
    [note] = [w for w in part.warnings if "check the units" in w]
    assert word in note and "read in mm from the file" in note
