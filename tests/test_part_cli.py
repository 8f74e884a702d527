"""``feederkit part analyze`` through ``main``: JSON, the table, bad input (exit 2), flags."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
STATE_KEYS = {"id", "edge", "normal_deg", "resting_range_deg", "diameter", "pose_deg"}


def outline_file(tmp_path: Path, name: str, vertices, **extra) -> str:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"name": name, "units": "mm", "vertices": vertices, **extra}))
    return str(path)


@pytest.fixture
def rect(tmp_path: Path) -> str:
    return outline_file(tmp_path, "rect", [[0, 0], [2, 0], [2, 1], [0, 1]])


def run_json(capsys, *args: str) -> list[dict]:
    assert main(["part", "analyze", *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def fails_with(capsys, args: list[str], words: str) -> None:
    assert main(args) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert words in err
    assert "\n" not in err, err  # one line
    assert "Traceback" not in captured.err


def test_json_of_the_centred_rectangle(capsys, rect: str) -> None:
    (d,) = run_json(capsys, rect)
    assert d["name"] == "rect" and d["units"] == "mm"
    assert d["com"] == pytest.approx([1.0, 0.5])
    assert d["hull"] == [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]
    assert d["symmetry_period_deg"] == pytest.approx(180.0)
    assert "class" not in d and "bound" not in d
    assert len(d["stable_states"]) == 4
    for s in d["stable_states"]:
        assert set(s) == STATE_KEYS
        lo, hi = s["resting_range_deg"]
        assert lo < s["normal_deg"] < hi
    ranges = [s["resting_range_deg"] for s in d["stable_states"]]
    widths = sorted(round(hi - lo, 2) for lo, hi in ranges)
    assert widths == [53.13, 53.13, 126.87, 126.87]
    assert sorted(s["diameter"] for s in d["stable_states"]) == pytest.approx([1, 1, 2, 2])
    assert d["push_period_deg"] == pytest.approx(180.0)
    assert d["push_diameter_symmetry"]["kind"] == "symmetric"
    assert d["edge_kinds"] == ["stable"] * 4
    assert d["near_metastable_edges"] == []


def test_sensor_models_give_class_and_bound(capsys, rect: str) -> None:
    (d,) = run_json(capsys, rect, "--tolerance", "0.01")
    assert (d["class"], d["bound"]) == (5, 1)
    assert d["sensor"] == {"model": "tolerance", "tolerance_mm": 0.01}
    (d,) = run_json(capsys, rect, "--led-pitch", "0.4", "--noise", "0.05")
    assert d["class"] in range(1, 9) and d["bound"] >= 1
    (d,) = run_json(capsys, rect, "--sensorless")
    assert (d["class"], d["bound"]) == (8, 3)


def test_com_option_and_several_sources(capsys, tmp_path: Path, rect: str) -> None:
    tri = outline_file(tmp_path, "tri", [[0, 0], [1, 0], [0, 1]])
    out = run_json(capsys, rect, tri)
    assert [d["name"] for d in out] == ["rect", "tri"]
    assert sorted(s["diameter"] for s in out[1]["stable_states"]) == pytest.approx(
        [math.sqrt(0.5), 1.0, 1.0]
    )
    (d,) = run_json(capsys, rect, "--com", "0.8", "0.4")
    assert d["com"] == [0.8, 0.4]
    assert d["symmetry_period_deg"] == 360.0


def test_table_for_people(capsys, rect: str) -> None:
    assert main(["part", "analyze", rect, "--tolerance", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "rect" in out and "4 stable states" in out
    assert "resting range" in out and "126.87" in out
    assert "class 5" in out


def test_whole_catalog(capsys) -> None:
    files = sorted(str(p) for p in CATALOG.glob("*.json"))
    out = run_json(capsys, *files, "--tolerance", "0.05")
    assert len(out) == len(files) >= 9
    assert all(1 <= d["class"] <= 8 for d in out)


def test_near_metastable_edge_is_analysed_and_named(capsys, tmp_path: Path) -> None:
    path = outline_file(tmp_path, "almost", [[0, 0], [2, 0], [3, 1], [0, 1]], com=[2.001, 0.5])
    assert main(["part", "analyze", path, "--json"]) == 0
    captured = capsys.readouterr()
    (d,) = json.loads(captured.out)
    assert d["edge_kinds"][0] == "unstable"
    assert [n["edge"] for n in d["near_metastable_edges"]] == [0]
    assert d["near_metastable_edges"][0]["vertex"] == 1
    warning = captured.err.strip()
    assert "almost" in warning and "near-metastable edge 0" in warning and "vertex 1" in warning
    assert "\n" not in warning
    assert main(["part", "analyze", path]) == 0
    out = capsys.readouterr().out
    assert "near-metastable: edge 0 (unstable" in out


def test_near_metastable_stable_edge_is_starred_in_the_table(capsys, tmp_path: Path) -> None:
    path = outline_file(tmp_path, "edgy", [[0, 0], [2, 0], [2, 1], [0, 1]], com=[1.999, 0.5])
    assert main(["part", "analyze", path]) == 0
    captured = capsys.readouterr()
    assert "4 stable states" in captured.out
    assert " 0* " in captured.out and " 2* " in captured.out
    assert "edge 0 (stable" in captured.err


@pytest.mark.parametrize(
    ("vertices", "extra", "words"),
    [
        ([[0, 0], [1, 0]], {}, "three distinct points"),
        ([[0, 0], [1, 0], [1, 0], [0, 0]], {}, "three distinct points"),
        ([[0, 0], [1, 0], [2, 0]], {}, "zero area"),
        ([[0, 0], [1, 0], [math.nan, 1]], {}, "NaN or infinite"),
        ([[0, 0], [1, 0], [0, math.inf]], {}, "NaN or infinite"),
        ([[0, 0], [2, 2], [2, 0], [0, 2]], {}, "self-intersecting"),
        ([[0, 0], [1, 0], [0, 1]], {"com": [1, 1]}, "outside the contact hull"),
        ([[0, 0], [1, 0], [0, 1]], {"holes": [[[5, 5], [6, 5], [5, 6]]]}, "hole"),
        ([[0, 0], [1, 0], [0, 1]], {"units": "furlong"}, "unknown unit"),
        ("nonsense", {}, "list of [x, y] points"),
    ],
)
def test_bad_outline_files_exit_2(capsys, tmp_path: Path, vertices, extra, words: str) -> None:
    path = outline_file(tmp_path, "bad", vertices, **extra)
    fails_with(capsys, ["part", "analyze", path], words)
    fails_with(capsys, ["part", "analyze", path, "--json"], words)


def test_com_outside_the_hull_from_the_command_line(capsys, rect: str) -> None:
    fails_with(capsys, ["part", "analyze", rect, "--com", "3", "0.5"], "outside the contact hull")
    fails_with(capsys, ["part", "analyze", rect, "--com", "2", "0.5"], "on the boundary")
    fails_with(capsys, ["part", "analyze", rect, "--com", "nan", "0.5"], "NaN or infinite")


def test_unreadable_files_exit_2(capsys, tmp_path: Path) -> None:
    fails_with(capsys, ["part", "analyze", str(tmp_path / "missing.json")], "missing.json")
    broken = tmp_path / "broken.json"
    broken.write_text("{ not json")
    fails_with(capsys, ["part", "analyze", str(broken)], "not valid JSON")
    binary = tmp_path / "binary.json"
    binary.write_bytes(b"\xff\xfe\x00\x01")
    fails_with(capsys, ["part", "analyze", str(binary)], "binary.json")
    folder = tmp_path / "folder.json"
    folder.mkdir()
    fails_with(capsys, ["part", "analyze", str(folder)], "folder.json")


def test_bad_sensor_options_exit_2(capsys, rect: str) -> None:
    fails_with(capsys, ["part", "analyze", rect, "--tolerance", "-1"], "--tolerance")
    fails_with(capsys, ["part", "analyze", rect, "--tolerance", "1", "--led-pitch", "1"], "one of")
    fails_with(capsys, ["part", "analyze", rect, "--noise", "0.1"], "--noise")
    assert main(["part", "analyze"]) == 2  # a SOURCE is required
    capsys.readouterr()


def test_part_group_lists_analyze_and_plot(capsys) -> None:
    assert main(["part", "--help"]) == 0
    out = capsys.readouterr().out
    assert "analyze" in out
    assert "plot" in out


def _unitless_plate(tmp_path: Path) -> str:
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 0
    doc.modelspace().add_lwpolyline([(0, 0), (40, 0), (40, 20), (0, 20)], close=True)
    doc.modelspace().add_lwpolyline([(60, 0), (70, 0), (70, 10), (60, 10)], close=True)
    path = tmp_path / "sheet.dxf"
    doc.saveas(path)
    return str(path)


def test_analyze_prints_the_importers_warnings(capsys, tmp_path: Path) -> None:
    src = _unitless_plate(tmp_path)
    assert main(["part", "analyze", src, "--json"]) == 0
    err = capsys.readouterr().err
    assert f"warning: {src}: the drawing has no units" in err
    assert "left out: sheet-2" in err


def test_analyze_takes_the_import_options(capsys, tmp_path: Path) -> None:
    src = _unitless_plate(tmp_path)
    (d,) = run_json(capsys, src, "--units", "cm")
    xs = [p[0] for p in d["hull"]]
    assert max(xs) - min(xs) == pytest.approx(400.0)
    fails_with(capsys, ["part", "analyze", src, "--max-entities", "1"], "--max-entities")
    fails_with(capsys, ["part", "analyze", src, "--space", "nope"], "--space must be")


def test_plot_and_lookalike_print_the_importers_warnings(capsys, tmp_path: Path) -> None:
    src = _unitless_plate(tmp_path)
    out = tmp_path / "p.png"
    assert main(["part", "plot", src, "-o", str(out), "--units", "mm"]) == 0
    assert "the drawing has no units" not in capsys.readouterr().err  # --units given
    assert main(["lookalike", src, "--keep", "push", "-o", str(tmp_path / "l.json")]) == 0
    assert "the drawing has no units" in capsys.readouterr().err


def test_units_apply_to_outline_files_and_are_refused_for_catalog_parts(tmp_path, capsys):
    """``--units`` overrides an outline file's units as it does a drawing's; an unknown
    unit, or one given for a catalog part (stored in mm), is one line and exit 2."""
    src = tmp_path / "tri.json"
    src.write_text(json.dumps({"name": "tri", "vertices": [[0, 0], [10, 0], [0, 5]]}))
    assert main(["part", "analyze", str(src), "--json"]) == 0
    mm = json.loads(capsys.readouterr().out)[0]
    assert main(["part", "analyze", str(src), "--units", "cm", "--json"]) == 0
    cm = json.loads(capsys.readouterr().out)[0]
    assert cm["com"] == pytest.approx([10 * x for x in mm["com"]])
    assert main(["part", "analyze", str(src), "--units", "furlong"]) == 2
    err = capsys.readouterr().err
    assert "unknown unit 'furlong'" in err and len(err.strip().splitlines()) == 1
    db = str(tmp_path / "cat.db")
    assert main(["catalog", "init", "--catalog", db]) == 0
    assert main(["catalog", "add", str(src), "--catalog", db]) == 0
    capsys.readouterr()
    assert main(["part", "analyze", "tri", "--catalog", db, "--units", "cm"]) == 2
    err = capsys.readouterr().err
    assert "--units applies to drawing files" in err and len(err.strip().splitlines()) == 1
    assert main(["part", "analyze", "tir", "--catalog", db, "--units", "cm"]) == 2
    assert "no such file or catalog part" in capsys.readouterr().err  # the typo first
