"""LED plan files: reading windows any controller arithmetic matches.

design.md: an LED array's reading is the beam count times the pitch, and a controller follows
the branch whose closed interval ``[lo, hi]`` holds it; a reading no branch holds stops the
line. A controller computes that product in its own arithmetic (float32 on a PLC, ``c / (1 /
p)``, decimal, integer micrometres), so a plan file's LED branch over the counts ``a..b`` holds
``[(a - 1/4) p, (b + 1/4) p]`` (``LedSensor.window``, docs/plans.md): every such product is in
its count's branch, the branches of different counts stay half a pitch apart, and a reading
half-way between two counts is in none. Files written before that rule (zero-width intervals
at the float64 product) still load, verify and run.
"""

from __future__ import annotations

import dataclasses
import json
from decimal import Decimal
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from shared import cli_ok

from feederkit.mechanics import push_function
from feederkit.outline import load_outline_json
from feederkit.part import make_part
from feederkit.plans.execute import execute
from feederkit.plans.fileformat import LED_WINDOWS, plan_json
from feederkit.plans.model import Plan, Step
from feederkit.plans.readplan import plan_from_dict
from feederkit.plans.verify import verify_declared
from feederkit.sensors import LED_WINDOW_REL, LedSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parent.parent / "catalog"
PITCH, NOISE = 0.05, 0.01
"""The review's LED array (``plan PART --led-pitch 0.05 --noise 0.01``)."""

PARTS = ("equilateral-triangle", "quadrilateral", "isosceles-right-triangle", "heptagon-fig17")
"""Catalog parts whose float64 products carry representation error (0.8500000000000001 ...)."""

UNCERTAINTIES = {"ideal": IDEAL, "strong": Uncertainty(1.0)}
"""The kinematic verifier (ideal model) and the strong one (rotation error 1 degree)."""


def controller_readings(count: int, pitch: float) -> dict[str, float]:
    """The reading ``count * pitch`` as controllers compute it (in integer micrometres when
    the pitch is a whole number of them)."""
    out = {
        "float64": count * pitch,
        "float32": float(np.float32(count) * np.float32(pitch)),
        "per mm": count / (1.0 / pitch),
        "decimal": float(Decimal(count) * Decimal(str(pitch))),
    }
    um = round(pitch * 1000.0)
    if abs(pitch * 1000.0 - um) < 1e-9:
        out["micrometres"] = count * um / 1000.0
    return out


@cache
def plan_file(part: str, uncertainty: str) -> str:
    """The plan file text for a catalog part with the review's LED array."""
    from feederkit.plans.make import make_plan

    pf = push_function(make_part(load_outline_json(CATALOG / f"{part}.json")))
    sensor = LedSensor(PITCH, NOISE)
    return plan_json(make_plan([pf], sensor, uncertainty=UNCERTAINTIES[uncertainty]).plan)


def steps(plan: Plan) -> list[Step]:
    """The plan's distinct operations."""
    return [node for node, _number in plan.walk() if isinstance(node, Step)]


def held_counts(sensor: LedSensor, step: Step) -> list[tuple[int, int]]:
    """Per branch, the beam counts its window holds (``[(a, k) for k in a..b]``)."""
    out = []
    for k, b in enumerate(step.branches):
        assert b.reading is not None
        first, last = sensor.counts_held(*b.reading)
        assert first <= last, f"branch {k} {b.reading} holds no beam count"
        out += [(k, c) for c in range(first, last + 1)]
    return out


# ------------------------------------------------------------------ the rule itself


@pytest.mark.parametrize("pitch", [0.05, 0.1, 0.025, 0.0125, 0.3, 1.0 / 3.0, 0.5, 2.0, 1e-4])
def test_each_count_window_holds_every_arithmetic_and_no_neighbour(pitch):
    sensor = LedSensor(pitch)
    for c in range(5000):
        lo, hi = sensor.window(c, c)
        for how, r in controller_readings(c, pitch).items():
            assert lo <= r <= hi, f"{c} beams at {pitch} mm computed as {how}: {r} not in {lo, hi}"
        upper = sensor.window(c + 1, c + 1)
        assert hi < upper[0], f"windows of {c} and {c + 1} beams meet"
        assert upper[0] - hi >= 0.49 * pitch  # half a pitch apart, whatever the rounding
        half_way = (c + 0.5) * pitch
        assert not lo <= half_way <= hi and not upper[0] <= half_way <= upper[1]
        assert sensor.counts_held(lo, hi) == (c, c)


