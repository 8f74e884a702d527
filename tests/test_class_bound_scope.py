"""The Fig. 14 class bound `part analyze` prints holds for one side on the ideal model: the
line says so, and a plan for that side alone on the ideal model stays within it, while the
default plan over both landings may need more (the l-bracket at 0.2 mm: bound 2, plan 3)."""

from __future__ import annotations

import json
from pathlib import Path

from shared import run_cli

BRACKET = str(Path(__file__).resolve().parent.parent / "catalog" / "l-bracket.json")


def _length(capsys, tmp_path, *flags: str) -> int:
    out = tmp_path / "p.json"
    rc, _, _ = run_cli(capsys, "plan", BRACKET, "--tolerance", "0.2", *flags, "-o", str(out))
    assert rc in (0, 1)
    return json.loads(out.read_text())["stats"]["length"]


def test_the_class_bound_names_its_scope_and_holds_there(capsys, tmp_path):
    rc, out, _ = run_cli(capsys, "part", "analyze", BRACKET, "--tolerance", "0.2", "--json")
    assert rc == 0
    bound = json.loads(out)[0]["bound"]
    rc, out, _ = run_cli(capsys, "part", "analyze", BRACKET, "--tolerance", "0.2")
    assert "for this side alone on the ideal model" in " ".join(out.split())
    one_side = _length(capsys, tmp_path, "--landings", "up", "--rotation-error", "0")
    assert one_side <= bound
    assert _length(capsys, tmp_path) > bound  # both landings: beyond the one side's bound
