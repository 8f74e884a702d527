"""A plan of some of a part's landings says which ways the part also lands, and how often.

``plan quad.json --landings up`` planned the face-up side of a part that lands face down in
half the drops with no word about the other half, and ``run PLAN quad.json --all`` passed
it as every path ending in its result: a part landing face down is not oriented by the plan
(docs/landings.md, "Planning over landings").
"""

from __future__ import annotations

import json
from pathlib import Path

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
QUAD = str(CATALOG / "quadrilateral.json")
WORDS = "quadrilateral also lands down in 50 % of drops, which the plan leaves out (--landings)"


def _one_line(text: str) -> str:
    return " ".join(text.split())


def test_plan_and_run_name_the_landing_left_out(tmp_path: Path, capsys) -> None:
    plan = tmp_path / "q.plan.json"
    assert main(["plan", QUAD, "--landings", "up", "-o", str(plan)]) == 0
    assert WORDS in _one_line(capsys.readouterr().err)
    assert main(["run", str(plan), QUAD, "--all", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert any(WORDS in w for w in out["warnings"])
    # Every landing planned: nothing left out (without a sensor the sides are not told apart).
    assert main(["plan", QUAD, "--landings", "up,down", "-o", str(plan)]) == 1
    assert "leaves out" not in capsys.readouterr().err
    assert main(["run", str(plan), QUAD, "--all"]) == 0
    assert "leaves out" not in _one_line(capsys.readouterr().err)


def test_a_changeover_of_one_landing_names_the_other(tmp_path: Path, capsys) -> None:
    db = str(tmp_path / "c.db")
    assert main(["catalog", "add", QUAD, "--catalog", db]) == 0
    capsys.readouterr()
    args = ["changeover", "compile", "q", "--mix", "quadrilateral", "--catalog", db]
    assert main([*args, "--landings", "up", "-o", str(tmp_path / "q.json")]) == 0
    err = _one_line(capsys.readouterr().err)
    assert "quadrilateral also lands down in 50 % of drops, which the changeover leaves out" in err
