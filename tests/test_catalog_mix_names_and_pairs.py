"""A new user's review of mixes and catalogs: part names ``--mix`` cannot name, the catalog
screen under a shape tolerance, the pairs a stored changeover cannot tell apart, the pairs'
``kind``, honest advice, and the wording and layout of the tables."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from shared import catalog_with, no_stray_profile, one_line_error, run_cli  # noqa: F401

from feederkit.catalog import list_parts, similar_names

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def outline(name: str) -> dict:
    """The chamfered plate's outline file under another name."""
    return {**json.loads((CATALOG / "chamfered-plate.json").read_text()), "name": name}


def rename_part(db: str, old: str, new: str) -> None:
    """A part stored before names with ',' or ':' were refused (an old catalog's row)."""
    with sqlite3.connect(db) as conn:
        conn.execute("UPDATE parts SET name = ? WHERE name = ?", (new, old))


@pytest.fixture()
def db(tmp_path, capsys) -> str:
    """The L bracket and the T clip."""
    return catalog_with(tmp_path, capsys, ("l-bracket", "t-clip"))


# Finding 1: a name with ',' or ':' cannot be put in a mix.


@pytest.mark.parametrize(("name", "char"), [("t-clip:0.5", "':'"), ("clip,a", "','")])
def test_add_refuses_a_name_from_the_file_that_mix_cannot_name(db, tmp_path, capsys, name, char):
    source = tmp_path / "odd.json"
    source.write_text(json.dumps(outline(name)))
    err = one_line_error(capsys, ["catalog", "add", str(source), "--catalog", db])
    assert f"invalid part name {name!r}: {char}" in err and "--name NAME" in err
    assert [p.name for p in list_parts(db)] == ["l-bracket", "t-clip"]


def test_add_refuses_such_a_name_given_with_name(db, tmp_path, capsys):
    source = tmp_path / "plate.json"
    source.write_text(json.dumps(outline("plate")))
    args = ["catalog", "add", str(source), "--name", "plate:2", "--catalog", db]
    err = one_line_error(capsys, args)
    assert "invalid part name 'plate:2': ':'" in err and "give --name a name without" in err
    assert "plate:2" not in {p.name for p in list_parts(db)}


def test_import_refuses_such_a_name_and_imports_nothing(db, tmp_path, capsys):
    folder = tmp_path / "parts"
    folder.mkdir()
    (folder / "good.json").write_text(json.dumps(outline("plate")))
    (folder / "odd.json").write_text(json.dumps(outline("clip,a")))
    err = one_line_error(capsys, ["catalog", "import", str(folder), "--catalog", db])
    assert "odd.json: invalid part name 'clip,a': ','" in err
    assert "rename the file, or change an outline file's" in err
    assert [p.name for p in list_parts(db)] == ["l-bracket", "t-clip"]


def test_an_old_part_with_a_colon_still_lists_and_shows(db, tmp_path, capsys):
    source = tmp_path / "plate.json"
    source.write_text(json.dumps(outline("plate")))
    assert run_cli(capsys, "catalog", "add", str(source), "--catalog", db)[0] == 0
    rename_part(db, "plate", "t-clip:0.5")
    rc, out, _ = run_cli(capsys, "catalog", "list", "--json", "--catalog", db)
    assert rc == 0 and "t-clip:0.5" in {p["name"] for p in json.loads(out)}
    rc, out, _ = run_cli(capsys, "catalog", "show", "t-clip:0.5", "--catalog", db)
    assert rc == 0 and "t-clip:0.5" in out


def test_a_mix_item_that_is_a_part_name_and_name_share_is_refused(db, tmp_path, capsys):
    source = tmp_path / "plate.json"
    source.write_text(json.dumps(outline("plate")))
    assert run_cli(capsys, "catalog", "add", str(source), "--catalog", db)[0] == 0
    rename_part(db, "plate", "t-clip:0.5")
    args = ["changeover", "compile", "odd", "--mix", "t-clip:0.5,l-bracket", "--catalog", db]
    err = one_line_error(capsys, [*args, "--tolerance", "0.2", "--landings", "up"])
    assert "--mix t-clip:0.5 is ambiguous" in err and "part 't-clip' at share 0.5" in err
    rc, out, _ = run_cli(capsys, "changeover", "list", "--json", "--catalog", db)
    assert rc == 0 and json.loads(out) == []


