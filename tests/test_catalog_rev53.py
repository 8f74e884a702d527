"""Review rev53, findings 5, 6, 7 and 8a (docs/catalog.md): a failed ``add``/``import`` leaves
no new catalog, ``catalog analyze`` without a sensor exits 1, the duplicate-name error of
``import`` names options ``import`` has, and a broken ``.json`` in a folder is a bad file."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from shared import run_cli

import feederkit.catalog.bulk as bulk
from feederkit.errors import InputError

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
SIDES = ("-wal", "-shm", "-journal")


@pytest.fixture
def here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A clean working folder without $FEEDERKIT_CATALOG."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    return tmp_path


run = run_cli  # (code, stdout, stderr) of the command line, in process


def broken_folder(here: Path) -> Path:
    """A folder whose only source files are bad."""
    d = here / "broken"
    d.mkdir()
    (d / "empty.dxf").write_text("")
    (d / "garbage.stl").write_bytes(b"solid x\nendsolid x\n")
    return d


def catalog_files(here: Path) -> list[str]:
    return sorted(p.name for p in here.iterdir() if p.name.startswith("c.db"))


# 5. A failed add or import leaves no new catalog behind, and an existing one as it was.


def failing_commands(here: Path) -> list[tuple[str, ...]]:
    d = broken_folder(here)
    return [
        ("catalog", "import", str(d)),
        ("catalog", "add", str(d / "empty.dxf")),
        ("catalog", "add", str(d / "empty.dxf"), "--name", "x"),
    ]


def test_a_failed_add_or_import_creates_no_catalog(here, capsys) -> None:
    for command in failing_commands(here):
        code, _, err = run(capsys, *command, "--catalog", "c.db")
        assert code == 2 and err.startswith("error: ") and len(err.splitlines()) == 1, command
        assert catalog_files(here) == [], command


def test_a_failed_add_or_import_leaves_an_empty_file_empty(here, capsys) -> None:
    for command in failing_commands(here):
        (here / "c.db").write_bytes(b"")
        assert run(capsys, *command, "--catalog", "c.db")[0] == 2, command
        assert catalog_files(here) == ["c.db"] and (here / "c.db").read_bytes() == b"", command


def test_a_failed_add_or_import_leaves_an_existing_catalog_byte_identical(here, capsys) -> None:
    assert run(capsys, "catalog", "add", str(CATALOG / "octagon.json"), "--catalog", "c.db")[0] == 0
    before = (here / "c.db").read_bytes()
    for command in failing_commands(here):
        assert run(capsys, *command, "--catalog", "c.db")[0] == 2, command
        assert catalog_files(here) == ["c.db"] and (here / "c.db").read_bytes() == before


def test_a_failure_while_writing_removes_the_new_catalog(here, capsys, monkeypatch) -> None:
    d = here / "good"
    d.mkdir()
    shutil.copy(CATALOG / "octagon.json", d / "octagon.json")

    def refuse(*_args: object, **_kwargs: object) -> None:
        raise InputError("c.db: the disk is full")

    monkeypatch.setattr(bulk, "write_revision", refuse)
    code, _, err = run(capsys, "catalog", "import", str(d), "--catalog", "c.db")
    assert code == 2 and "disk is full" in err
    assert catalog_files(here) == []


def test_an_interrupted_import_removes_the_new_catalog(here, capsys, monkeypatch) -> None:
    d = here / "good"
    d.mkdir()
    shutil.copy(CATALOG / "octagon.json", d / "octagon.json")

    def interrupt(*_args: object, **_kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(bulk, "import_parts", interrupt)
    code, _, _ = run(capsys, "catalog", "import", str(d), "--catalog", "c.db")
    assert code != 0
    assert catalog_files(here) == []


def test_a_successful_add_still_creates_the_catalog(here, capsys) -> None:
    assert run(capsys, "catalog", "add", str(CATALOG / "octagon.json"), "--catalog", "c.db")[0] == 0
    assert "c.db" in catalog_files(here)


# 6. catalog analyze without a sensor: no pair is told apart, so exit 1 (a result to act on).


def two_parts(here: Path, capsys: pytest.CaptureFixture[str], *names: str) -> str:
    for name in names:
        assert run(capsys, "catalog", "add", str(CATALOG / name), "--catalog", "c.db")[0] == 0
    return "c.db"


@pytest.mark.parametrize("flags", [(), ("--sensorless",), ("--json",)])
def test_analyze_without_a_sensor_exits_1_with_one_result_line(here, capsys, flags) -> None:
    db = two_parts(here, capsys, "octagon.json", "isosceles-right-triangle.json")
    code, out, err = run(capsys, "catalog", "analyze", *flags, "--catalog", db)
    assert code == 1
    lines = [x for x in err.splitlines() if not x.startswith("warning:")]
    assert len(lines) == 1 and lines[0].startswith("result: without a sensor no pair")
    assert "--tolerance" in lines[0]
    if "--json" in flags:
        assert json.loads(out)["all_pairs_unrecognizable"] is True


def test_analyze_without_a_sensor_and_one_member_exits_0(here, capsys) -> None:
    db = two_parts(here, capsys, "octagon.json")  # mirror-symmetric: one landing
    code, _, err = run(capsys, "catalog", "analyze", "--catalog", db)
    assert code == 0 and "result:" not in err


# 7. The duplicate-name error of catalog import names options catalog import has.


def test_import_duplicate_name_advice_names_options_import_has(here, capsys) -> None:
    plate = json.loads((CATALOG / "chamfered-plate.json").read_text())
    plate["name"] = "my-plate"
    (here / "plate.json").write_text(json.dumps(plate))
    assert run(capsys, "catalog", "add", "plate.json", "--catalog", "c.db")[0] == 0
    imp = here / "imp"
    imp.mkdir()
    (imp / "plate.json").write_text(json.dumps(plate))
    shutil.copy(CATALOG / "octagon.json", imp / "octagon.json")
    before = (here / "c.db").read_bytes()
    code, _, err = run(capsys, "catalog", "import", str(imp), "--catalog", "c.db")
    assert code == 2 and len(err.splitlines()) == 1
    assert "duplicate name: part 'my-plate' already exists" in err
    assert str(imp / "plate.json") in err
    advised = set(re.findall(r"--[a-z-]+", err))
    assert advised == {"--revise", "--skip-bad"}
    _, help_text, _ = run(capsys, "catalog", "import", "--help")
    assert all(option in help_text for option in advised)
    assert (here / "c.db").read_bytes() == before
    _, _, err = run(capsys, "catalog", "import", str(imp), "--skip-bad", "--catalog", "c.db")
    assert "--name" not in err and "--revise" in err


# 8a. A broken .json in a folder is a bad file; JSON that is clearly no outline is ignored.


def json_folder(here: Path) -> Path:
    d = here / "parts"
    d.mkdir()
    shutil.copy(CATALOG / "octagon.json", d / "octagon.json")
    (d / "notjson.json").write_text("{ not json")
    (d / "package.json").write_text('{"name": "x", "version": "1.0.0"}')
    (d / "plan.json").write_text('{"parts": [], "steps": []}')
    return d


def test_a_broken_json_file_is_a_bad_file_not_ignored(here, capsys) -> None:
    d = json_folder(here)
    code, _, err = run(capsys, "catalog", "import", str(d), "--catalog", "c.db")
    assert code == 2 and "1 of 2 files" in err and str(d / "notjson.json") in err
    code, out, err = run(
        capsys, "catalog", "import", str(d), "--skip-bad", "--json", "--catalog", "c.db"
    )
    assert code == 0, err
    data = json.loads(out)
    assert [p["name"] for p in data["parts"]] == ["octagon"]
    assert [s.split(":")[0] for s in data["skipped"]] == [str(d / "notjson.json")]
    assert sorted(Path(p).name for p in data["ignored"]) == ["package.json", "plan.json"]
    assert "skipped:" in err and "notjson.json" in err


def test_is_outline_file_decides_by_whether_the_text_parses(tmp_path) -> None:
    cases = {
        "{ not json": True,  # does not parse: read as an outline, reported as bad
        "": True,
        '{"vertices": [[0, 0], [1': True,
        '{"name": "a", "vertices": []}': True,
        '{"name": "x", "version": "1.0.0"}': False,  # parses, and is no outline
        "[1, 2, 3]": False,
    }
    for k, (text, expected) in enumerate(cases.items()):
        path = tmp_path / f"f{k}.json"
        path.write_text(text)
        assert bulk.is_outline_file(path) is expected, text
    (tmp_path / "latin1.json").write_bytes(b'{"name": "\xe9"}')
    assert bulk.is_outline_file(tmp_path / "latin1.json")


# 8e. A Ctrl-C while the results are printed, after the work is stored and written, says so.


def compile_c1(capsys, db: str, *extra: str) -> tuple[int, str]:
    """``changeover compile c1`` of the octagon and the triangle at 0.2 mm: exit code, stderr."""
    args = ["changeover", "compile", "c1", "--mix", "octagon,isosceles-right-triangle"]
    code, _, err = run(capsys, *args, "--tolerance", "0.2", *extra, "--catalog", db)
    return code, err


def stored_names(capsys, db: str) -> list[str]:
    """The names of the catalog's stored changeovers."""
    code, out, _ = run(capsys, "changeover", "list", "--catalog", db, "--json")
    assert code == 0
    return [c["name"] for c in json.loads(out)]


