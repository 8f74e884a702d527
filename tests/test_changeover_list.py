"""``changeover list`` shows each changeover's declared uncertainty (docs/changeovers.md): two
changeovers of one mix at different tolerances differ in the table and in ``--json``, and the
table keeps part names whole at 80 columns."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from shared import cli_ok

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = ["--mix", "isosceles-right-triangle,octagon", "--tolerance", "0.01"]
TIGHT = ["--rotation-error", "0.5", "--shape-tolerance", "0.005", "--com-tolerance", "0.01"]


def feederkit_at_80_columns(*args: str) -> subprocess.CompletedProcess[str]:
    """``feederkit ARGS`` in a process of its own whose terminal is 80 columns wide."""
    code = "import sys; from feederkit.cli.app import main; sys.exit(main(sys.argv[1:]))"
    env = {**os.environ, "COLUMNS": "80"}
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )


@pytest.fixture()
def db(tmp_path: Path, capsys) -> Path:
    """The triangle and the octagon, compiled at the default uncertainty (``loose``) and at a
    tighter one (``tight``)."""
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("isosceles-right-triangle", "octagon"):
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    cat = ["--catalog", str(path)]
    cli_ok(capsys, ["catalog", "import", str(folder), *cat])
    cli_ok(capsys, ["changeover", "compile", "loose", *MIX, *cat])
    cli_ok(capsys, ["changeover", "compile", "tight", *MIX, *TIGHT, *cat])
    return path


def test_list_json_gives_each_changeovers_declared_uncertainty(db: Path, capsys) -> None:
    listed = json.loads(cli_ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out)
    by_name = {c["name"]: c for c in listed}
    assert by_name["loose"]["uncertainty"] == {
        "rotation_error_deg": 1.0,
        "shape_tolerance_mm": 0.0,
        "com_tolerance_mm": 0.0,
    }
    assert by_name["tight"]["uncertainty"] == {
        "rotation_error_deg": 0.5,
        "shape_tolerance_mm": 0.005,
        "com_tolerance_mm": 0.01,
    }
    assert all(c["uncertainty_declared"] is True for c in listed)
    assert by_name["loose"]["parts"] == by_name["tight"]["parts"]  # one mix, two tolerances
    assert by_name["tight"]["created_at"].endswith("+00:00")  # the stored time, whole


def _cells(text: str, header: str, after: str) -> dict[str, str]:
    """Each row's cell of the column ``header`` (up to the column ``after``), its wrapped
    lines joined, by the row's name (the first column)."""
    lines = text.splitlines()
    top = next(i for i, line in enumerate(lines) if header in line.split())
    start, end = lines[top].index(header), lines[top].index(after)
    names = lines[top].index("parts")  # the name column ends where the parts begin
    cells: dict[str, list[str]] = {}
    name = ""
    for line in lines[top + 2 :]:
        if line[:names].split():
            name = line[:names].split()[0]
        if name and line[start:end].strip():
            cells.setdefault(name, []).append(line[start:end].strip())
    return {k: " ".join(v) for k, v in cells.items()}


def test_list_table_tells_the_two_apart_at_80_columns(db: Path) -> None:
    done = feederkit_at_80_columns("changeover", "list", "--catalog", str(db))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert max(len(line) for line in lines) <= 80
    uncertainty = _cells(done.stdout, "uncertainty", "created")
    assert uncertainty == {
        "loose": "±1°, shape 0 mm, COM 0 mm",
        "tight": "±0.5°, shape 0.005 mm, COM 0.01 mm",
    }
    assert set(_cells(done.stdout, "sensor", "uncertainty").values()) == {"tolerance ±0.01 mm"}
    # every part name whole, on a line of each row
    for name in ("isosceles-right-triangle@1", "octagon@1"):
        assert sum(name in line for line in lines) == 2, done.stdout


def test_a_plan_without_a_declared_uncertainty_and_a_damaged_one(db: Path, capsys) -> None:
    """A version-1 plan (no ``uncertainty``) is the ideal model; a stored plan that is not
    JSON is listed as unreadable (``show`` says what is wrong), not a failure of ``list``."""
    with sqlite3.connect(db) as conn:
        (text,) = conn.execute("SELECT plan_json FROM changeovers WHERE name = 'loose'").fetchone()
        plan = json.loads(text)
        del plan["uncertainty"]
        conn.execute(
            "UPDATE changeovers SET plan_json = ? WHERE name = 'loose'", (json.dumps(plan),)
        )
        conn.execute("UPDATE changeovers SET plan_json = '{oops' WHERE name = 'tight'")
    listed = json.loads(cli_ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out)
    by_name = {c["name"]: c for c in listed}
    assert by_name["loose"]["uncertainty_declared"] is False
    assert by_name["loose"]["uncertainty"] == {
        "rotation_error_deg": 0.0,
        "shape_tolerance_mm": 0.0,
        "com_tolerance_mm": 0.0,
    }
    assert (
        by_name["tight"]["uncertainty"] is None and by_name["tight"]["uncertainty_declared"] is None
    )
    done = feederkit_at_80_columns("changeover", "list", "--catalog", str(db))
    assert _cells(done.stdout, "uncertainty", "created") == {
        "loose": "ideal model (none declared)",
        "tight": "unreadable",
    }
