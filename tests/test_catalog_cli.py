"""``feederkit catalog ...`` end to end: output, exit codes, one-line errors, catalog unchanged."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import fixtures_cad as fx
import pytest
import trimesh
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


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def run_json(capsys, *args: str):
    code, out, err = run(capsys, *args, "--json")
    assert code == 0, err
    return json.loads(out)


def square(path: Path, side: float = 10.0, name: str | None = None) -> Path:
    save_outline_json(
        make_outline(name or path.stem, [(0, 0), (side, 0), (side, side), (0, side)]), path
    )
    return path


def test_init_add_list_show_export_remove(tmp_path, db, capsys):
    plate = fx.write_plate(tmp_path / "plate.dxf")
    (added,) = run_json(capsys, "catalog", "add", str(plate), "--catalog", str(db))
    assert added["name"] == "plate" and added["revision"] == 1 and added["status"] == "added"
    (again,) = run_json(capsys, "catalog", "add", str(plate), "--catalog", str(db))
    assert again["status"] == "unchanged"
    listed = run_json(capsys, "catalog", "list", "--catalog", str(db))
    assert [p["name"] for p in listed] == ["plate"]
    assert listed[0]["area"] == pytest.approx(fx.PLATE_AREA, rel=2e-4) and listed[0]["holes"] == 2
    shown = run_json(capsys, "catalog", "show", "plate", "--catalog", str(db))
    assert shown["revision"] == 1 and shown["source"]["kind"] == "dxf"
    assert shown["source"]["units"] == "mm" and shown["hull_tolerance"] == 0.05
    assert shown["orientable"] is True and len(shown["outline"]["holes"]) == 2
    assert shown["revisions"][0]["sha256"] == shown["source"]["sha256"]
    code, out, _ = run(capsys, "catalog", "show", "plate", "--catalog", str(db))
    assert code == 0 and "plate revision 1" in out and "sha256" in out
    code, out, _ = run(capsys, "catalog", "list", "--catalog", str(db))
    assert code == 0 and "plate" in out
    target = tmp_path / "out" / "plate.json"
    target.parent.mkdir()
    assert (
        run(capsys, "catalog", "export", "plate", "-o", str(target), "--catalog", str(db))[0] == 0
    )
    data = json.loads(target.read_text())
    assert data["name"] == "plate" and data["units"] == "mm" and len(data["holes"]) == 2
    assert run(capsys, "catalog", "remove", "plate", "--catalog", str(db))[0] == 0
    assert run_json(capsys, "catalog", "list", "--catalog", str(db)) == []


def test_add_with_name_and_revisions(tmp_path, db, capsys):
    src = square(tmp_path / "s.json")
    run_json(capsys, "catalog", "add", str(src), "--name", "bracket", "--catalog", str(db))
    square(src, side=20.0)
    (rev,) = run_json(capsys, "catalog", "add", str(src), "--name", "bracket", "--catalog", str(db))
    assert rev["revision"] == 2 and rev["status"] == "revised"
    shown = run_json(capsys, "catalog", "show", "bracket", "--revision", "1", "--catalog", str(db))
    assert shown["area"] == 100.0 and len(shown["revisions"]) == 2


def test_env_and_default_catalog(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    src = square(tmp_path / "a.json")
    assert run(capsys, "catalog", "add", str(src))[0] == 0
    assert (tmp_path / "feederkit.db").exists()
    env_db = tmp_path / "env.db"
    monkeypatch.setenv("FEEDERKIT_CATALOG", str(env_db))
    assert run(capsys, "catalog", "add", str(src))[0] == 0
    assert [p["name"] for p in run_json(capsys, "catalog", "list")] == ["a"]
    assert env_db.exists()


def test_import_directory_table_and_json(tmp_path, db, capsys):
    d = tmp_path / "parts"
    (d / "deep").mkdir(parents=True)
    square(d / "a.json")
    square(d / "deep" / "b.json", side=4.0)
    fx.write_disk(d / "deep" / "disk.dxf")
    fx.write_mesh(trimesh.creation.box((10, 20, 30)), d / "box.stl")
    code, out, err = run(capsys, "catalog", "import", str(d), "--catalog", str(db))
    assert code == 0, err
    for name in ("a", "b", "disk", "box", "4 added"):
        assert name in out
    assert "not orientable by pushing" in err
    data = run_json(capsys, "catalog", "import", str(d), "--catalog", str(db))
    assert sorted(p["name"] for p in data["parts"]) == ["a", "b", "box", "disk"]
    assert {p["status"] for p in data["parts"]} == {"unchanged"}
    assert [p["orientable"] for p in data["parts"] if p["name"] == "disk"] == [False]


def test_cad_options_reach_the_importer(tmp_path, db, capsys):
    two = fx.write_two_parts(tmp_path / "two.dxf")
    data = run_json(capsys, "catalog", "add", str(two), "--all-parts", "--catalog", str(db))
    assert [p["name"] for p in data] == ["two", "two-2"]
    box = fx.write_mesh(trimesh.creation.box((10, 20, 30)), tmp_path / "box.stl")
    run_json(
        capsys, "catalog", "add", str(box), "--pose", "5", "--units", "cm", "--catalog", str(db)
    )
    shown = run_json(capsys, "catalog", "show", "box", "--catalog", str(db))
    assert shown["mesh_pose"]["index"] == 5 and shown["area"] == pytest.approx(20000.0)
    blk = fx.write_rotated_block(tmp_path / "blk.dxf")
    run_json(
        capsys,
        "catalog",
        "add",
        str(blk),
        "--hull-tolerance",
        "0",
        "--flatten-tolerance",
        "0.5",
        "--layer",
        "0",
        "--catalog",
        str(db),
    )
    assert run_json(capsys, "catalog", "show", "blk", "--catalog", str(db))["hull_tolerance"] == 0.0


# ---- bad input: exit 2, one line, catalog unchanged --------------------------------------


def open_square(msp):
    msp.add_line((0, 0), (10, 0))
    msp.add_line((10, 0), (10, 10))


def zero_area(msp):
    msp.add_lwpolyline([(0, 0), (5, 0), (10, 0)], close=True)


def bad_files(tmp_path: Path) -> dict[str, tuple[Path, list[str], str]]:
    empty = tmp_path / "empty.dxf"
    empty.write_bytes(b"")
    corrupt = tmp_path / "corrupt.dxf"
    corrupt.write_bytes(b"\x00\xff garbage " * 300)
    box = trimesh.creation.box((10, 20, 30))
    leaky = fx.write_mesh(
        trimesh.Trimesh(box.vertices, box.faces[3:], process=False), tmp_path / "leaky.stl"
    )
    big = tmp_path / "big.dxf"
    with big.open("wb") as fh:
        fh.truncate(51_000_000)
    return {
        "empty": (empty, [], "empty"),
        "corrupt": (corrupt, [], "not a DXF file"),
        "text only": (
            fx.write_entities(tmp_path / "text.dxf", lambda m: m.add_text("x")),
            [],
            "no outline",
        ),
        "open": (fx.write_entities(tmp_path / "open.dxf", open_square), [], "no closed outline"),
        "zero area": (fx.write_entities(tmp_path / "zero.dxf", zero_area), [], "zero area"),
        "unit": (fx.write_plate(tmp_path / "plate.dxf"), ["--units", "furlong"], "unknown unit"),
        "leaky mesh": (leaky, [], "not a closed"),
        "over 50 MB": (big, [], "over the 50 MB limit"),
        "missing": (tmp_path / "missing.dxf", [], "no such file"),
    }


CASES = [
    "empty",
    "corrupt",
    "text only",
    "open",
    "zero area",
    "unit",
    "leaky mesh",
    "over 50 MB",
    "missing",
]


@pytest.mark.parametrize("case", CASES)
def test_bad_input_exit_2_one_line_catalog_unchanged(tmp_path, db, capsys, case):
    assert main(["catalog", "add", str(square(tmp_path / "keep.json")), "--catalog", str(db)]) == 0
    capsys.readouterr()
    path, extra, message = bad_files(tmp_path)[case]
    before = snapshot(db)
    code, out, err = run(capsys, "catalog", "add", str(path), *extra, "--catalog", str(db))
    assert code == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], err
    assert "Traceback" not in err and out == ""
    assert snapshot(db) == before


def test_large_file_allowed_with_a_flag(tmp_path, db, capsys):
    big = bad_files(tmp_path)["over 50 MB"][0]
    code, _, err = run(capsys, "catalog", "add", str(big), "--allow-large", "--catalog", str(db))
    assert code == 2 and "limit" not in err and "not a DXF file" in err  # read, then refused


def test_leaky_mesh_with_com(tmp_path, db, capsys):
    leaky = bad_files(tmp_path)["leaky mesh"][0]
    data = run_json(capsys, "catalog", "add", str(leaky), "--com", "0", "0", "--catalog", str(db))
    assert data[0]["status"] == "added"


def test_duplicate_name(tmp_path, db, capsys):
    run_json(capsys, "catalog", "add", str(square(tmp_path / "a.json")), "--catalog", str(db))
    other = square(tmp_path / "b.json", side=3.0)
    before = snapshot(db)
    code, _, err = run(capsys, "catalog", "add", str(other), "--name", "a", "--catalog", str(db))
    assert code == 2 and "duplicate name" in err and snapshot(db) == before


def test_directory_with_one_bad_file_adds_nothing(tmp_path, db, capsys):
    d = tmp_path / "parts"
    d.mkdir()
    for k in range(5):
        square(d / f"p{k}.json", side=3.0 + k)
    fx.write_entities(d / "open.dxf", open_square)
    before = snapshot(db)
    code, out, err = run(capsys, "catalog", "import", str(d), "--catalog", str(db))
    assert code == 2 and "open.dxf" in err and "no closed outline" in err
    assert snapshot(db) == before


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["catalog", "show", "nope"], "no part named 'nope'"),
        (["catalog", "remove", "nope"], "no part named 'nope'"),
        (["catalog", "export", "nope", "-o", "x.json"], "no part named 'nope'"),
        (["catalog", "import", "no-such-dir"], "no such directory"),
        (["catalog", "add", "x.step"], "no such file"),
    ],
)
def test_usage_errors(db, capsys, args, message):
    code, _, err = run(capsys, *args, "--catalog", str(db))
    assert code == 2 and message in err and "Traceback" not in err
    if "no part named" in message:  # which catalog file was searched
        assert str(db) in "".join(err.split())  # a wrapped line joined


def test_export_to_a_missing_folder(tmp_path, db, capsys):
    run_json(capsys, "catalog", "add", str(square(tmp_path / "a.json")), "--catalog", str(db))
    code, _, err = run(
        capsys,
        "catalog",
        "export",
        "a",
        "-o",
        str(tmp_path / "no" / "a.json"),
        "--catalog",
        str(db),
    )
    assert code == 2 and "does not exist" in err


def test_missing_catalog_for_reading(tmp_path, capsys):
    code, _, err = run(capsys, "catalog", "list", "--catalog", str(tmp_path / "none.db"))
    assert code == 2 and "no catalog there" in err


@pytest.mark.slow  # three fresh interpreters; test_errors_boundary runs one by default
def test_subprocess_exit_codes(tmp_path):
    cmd = [sys.executable, "-c", "from feederkit.cli.app import run; run()"]
    db = tmp_path / "c.db"
    ok = subprocess.run(
        [*cmd, "catalog", "init", "--catalog", str(db)], capture_output=True, text=True
    )
    assert ok.returncode == 0
    bad = subprocess.run(
        [*cmd, "catalog", "add", str(tmp_path / "none.dxf"), "--catalog", str(db)],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "Traceback" not in bad.stderr
    usage = subprocess.run([*cmd, "catalog", "add"], capture_output=True, text=True)
    assert usage.returncode == 2 and "Traceback" not in usage.stderr


def test_orientability_is_said_to_be_the_ideal_models(tmp_path, db, capsys):
    """A part flagged orientable may have no strong plan at 1 degree: list, show and --json
    say the flag is the ideal model's."""
    square(tmp_path / "sq.json")
    (added,) = run_json(capsys, "catalog", "add", str(tmp_path / "sq.json"), "--catalog", str(db))
    assert added["orientable_ideal"] is True and added["orientable"] is True
    (listed,) = run_json(capsys, "catalog", "list", "--catalog", str(db))
    assert listed["orientable_ideal"] is True and listed["orientable"] is True
    shown = run_json(capsys, "catalog", "show", "sq", "--catalog", str(db))
    assert shown["orientable_ideal"] is True
    code, out, _ = run(capsys, "catalog", "list", "--catalog", str(db))
    assert code == 0 and "orient*" in out.splitlines()[0]
    note = " ".join(out.split())
    assert "* orient: pushing orients the part on the ideal model" in note
    assert "catalog analyze --rotation-error DEG" in note and "under uncertainty" in note
    assert out.splitlines()[-1] == "1 part"
    assert max(len(line) for line in out.splitlines()) <= 80
    code, out, _ = run(capsys, "catalog", "show", "sq", "--catalog", str(db))
    assert code == 0 and "orientable (ideal)" in out


def test_an_empty_list_has_no_footnote(db, capsys):
    code, out, _ = run(capsys, "catalog", "list", "--catalog", str(db))
    assert code == 0 and "ideal model" not in out and out.splitlines()[-1] == "0 parts"