def test_a_hint_never_suggests_a_name_mix_cannot_take(db, tmp_path, capsys):
    source = tmp_path / "plate.json"
    source.write_text(json.dumps(outline("clip-a")))
    assert run_cli(capsys, "catalog", "add", str(source), "--catalog", db)[0] == 0
    assert "clip-a" in similar_names(db, "clip")
    rename_part(db, "clip-a", "clip,a")
    assert "clip,a" not in similar_names(db, "clip")
    err = one_line_error(capsys, ["catalog", "show", "clip,", "--catalog", db])
    assert "clip,a" not in err and "no part named 'clip,'" in err


# Finding 11: a revision that is not a number; inputs checked before the changeover's name.


@pytest.mark.parametrize(
    "args",
    [
        ["changeover", "compile", "x", "--mix", "l-bracket@abc,t-clip"],
        ["design", "sensor", "--mix", "l-bracket@abc,t-clip"],
    ],
)
def test_a_revision_that_is_not_a_number_is_named_as_such(db, capsys, args):
    err = one_line_error(capsys, [*args, "--catalog", db])
    assert "part 'l-bracket' has no revision 'abc'" in err and "no such file" not in err


def test_a_source_with_a_revision_that_is_not_a_number_is_named_as_such(db, capsys):
    # A SOURCE may be a file, so "no such file" stays; the revision is named too.
    err = one_line_error(capsys, ["plan", "l-bracket@abc", "--tolerance", "0.2", "--catalog", db])
    assert "no such file" in err and "part 'l-bracket' has no revision 'abc'" in err


def test_compile_checks_its_inputs_before_the_name_is_taken(db, capsys):
    args = ["changeover", "compile", "lt", "--mix", "l-bracket,t-clip", "--catalog", db]
    assert run_cli(capsys, *args, "--tolerance", "0.5", "--landings", "up")[0] in (0, 1)
    err = one_line_error(capsys, [*args, "--tolerance", "0.5", "--landings", "sideways"])
    assert "already exists" not in err and "sideways" in err
    err = one_line_error(capsys, [*args, "--tolerance", "0.5", "--accept", "pose-x"])
    assert "already exists" not in err


# Finding 5: a member that cannot take the shape tolerance is left out of the screen.


def nicked_square(tmp_path: Path) -> Path:
    """A 20 mm square with one corner cut by 0.2 mm: half its smallest hull edge is 0.14 mm."""
    path = tmp_path / "nicked.json"
    square = [[0, 0], [20, 0], [20, 19.8], [19.8, 20], [0, 20]]
    path.write_text(json.dumps({"name": "nicked", "units": "mm", "vertices": square}))
    return path


def test_analyze_leaves_out_a_member_too_small_for_the_shape_tolerance(db, tmp_path, capsys):
    assert run_cli(capsys, "catalog", "add", str(nicked_square(tmp_path)), "--catalog", db)[0] == 0
    args = ("catalog", "analyze", "--tolerance", "0.5", "--shape-tolerance", "0.5")
    rc, out, _ = run_cli(capsys, *args, "--json", "--catalog", db)
    data = json.loads(out)
    assert rc in (0, 1) and data["uncertainty"]["shape_tolerance_mm"] == 0.5
    assert data["counts"]["parts"] == 3  # the L bracket up and down, the T clip (symmetric)
    left_out = [line for line in data["skipped"] if "nicked" in line]
    assert len(left_out) == 1 and "smallest hull edge" in left_out[0]
    assert "left out (--shape-tolerance)" in left_out[0]
    rc, _, err = run_cli(capsys, *args, "--catalog", db)
    warned = [line for line in err.splitlines() if line.startswith("warning: nicked")]
    assert rc in (0, 1) and len(warned) == 1 and warned[0].endswith("(--shape-tolerance)")


