"""Catalog analysis under uncertainty screens pairs on the machine the planner plans on
(mix.strongpairs, machine.widths): each state read over the part's own widths where import
simplified its contact hull. A 60 x 20 mm ellipse's flattened arcs model its 20 mm width
as 19.98 mm, apart from a 61 x 20 mm slot's at a fine sensor; the parts themselves both
read 20 mm, and no plan tells them apart."""

from __future__ import annotations

import math

import pytest

from feederkit.machine import members
from feederkit.machine.inseparable import inseparable_masks
from feederkit.mechanics.push import push_function
from feederkit.mix.analyze import analyze_mix
from feederkit.mix.strongpairs import check_strong_pair, reading_pairs
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import Uncertainty

UNC = Uncertainty(1.0, 0.0, 0.0)


def ellipse():
    n = 360
    pts = [
        (30.0 * math.cos(2 * math.pi * k / n), 10.0 * math.sin(2 * math.pi * k / n))
        for k in range(n)
    ]
    return make_outline("ell", pts)


def slot():
    """A 41 mm bar with R10 ends: 61 x 20 mm."""
    pts = []
    for end, start in ((20.5, -math.pi / 2), (-20.5, math.pi / 2)):
        pts += [
            (
                end + 10.0 * math.cos(start + math.pi * k / 90),
                10.0 * math.sin(start + math.pi * k / 90),
            )
            for k in range(91)
        ]
    return make_outline("slot", pts)


@pytest.fixture(scope="module")
def pfs():
    return [
        push_function(make_part(ellipse(), hull_tolerance=0.05)),
        push_function(make_part(slot(), hull_tolerance=0.05)),
    ]


def _plan_confuses(pfs, tolerance):
    """Whether the planner's goal (its machine's inseparable relation) holds the two parts."""
    made = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=UNC, certify=False)
    m = made.result.machine
    masks = inseparable_masks(m)
    return any(m.states[i].part != m.states[j].part for i in range(m.n) for j in members(masks[i]))


def test_the_pair_check_is_the_plans(pfs):
    sensor = ToleranceSensor(0.005)
    assert _plan_confuses(pfs, 0.005)
    assert (0, 1) in reading_pairs(pfs, sensor, UNC)
    check = check_strong_pair(*pfs, sensor, UNC)
    assert check.decided and check.witness is not None
    analysis = analyze_mix(pfs, sensor, uncertainty=UNC)
    assert analysis.pairs == ()  # the ideal test, on the models' diameters
    assert [(w.index_a, w.index_b) for w in analysis.strong_pairs] == [(0, 1)]


def test_exact_hulls_are_screened_as_before():
    box = push_function(make_part(make_outline("box", [(0, 0), (40, 0), (40, 10), (0, 10)])))
    bar = push_function(make_part(make_outline("bar", [(0, 0), (41, 0), (41, 10), (0, 10)])))
    sensor = ToleranceSensor(0.2)
    assert reading_pairs([box, bar], sensor, UNC) == reading_pairs(
        [box, bar], sensor, UNC, offsets=[(None,) * box.n, (None,) * bar.n]
    )
    assert check_strong_pair(box, bar, sensor, UNC).witness is None
