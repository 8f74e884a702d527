"""Small plans built by hand from the push function, for the simulator's tests and benchmark.

The planner lives elsewhere; these builders only pick, for a set of possible states, the
action on a 0.05-degree grid that best splits the set by reading (then the widest margin),
and write the plan file of design.md. The tests in this file check every plan they build
on the kinematic model from a dense grid of start orientations, so the simulator's tests
start from plans known to be right.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from shared import plan_part_entry as part_entry

from feederkit.angles import norm360
from feederkit.mechanics.push import PushFunction, push, push_function
from feederkit.outline import make_outline
from feederkit.part import Part, make_part

GRID_DEG = 0.05


def rectangle() -> Part:
    """A 40 x 20 mm rectangle with its COM 4 mm off centre along its length (2x1, COM offset)."""
    return make_part(make_outline("rect-2x1", [(0, 0), (40, 0), (40, 20), (0, 20)], com=(24, 10)))


def right_triangle() -> Part:
    """The isosceles right triangle with 40 mm legs."""
    return make_part(make_outline("right-triangle", [(0, 0), (40, 0), (0, 40)]))


def pentagon() -> Part:
    """An irregular convex pentagon whose diameters all differ."""
    return make_part(make_outline("pentagon", [(0, 0), (38, 4), (46, 27), (20, 41), (-6, 22)]))


def offset_triangle() -> Part:
    """An equilateral triangle (side 40 mm) with its COM moved off centre: all widths equal."""
    h = 40 * math.sqrt(3) / 2
    return make_part(make_outline("offset-triangle", [(0, 0), (40, 0), (20, h)], com=(17.5, 10.5)))


def _divergent_distance(pf: PushFunction, theta: float) -> float:
    t = norm360(theta)
    return min(min(norm360(t - d), norm360(d - t)) for d in pf.divergent_deg)


def _groups(pf: PushFunction, states: list[int], tolerance: float | None) -> list[list[int]]:
    """States grouped by reading: chains of diameters closer than 2 e (one group sensorless)."""
    if tolerance is None:
        return [sorted(set(states))]
    order = sorted(set(states), key=lambda s: pf.states[s].diameter)
    groups: list[list[int]] = []
    for s in order:
        d = pf.states[s].diameter
        if groups and d - pf.states[groups[-1][-1]].diameter < 2 * tolerance:
            groups[-1].append(s)
        else:
            groups.append([s])
    return groups


def _branches(pf, name, states, tolerance, depth):
    out = []
    for g in _groups(pf, states, tolerance):
        if tolerance is None:
            reading = None
        else:
            ds = [pf.states[s].diameter for s in g]
            reading = [min(ds) - tolerance, max(ds) + tolerance]
        out.append({"reading": reading, "next": _node(pf, name, g, tolerance, depth + 1)})
    return out


def _node(pf: PushFunction, name: str, states: list[int], tolerance, depth: int) -> dict:
    if len(set(states)) == 1:
        s = pf.states[states[0]]
        return {"result": [{"part": name, "state": s.id, "pose_deg": s.pose_deg}]}
    if depth > 8:
        raise AssertionError("the hand planner found no plan")
    best = None
    for a in np.arange(0.0, 360.0, GRID_DEG):
        thetas = [pf.states[s].normal_deg - a for s in states]
        outs = [push(pf, t).id for t in thetas]
        worst = max(len(g) for g in _groups(pf, outs, tolerance))
        margin = min(_divergent_distance(pf, t) for t in thetas)
        key = (worst, -margin)
        if worst < len(set(states)) and (best is None or key < best[0]):
            best = (key, float(a), margin, outs)
    if best is None:
        raise AssertionError("no action makes progress")
    _, a, margin, outs = best
    return {
        "action_deg": round(a, 4),
        "margin_deg": math.floor(margin * 1e4) / 1e4,  # rounded down: never claim more
        "branches": _branches(pf, name, sorted(set(outs)), tolerance, depth),
    }


def _depth(node: dict) -> int:
    if "result" in node:
        return 0
    return 1 + max(_depth(b["next"]) for b in node["branches"])


def _margins(node: dict) -> list[float]:
    if "result" in node:
        return []
    own = [node["margin_deg"]] if node.get("margin_deg") is not None else []
    return own + [m for b in node["branches"] for m in _margins(b["next"])]


def _expected_length(pf: PushFunction, root: dict) -> float:
    """Operations on average from a uniform start: each first resting state weighted by its
    resting range, then the plan followed on the push function."""
    total = 0.0
    for s in pf.states:
        lo, hi = s.resting_range_deg
        node, state, ops = root, s, 0
        while "result" not in node:
            if node["action_deg"] is not None:
                state = push(pf, state.normal_deg - node["action_deg"])
            ops += 1
            node = next(
                b["next"]
                for b in node["branches"]
                if b["reading"] is None or b["reading"][0] <= state.diameter <= b["reading"][1]
            )
        total += (hi - lo) / 360.0 * ops
    return total


def build_plan(part: Part, tolerance: float | None) -> dict:
    """A plan file (design.md) orienting ``part`` with a tolerance sensor (None: sensorless)."""
    pf = push_function(part)
    root = {
        "action_deg": None,
        "margin_deg": None,
        "branches": _branches(pf, part.name, [s.id for s in pf.states], tolerance, 0),
    }
    sensor = {"model": "none"}
    if tolerance is not None:
        sensor = {"model": "tolerance", "tolerance_mm": tolerance}
    margins = _margins(root)
    return {
        "format": "feederkit-plan",
        "version": 1,
        "conventions": "theta is the fence's contact normal in the part frame; actions rotate "
        "the part counter-clockwise, theta' = theta - a; pose = -90 - normal (design.md).",
        "sensor": sensor,
        "parts": [part_entry(part)],
        "root": root,
        "stats": {
            "length": _depth(root),
            "expected_length": _expected_length(pf, root),
            "min_margin_deg": min(margins) if margins else None,
            "optimal": False,
            "lower_bound": 1,
        },
    }


def run_kinematic(plan: dict, part: Part, theta: float, error_deg: float = 0.0) -> bool:
    """Execute a plan on the push function from fence orientation ``theta``; True if right."""
    pf = push_function(part)
    node, state = plan["root"], None
    while "result" not in node:
        if node["action_deg"] is not None:
            theta = state.normal_deg - node["action_deg"] - error_deg
        state = push(pf, theta)
        nxt = None
        for b in node["branches"]:
            r = b["reading"]
            if r is None or r[0] <= state.diameter <= r[1]:
                nxt = b["next"]
                break
        if nxt is None:
            return False
        node = nxt
    return any(r["state"] == state.id for r in node["result"])


PLANS = {
    "rect-2step": (rectangle, 1.0, 2),
    "pentagon-1step": (pentagon, 0.5, 1),
    "triangle-3step": (offset_triangle, 0.5, 3),
}


@pytest.mark.parametrize("key", sorted(PLANS))
def test_hand_plans_are_right_on_the_kinematic_model(key: str) -> None:
    make, tol, length = PLANS[key]
    part = make()
    plan = build_plan(part, tol)
    assert plan["stats"]["length"] == length
    starts = np.arange(0.0, 360.0, 0.25) + 0.01
    assert all(run_kinematic(plan, part, float(t)) for t in starts)


def test_hand_plan_fails_kinematically_beyond_its_margin() -> None:
    part = rectangle()
    plan = build_plan(part, 1.0)
    m = plan["stats"]["min_margin_deg"]
    starts = np.arange(0.0, 360.0, 1.0) + 0.01
    assert all(run_kinematic(plan, part, float(t), 0.9 * m) for t in starts)
    assert all(run_kinematic(plan, part, float(t), -0.9 * m) for t in starts)
    errors = (1.2 * m, -1.2 * m)
    assert any(not run_kinematic(plan, part, float(t), e) for t in starts for e in errors)
