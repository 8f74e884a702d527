"""Plans hold the part itself, not only its simplified contact hull (mechanics.modelerror,
machine.widths): a D-shaped plate whose arc's top a chord cuts reads wider than its model."""

from __future__ import annotations

import math

import pytest
from fixtures_cad import d_shape_outline

from feederkit.mechanics.modelerror import largest_offset, reading_offsets, state_offsets
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor

d_shape = d_shape_outline


def test_an_exact_hull_has_no_offsets():
    pf = push_function(make_part(d_shape()))
    assert reading_offsets(pf) == (None,) * pf.n


def test_a_simplified_hull_reads_narrower_than_the_part():
    model = push_function(make_part(d_shape(), hull_tolerance=0.05))
    exact = push_function(make_part(d_shape()))
    offsets = state_offsets(model, exact)
    assert offsets == reading_offsets(model)
    worst, state = largest_offset(offsets)
    # The model's state across the arc reads less than the part's 40 mm.
    assert state is not None and model.states[state].diameter < 40.0 - 1e-3
    assert worst == pytest.approx(40.0 - model.states[state].diameter, abs=1e-9)


def _branches(node):
    return [tuple(b["reading"]) for b in node["branches"]]


@pytest.mark.parametrize("tolerance", [0.01, 0.1])
def test_every_reading_of_the_part_itself_lies_in_a_root_branch(tolerance):
    """At the first alignment the part may rest in any of its own stable states: each of
    its readings (its outline's width there, within the sensor's tolerance) must lie in a
    branch, or the controller stops a good part. A plan on the simplified model alone puts
    the 40 mm state's branch at 39.98 +- e."""
    part = make_part(d_shape(), hull_tolerance=0.05)
    exact = push_function(make_part(d_shape()))
    made = make_plan([push_function(part)], ToleranceSensor(tolerance))
    branches = _branches(made.plan["root"])
    for s in exact.states:
        for k in range(-20, 21):
            reading = s.diameter + tolerance * 0.999 * k / 20
            assert any(a <= reading <= b for a, b in branches), (reading, branches)
    assert any("widths, those of the parts" in w for w in made.warnings)


def test_led_branches_take_the_counts_the_part_itself_blocks():
    """An LED array of 0.05 mm pitch: the model's 39.987 mm state blocks 799 beams, the part
    itself, 40 mm across, 800; the branch holding the state reaches 40.0 mm."""
    from feederkit.sensors import LedSensor

    part = make_part(d_shape(), hull_tolerance=0.05)
    made = make_plan([push_function(part)], LedSensor(0.05))
    assert any(hi >= 40.0 - 1e-9 for _lo, hi in _branches(made.plan["root"]))


def test_no_strong_plan_on_a_simplified_hull_points_to_the_hull_tolerance():
    """A 60 x 54 mm ellipse whose simplified hull has stable states of the simplification
    only has no strong plan at 0.1 mm; the refusal says a smaller --hull-tolerance may help
    (at 0.005 mm it plans)."""
    from feederkit.errors import PlanningError

    ring = [
        (30 * math.cos(2 * math.pi * k / 128), 27 * math.sin(2 * math.pi * k / 128))
        for k in range(128)
    ]
    outline = make_outline("ellipse", ring)
    coarse = push_function(make_part(outline, hull_tolerance=0.05))
    with pytest.raises(PlanningError, match="smaller --hull-tolerance"):
        make_plan([coarse], ToleranceSensor(0.1), certify=False)
    fine = push_function(make_part(outline, hull_tolerance=0.005))
    assert make_plan([fine], ToleranceSensor(0.1), certify=False).result.length >= 1
