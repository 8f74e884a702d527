"""The contact hull is a fixpoint: a hull read back from a plan file is the hull written.

A plan file carries each part's contact hull; whoever rebuilds the part from it (the
verifier, the executor, reports) re-hulls it with tolerance 0, and must get the same
vertices in the same numbering (design.md: vertex 0 is the lowest-then-leftmost, exactly).
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.hull import contact_hull, number_hull
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part


def _bulged_rectangle(bulge: float, points: int = 41) -> list[tuple[float, float]]:
    """A 2 x 1 rectangle whose bottom edge sags by ``bulge`` mm over ``points`` points."""
    bottom = [
        (2.0 * i / (points - 1), -bulge * math.sin(math.pi * i / (points - 1)))
        for i in range(points)
    ]
    return [*bottom, (2.0, 1.0), (0.0, 1.0)]


def test_vertex_zero_is_the_lowest_then_leftmost_exactly() -> None:
    ring = [(1.0, 1e-12), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0), (0.0, 1e-12)]
    assert number_hull(ring)[0] == (2.0, 0.0)
    assert number_hull([(0.0, 1.0), (0.0, 0.0), (1.0, 0.0)])[0] == (0.0, 0.0)


def test_a_cleaned_hull_rehulled_with_tolerance_zero_is_unchanged() -> None:
    hull = contact_hull(_bulged_rectangle(1e-8))
    assert contact_hull(hull, 0.0) == hull


@settings(max_examples=60)
@given(
    st.lists(
        st.tuples(st.floats(-50, 50, allow_nan=False), st.floats(-50, 50, allow_nan=False)),
        min_size=3,
        max_size=40,
    ),
    st.sampled_from([None, 0.0, 1e-6, 1e-3, 0.05]),
)
def test_contact_hull_is_a_fixpoint_at_tolerance_zero(points, tol) -> None:
    hull = contact_hull(points, tol)
    if len(hull) < 3:
        return
    assert contact_hull(hull, 0.0) == hull
    start = min(range(len(hull)), key=lambda i: (hull[i][1], hull[i][0]))
    assert start == 0


def test_a_plan_for_a_bulged_rectangle_passes_its_own_verification() -> None:
    """The verifier rebuilds the part from the file's hull: it must not simplify it again
    (a 1e-8 mm bulge over 41 points used to give 'the file says edge 2 ... gives edge 1')."""
    from feederkit.mechanics.push import push_function
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.plans.make import make_plan
    from feederkit.sensors import ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    part = make_part(make_outline("bulge", _bulged_rectangle(1e-8)))
    made = make_plan([push_function(part)], ToleranceSensor(0.1), uncertainty=Uncertainty(0.0))
    assert made.result.length >= 1


@pytest.mark.parametrize("off", [1e-11, 1e-12, 1e-13])
def test_a_vertex_off_an_edge_by_rounding_is_collinear_at_tolerance_zero(off) -> None:
    """Two edges whose normals differ by rounding alone cannot be classified by the push
    function ("3 stable edges but 4 divergent orientations", a crash of plan
    --hull-tolerance 0): such a vertex is collinear (``COLLINEAR_REL``) and dropped; one a
    billionth of the size off is kept."""
    ring = [(0.0, 0.0), (5.0, -off), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0)]
    hull = contact_hull(ring, 0.0)
    assert hull == ((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0))
    part = make_part(make_outline("hair", [list(p) for p in ring]), hull_tolerance=0.0)
    assert push_function(part).n == 4
    assert len(contact_hull([(0, 0), (5, -1e-8), (10, 0), (10, 6), (0, 6)], 0.0)) == 5
