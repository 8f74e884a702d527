"""``simulate --part``: the width is read where the part rests, not on its way there.

A part on its own outline settles by the drift rule (``REAL_SETTLE_RULE``: its mean orientation
drifting less than 0.5 degree between the halves of a window a part size long), which a gentle
arc needs (docs/simulation.md, "A part's own outline"). That window may still hold the last
looks of the part's turn onto its rest; read as the window's mean, a 60 mm part flush at 270
degrees read 270.2 degrees and 40.26 mm for a 40 mm width, in no ±0.2 mm branch, so a part
identical to the plan's failed where the plan's own hull passed. The reading is now the
medians of the window's second half (``SettleRule.reading``).
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import pytest
from shared import cli_ok

from feederkit.mechanics.push import push_function
from feederkit.plans.fileformat import plan_json
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.sim.pushalign import SettleRule
from feederkit.sim.real import REAL_SETTLE_RULE
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"

needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these",
)


def test_the_drift_rule_reads_the_windows_second_half_where_the_part_rests() -> None:
    """The end of a turn onto the rest (three looks 8, 4.5 and 0.8 degrees off, widths 48,
    44.5 and 40.8 mm) passes the drift rule's halves but not the reading."""
    rest = [270.0 + (0.02 if k % 2 else -0.02) for k in range(57)]
    thetas = [278.0, 274.5, 270.8, *rest]
    widths = [48.0, 44.5, 40.8, *(40.0 + (t - 270.0) for t in rest)]
    assert REAL_SETTLE_RULE.still(thetas)  # the window counts as still ...
    mean = sum(thetas) / len(thetas)
    assert mean - 270.0 > 0.2  # ... and its mean lies off flush
    theta, width = REAL_SETTLE_RULE.reading(thetas, widths)
    assert abs(theta - 270.0) <= 0.02 and abs(width - 40.0) <= 0.02
    # the range rule's window lies within a degree: its means, as before
    flush = [270.4, 270.0, 269.9, 270.1]
    assert SettleRule().reading(flush, [40.4, 40.0, 39.9, 40.1]) == (
        pytest.approx(270.1),
        pytest.approx(40.1),
    )


def test_a_jitter_about_the_rest_reads_as_its_middle() -> None:
    """A part rolling on a gentle arc jitters a degree or two about its rest: the median of
    the looks is that rest, as their mean was."""
    thetas = [265.0 + (1.5 if k % 2 else -1.5) for k in range(40)]
    theta, width = REAL_SETTLE_RULE.reading(thetas, [27.0] * 40)
    assert theta == pytest.approx(265.0, abs=1.5) and width == 27.0


@lru_cache(maxsize=2)
def _plan(name: str) -> str:
    """A catalog part's plan with a ±0.2 mm tolerance sensor (rotation error 1 degree)."""
    part = load_part(str(CATALOG / f"{name}.json"))
    return plan_json(make_plan([push_function(part)], ToleranceSensor(0.2)).plan)


def _simulate(capsys, plan: Path, *extra: str) -> dict:
    args = ["simulate", str(plan), "--seed", "0", "--json", *extra]
    return json.loads(cli_ok(capsys, args).out)


@needs_mujoco
def test_a_part_identical_to_the_plans_reads_as_the_plans_hull(tmp_path: Path, capsys) -> None:
    """The chamfered plate on its own outline (hull and COM 0 from the plan's): its first five
    trials, four of which read 0.2-0.3 mm too wide before, all succeed, as on the plan's
    hull."""
    plan = tmp_path / "plate.plan.json"
    plan.write_text(_plan("chamfered-plate"), encoding="utf-8")
    source = str(CATALOG / "chamfered-plate.json")
    real = _simulate(capsys, plan, "--trials", "5", "--part", source)
    assert real["geometry"][0]["hull_distance_mm"] == 0.0
    assert real["successes"] == 5, real["went_wrong"][:1]


@needs_mujoco
@pytest.mark.slow
def test_on_its_own_outline_a_part_does_as_well_as_on_the_plans_hull(
    tmp_path: Path, capsys
) -> None:
    """Measured (100 trials, seed 0, docs/simulation.md): the l-bracket and the chamfered
    plate, ±0.2 mm, 100 of 100 on the plan's hull, 31 of 100 on their own outlines before,
    100 of 100 now. Here 40 trials each: no fewer successes with --part."""
    for name in ("l-bracket", "chamfered-plate"):
        plan = tmp_path / f"{name}.plan.json"
        plan.write_text(_plan(name), encoding="utf-8")
        plain = _simulate(capsys, plan, "--trials", "40")
        real = _simulate(capsys, plan, "--trials", "40", "--part", str(CATALOG / f"{name}.json"))
        assert real["successes"] >= plain["successes"] == 40, (name, real["by_cause"])