def test_window_ends_are_short_decimals():
    sensor = LedSensor(0.05)
    assert sensor.window(17, 17) == (0.8375, 0.8625)
    assert sensor.window(13, 14) == (0.6375, 0.7125)
    assert sensor.window(0, 2) == (0.0, 0.1125)  # never below 0
    assert LED_WINDOW_REL == 0.25 and "(a - 1/4) p" in LED_WINDOWS


@pytest.mark.parametrize("grouping", ["exact", "components"])
def test_both_groupings_write_windows_over_their_counts(grouping):
    """Noise 0.01 mm: 0.8 mm blocks 15-16 beams, 0.85 mm 16-17, 2.0 mm 39-40."""
    branches = LedSensor(0.05, 0.01).split([0.8, 0.85, 2.0], grouping)
    got = [(b.lo, b.hi, b.members) for b in branches]
    want = {
        "exact": [
            (0.7375, 0.7625, (0,)),
            (0.7875, 0.8125, (0, 1)),
            (0.8375, 0.8625, (1,)),
            (1.9375, 2.0125, (2,)),
        ],
        "components": [(0.7375, 0.8625, (0, 1)), (1.9375, 2.0125, (2,))],
    }[grouping]
    assert [m for *_e, m in got] == [m for *_e, m in want]
    for (lo, hi, _m), (want_lo, want_hi, _w) in zip(got, want, strict=True):
        assert lo == pytest.approx(want_lo, abs=1e-12) and hi == pytest.approx(want_hi, abs=1e-12)


# ------------------------------------------------------------------ plan files


@pytest.mark.parametrize("uncertainty", sorted(UNCERTAINTIES))
@pytest.mark.parametrize("part", PARTS)
def test_every_controller_arithmetic_follows_the_branch_of_its_count(part, uncertainty):
    data = json.loads(plan_file(part, uncertainty))
    plan = plan_from_dict(data)
    assert verify_declared(plan).ok
    assert data["conventions"].endswith(LED_WINDOWS)
    sensor = plan.sensor
    assert isinstance(sensor, LedSensor)
    for step in steps(plan):
        for k, c in held_counts(sensor, step):
            for how, r in controller_readings(c, PITCH).items():
                assert step.held_by(r) == (k,), f"{c} beams as {how} ({r}) in {step.held_by(r)}"
        windows = sorted(b.reading for b in step.branches)
        assert all(a[1] < b[0] for a, b in zip(windows, windows[1:], strict=False))


def test_the_reviewed_triangle_matches_seventeen_beams_however_computed():
    """The review's case: 17 beams at 0.05 mm was written [0.8500000000000001] * 2, which
    17 / 20 (0.85) and float32 (0.8500000238) missed: every part rejected."""
    root = json.loads(plan_file("equilateral-triangle", "strong"))["root"]
    ((lo, hi),) = [b["reading"] for b in root["branches"]]
    assert lo == pytest.approx(0.8375, abs=1e-12) and hi == pytest.approx(0.8625, abs=1e-12)
    for r in (17 * 0.05, 17 / 20, float(np.float32(17) * np.float32(0.05)), 0.85):
        assert lo <= r <= hi


class _ControllerLed(LedSensor):
    """An LED array whose reading a controller computes its own way (``how``)."""

    how: str = "float64"

    def nominal_reading(self, diameter):
        count = round(super().nominal_reading(diameter) / self.pitch)
        return controller_readings(count, self.pitch)[self.how]


@pytest.mark.parametrize("how", ["float32", "per mm", "decimal", "micrometres"])
def test_runs_with_a_controllers_readings_end_in_their_results(how):
    for part in PARTS:
        plan = plan_from_dict(json.loads(plan_file(part, "strong")))
        own = _ControllerLed(plan.sensor.pitch, plan.sensor.noise)
        object.__setattr__(own, "how", how)
        controller = dataclasses.replace(plan, sensor=own)
        for p, entry in enumerate(plan.parts):
            for s in entry.states:
                start = sum(s.resting_range_deg) / 2.0
                trace = execute(controller, p, start)
                assert trace.success, f"{part} from {start} with {how} readings: {trace.message}"


