"""Plan files (design.md, version 1): the model, JSON round trip, execution and verification."""

from __future__ import annotations

import copy
import json
import math
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from feederkit.errors import CheckFailed, InputError, PlanningError
from feederkit.machine import branches, build_machine, inseparable, is_goal, overlap_ranges
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.options import PlanningOptions
from feederkit.planning.stats import expected_operations
from feederkit.planning.tree import Leaf, PlanResult, Step
from feederkit.plans import (
    CONVENTIONS,
    check_plan,
    execute,
    plan_from_dict,
    plan_json,
    plan_to_dict,
    read_plan,
    validate_plan,
    verify_plan,
    write_plan,
)
from feederkit.plans.make import make_plan
from feederkit.plans.match import leaf_part_pairs
from feederkit.plans.verify import verify_declared
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

RECT = [(0, 0), (2, 0), (2, 1), (0, 1)]
TRI = [(0, 0), (1, 0), (0, 1)]


def pf_of(name, pts, com=None):
    return push_function(make_part(make_outline(name, pts, com=com)))


def _goal_tree(m, insep, mask, depth):
    """A plan tree for the states ``mask`` after a push, by plain search (``depth`` more ops)."""
    subs = []
    for b in branches(m, mask):
        if is_goal(insep, b.mask):
            subs.append((b, Leaf(b.mask)))
            continue
        if depth == 0:
            return None
        for sa in overlap_ranges(m, b.mask):
            child = _goal_tree(m, insep, sa.image, depth - 1)
            if child is not None:
                subs.append((b, Step(sa, child.branches)))
                break
        else:
            return None
    return Step(None, tuple(subs))


def hand_plan(pfs, sensor, length):
    """A PlanResult built by hand from Step and Leaf, independent of the product's planners."""
    m = build_machine(pfs, sensor)
    root = _goal_tree(m, inseparable(m), m.all_states, length - 1)
    assert root is not None
    margins = []

    def walk(n):
        if isinstance(n, Step):
            if n.action is not None:
                margins.append(n.action.margin)
            for _, c in n.branches:
                walk(c)

    walk(root)
    expected = expected_operations(m, root)
    return PlanResult(m, root, length, expected, min(margins, default=math.inf), True, length)


@pytest.fixture(scope="module")
def tri_plan():
    pf = pf_of("tri", TRI)
    return plan_to_dict(hand_plan([pf], ToleranceSensor(0.01), 2), [pf])


@pytest.fixture(scope="module")
def rect_plan():
    pf = pf_of("rect", RECT)
    return plan_to_dict(hand_plan([pf], NoSensor(), 2), [pf])


# ------------------------------------------------------------------ the file


