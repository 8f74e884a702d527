"""The convex hull keeps every real corner when the points of an edge differ by rounding alone.

A drawing converted from inches puts the points of one vertical edge at x values a unit in
the last place apart; a hull that dropped near-collinear points inside the monotone chain took
them in the wrong order and cut a corner off (the wrench sample lost 21 mm2). The reference is
shapely's convex hull, an independent implementation.
"""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Point, Polygon

from feederkit.hull import convex_hull


def _ulps(x: float, k: int) -> float:
    for _ in range(abs(k)):
        x = math.nextafter(x, math.inf if k > 0 else -math.inf)
    return x


def test_a_corner_one_ulp_right_of_its_edge_is_kept() -> None:
    x = 75.0054901286538
    pts = [(x, 113.869), (_ulps(x, -1), 116.126), (x, 126.383), (100.0, 113.0), (100.0, 127.0)]
    hull = convex_hull(pts)
    assert (x, 113.869) in hull
    assert len(hull) == 4
    assert math.isclose(Polygon(hull).area, MultiPoint(pts).convex_hull.area, rel_tol=1e-12)


@settings(max_examples=150, deadline=None)
@given(
    st.lists(st.integers(-3, 3), min_size=12, max_size=12),
    st.floats(1.0, 500.0),
    st.floats(1.0, 500.0),
    st.lists(st.tuples(st.floats(0.01, 0.99), st.floats(0.01, 0.99)), max_size=10),
)
def test_points_of_an_edge_a_few_ulps_apart_keep_every_corner(shifts, w, h, inside) -> None:
    # Three points per side of a w x h box at (x0, y0), each moved across its side by a few
    # ulps (as a unit conversion leaves them).
    x0, y0 = 10.0, 20.0
    x1, y1 = x0 + w, y0 + h
    sides = []
    for k, t in enumerate((0.2, 0.5, 0.8)):
        sides += [
            (_ulps(x0, shifts[k]), y0 + t * h),
            (_ulps(x1, shifts[3 + k]), y0 + t * h),
            (x0 + t * w, _ulps(y0, shifts[6 + k])),
            (x0 + t * w, _ulps(y1, shifts[9 + k])),
        ]
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    pts = sides + corners + [(x0 + a * w, y0 + b * h) for a, b in inside]
    hull = convex_hull(pts)
    poly = Polygon(hull)
    reference = MultiPoint(pts).convex_hull
    assert math.isclose(poly.area, reference.area, rel_tol=1e-9)
    # Every point is inside the hull or on it to rounding, and every vertex is a real turn.
    assert all(poly.distance(Point(p)) <= 1e-9 * max(w, h) for p in pts)
    assert len(hull) == 4


def test_points_collinear_to_rounding_give_the_segment_between_the_farthest_two() -> None:
    # A middle point rounding puts off the line once ended the chain and dropped a real end.
    assert convex_hull([(math.nextafter(1.0, 0.0), 1.0), (1.0, 0.0), (1.0, 2.0)]) == [
        (1.0, 0.0),
        (1.0, 2.0),
    ]
    assert convex_hull([(0.0, 0.0), (2.4e-172, 0.0), (0.0, 1.0)]) == [(0.0, 0.0), (0.0, 1.0)]
    assert convex_hull([(3.0, 3.0), (1.0, 1.0), (0.0, 0.0), (2.0, 2.0)]) == [
        (0.0, 0.0),
        (3.0, 3.0),
    ]
