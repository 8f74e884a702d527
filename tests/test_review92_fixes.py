"""Small command-line defects found in review, each pinned: holes that enclose or equal the
outline, a part simulated at another size than its own, ``python -m feederkit``, a start
angle beyond 360 degrees, the report's "wrote" line."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from shared import catalog_snapshot, cli_ok, no_stray_profile, one_line_error  # noqa: F401

from feederkit.errors import InputError
from feederkit.outline import make_outline
from feederkit.sim import mujoco_available

ROOT = Path(__file__).resolve().parents[1]
TRIANGLE = str(ROOT / "catalog" / "equilateral-triangle.json")
SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]


@pytest.fixture(scope="module")
def triangle_plan(tmp_path_factory) -> Path:
    """A plan of the bundled 1 mm equilateral triangle."""
    from feederkit.cli.app import main

    path = tmp_path_factory.mktemp("plans") / "tri.plan.json"
    assert main(["plan", TRIANGLE, "-o", str(path)]) == 0
    return path


# 1. A hole that encloses or is the outline: one line, exit 2, not a crash.

HOLES = {
    "encloses": ([[[-1, -1], [11, -1], [11, 11], [-1, 11]]], "hole 0 encloses the outline"),
    "encloses, an edge shared": (
        [[[0, -1], [11, -1], [11, 11], [0, 11]]],
        "hole 0 encloses the outline",
    ),
    "encloses, corners on the outline": (
        [[[-5, -5], [10, 0], [15, 15], [0, 10]]],
        "hole 0 encloses the outline",
    ),
    "encloses, before another hole": (
        [[[-1, -1], [11, -1], [11, 11], [-1, 11]], [[2, 2], [3, 2], [3, 3]]],
        "hole 0 encloses the outline",
    ),
    "the outline itself": ([SQUARE], "hole 0 is the outline itself"),
    "the outline reversed": ([SQUARE[::-1]], "hole 0 is the outline itself"),
    "along an edge": (
        [[[0, 2], [5, 2], [5, 8], [0, 8]]],
        "the holes and the outline touch along a line",
    ),
    "half the outline": (
        [[[0, 0], [10, 0], [10, 5], [0, 5]]],
        "the holes and the outline touch along a line",
    ),
}


@pytest.mark.parametrize("case", list(HOLES))
def test_a_hole_enclosing_or_touching_the_outline_is_named(case):
    holes, words = HOLES[case]
    with pytest.raises(InputError, match=f"^x: {words}"):
        make_outline("x", SQUARE, holes)


def test_part_analyze_of_a_hole_enclosing_the_outline_exits_2(tmp_path, capsys):
    path = tmp_path / "hole-covers.json"
    holes = HOLES["encloses"][0]
    path.write_text(json.dumps({"name": "x", "units": "mm", "vertices": SQUARE, "holes": holes}))
    err = one_line_error(capsys, ["part", "analyze", str(path)])
    assert f"{path}: x: hole 0 encloses the outline" in err and "bug" not in err


def test_catalog_add_of_a_hole_enclosing_the_outline_leaves_the_catalog(tmp_path, capsys):
    db = tmp_path / "c.db"
    cli_ok(capsys, ["catalog", "add", TRIANGLE, "--catalog", str(db)])
    before = catalog_snapshot(db)
    path = tmp_path / "hole-covers.json"
    holes = HOLES["encloses"][0]
    path.write_text(json.dumps({"name": "x", "vertices": SQUARE, "holes": holes}))
    err = one_line_error(capsys, ["catalog", "add", str(path), "--catalog", str(db)])
    assert "hole 0 encloses the outline" in err
    assert catalog_snapshot(db) == before


# 2. A part simulated scaled says so: its trials are of the 20 mm copy.

NOTE = (
    "equilateral-triangle was simulated at 20x its size (a 1 mm part at 20 mm, as "
    'docs/simulation.md "Scale" says): the dynamics of the real small part are not checked'
)


@pytest.mark.skipif(not mujoco_available(), reason="needs mujoco")
def test_simulate_says_a_small_part_was_simulated_scaled(triangle_plan, capsys):
    out = cli_ok(capsys, ["simulate", str(triangle_plan), "--trials", "2"]).out
    assert f"note: {NOTE}" in " ".join(out.split())
    found = json.loads(
        cli_ok(capsys, ["simulate", str(triangle_plan), "--trials", "2", "--json"]).out
    )
    assert found["scale"] == [20.0] and found["scale_notes"] == [NOTE]


def test_a_part_simulated_at_its_own_size_gets_no_note_and_the_report_says_the_note():
    from simsummaries import sim_summary

    from feederkit.reports.sections import simulation_text

    own = sim_summary({"bracket": (20, 20)})
    assert own.scale_notes() == [] and own.to_dict()["scale_notes"] == []
    big = {**own.to_dict(), "scale_notes": ["bracket was simulated at 0.5x its size"]}
    assert "; note: bracket was simulated at 0.5x its size" in simulation_text(big)


# 3. python -m feederkit is the feederkit command.


@pytest.mark.parametrize("args", [["--help"], ["demo", "--help"]])
def test_python_m_feederkit_runs_the_command(args):
    paths = [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    done = subprocess.run(
        [sys.executable, "-m", "feederkit", *args],
        capture_output=True,
        text=True,
        check=False,
        env=env,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    assert "Usage: feederkit" in done.stdout


# 4. run --start-deg 400 says 40.


def test_run_says_a_start_beyond_360_in_0_to_360(triangle_plan, capsys):
    out = " ".join(cli_ok(capsys, ["run", str(triangle_plan), "--start-deg", "400"]).out.split())
    assert "from theta 40°" in out and "from theta 40 deg" in out and "400" not in out


# 5. report -o says what it wrote as plan and changeover do.


def test_report_says_it_wrote_the_report(triangle_plan, tmp_path, capsys):
    page = tmp_path / "r4.html"
    out = cli_ok(capsys, ["report", str(triangle_plan), "-o", str(page)]).out
    assert f"wrote the report to {page}" in " ".join(out.split())