def test_analyze_refuses_a_shape_tolerance_no_member_takes(tmp_path, capsys):
    path = str(tmp_path / "c.db")
    assert run_cli(capsys, "catalog", "init", "--catalog", path)[0] == 0
    assert (
        run_cli(capsys, "catalog", "add", str(nicked_square(tmp_path)), "--catalog", path)[0] == 0
    )
    args = ["catalog", "analyze", "--tolerance", "0.5", "--shape-tolerance", "0.5"]
    err = one_line_error(capsys, [*args, "--catalog", path])
    assert "no member takes the declared tolerances" in err and "--shape-tolerance" in err


# Finding 6: a stored changeover shows the pairs its plan cannot tell apart, as compile did.


def add_variant(db: str, tmp_path: Path, capsys, name: str, change) -> None:
    """The L bracket changed by ``change`` (its outline file's dict), added as ``name``."""
    data = {**json.loads((CATALOG / "l-bracket.json").read_text()), "name": name}
    change(data)
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    assert run_cli(capsys, "catalog", "add", str(path), "--catalog", db)[0] == 0


def mirror(data: dict) -> None:
    data["vertices"] = [[-x, y] for x, y in data["vertices"]]
    data["holes"] = [[[-x, y] for x, y in h] for h in data["holes"]]


def move_hole(data: dict) -> None:
    data["holes"][0] = [[x - 3, y] for x, y in data["holes"][0]]


@pytest.mark.parametrize(
    ("variant", "change", "landings", "kind"),
    [
        ("l-bracket-mirror", mirror, "all", "same-push-diameter"),  # decided again exactly
        ("l-bracket-hole-moved", move_hole, "up", "uncertainty"),  # read off the plan
    ],
)
def test_show_and_list_name_the_pairs_compile_named(
    db, tmp_path, capsys, variant, change, landings, kind
):
    add_variant(db, tmp_path, capsys, variant, change)
    mix = f"l-bracket,{variant}"
    args = ["changeover", "compile", "co", "--mix", mix, "--tolerance", "0.2"]
    rc, out, _ = run_cli(capsys, *args, "--landings", landings, "--json", "--catalog", db)
    compiled = json.loads(out)["unrecognizable_pairs"]
    assert rc == 1 and compiled and {w["kind"] for w in compiled} == {kind}  # finding 10
    rc, out, _ = run_cli(capsys, "changeover", "show", "co", "--json", "--catalog", db)
    assert rc == 0 and json.loads(out)["unrecognizable_pairs"] == compiled
    rc, out, _ = run_cli(capsys, "changeover", "list", "--json", "--catalog", db)
    assert rc == 0 and json.loads(out)[0]["unrecognizable_pairs"] == compiled
    rc, out, _ = run_cli(capsys, "changeover", "show", "co", "--catalog", db)
    text = " ".join(out.split())
    assert rc == 0 and "parts (or landings) this plan cannot tell apart" in text
    assert all(w["reason"].split()[0] in text for w in compiled)
    rc, out, _ = run_cli(capsys, "changeover", "list", "--catalog", db)
    pair = f"{compiled[0]['part_a']} & {compiled[0]['part_b']}"
    assert rc == 0 and "changeover co: its plan cannot tell apart" in out and pair in out


def test_show_of_a_mix_told_apart_names_no_pairs(db, capsys):
    args = ["changeover", "compile", "lt", "--mix", "l-bracket,t-clip", "--tolerance", "0.5"]
    assert run_cli(capsys, *args, "--landings", "up", "--catalog", db)[0] == 0
    rc, out, _ = run_cli(capsys, "changeover", "show", "lt", "--json", "--catalog", db)
    assert rc == 0 and json.loads(out)["unrecognizable_pairs"] == []
    for command in (("show", "lt"), ("list",)):
        rc, out, _ = run_cli(capsys, "changeover", *command, "--catalog", db)
        assert rc == 0 and "lt" in out and "cannot tell apart" not in out


