"""The MuJoCo feeder against the push function and hand-built plans (issue 7).

Skipped, with the reason, only where MuJoCo cannot be imported.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip(
    "mujoco", reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these"
)

from test_sim_plans import (  # noqa: E402
    build_plan,
    part_entry,
    pentagon,
    rectangle,
    right_triangle,
)

from feederkit.errors import CheckFailed  # noqa: E402
from feederkit.mechanics.push import push_function  # noqa: E402
from feederkit.outline import make_outline  # noqa: E402
from feederkit.part import make_part  # noqa: E402
from feederkit.sim import SettleRule, simulate_plan, simulate_push  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
AGREEMENT_PARTS = {"rectangle": rectangle, "right triangle": right_triangle, "pentagon": pentagon}


@pytest.mark.parametrize("name", sorted(AGREEMENT_PARTS))
def test_simulated_pushes_agree_with_the_push_function(name: str) -> None:
    part = AGREEMENT_PARTS[name]()
    pf = push_function(part)
    rng = np.random.default_rng(7)
    checks = [simulate_push(part, float(t)) for t in rng.uniform(0.0, 360.0, 50)]
    misses = [c for c in checks if not c.agrees]
    assert len(checks) - len(misses) >= 0.96 * len(checks), [
        (c.outcome.theta_start_deg, c.divergent_distance_deg) for c in misses
    ]
    assert all(c.divergent_distance_deg <= 1.5 for c in misses)
    for c in checks:
        if c.agrees:
            # At rest on the predicted edge: flush with the fence, the width its diameter.
            off = (c.outcome.theta_end_deg - c.predicted.normal_deg + 180.0) % 360.0 - 180.0
            assert abs(off) < 1.0
            assert c.outcome.width_mm == pytest.approx(c.predicted.diameter, abs=0.5)
    assert {c.predicted.id for c in checks} == {s.id for s in pf.states}


def test_drops_just_off_a_divergent_orientation_go_their_own_way() -> None:
    part = rectangle()
    pf = push_function(part)
    for d in pf.divergent_deg:
        for off in (-2.0, 2.0):
            c = simulate_push(part, d + off)
            assert c.agrees, (d, off, c.outcome)


def test_a_two_step_plan_succeeds_in_at_least_19_of_20_trials() -> None:
    plan = build_plan(rectangle(), 1.0)
    assert plan["stats"]["length"] == 2
    s = simulate_plan(plan, 20, seed=1)
    assert s.trials == 20
    assert s.successes >= 19, [f.to_dict() for f in s.failures + s.unsettled]
    assert s.successes + len(s.failures) + len(s.unsettled) == s.trials
    assert s.pushes == 40
    assert s.push_agreement >= 0.95


def test_rotation_noise_beyond_the_smallest_margin_makes_failures_appear() -> None:
    plan = build_plan(rectangle(), 1.0)
    margin = plan["stats"]["min_margin_deg"]
    calm = simulate_plan(plan, 20, seed=3, rotation_noise_deg=0.5 * margin)
    assert calm.successes == 20, [f.to_dict() for f in calm.failures + calm.unsettled]
    rough = simulate_plan(plan, 20, seed=3, rotation_noise_deg=2.5 * margin)
    assert rough.failures
    for f in rough.failures:
        assert f.step == 2  # the first alignment cannot go wrong; the rotation can
        # the plan declares the ideal model: errors beyond it are outcomes it did not predict
        assert f.predicted is False and f.cause == "wrong result"
        assert "a model error" in f.reason and ("error +" in f.reason or "error -" in f.reason)
        bad = f.pushes[1]
        assert abs(bad.rotation_error_deg) > margin
        assert bad.simulated_state != bad.expected_state


def test_same_seed_same_outcome() -> None:
    plan = build_plan(rectangle(), 1.0)
    a = simulate_plan(plan, 4, seed=11, rotation_noise_deg=3.0).to_dict()
    b = simulate_plan(plan, 4, seed=11, rotation_noise_deg=3.0).to_dict()
    for d in (a, b):
        d.pop("wall_time_s")
    assert a == b


def test_a_reading_in_no_branch_stops_the_trial_and_says_so() -> None:
    plan = build_plan(pentagon(), 0.5)
    for b in plan["root"]["branches"]:
        b["reading"] = [b["reading"][0] + 3.0, b["reading"][1] + 3.0]
    with pytest.raises(CheckFailed):
        simulate_plan(plan, 3, seed=0)  # the kinematic model already says it is wrong
    s = simulate_plan(plan, 3, seed=0, check=False)
    assert s.successes == 0 and len(s.failures) == 3
    assert all(f.step == 1 and "no branch" in f.reason for f in s.failures)


def test_a_plan_claiming_the_wrong_result_fails_at_its_last_step() -> None:
    plan = build_plan(pentagon(), 0.5)
    wrong = copy.deepcopy(plan)
    branches = wrong["root"]["branches"]
    results = [b["next"]["result"] for b in branches]
    for b, r in zip(branches, results[1:] + results[:1], strict=True):
        b["next"]["result"] = r
    s = simulate_plan(wrong, 3, seed=0, check=False)
    assert s.successes == 0
    assert all(f.step == 1 and "result" in f.reason for f in s.failures)


def test_runs_that_never_settle_are_counted_apart() -> None:
    plan = build_plan(rectangle(), 1.0)
    s = simulate_plan(plan, 3, seed=0, rule=SettleRule(max_travel_sizes=0.05, min_max_time_s=0.0))
    assert s.successes == 0 and not s.failures and len(s.unsettled) == 3
    assert all(u.step == 1 and "never settled" in u.reason for u in s.unsettled)


def test_a_mix_plan_recognizes_each_part() -> None:
    big = pentagon()
    small = make_part(make_outline("pentagon-small", [(0.7 * x, 0.7 * y) for x, y in big.hull]))
    branches = []
    for part in (big, small):
        for st in push_function(part).states:
            result = [{"part": part.name, "state": st.id, "pose_deg": st.pose_deg}]
            reading = [st.diameter - 0.4, st.diameter + 0.4]
            branches.append({"reading": reading, "next": {"result": result}})
    plan = build_plan(big, 0.4)
    plan["parts"] = [part_entry(big), part_entry(small)]
    plan["root"] = {"action_deg": None, "margin_deg": None, "branches": branches}
    s = simulate_plan(plan, 12, seed=4)
    assert s.parts == ("pentagon", "pentagon-small")
    assert s.successes == 12, [f.to_dict() for f in s.failures + s.unsettled]
    assert sum(s.part_trials) == 12 and min(s.part_trials) > 0
    assert s.part_successes == s.part_trials


def test_a_part_drawn_in_other_units_is_simulated_at_feeder_size() -> None:
    unit = make_part(make_outline("unit-triangle", [(0, 0), (1, 0), (0, 1)]))
    s = simulate_plan(build_plan(unit, 0.05), 5, seed=2)
    assert s.scales[0] > 1.0
    assert s.successes == 5, [f.to_dict() for f in s.failures + s.unsettled]


def test_cli_json_has_integer_trials_successes_and_failures(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(build_plan(rectangle(), 1.0)), encoding="utf-8")
    code = "from feederkit.cli.app import run; run()"
    out = subprocess.run(
        [sys.executable, "-c", code, "simulate", str(path), "--trials", "3", "--json"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert isinstance(data["trials"], int) and data["trials"] == 3
    assert isinstance(data["successes"], int) and data["successes"] == 3
    assert data["failures"] == [] and data["unsettled"] == []


def test_cli_require_success_exits_1_below_the_rate(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    plan = build_plan(rectangle(), 1.0)
    path.write_text(json.dumps(plan), encoding="utf-8")
    noise = str(3 * plan["stats"]["min_margin_deg"])
    code = "from feederkit.cli.app import run; run()"
    args = ["simulate", str(path), "--trials", "8", "--rotation-noise", noise]
    out = subprocess.run(
        [sys.executable, "-c", code, *args, "--require-success", "1"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 1, out.stdout + out.stderr
    assert "below the required" in out.stderr
    assert "Traceback" not in out.stderr
