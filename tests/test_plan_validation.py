"""One validator and one verifier for every consumer: types, ranges, stats, exact intervals.

The validator (``plan_from_dict``) checks a plan's structure; the verifier
(``verify_plan``) follows it on the kinematic model by interval arithmetic: a whole overlap
range per rotation, every reading branch however narrow. Fixtures are golden plan files.
"""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path

import pytest

from feederkit.angles import norm360
from feederkit.errors import CheckFailed, InputError
from feederkit.plans import check_plan, plan_from_dict, verify_plan
from feederkit.plans.model import Step, push_function_of
from feederkit.plans.verify import (
    ANGLE_EPS_DEG,
    candidate_readings,
    resting_arcs,
    rotation_outcomes,
)
from feederkit.sensors import ToleranceSensor

GOLDEN = Path(__file__).resolve().parent / "golden"
NARROW = GOLDEN / "narrow" / "rectangle-2x1.tolerance-0.500000001.json"


def load(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def edited(name: str, edit) -> dict:
    d = copy.deepcopy(load(GOLDEN / name))
    edit(d)
    return d


def first_rotation(d: dict) -> dict:
    return next(b["next"] for b in d["root"]["branches"] if "action_deg" in b["next"])


def restat(d: dict) -> None:
    """Make ``stats`` describe the tree again: its depth and its smallest margin."""
    margins, depth, stack = [], 0, [(d["root"], 1)]
    while stack:
        n, k = stack.pop()
        if "branches" in n:
            depth = max(depth, k)
            if n["margin_deg"] is not None:
                margins.append(n["margin_deg"])
            stack.extend((b["next"], k + 1) for b in n["branches"])
    s = d["stats"]
    s.update(length=depth, min_margin_deg=min(margins, default=None))
    s.update(
        lower_bound=min(s["lower_bound"], depth), expected_length=min(s["expected_length"], depth)
    )


def set_margin(d: dict, margin: float) -> None:
    """Set the first rotation's margin, keeping ``stats`` consistent with the tree."""
    first_rotation(d)["margin_deg"] = margin
    restat(d)


STRUCTURAL = {
    "version 1.0": lambda d: d.update(version=1.0),
    "version true": lambda d: d.update(version=True),
    "version string": lambda d: d.update(version="1"),
    "part a list": lambda d: first_result(d).update(part=[d["parts"][0]["name"]]),
    "state a float": lambda d: first_result(d).update(state=0.0),
    "length inflated": lambda d: d["stats"].update(length=d["stats"]["length"] + 1),
    "length deflated": lambda d: d["stats"].update(length=d["stats"]["length"] - 1),
    "margin removed": lambda d: first_rotation(d).pop("margin_deg"),
    "margin 180": lambda d: set_margin(d, 180.0),
    "stats removed": lambda d: d.pop("stats"),
    "stats margin wrong": lambda d: d["stats"].update(min_margin_deg=0.5),
    "lower bound above length": lambda d: d["stats"].update(lower_bound=99),
    "tolerance a string": lambda d: d["sensor"].update(tolerance_mm="0.02"),
    "tolerance true": lambda d: d["sensor"].update(tolerance_mm=True),
    "revision true": lambda d: d["parts"][0].update(revision=True),
    "hull a point": lambda d: d["parts"][0].update(hull=[[0, 0], [1, 0], [2, 0]]),
}


def first_result(d: dict) -> dict:
    stack = [d["root"]]
    while stack:
        n = stack.pop()
        if "result" in n:
            return n["result"][0]
        stack.extend(b["next"] for b in n["branches"])
    raise AssertionError("no result")


@pytest.mark.parametrize("what", sorted(STRUCTURAL))
def test_structural_faults_are_one_line_input_errors(what):
    bad = edited("quadrilateral.tolerance.json", STRUCTURAL[what])
    with pytest.raises(InputError) as exc:
        plan_from_dict(bad, "q.json")
    msg = str(exc.value)
    assert msg.startswith("q.json: ") and "\n" not in msg


def test_an_inflated_length_fails_even_for_some_parts_only():
    bad = edited("changeover-fig27-triangle-octagon.json", STRUCTURAL["length inflated"])
    with pytest.raises(InputError, match="stats length"):
        verify_plan(bad, [0])


@pytest.mark.parametrize("name", ["quadrilateral.sensorless.json", "l-bracket.tolerance.json"])
def test_margins_are_checked_over_the_whole_range(name):
    margin = first_rotation(load(GOLDEN / name))["margin_deg"]
    assert verify_plan(edited(name, lambda d: set_margin(d, margin))).ok
    for wider in (179.0, margin + 1e-5):
        report = verify_plan(edited(name, lambda d, m=wider: set_margin(d, m)))
        assert not report.ok, wider


def test_rotation_outcomes_are_every_state_the_range_meets():
    plan = plan_from_dict(load(GOLDEN / "quadrilateral.sensorless.json"))
    pf = push_function_of(plan.parts[0])
    s = pf.states[0]
    step = Step(0.0, 179.0, ())
    assert {t.id for t in rotation_outcomes(pf, s.normal_deg, step)} == {t.id for t in pf.states}
    assert rotation_outcomes(pf, s.normal_deg, Step(0.0, 0.0, ())) == [s]


def _arcs_meet(t0: float, width: float, rng: tuple[float, float]) -> bool:
    """The reference: whether the open arc (t0, t0 + width) meets the open range, compared
    once a turn apart each way, one range at a time."""
    lo = norm360(rng[0])
    hi = lo + (rng[1] - rng[0])
    t0 = norm360(t0)
    return any(max(t0, lo + 360.0 * k) < min(t0 + width, hi + 360.0 * k) for k in (-1, 0, 1))


@pytest.mark.parametrize("name", ["quadrilateral.sensorless.json", "t-clip.tolerance.json"])
def test_rotation_outcomes_match_the_arc_test_range_by_range(name):
    plan = plan_from_dict(load(GOLDEN / name))
    pf = push_function_of(plan.parts[0])
    rng = random.Random(7)
    arcs = resting_arcs(pf)
    for _ in range(400):
        s = rng.choice(pf.states)
        action, margin = rng.uniform(-400.0, 400.0), rng.choice([1e-3, 0.5, 5.0, 40.0, 179.0])
        # also arcs that start or end exactly on a range's boundary
        if rng.random() < 0.3:
            edge = rng.choice(rng.choice(pf.states).resting_range_deg)
            action = s.normal_deg - edge - margin + ANGLE_EPS_DEG
        step = Step(action, margin, ())
        t0 = s.normal_deg - action - margin + ANGLE_EPS_DEG
        width = 2.0 * (margin - ANGLE_EPS_DEG)
        want = {t.id for t in pf.states if _arcs_meet(t0, width, t.resting_range_deg)}
        got = rotation_outcomes(pf, s.normal_deg, step, arcs)
        assert {t.id for t in got} - {got[0].id} <= want
        assert want <= {t.id for t in got}
        assert got == rotation_outcomes(pf, s.normal_deg, step)


def test_a_hand_edited_diameter_fails_verification():
    bad = edited(
        "t-clip.tolerance.json",
        lambda d: d["parts"][0]["stable_states"][0].update(
            diameter=d["parts"][0]["stable_states"][0]["diameter"] + 0.01
        ),
    )
    with pytest.raises(CheckFailed, match="diameter"):
        check_plan(bad)


def test_a_plan_with_a_branch_a_billionth_wide_verifies():
    report = verify_plan(load(NARROW))
    assert report.ok, report.first_problem()


def test_a_wrong_branch_a_billionth_wide_is_caught():
    d = load(NARROW)
    narrow = d["root"]["branches"][1]
    assert narrow["reading"][1] - narrow["reading"][0] < 1e-8
    narrow["next"] = {"result": [first_result(d)]}
    restat(d)
    assert not verify_plan(d).ok


def test_candidate_readings_meet_every_branch_of_a_tolerance_state():
    sensor = ToleranceSensor(0.5)
    from feederkit.plans.model import Branch, Leaf

    leaf = Leaf(())
    step = Step(
        None,
        None,
        tuple(Branch(r, leaf) for r in [(0.0, 1.0), (1.0, 1.0 + 1e-12), (1.0 + 1e-12, 3.0)]),
    )
    readings = candidate_readings(sensor, step, 1.2)
    assert all(0.7 < r < 1.7 for r in readings)
    met = {k for r in readings for k in step.held_by(r)}
    assert met == {0, 1, 2}


def test_planned_rectangle_with_a_narrow_branch_verifies():
    """The plan command's case: ``plan catalog/rectangle-2x1.json --tolerance 0.500000001``."""
    from feederkit.mechanics.push import push_function
    from feederkit.plans.make import make_plan
    from feederkit.sources import load_part

    pf = push_function(
        load_part(str(Path(__file__).resolve().parents[1] / "catalog" / "rectangle-2x1.json"))
    )
    for tolerance in (0.500000001, 0.5000001):
        made = make_plan([pf], ToleranceSensor(tolerance))
        assert made.report.ok and made.plan["stats"]["length"] == 4