# Finding 10: every JSON pair carries its kind.


def test_analyze_json_pairs_carry_their_kind(db, tmp_path, capsys):
    add_variant(db, tmp_path, capsys, "l-bracket-mirror", mirror)
    add_variant(db, tmp_path, capsys, "l-bracket-hole-moved", move_hole)
    args = ("catalog", "analyze", "--tolerance", "0.2", "--rotation-error", "1", "--json")
    rc, out, _ = run_cli(capsys, *args, "--catalog", db)
    data = json.loads(out)
    assert rc == 1
    assert {w["kind"] for w in data["unrecognizable_pairs"]} == {"same-push-diameter"}
    assert {w["kind"] for w in data["apart_only_on_the_ideal_model"]} == {"uncertainty"}


# Finding 3: no promise that a smaller rotation error helps.


def test_analyze_does_not_promise_that_a_smaller_rotation_error_helps(db, tmp_path, capsys):
    add_variant(db, tmp_path, capsys, "l-bracket-hole-moved", move_hole)
    args = ("catalog", "analyze", "--tolerance", "0.2", "--rotation-error", "0.001")
    rc, _, err = run_cli(capsys, *args, "--catalog", db)
    assert rc == 1 and "l-bracket/up & l-bracket-hole-moved/up" in err
    assert "need a smaller rotation error" not in err
    assert "may or may not be told apart with a smaller rotation error" in err
    assert "vibration" in err


# Finding 11: tolerances without float noise, no "none mm", names whole at 80 columns.


def test_a_tolerance_is_shown_without_float_noise_and_never_above_itself():
    from feederkit.design.sensor import shown_tolerance

    assert shown_tolerance(0.3 - 1e-12) == "0.3"
    assert shown_tolerance(0.3) == "0.3"
    assert float(shown_tolerance(6.0274085)) <= 6.0274085


def test_design_pitches_say_no_tolerance_rather_than_none_mm(db, tmp_path, capsys):
    add_variant(db, tmp_path, capsys, "l-bracket-mirror", mirror)
    args = ("design", "sensor", "--mix", "l-bracket,l-bracket-mirror", "--pitches", "0.5")
    rc, out, _ = run_cli(capsys, *args, "--catalog", db)
    assert rc == 1 and "none mm" not in out
    assert "an exact diameter sensor: no tolerance tells every pair apart" in out


def at_80_columns(*args: str) -> list[str]:
    """``feederkit ARGS``'s stdout lines in a process whose terminal is 80 columns wide."""
    code = "import sys; from feederkit.cli.app import main; sys.exit(main(sys.argv[1:]))"
    root = str(Path(__file__).resolve().parents[1])  # this tree's feederkit
    env = {**os.environ, "COLUMNS": "80", "PYTHONPATH": root}
    done = subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )
    return done.stdout.splitlines()


def test_pair_tables_keep_names_whole_at_80_columns(db, tmp_path, capsys):
    add_variant(db, tmp_path, capsys, "l-bracket-mirror", mirror)
    mix = ["--mix", "l-bracket,l-bracket-mirror", "--tolerance", "0.2", "--catalog", db]
    assert run_cli(capsys, "changeover", "compile", "lr", *mix)[0] == 1
    for args in (
        ("changeover", "show", "lr", "--catalog", db),
        ("catalog", "analyze", "--tolerance", "0.2", "--catalog", db),
        ("design", "sensor", "--mix", "l-bracket,l-bracket-mirror", "--catalog", db),
    ):
        lines = at_80_columns(*args)
        table = [line for line in lines if line.startswith(("│", "┃", "┏", "└"))]
        assert table and max(len(line) for line in table) <= 80, args
        assert any("l-bracket-mirror/down" in line for line in table), args
        assert any("l-bracket-mirror/up" in line for line in table), args
        assert not any("…" in line for line in table), args