def interrupted_after_storing(here, capsys, db: str) -> str:
    """Compile c1 with ``-o c1.json`` under an interrupt that comes after the COMMIT: one line,
    exit 130, naming the stored changeover and the plan file, both in place. The line."""
    code, err = compile_c1(capsys, db, "-o", "c1.json")
    assert code == 130
    (line,) = err.splitlines()
    assert line.startswith("error: interrupted after it stored changeover 'c1' in c.db")
    assert "wrote the plan to c1.json" in line
    assert json.loads((here / "c1.json").read_text())["format"] == "feederkit-plan"
    assert stored_names(capsys, db) == ["c1"]
    return line


def test_ctrl_c_after_the_changeover_is_stored_says_nothing_is_lost(here, capsys, monkeypatch):
    import feederkit.cli.changeover as changeover_cli

    db = two_parts(here, capsys, "octagon.json", "isosceles-right-triangle.json")

    def interrupt(*_args: object, **_kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(changeover_cli, "plan_tree", interrupt)  # drawn after the commit
    line = interrupted_after_storing(here, capsys, db)
    assert "only the printing was cut" in line


def test_ctrl_c_just_after_the_commit_keeps_the_files_of_the_stored_changeover(
    here, capsys, monkeypatch
):
    # A new user's review: one Ctrl-C in about a hundred left a changeover stored with no plan
    # file (it came after the COMMIT, and the files were taken back as if nothing was stored).
    import feederkit.mix.changeover as changeover_lib

    db = two_parts(here, capsys, "octagon.json", "isosceles-right-triangle.json")
    real = changeover_lib.save_changeover

    def then_interrupt(*args: object, **kwargs: object) -> None:
        real(*args, **kwargs)  # committed
        raise KeyboardInterrupt

    monkeypatch.setattr(changeover_lib, "save_changeover", then_interrupt)
    interrupted_after_storing(here, capsys, db)


def test_ctrl_c_after_the_files_are_placed_and_before_the_commit_leaves_neither(
    here, capsys, monkeypatch
):
    import feederkit.mix.changeover as changeover_lib

    db = two_parts(here, capsys, "octagon.json", "isosceles-right-triangle.json")
    real = changeover_lib.save_changeover

    def files_then_interrupt(*args: object, before_commit=None, **kwargs: object) -> None:
        def placed_then_interrupt() -> None:
            before_commit()
            assert (here / "c1.json").is_file()
            raise KeyboardInterrupt

        real(*args, before_commit=placed_then_interrupt, **kwargs)

    monkeypatch.setattr(changeover_lib, "save_changeover", files_then_interrupt)
    code, err = compile_c1(capsys, db, "-o", "c1.json")
    assert (code, err) == (130, "error: interrupted\n")
    assert not (here / "c1.json").exists() and list(here.glob(".c1.json.*")) == []
    assert stored_names(capsys, db) == []


def test_ctrl_c_before_anything_is_stored_says_only_interrupted(here, capsys, monkeypatch):
    import feederkit.cli.changeover as changeover_cli

    db = two_parts(here, capsys, "octagon.json", "isosceles-right-triangle.json")

    def interrupt(*_args: object, **_kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(changeover_cli, "compile_changeover", interrupt)
    code, err = compile_c1(capsys, db)
    assert (code, err) == (130, "error: interrupted\n")
