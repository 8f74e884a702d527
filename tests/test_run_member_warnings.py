"""``run PLAN SOURCE`` warns of the fragile states of the part it runs, not of every part of
the plan's mix (a review ran one part of an 8-part changeover and read two others' warnings)."""

from __future__ import annotations

from pathlib import Path

from shared import run_cli

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def test_run_of_one_member_warns_of_its_own_fragile_states_only(tmp_path, capsys):
    bracket, washer = str(CATALOG / "l-bracket.json"), str(CATALOG / "d-washer.json")
    plan = str(tmp_path / "p.json")
    flags = ["--tolerance", "0.5", "--landings", "up", "-o", plan]
    assert run_cli(capsys, "plan", bracket, washer, *flags)[0] == 0
    _, _, err = run_cli(capsys, "run", plan)  # warnings on stderr (docs/cli.md)
    every = " ".join(err.split())
    assert "l-bracket (up): fragile states" in every and "d-washer (up): fragile states" in every
    rc, _, err = run_cli(capsys, "run", plan, bracket)
    one = " ".join(err.split())
    assert rc == 0 and "l-bracket (up): fragile states" in one
    assert "d-washer" not in one
