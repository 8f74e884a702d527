"""The sensor design reads each state over the part's own widths, as the planner does
(design.critical.planned_machine, machine.widths): a D-shaped plate whose contact hull
simplifies its arc models 39.987 mm across where it is 40.0 mm, as wide as the rectangle
beside it, so no step of the design may rest on that difference, and the design's lengths
are the plans'."""

from __future__ import annotations

import pytest
from fixtures_cad import d_shape_outline

from feederkit.design.critical import mix_critical_tolerance
from feederkit.design.sensor import design_pitches, design_tolerance
from feederkit.design.steps import LengthOracle, mix_breakpoints, optimal_length
from feederkit.design.strong import StrongMix, strong_mix_critical
from feederkit.machine import members
from feederkit.machine.build import build_machine
from feederkit.machine.inseparable import inseparable_masks
from feederkit.machine.widths import widen_widths
from feederkit.mechanics.modelerror import largest_offset, reading_offsets
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import LedSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

d_shape = d_shape_outline


def rectangle():
    """A 40 x 20 mm rectangle: exactly 40 mm across, as the D-shape itself is."""
    return make_outline("rect", [(0.0, 0.0), (40.0, 0.0), (40.0, 20.0), (0.0, 20.0)])


@pytest.fixture(scope="module")
def pfs():
    d = push_function(make_part(d_shape(), hull_tolerance=0.05))
    return [d, push_function(make_part(rectangle()))]


def step_of(steps, e):
    return next(s for s in steps if s.lo < e and (s.hi is None or e <= s.hi))


def test_the_mix_models_a_difference_only_the_simplification_makes(pfs):
    d, rect = pfs
    offsets = [reading_offsets(pf) for pf in pfs]
    worst, state = largest_offset(offsets[0])
    # The D-shape's state across its arc models 39.988 mm; the part itself reads 40 mm.
    assert state is not None and d.states[state].diameter < 40.0 - 0.01
    assert d.states[state].diameter + worst == pytest.approx(40.0, abs=1e-9)
    assert any(s.diameter == 40.0 for s in rect.states)
    assert offsets[1] == (None,) * rect.n  # an exact hull
    machine = widen_widths(build_machine(pfs, uncertainty=IDEAL), offsets)
    # The planner reads that state up to the part's own 40 mm, the rectangle's width.
    ((lo, hi),) = [s.sensed for s in machine.states if s.part == 0 and s.state == state]
    assert lo == d.states[state].diameter and hi == pytest.approx(40.0, abs=1e-9)


@pytest.mark.parametrize("tolerance", [0.003, 0.005, 0.0059, 0.0061, 0.01, 0.1, 1.0, 3.0])
def test_the_designs_length_is_the_plans(pfs, tolerance):
    made = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=IDEAL, certify=False)
    assert LengthOracle(pfs).length(tolerance) == made.result.length
    assert optimal_length(pfs, tolerance) == made.result.length


def test_the_design_table_holds_the_plans_lengths(pfs):
    design = design_tolerance(pfs)  # the ideal model
    steps = design.steps
    assert steps and steps[-1].hi == design.critical.critical_tolerance
    for e in (0.005, 0.0061, 0.01, 0.5, 9.0):
        made = make_plan(pfs, ToleranceSensor(e), uncertainty=IDEAL, certify=False)
        assert step_of(steps, e).length == made.result.length, e
    # No step ends at or below the offset: there the D-shape's 39.988 mm state and the
    # rectangle's 40 mm one are told apart by the simplification only (on the model the
    # table rose from 2 to 3 operations at 0.006 mm, where every plan takes 3).
    worst, _state = largest_offset([reading_offsets(pf) for pf in pfs][0])
    assert all(s.hi is None or s.hi > worst for s in steps)
    assert step_of(steps, 0.005).length == step_of(steps, 0.0061).length


def _parts_the_plan_cannot_tell_apart(pfs, tolerance):
    """Whether the planner's goal (its machine's inseparable relation) holds two parts."""
    machine = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=IDEAL).result.machine
    masks = inseparable_masks(machine)
    states = machine.states
    return any(
        states[i].part != states[j].part for i in range(machine.n) for j in members(masks[i])
    )


def test_critical_tolerances_are_the_planned_machines(pfs):
    critical = mix_critical_tolerance(pfs)
    (pair,) = critical.pairs
    x = pair.critical_tolerance
    assert x is not None and x in mix_breakpoints(pfs)
    # Told apart at its critical tolerance and not past it, as the plans tell them.
    assert not _parts_the_plan_cannot_tell_apart(pfs, x)
    assert _parts_the_plan_cannot_tell_apart(pfs, x * (1 + 1e-6))


@pytest.mark.parametrize("tolerance", [0.005, 0.0061, 0.1])
def test_strong_designs_read_the_parts_own_widths(pfs, tolerance):
    unc = Uncertainty(1.0, 0.0, 0.0)
    mix = StrongMix(pfs, unc)
    design = design_tolerance(pfs, uncertainty=unc, max_tolerance=tolerance)
    made = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=unc, certify=False)
    assert step_of(design.steps, tolerance).length == made.result.length
    assert strong_mix_critical(mix).critical_tolerance == design.critical.critical_tolerance


def test_led_pitches_decide_on_the_planned_machine(pfs):
    design = design_pitches(pfs, [0.01, 0.5])
    for row in design.rows:
        assert row.recognizable
        made = make_plan(pfs, LedSensor(row.pitch, 0.0), uncertainty=IDEAL, certify=False)
        assert made.result.length == row.length
