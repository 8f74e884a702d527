"""Words of ``simulate``'s output a review found wrong: a part simulated smaller was said to be
simulated "times larger", and the table of trials that went wrong named no landing in a plan
over landings (a failed part the plan rejects could not be told from one it accepts)."""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.sim.summary import width_accuracy_warning

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def test_a_part_simulated_smaller_is_not_said_to_be_larger():
    words = width_accuracy_warning((0.5, "the sensor tolerance ±0.5 mm"), scale=0.576)
    assert words is not None
    assert "0.521 mm at the plan's size, simulated at 0.576 times its size" in words
    assert "larger" not in words


def test_the_trials_that_went_wrong_name_the_landing(tmp_path, capsys):
    pytest.importorskip("mujoco")
    plan = tmp_path / "rect.plan.json"
    args = ["plan", str(CATALOG / "rectangle-2x1.json"), "--tolerance", "0.01"]
    assert main([*args, "--accept", "down", "-o", str(plan)]) == 0
    capsys.readouterr()
    main(["simulate", str(plan), "--trials", "8"])
    out = capsys.readouterr().out
    assert "trials that went wrong" in out  # a ±0.01 mm sensor in a 0.3 mm simulator
    table = out[out.index("trials that went wrong") :]
    # The part column, its cells folded over lines joined again.
    column = "".join(ln.split("│")[2].strip() for ln in table.splitlines() if ln.startswith("│"))
    assert "rectangle-2x1 (up)" in column or "rectangle-2x1 (down)" in column, table
