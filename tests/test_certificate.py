"""Verification and certificate that scale with the plan, under the command's time limit.

The verifier indexes a node's branches by reading interval (``Sensor.branch_reach`` must
bound every branch a state can follow), the rotation certificate takes each (node, state)
once (``max_rotation_error`` must not depend on how states are grouped), the shape
certificate ends its bisection early when the plan fails just above the declared value
(it must equal the plain bisection), both stop at a deadline, and ``make_plan`` then states
the declared values and says so. Ranges whose widths differ only by rounding are equally
wide, so the plan is the same on every machine.
"""

from __future__ import annotations

import copy
import math
import random

import pytest
from shared import PollsLeft
from test_strong_plans import random_pf

from feederkit.angles import ActionRange, width_key
from feederkit.errors import PlanningError
from feederkit.machine import MachineState, PushAlignMachine, build_machine
from feederkit.mechanics import push_function
from feederkit.mechanics.certificates import max_rotation_error
from feederkit.mechanics.outcomes import outcome_set
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.planning.api import plan
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.plans import certify, timelimit
from feederkit.plans.make import make_plan
from feederkit.plans.strong import (
    declared_uncertainty,
    expected_operations,
    max_rotation_error_deg,
    max_shape_tolerance_mm,
    strong_holds,
    strong_model,
    verify_strong,
)
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty
from feederkit.uncertainty import max_shape_tolerance as shape_tolerance_limit

SENSORS = [ToleranceSensor(0.3), LedSensor(0.5, 0.1), LedSensor(0.25, 0.0)]


@pytest.mark.parametrize("sensor", SENSORS, ids=["tolerance", "led-noise", "led"])
def test_branch_reach_bounds_every_branch_a_state_can_follow(sensor):
    rng = random.Random(5)
    for _ in range(3000):
        d = rng.uniform(0.0, 5.0)
        diameter = d if rng.random() < 0.5 else (d, d + rng.uniform(0.0, 0.5))
        lo = rng.uniform(-0.5, 6.0)
        hi = lo + rng.choice([0.0, rng.uniform(0.0, 1.0)])
        a, b = sensor.branch_reach(diameter)
        if sensor.reads_into(diameter, lo, hi) or sensor.reading_probability(diameter, lo, hi):
            assert hi >= a and lo <= b, (diameter, lo, hi, a, b)
    assert NoSensor().branch_reach(1.0) is None


@pytest.mark.parametrize("seed", range(6))
def test_the_rotation_certificate_is_the_same_however_the_states_are_grouped(seed):
    pf = random_pf(4000 + seed)
    mech = uncertain_mechanics(pf.part, Uncertainty(1.0))
    rng = random.Random(seed)
    states = [s.id for s in mech.states]
    for _ in range(10):
        action = rng.uniform(0.0, 360.0)
        allowed = {
            s: frozenset(outcome_set(mech, s, action)) | frozenset(rng.sample(states, 1))
            for s in states
        }
        together = max_rotation_error(mech, states, action, allowed)
        alone = min(max_rotation_error(mech, [s], action, allowed) for s in states)
        assert together == alone
        assert max_rotation_error(mech, list(reversed(states)), action, allowed) == together


def _plain_shape_bisection(plan: dict, rel_tol: float = 1e-3) -> float:
    """The shape certificate's bisection without its early end (the reference)."""
    declared = declared_uncertainty(plan)
    model = strong_model(plan)
    pfs = [m.part for m in model.mechanics]
    limit = min(shape_tolerance_limit(p) for p in pfs)

    def holds(t: float) -> bool:
        unc = Uncertainty(declared.rotation_error_deg, t, declared.com_tolerance_mm)
        return strong_holds(plan, unc)

    lo, hi = declared.shape_tolerance_mm, limit * (1.0 - 1e-9)
    if holds(hi):
        return hi
    while hi - lo > rel_tol * limit:
        mid = (lo + hi) / 2.0
        lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    return lo