@pytest.mark.parametrize("part", PARTS)
def test_a_reading_half_way_between_counts_follows_the_branch_of_both_or_none(part):
    """Half-way between two beam counts is no reading an LED array gives: inside one
    branch's counts it follows that branch, between the counts of two branches (or past a
    branch's outer count) it is in none, and the controller stops (design.md). Within a fifth
    of a pitch of a count the count's branch is followed."""
    plan = plan_from_dict(json.loads(plan_file(part, "ideal")))
    sensor = plan.sensor
    for step in steps(plan):
        branch_of = dict((c, k) for k, c in held_counts(sensor, step))
        for c, k in branch_of.items():
            for off in (-0.2, 0.2):
                assert step.follow((c + off) * PITCH) == k
            for side in (-1, 1):
                half_way = (c + side / 2.0) * PITCH
                both = branch_of.get(c + side) == k
                assert step.follow(half_way) == (k if both else None)
    first, last = sensor.counts_held(*plan.root.branches[0].reading)
    s = plan.parts[0].states[0]
    trace = execute(plan, 0, sum(s.resting_range_deg) / 2.0, [(last + 0.5) * PITCH])
    assert not trace.success and trace.steps[0].branch is None
    assert "no branch" in trace.message


# ------------------------------------------------------------------ old files, wrong windows


def old_style(data: dict) -> dict:
    """The plan file as feederkit wrote it before the rule: every LED window zero-width (or
    count to count) at the float64 products of its beam counts."""
    data = json.loads(json.dumps(data))
    sensor = LedSensor(data["sensor"]["pitch_mm"], data["sensor"]["noise_mm"])
    nodes = [data["root"], *data.get("nodes", {}).values()]
    while nodes:
        node = nodes.pop()
        for b in node.get("branches", ()):
            first, last = sensor.counts_held(*b["reading"])
            b["reading"] = [first * sensor.pitch, last * sensor.pitch]
            nodes.append(b["next"])
    return data


@pytest.mark.parametrize("uncertainty", sorted(UNCERTAINTIES))
@pytest.mark.parametrize("part", PARTS)
def test_old_zero_width_windows_still_load_verify_and_run(part, uncertainty):
    old = old_style(json.loads(plan_file(part, uncertainty)))
    ends = [x for b in old["root"]["branches"] for x in b["reading"]]
    assert any(x != round(x, 6) for x in ends) or part == "heptagon-fig17"  # float64 products
    plan = plan_from_dict(old)
    report = verify_declared(plan)
    assert report.ok, report.first_problem()
    for p, entry in enumerate(plan.parts):
        for s in entry.states:
            assert execute(plan, p, sum(s.resting_range_deg) / 2.0).success


def test_an_old_led_file_runs_from_the_command_line(tmp_path, capsys):
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old_style(json.loads(plan_file("quadrilateral", "strong")))))
    out = cli_ok(capsys, ["run", str(path), "--all"]).out
    assert "end in their result" in out


def _last_choice(data: dict) -> list[dict]:
    """The branches of the first operation (depth first) whose branches all end in results."""
    shared = data.get("nodes", {})
    stack = [data["root"]]
    while stack:
        node = stack.pop()
        while "ref" in node:
            node = shared[node["ref"]]
        branches = node.get("branches", ())
        nexts = [shared.get(b["next"].get("ref"), b["next"]) for b in branches]
        if len(branches) > 1 and all("result" in n for n in nexts):
            return list(branches)
        stack.extend(b["next"] for b in branches)
    raise AssertionError("no operation choosing between results")


def _shift_up(branches: list[dict]) -> None:
    """The first window one pitch higher: its lowest count is read by no branch."""
    lo, hi = branches[0]["reading"]
    branches[0]["reading"] = [lo + PITCH, hi + PITCH]


def _take_neighbour(branches: list[dict]) -> None:
    """The second window stretched down over the first one's highest count, so a state
    there may end in the second one's result, which does not name it."""
    lo, hi = branches[1]["reading"]
    branches[1]["reading"] = [branches[0]["reading"][1] - 0.3 * PITCH, hi]


@pytest.mark.parametrize("uncertainty", sorted(UNCERTAINTIES))
@pytest.mark.parametrize("change", [_shift_up, _take_neighbour])
def test_wrong_windows_are_still_refused(change, uncertainty):
    data = json.loads(plan_file("quadrilateral", uncertainty))
    branches = _last_choice(data)
    assert verify_declared(plan_from_dict(data)).ok
    change(branches)
    assert not verify_declared(plan_from_dict(data)).ok
