"""``catalog analyze --time-limit S`` bounds the checks under a declared uncertainty.

A plant's catalog of 67 D-washers took 129 s under ``--rotation-error 1`` (1,124 pairs, each
a strong-plan check) and 614 parts did not answer in minutes, with no limit to give and a
bare spinner. The checks left at the limit are counted undecided, the command says so and
exits 1; without the option every check runs.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


@pytest.fixture()
def db(tmp_path: Path, capsys) -> str:
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("quadrilateral", "rectangle-2x1", "l-bracket"):
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = str(tmp_path / "c.db")
    assert main(["catalog", "import", str(folder), "--catalog", path]) == 0
    capsys.readouterr()
    return path


ARGS = ["catalog", "analyze", "--tolerance", "0.2", "--rotation-error", "1", "--json"]


def test_a_spent_limit_leaves_every_check_undecided(db: str, capsys) -> None:
    assert main([*ARGS, "--time-limit", "0.001", "--catalog", db]) == 1
    out = capsys.readouterr()
    data = json.loads(out.out)
    assert data["cut_by_time_limit"] is True
    assert data["counts"]["undecided_alone"] == data["counts"]["parts"]
    # Every pair that was to be checked is undecided, and the JSON says how many there were.
    c = data["counts"]
    assert c["undecided_pairs"] == c["pairs_checked_under_uncertainty"]
    assert "the time limit of 0.001 s ended the checks" in " ".join(out.err.split())


def test_without_a_limit_every_check_runs(db: str, capsys) -> None:
    code = main([*ARGS, "--catalog", db])
    data = json.loads(capsys.readouterr().out)
    assert data["cut_by_time_limit"] is False and data["counts"]["undecided_alone"] == 0
    assert data["counts"]["undecided_pairs"] <= data["counts"]["pairs_checked_under_uncertainty"]
    assert code in (0, 1)


def test_a_bad_limit_is_one_line(db: str, capsys) -> None:
    assert main([*ARGS, "--time-limit", "-3", "--catalog", db]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--time-limit" in err[0]