@pytest.mark.parametrize("seed", range(5))
def test_the_shape_certificate_equals_the_plain_bisection(seed):
    pf = random_pf(5000 + seed)
    sensor = ToleranceSensor(0.2) if seed % 2 else NoSensor()
    try:
        made = make_plan([pf], sensor, uncertainty=Uncertainty(1.0), certify=False)
    except PlanningError:
        pytest.skip("no strong plan")
    assert max_shape_tolerance_mm(made.plan) == _plain_shape_bisection(made.plan)


def _shuffled(plan: dict, seed: int) -> dict:
    """The plan with every node's branches in a random order (a hand-edited file: the
    verifier's interval index must then look at all of them)."""
    out = copy.deepcopy(plan)
    rng = random.Random(seed)
    stack = [out["root"]]
    while stack:
        node = stack.pop()
        if "branches" in node:
            rng.shuffle(node["branches"])
            stack.extend(b["next"] for b in node["branches"])
    return out


@pytest.mark.parametrize("seed", range(4))
def test_verification_does_not_depend_on_the_order_of_branches(seed):
    pfs = [random_pf(6000 + seed), random_pf(6100 + seed)]
    try:
        made = make_plan(pfs, ToleranceSensor(0.15), uncertainty=Uncertainty(1.0), certify=False)
    except PlanningError:
        pytest.skip("no strong plan")
    mixed = _shuffled(made.plan, seed)
    assert verify_strong(mixed) == made.report
    model = strong_model(made.plan)
    pf_list = [push_function(m.part) for m in model.mechanics]
    assert math.isclose(
        expected_operations(mixed, strong_model(mixed), pf_list),
        expected_operations(made.plan, model, pf_list),
        rel_tol=1e-12,
    )
    assert max_rotation_error_deg(mixed) == max_rotation_error_deg(made.plan)


def test_the_certificates_stop_at_their_deadline():
    made = make_plan([random_pf(7000)], ToleranceSensor(0.2), uncertainty=Uncertainty(1.0))
    with pytest.raises(Timeout):
        max_rotation_error_deg(made.plan, deadline=Deadline(0.0))
    with pytest.raises(Timeout):
        max_shape_tolerance_mm(made.plan, deadline=Deadline(0.0))


def test_a_certificate_stops_inside_a_verification_not_after_it(monkeypatch):
    # Each bisection step of the shape certificate rebuilds every part's mechanics and walks
    # the plan: 0.4 s CPU for a 100-part mix, so a deadline polled only between steps let
    # `plan --time-limit 10` answer after 12.6 s. It is polled per part rebuilt and per
    # (node, state) pair walked.
    pfs = [random_pf(7000 + k) for k in range(4)]
    made = make_plan(pfs, ToleranceSensor(0.2), uncertainty=Uncertainty(1.0), certify=False)
    import feederkit.plans.strong as strong_module

    built = []
    real = strong_module.uncertain_mechanics

    def counted(*args, **kwargs):
        built.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(strong_module, "uncertain_mechanics", counted)
    for figure in (max_shape_tolerance_mm, max_rotation_error_deg):
        built.clear()
        with pytest.raises(Timeout):
            figure(made.plan, deadline=PollsLeft(2 + len(pfs)))
        assert len(built) <= len(pfs)  # stopped within its first rebuild and walk
    built.clear()
    with pytest.raises(Timeout):
        # a poll per part read from the file, per part rebuilt, then the walk's
        strong_holds(made.plan, Uncertainty(1.0), deadline=PollsLeft(2 * len(pfs) + 1))
    assert len(built) == len(pfs)  # rebuilt, then stopped in the walk


