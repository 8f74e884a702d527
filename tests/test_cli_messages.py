"""Errors are one clean line: no doubled words from the JSON parser, no blank line first."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from feederkit.errors import InputError
from feederkit.jsonio import read_json


def test_a_truncated_json_file_is_named_without_a_doubled_word(tmp_path) -> None:
    path = tmp_path / "trunc.json"
    path.write_text('{"format": "feederkit-plan",\n "x": "abc')
    with pytest.raises(InputError) as exc:
        read_json(path, "plan file")
    assert "at at" not in str(exc.value) and "line 2" in str(exc.value)


@pytest.mark.slow  # imports MuJoCo: seconds
def test_simulate_errors_start_on_the_first_line(tmp_path, capfd) -> None:
    pytest.importorskip("mujoco")
    from pathlib import Path

    from feederkit.cli.app import main

    plan = Path(__file__).resolve().parent / "golden" / "t-clip.tolerance.json"
    assert main(["simulate", str(plan), "--trials", "0"]) == 2
    err = capfd.readouterr().err
    assert err.startswith("error:") and len(err.strip().splitlines()) == 1


def test_a_sensor_finer_than_rounding_is_bad_input(capsys) -> None:
    from pathlib import Path

    from feederkit.cli.app import main

    part = Path(__file__).resolve().parents[1] / "catalog" / "rectangle-2x1.json"
    assert main(["plan", str(part), "--tolerance", "1e-300"]) == 2
    err = capsys.readouterr().err
    assert "resolution" in err and "root has no branches" not in err
    assert len(err.strip().splitlines()) == 1


def test_lookalike_prints_its_check_as_json(tmp_path, capsys) -> None:
    import json
    from pathlib import Path

    from feederkit.cli.app import main

    part = Path(__file__).resolve().parents[1] / "catalog" / "l-bracket.json"
    out = tmp_path / "twin.json"
    assert main(["lookalike", str(part), "--keep", "push", "-o", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["same_push"] is True and d["similar"] is False
    assert json.loads(out.read_text())["vertices"] == d["outline"]["vertices"]


# --- what a new user sees: results, counts, the cell profile, names, a closed pipe ---------

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def test_a_result_to_act_on_is_a_result_line_not_an_error(capsys) -> None:
    """Exit 1 (design.md: a result the user must act on) prints ``result: ...``; bad input
    (exit 2) keeps ``error: ...``; each is one line on stderr."""
    from feederkit.cli.app import main

    part = str(CATALOG / "rectangle-2x1.json")
    assert main(["plan", part, "--rotation-error", "0", "--min-margin", "80"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("result: no plan keeps a margin of 80 deg"), err
    assert "error:" not in err and len(err.strip().splitlines()) == 1
    assert main(["plan", part, "--min-margin", "-1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("n", "word", "many", "text"),
    [
        (1, "part", None, "1 part"),
        (2, "part", None, "2 parts"),
        (0, "operation", None, "0 operations"),
        (1, "vertex", "vertices", "1 vertex"),
        (5, "vertex", "vertices", "5 vertices"),
    ],
)
def test_plural_takes_the_noun_in_its_number(n, word, many, text) -> None:
    from feederkit.cli.common import plural

    assert plural(n, word, many) == text


def test_one_of_a_thing_is_not_plural_in_the_output(tmp_path, capsys) -> None:
    from feederkit.cli.app import main

    db = tmp_path / "cat.db"
    assert main(["catalog", "init", "--catalog", str(db)]) == 0
    assert main(["catalog", "add", str(CATALOG / "octagon.json"), "--catalog", str(db)]) == 0
    capsys.readouterr()
    assert main(["catalog", "list", "--catalog", str(db)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "1 part"
    assert main(["plan", str(CATALOG / "octagon.json"), "--rotation-error", "0"]) == 0
    out = capsys.readouterr().out
    assert "at most 1 push-align operation\n" in out
    assert not re.search(r"\b1 (operations|parts|states|paths|trials|vertices)\b", out), out


TIMED_CELL = """
[robot]
rotation_error_deg = 1
pick_place_s = 2
rotation_speed_deg_s = 90
[belt]
speed_m_s = 0.1
drop_to_fence_mm = 200
"""


@pytest.mark.parametrize("how", ["./feederkit.toml", "--cell"])
def test_plan_names_the_cell_profile_once(tmp_path, monkeypatch, capsys, how) -> None:
    from feederkit.cli.app import main

    monkeypatch.chdir(tmp_path)
    name = "feederkit.toml" if how == "./feederkit.toml" else "line-3.toml"
    (tmp_path / name).write_text(TIMED_CELL)
    extra = [] if how == "./feederkit.toml" else ["--cell", name]
    assert main(["plan", str(CATALOG / "octagon.json"), *extra]) == 0
    out = capsys.readouterr().out
    assert out.count("cell profile") == 1, out
    assert f"cell profile: {name}" in out and "cycle time: 2.00 s per part" in out


def _first_column(table_text: str) -> str:
    """The cells of a rich table's first column, joined: a name folded over lines is whole."""
    rows = [ln.split("│")[1].strip() for ln in table_text.splitlines() if ln.startswith("│")]
    return "".join(rows)


def test_long_part_names_are_shown_whole_in_tables(tmp_path, capsys) -> None:
    from feederkit.cli.app import main

    name = "very-long-part-name-for-the-bracket-assembly-left-hand-revision-b"
    src = tmp_path / "long.json"
    src.write_text(json.dumps({"name": name, "vertices": [[0, 0], [8, 0], [8, 3], [0, 5]]}))
    plan = tmp_path / "plan.json"
    code = main(["plan", str(src), "--rotation-error", "0", "--tolerance", "0.05", "-o", str(plan)])
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main(["run", str(plan), "--all"]) == 0
    out = capsys.readouterr().out
    assert "…" not in out
    table = out[out.index("verification") :]
    assert _first_column(table).count(name) == 2  # up and down, each whole


@pytest.mark.slow
def test_a_closed_stdout_ends_quietly() -> None:
    """``feederkit ... | head -1``: the process ends by SIGPIPE (141 in the shell), nothing on
    stderr, no traceback, not exit 1 (which is a result to act on)."""
    import signal
    import subprocess
    import sys

    sources = [str(CATALOG / "octagon.json")] * 150  # ~190 kB of text, more than a pipe holds
    proc = subprocess.Popen(
        [sys.executable, "-c", "from feederkit.cli.app import run; run()", "part", "analyze"]
        + sources,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    assert proc.stdout.readline().startswith(b"octagon:")
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == -signal.SIGPIPE, err
    assert "Traceback" not in err and "error" not in err.lower(), err


def test_an_outline_with_two_points_names_the_file(tmp_path, capsys) -> None:
    from feederkit.cli.app import main

    src = tmp_path / "two-points.json"
    src.write_text(json.dumps({"name": "widget", "vertices": [[0, 0], [1, 0]]}))
    assert main(["plan", str(src)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "two-points.json" in err and "three distinct points" in err, err


@pytest.mark.parametrize("name", [":thumbs_up:.json", "x:100:y", "part:smile:2.dxf"])
def test_names_with_colons_are_echoed_as_typed(name, tmp_path, capsys, monkeypatch) -> None:
    """No emoji codes in messages: a part number like ``x:100:y`` stays as the user typed it."""
    from feederkit.cli.app import main

    monkeypatch.chdir(tmp_path)
    assert main(["part", "analyze", name]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {name}: no such file") and len(err.splitlines()) == 1