def test_plan_dict_has_design_md_fields(tri_plan):
    d = tri_plan
    assert d["format"] == "feederkit-plan" and d["version"] == 2
    assert list(d)[list(d).index("sensor") + 1] == "uncertainty"
    assert d["conventions"] == CONVENTIONS
    assert d["sensor"] == {"model": "tolerance", "tolerance_mm": 0.01}
    (part,) = d["parts"]
    assert part["name"] == "tri" and part["revision"] is None
    assert part["hull"] == [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    assert sorted(s["diameter"] for s in part["stable_states"]) == pytest.approx(
        [math.sqrt(0.5), 1.0, 1.0]
    )
    for s in part["stable_states"]:
        lo, hi = s["resting_range_deg"]
        assert lo < s["normal_deg"] < hi
        assert s["pose_deg"] == pytest.approx((-90 - s["normal_deg"]) % 360)
    root = d["root"]
    assert root["action_deg"] is None and root["margin_deg"] is None
    assert all(len(b["reading"]) == 2 for b in root["branches"])
    stats = d["stats"]
    assert stats["length"] == 2 and stats["optimal"] is True and stats["lower_bound"] == 2
    assert stats["class"] == 2 and stats["class_bound"] == 2 and stats["meets_bound"] is True


def test_actions_in_range_and_sensorless_readings_null(rect_plan):
    node = rect_plan["root"]
    assert node["branches"][0]["reading"] is None
    nxt = node["branches"][0]["next"]
    assert 0.0 <= nxt["action_deg"] < 360.0 and nxt["margin_deg"] > 0
    leaf = nxt["branches"][0]["next"]
    # oriented up to the 180-degree symmetry: two poses 180 apart
    poses = sorted(e["pose_deg"] for e in leaf["result"])
    assert len(poses) == 2 and poses[1] - poses[0] == pytest.approx(180.0)


def test_json_round_trip(tmp_path, tri_plan):
    path = tmp_path / "p.json"
    write_plan(plan_from_dict(tri_plan), path)
    assert plan_to_dict(read_plan(path)) == tri_plan
    assert json.loads(plan_json(tri_plan)) == tri_plan
    assert plan_json(read_plan(path)) == path.read_text()


def test_mix_has_no_class_and_lists_parts():
    a, b = pf_of("tri", TRI), pf_of("rect", RECT)
    d = plan_to_dict(hand_plan([a, b], ToleranceSensor(0.01), 3), [a, b])
    assert [p["name"] for p in d["parts"]] == ["tri", "rect"]
    assert d["stats"]["class"] is None and d["stats"]["meets_bound"] is None
    assert check_plan(d).ok


def test_duplicate_part_names_are_refused():
    a, b = pf_of("tri", TRI), pf_of("tri", RECT)
    with pytest.raises(InputError, match="both named"):
        plan_to_dict(hand_plan([a, b], ToleranceSensor(0.01), 3), [a, b])


def test_lookalike_mix_lumps_the_pair():
    a, b = pf_of("tri", TRI), pf_of("tri-copy", TRI)
    d = make_plan([a, b], ToleranceSensor(0.01)).plan
    assert leaf_part_pairs(d) == [("tri", "tri-copy")]


# ------------------------------------------------------------------ validation


def _broken(plan, edit):
    d = copy.deepcopy(plan)
    edit(d)
    return d


BROKEN = {
    "not a plan": lambda d: d.update(format="other"),
    "version": lambda d: d.update(version=3),
    "conventions": lambda d: d.pop("conventions"),
    "sensor": lambda d: d.update(sensor={"model": "sonar"}),
    "no parts": lambda d: d.update(parts=[]),
    "hull": lambda d: d["parts"][0].update(hull=[[0, 0], [1, 0]]),
    "edge": lambda d: d["parts"][0]["stable_states"][0].update(edge=7),
    "range": lambda d: d["parts"][0]["stable_states"][0].update(resting_range_deg=[0, 1]),
    "root action": lambda d: d["root"].update(action_deg=10.0),
    "no branches": lambda d: d["root"].update(branches=[]),
    "reading": lambda d: d["root"]["branches"][0].update(reading=[2.0, 1.0]),
    "null reading": lambda d: d["root"]["branches"][0].update(reading=None),
    "action": lambda d: d["root"]["branches"][1]["next"].update(action_deg=360.0),
    "nan": lambda d: d["root"]["branches"][1]["next"].update(margin_deg=float("nan")),
    "unknown part": lambda d: d["root"]["branches"][0]["next"]["result"][0].update(part="x"),
    "unknown state": lambda d: d["root"]["branches"][0]["next"]["result"][0].update(state=9),
    "empty result": lambda d: d["root"]["branches"][0]["next"].update(result=[]),
    "stats": lambda d: d.pop("stats"),
    "length": lambda d: d["stats"].update(length=0),
    "length inflated": lambda d: d["stats"].update(length=3),
    "length deflated": lambda d: d["stats"].update(length=1),
    "version float": lambda d: d.update(version=1.0),
    "version true": lambda d: d.update(version=True),
    "part a list": lambda d: d["root"]["branches"][0]["next"]["result"][0].update(part=["tri"]),
    "margin 180": lambda d: d["root"]["branches"][1]["next"].update(margin_deg=180.0),
    "margin stats": lambda d: d["stats"].update(min_margin_deg=1.0),
    "margin removed": lambda d: d["root"]["branches"][1]["next"].pop("margin_deg"),
    "tolerance a string": lambda d: d["sensor"].update(tolerance_mm="0.01"),
}


@pytest.mark.parametrize("what", sorted(BROKEN))
def test_broken_plans_are_one_line_input_errors(tri_plan, what):
    with pytest.raises(InputError) as err:
        validate_plan(_broken(tri_plan, BROKEN[what]), "p.json")
    assert "\n" not in str(err.value) and str(err.value).startswith("p.json: ")


def test_read_plan_bad_files(tmp_path):
    with pytest.raises(InputError, match="no such plan file"):
        read_plan(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        read_plan(bad)
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(InputError):
        read_plan(deep)


def test_write_is_atomic(tmp_path, tri_plan, monkeypatch):
    path = tmp_path / "p.json"
    path.write_text("old")

    def boom(fd):
        raise OSError(5, "disk on fire")

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(InputError, match="cannot write"):
        write_plan(path, tri_plan)
    assert path.read_text() == "old"
    fresh = tmp_path / "q.json"
    with pytest.raises(InputError):
        write_plan(fresh, tri_plan)
    assert not fresh.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.json"]


def test_write_refuses_nan_without_leaving_a_file(tmp_path, tri_plan):
    bad = _broken(tri_plan, lambda d: d["stats"].update(expected_length=float("inf")))
    with pytest.raises(ValueError):
        write_plan(tmp_path / "p.json", bad)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ execution


@pytest.mark.parametrize("choice", ["nominal", "low", "high"])
@pytest.mark.parametrize("start", [0.0, 45.0, 100.0, 200.0, 300.0])
def test_execute_tri(tri_plan, choice, start):
    t = execute(tri_plan, 0, start, choice)
    assert t.success, t.message
    assert 1 <= len(t.steps) <= 2
    assert t.steps[0].action_deg is None and t.steps[0].theta_deg == start
    assert t.final_pose_deg in {e.pose_deg for e in t.result}


def test_execute_stops_on_a_foreign_reading(tri_plan):
    t = execute(tri_plan, 0, 0.0, [1.5])
    assert not t.success and t.steps[-1].branch is None
    assert "no branch" in t.message and "foreign part" in t.message


def test_execute_wrong_reading_is_a_wrong_result(tri_plan):
    # state 1 (diameter 0.707) read as 1.0: the plan believes a diameter-1 state
    t = execute(tri_plan, 0, 45.0, [1.0, 1.0])
    assert not t.success and "but the plan's result says" in t.message


# ------------------------------------------------------------------ verification


def test_hand_plans_pass(tri_plan, rect_plan):
    for plan in (tri_plan, rect_plan):
        report = check_plan(plan)
        assert report.ok and report.first_problem() is None
        (part,) = report.parts
        assert part.starts == len(plan["parts"][0]["stable_states"])  # every stable start
        assert part.worst_operations == plan["stats"]["length"]


def _op2(d):
    return d["root"]["branches"][1]["next"]


def _inflate_margin(d, margin):
    """Widen the second operation's margin, keeping ``stats`` consistent with the tree."""
    _op2(d).update(margin_deg=margin)
    d["stats"]["min_margin_deg"] = min(
        b["next"]["margin_deg"] for b in d["root"]["branches"] if "margin_deg" in b["next"]
    )


CORRUPT = {
    "action": lambda d: _op2(d).update(action_deg=0.0),
    "margin": lambda d: _inflate_margin(d, 170.0),
    "interval shifted": lambda d: d["root"]["branches"][0].update(reading=[0.71, 0.8]),
    "interval narrowed": lambda d: _op2(d)["branches"][-1].update(reading=[1.0, 1.01]),
    "result": lambda d: d["root"]["branches"][0]["next"]["result"][0].update(state=0, pose_deg=0.0),
    "pose": lambda d: d["root"]["branches"][0]["next"]["result"][0].update(pose_deg=1.0),
    "diameter": lambda d: d["parts"][0]["stable_states"][0].update(
        diameter=d["parts"][0]["stable_states"][0]["diameter"] * 1.01
    ),
    "state normal": lambda d: d["parts"][0]["stable_states"][0].update(normal_deg=271.0),
    "com": lambda d: d["parts"][0].update(com=[0.2, 0.2]),
}


@pytest.mark.parametrize("what", sorted(CORRUPT))
def test_verification_catches_corruption(tri_plan, what):
    bad = _broken(tri_plan, CORRUPT[what])
    validate_plan(bad)  # structurally fine
    report = verify_plan(bad)
    assert not report.ok
    with pytest.raises(CheckFailed) as err:
        check_plan(bad)
    assert "\n" not in str(err.value)


def _split_at(branch, x, middle_next):
    lo, hi = branch["reading"]
    nxt = branch["next"]
    return [
        {"reading": [lo, x], "next": nxt},
        {"reading": [x, x], "next": middle_next},
        {"reading": [x, hi], "next": nxt},
    ]


def test_shared_endpoints_each_branch_must_be_right(tri_plan):
    second = tri_plan["root"]["branches"][1]
    fine = _broken(
        tri_plan,
        lambda d: d["root"].update(
            branches=[d["root"]["branches"][0], *_split_at(second, 1.0, second["next"])]
        ),
    )
    assert verify_plan(fine).ok
    wrong = {"result": [{"part": "tri", "state": 1, "pose_deg": 225.0}]}
    bad = _broken(
        tri_plan,
        lambda d: d["root"].update(
            branches=[d["root"]["branches"][0], *_split_at(second, 1.0, wrong)]
        ),
    )
    report = verify_plan(bad)
    assert not report.ok
    assert report.failures[0].steps[0].reading == 1.0


def test_counterexample_names_the_path(tri_plan):
    bad = _broken(tri_plan, CORRUPT["action"])
    msg = verify_plan(bad).first_problem()
    assert msg.startswith("tri from theta") and "but the plan's result says" in msg


def test_led_plan_verifies_every_count():
    pf = pf_of("tri", TRI)
    sensor = LedSensor(0.1, 0.02)
    plan = plan_to_dict(hand_plan([pf], sensor, 2), [pf])
    assert check_plan(plan).ok
    bad = _broken(plan, lambda d: d["root"]["branches"][0].update(reading=[0.7, 0.7]))
    assert not verify_plan(bad).ok


def _convex(points):
    pts = [(round(x, 3), round(y, 3)) for x, y in points]
    from feederkit.hull import convex_hull

    return convex_hull(pts)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pts=st.lists(
        st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=9, unique=True
    ),
    kind=st.sampled_from(["none", "tol", "led"]),
)
def test_emitted_plans_of_random_parts_verify(pts, kind):
    hull = _convex(pts)
    if len(hull) < 3:
        return
    try:
        pf = pf_of("rnd", hull)
    except InputError:
        return  # a degenerate outline
    size = pf.part.size
    sensor = {
        "none": NoSensor(),
        "tol": ToleranceSensor(0.03 * size),
        "led": LedSensor(0.05 * size, 0.01 * size),
    }[kind]
    made = make_plan([pf], sensor, PlanningOptions(time_limit_s=5.0), uncertainty=IDEAL)
    assert made.report.ok
    if made.plan["stats"]["meets_bound"] is not None and made.plan["stats"]["optimal"]:
        assert made.plan["stats"]["meets_bound"]
    try:  # at design.md's default rotation error: a strong plan that verifies, or none at all
        strong = make_plan(
            [pf], sensor, PlanningOptions(time_limit_s=5.0), uncertainty=Uncertainty(1.0)
        )
    except PlanningError as exc:
        assert "no strong plan" in str(exc)
    else:
        assert verify_declared(strong.plan).ok


def test_plan_files_from_disk_match_memory(tmp_path):
    pf = pf_of("rect", RECT, com=(1.2, 0.45))
    made = make_plan([pf], ToleranceSensor(0.05))
    path = Path(tmp_path / "r.json")
    write_plan(plan_from_dict(made.plan), path)
    report = verify_plan(read_plan(path))
    assert report.ok and report.paths == made.report.paths