def test_a_certificate_out_of_time_states_the_declared_values_and_says_so(monkeypatch):
    unc = Uncertainty(1.0, 0.01)
    options = PlanningOptions(time_limit_s=30.0)
    full = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    assert full.plan["stats"]["certificate"]["max_rotation_error_deg"] > 1.0
    assert not any("whole certificate" in w for w in full.warnings)

    def out_of_time(real):
        def cut(plan, **kwargs):
            return real(plan, **{**kwargs, "deadline": Deadline(0.0)})

        return cut

    for name in ("max_rotation_error_deg", "max_shape_tolerance_mm"):
        monkeypatch.setattr(certify, name, out_of_time(getattr(certify, name)))
    made = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    cert = made.plan["stats"]["certificate"]
    assert cert["max_rotation_error_deg"] == 1.0 and cert["max_shape_tolerance_mm"] == 0.01
    assert cert["ideal_length"] == full.plan["stats"]["certificate"]["ideal_length"]
    note = "no time for the whole certificate: its rotation and shape bounds are the declared"
    assert any(note in w for w in made.warnings)
    assert made.plan["root"] == full.plan["root"]


def test_the_certificate_leaves_the_time_its_plan_needs_to_be_written(monkeypatch):
    # Writing and showing the plan takes time per node of its file: a plan whose output
    # would take the whole limit gets no certificate search at all (declared values).
    unc = Uncertainty(1.0, 0.01)
    options = PlanningOptions(time_limit_s=30.0)
    monkeypatch.setattr(timelimit, "OUTPUT_S_PER_NODE", 30.0)
    made = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    cert = made.plan["stats"]["certificate"]
    assert cert["max_rotation_error_deg"] == 1.0 and cert["max_shape_tolerance_mm"] == 0.01
    assert cert["ideal_length"] is None
    assert any("no time for the whole certificate" in w for w in made.warnings)


def test_the_limit_counts_from_the_callers_start():
    # A command passes its own start: the time it took to read its parts is spent. Started
    # 29.5 s before a 30 s limit, no time is left for the certificate (declared values).
    import time

    unc = Uncertainty(1.0, 0.01)
    options = PlanningOptions(time_limit_s=30.0)
    made = make_plan(
        [random_pf(7000)],
        ToleranceSensor(0.2),
        options,
        uncertainty=unc,
        started=time.monotonic() - 29.5,
    )
    cert = made.plan["stats"]["certificate"]
    assert cert["max_rotation_error_deg"] == 1.0 and cert["max_shape_tolerance_mm"] == 0.01
    assert any("no time for the whole certificate" in w for w in made.warnings)


def test_a_plan_under_a_callers_budget_names_the_options_limit():
    machine = build_machine([random_pf(7100), random_pf(7101)], NoSensor(), Uncertainty(1.0))
    with pytest.raises(PlanningError, match="time limit of 30 s"):
        plan(machine, PlanningOptions(time_limit_s=30.0), budget=Deadline(0.0))


def _three_ranges(b_extra: float) -> PushAlignMachine:
    """One state whose ranges are 100, 100 + ``b_extra`` and the rest of the circle wide,
    each to another state (an oriented sink each)."""
    b0, b1 = 110.0, 210.0 + b_extra
    maps = (
        (ActionRange(10.0, b0, 1), ActionRange(b0, b1, 2), ActionRange(b1, 370.0, 3)),
        (ActionRange(0.0, 360.0, 1),),
        (ActionRange(0.0, 360.0, 2),),
        (ActionRange(0.0, 360.0, 3),),
    )
    states = tuple(MachineState(0, k, 1.0 + k, 0.25) for k in range(4))
    return PushAlignMachine(("toy",), states, maps, NoSensor())


@pytest.mark.parametrize("extra", [1e-12, -1e-12, 0.0])
def test_ranges_as_wide_up_to_rounding_are_ordered_by_rotation(extra):
    machine = _three_ranges(extra)
    problem = Problem(machine)
    cells = problem.choices.cells(1, useful=False)
    # The widest (160 deg) first, then the two 100 deg ranges by rotation (60 before 160),
    # whichever is a rounding wider.
    assert [round((lo + hi) / 2.0) % 360 for lo, hi, _img in cells] == [290, 60, 160]
    assert width_key(100.0) == width_key(100.0 + extra)
