"""Properties of the exact mechanics on random convex polygons and COMs (hypothesis).

The exact push function is checked against a brute-force descent on a densely sampled radius
function, resting ranges against the circle, the push-diameter function against widths
measured directly, relabelling and rotation against the analysis, and action and overlap
ranges against the push function evaluated at sampled rotations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from feederkit.hull import REL_LENGTH_TOL, convex_hull
from feederkit.machine import build_machine, mask_of, overlap_ranges
from feederkit.mechanics import (
    action_ranges,
    diameter,
    polygon_class,
    push,
    push_diameter,
    push_function,
    radius,
    symmetry,
)
from feederkit.mechanics.symmetry import periods_of, push_periods
from feederkit.outline import make_outline
from feederkit.part import Part, make_part
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much]
)
GRID_STEP = 0.01  # degrees between radius samples of the brute-force descent


def circ(a: float, b: float) -> float:
    """Distance between two angles on the circle (deg)."""
    d = (a - b) % 360.0
    return min(d, 360.0 - d)


def reasonable(hull: list[tuple[float, float]]) -> bool:
    """At least a triangle, not a sliver, no edge shorter than 1e-3."""
    if len(hull) < 3:
        return False
    n = len(hull)
    area = 0.5 * sum(
        hull[i][0] * hull[(i + 1) % n][1] - hull[(i + 1) % n][0] * hull[i][1] for i in range(n)
    )
    return area > 0.2 and min(math.dist(hull[i], hull[i - 1]) for i in range(n)) > 1e-3


@st.composite
def polygons(draw, min_n: int = 3, max_n: int = 10):
    """A random convex polygon (its hull vertices, CCW) and a COM well inside it."""
    n = draw(st.integers(min_n, max_n))
    angles = draw(
        st.lists(st.floats(0.0, 360.0, exclude_max=True), min_size=n, max_size=n, unique=True)
    )
    radii = draw(st.lists(st.floats(0.5, 2.0), min_size=n, max_size=n))
    pts = [
        (r * math.cos(math.radians(a)), r * math.sin(math.radians(a)))
        for a, r in zip(angles, radii, strict=True)
    ]
    hull = convex_hull(pts)
    assume(reasonable(hull))
    w = draw(st.lists(st.floats(0.05, 1.0), min_size=len(hull), max_size=len(hull)))
    com = (
        sum(wi * p[0] for wi, p in zip(w, hull, strict=True)) / sum(w),
        sum(wi * p[1] for wi, p in zip(w, hull, strict=True)) / sum(w),
    )
    return hull, com


def build(vertices, com) -> Part:
    return make_part(make_outline("random", vertices), com)


# --- push function against a brute-force descent on the sampled radius function ------------


def descend(r: np.ndarray) -> np.ndarray:
    """For each sample, the index where steepest descent on the circular samples stops."""
    n = len(r)
    idx = np.arange(n)
    left, right = np.roll(r, 1), np.roll(r, -1)
    step = np.where((left < r) & (left <= right), idx - 1, np.where(right < r, idx + 1, idx)) % n
    for _ in range(int(math.log2(n)) + 2):  # pointer jumping: 2^k steps at once
        step = step[step]
    return step


@SETTINGS
@given(polygons())
def test_push_function_agrees_with_descent_on_the_radius_function(poly) -> None:
    part = build(*poly)
    pf = push_function(part)
    # Stay away from (near-)metastable edges, where the sampled function is too flat to descend.
    assume(min(abs(m) for m in pf.edge_margin_deg) > 0.2)
    grid = np.arange(0.0, 360.0, GRID_STEP)
    ends = descend(radius(part, grid))
    div = np.array(pf.divergent_deg)
    for i in range(0, len(grid), 47):
        theta = float(grid[i])
        if np.min(np.abs((div - theta + 180.0) % 360.0 - 180.0)) < 5 * GRID_STEP:
            continue  # away from divergent orientations
        settled = push(pf, theta).normal_deg
        assert circ(float(grid[ends[i]]), settled) <= 1.01 * GRID_STEP


@SETTINGS
@given(polygons())
def test_resting_ranges_tile_the_circle(poly) -> None:
    pf = push_function(build(*poly))
    ranges = sorted((s.resting_range_deg for s in pf.states), key=lambda r: r[0] % 360.0)
    assert sum(hi - lo for lo, hi in ranges) == pytest.approx(360.0, abs=1e-9)
    for (_, hi), (lo, _) in zip(ranges, ranges[1:] + ranges[:1], strict=True):
        assert circ(hi, lo) < 1e-9
    for s in pf.states:
        lo, hi = s.resting_range_deg
        assert lo < s.normal_deg < hi
        assert hi - lo <= 360.0
        assert circ(s.pose_deg, -90.0 - s.normal_deg) < 1e-12
    bounds = sorted(lo % 360.0 for lo, _ in ranges)
    assert np.allclose(bounds, sorted(d % 360.0 for d in pf.divergent_deg), atol=1e-9)
    for k, d in enumerate(pf.divergent_deg):  # range k starts at divergent k
        s = pf.states[pf.range_state[k]]
        assert circ(s.resting_range_deg[0], d) < 1e-9


@SETTINGS
@given(polygons(), st.lists(st.floats(0.0, 360.0), min_size=5, max_size=20))
def test_push_diameter_is_the_width_at_the_settled_state(poly, thetas) -> None:
    vertices, com = poly
    part = build(vertices, com)
    pf = push_function(part)
    pts = np.array(vertices)
    for theta in thetas:
        s = push(pf, theta)
        u = np.array([math.cos(math.radians(s.normal_deg)), math.sin(math.radians(s.normal_deg))])
        measured = float(np.ptp(pts @ u))  # width of the raw outline across the fence
        # The contact hull drops vertices within its cleaning tolerance of an edge (hull.py),
        # so the raw outline's width may differ by that much.
        slack = 1e-9 + 2.0 * REL_LENGTH_TOL * part.size
        assert push_diameter(pf, theta) == pytest.approx(measured, abs=slack)
        assert push_diameter(pf, theta) == pytest.approx(diameter(part, s.normal_deg), abs=1e-9)


# --- relabelling and rotating change nothing but the frame -----------------------------------


def signature(pf) -> np.ndarray:
    """Resting-range widths and diameters of the states, in sorted order."""
    return np.array(
        sorted((s.resting_range_deg[1] - s.resting_range_deg[0], s.diameter) for s in pf.states)
    )


@SETTINGS
@given(polygons(), st.integers(0, 20), st.booleans())
def test_relabelling_the_vertices_changes_nothing(poly, shift, reverse) -> None:
    vertices, com = poly
    ref = push_function(build(vertices, com))
    k = shift % len(vertices)
    relabelled = vertices[k:] + vertices[:k]
    if reverse:
        relabelled = relabelled[::-1]
    pf = push_function(build(relabelled, com))
    assert pf.part.hull == ref.part.hull  # the numbering is the part's, not the file's
    assert [s.edge for s in pf.states] == [s.edge for s in ref.states]
    for a, b in zip(pf.states, ref.states, strict=True):
        assert a.normal_deg == pytest.approx(b.normal_deg, abs=1e-9)
        assert a.resting_range_deg == pytest.approx(b.resting_range_deg, abs=1e-9)
        assert a.diameter == pytest.approx(b.diameter, abs=1e-12)


@SETTINGS
@given(polygons(), st.floats(-180.0, 180.0), st.floats(-50.0, 50.0), st.floats(-50.0, 50.0))
def test_rotating_the_part_shifts_the_frame_only(poly, alpha, tx, ty) -> None:
    vertices, com = poly
    ref = push_function(build(vertices, com))
    assume(min(abs(m) for m in ref.edge_margin_deg) > 1e-6)
    c, s = math.cos(math.radians(alpha)), math.sin(math.radians(alpha))

    def move(p):
        return (c * p[0] - s * p[1] + tx, s * p[0] + c * p[1] + ty)

    pf = push_function(build([move(p) for p in vertices], move(com)))
    assert pf.n == ref.n
    assert np.allclose(signature(pf), signature(ref), atol=1e-6)
    shifted = sorted((s.normal_deg + alpha) % 360.0 for s in ref.states)
    got = sorted(s.normal_deg % 360.0 for s in pf.states)
    for a, b in zip(shifted, got, strict=True):
        assert circ(a, b) < 1e-7 or circ(a, b) > 359.9999999
    assert symmetry(pf).part_period_deg == symmetry(ref).part_period_deg
    tol = ToleranceSensor(0.05)
    assert polygon_class(pf, tol).number == polygon_class(ref, tol).number


# --- action and overlap ranges against the push function at sampled rotations --------------


def _inside(lo: float, hi: float, a: float) -> bool:
    return lo < a < hi or lo < a + 360.0 < hi


@SETTINGS
@given(polygons(), st.lists(st.floats(0.0, 360.0, exclude_max=True), min_size=10, max_size=30))
def test_action_ranges_agree_with_push(poly, rotations) -> None:
    pf = push_function(build(*poly))
    for s in pf.states:
        ranges = action_ranges(pf, s.id)
        assert len(ranges) == pf.n
        assert sum(r.hi - r.lo for r in ranges) == pytest.approx(360.0)
        assert sorted(r.target for r in ranges) == list(range(pf.n))
        for a in rotations:
            if min(circ(a, r.lo) for r in ranges) < 1e-6:
                continue
            (hit,) = [r for r in ranges if _inside(r.lo, r.hi, a)]
            assert hit.target == push(pf, s.normal_deg - a).id


@SETTINGS
@given(polygons(), st.data())
def test_overlap_ranges_agree_with_push(poly, data) -> None:
    pf = push_function(build(*poly))
    subset = data.draw(
        st.lists(st.sampled_from(range(pf.n)), min_size=1, max_size=pf.n, unique=True)
    )
    cells = overlap_ranges(build_machine([pf], uncertainty=IDEAL), mask_of(subset))
    assert len(cells) <= len(subset) * pf.n
    assert sum(c.hi - c.lo for c in cells) == pytest.approx(360.0)
    for c in cells:
        for f in (0.05, 0.5, 0.95):
            a = c.lo + f * (c.hi - c.lo)
            got = {push(pf, pf.states[i].normal_deg - a).id for i in subset}
            assert mask_of(got) == c.image
        assert 0.0 <= c.representative < 360.0 and c.margin > 0.0


# --- symmetry ---------------------------------------------------------------------------------


@st.composite
def symmetric_polygons(draw):
    """A polygon repeated k times around the origin, with its COM at the origin."""
    k = draw(st.integers(2, 6))
    wedge = 360.0 / k
    m = draw(st.integers(1, 3))
    angles = draw(
        st.lists(st.floats(0.0, wedge, exclude_max=True), min_size=m, max_size=m, unique=True)
    )
    radii = draw(st.lists(st.floats(0.6, 2.0), min_size=m, max_size=m))
    pts = [
        (r * math.cos(math.radians(a + j * wedge)), r * math.sin(math.radians(a + j * wedge)))
        for j in range(k)
        for a, r in zip(angles, radii, strict=True)
    ]
    hull = convex_hull(pts)
    assume(reasonable(hull))
    return k, hull


@SETTINGS
@given(symmetric_polygons(), st.lists(st.floats(0.0, 360.0), min_size=10, max_size=30))
def test_k_fold_parts_have_a_push_period_dividing_360_over_k(sym, thetas) -> None:
    k, hull = sym
    pf = push_function(build(hull, (0.0, 0.0)))
    periods = push_periods(pf)
    assert periods % k == 0
    assert round(360.0 / symmetry(pf).part_period_deg) % k == 0
    t = 360.0 / periods
    for theta in thetas:
        if min(circ(theta, d) for d in pf.divergent_deg) < 1e-6:
            continue
        a, b = push(pf, theta), push(pf, theta + t)
        assert circ(b.normal_deg, a.normal_deg + t) < 1e-6  # definition 3
        c = push(pf, theta + 360.0 / k)
        assert c.diameter == pytest.approx(a.diameter, abs=1e-9)


def _invariant(items: list[tuple[float, int]], shift: float) -> bool:
    return all(
        any(kind == k2 and circ(a + shift, b) < 1e-6 for b, k2 in items) for a, kind in items
    )


@SETTINGS
@given(polygons())
def test_reported_periods_are_periods_and_none_smaller_exists(poly) -> None:
    pf = push_function(build(*poly))
    b = push_periods(pf)
    angles = sorted(
        [(s.normal_deg % 360.0, 0) for s in pf.states] + [(d, 1) for d in pf.divergent_deg]
    )
    q = len(angles)

    smallest = next(
        (360.0 * j / q for j in range(1, q) if _invariant(angles, 360.0 * j / q)), 360.0
    )
    assert 360.0 / b == pytest.approx(smallest)


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.floats(0.0, 359.0), min_size=1, max_size=6, unique=True),
    st.lists(st.integers(0, 2), min_size=6, max_size=6),
    st.integers(1, 8),
)
def test_periods_of_finds_the_smallest_period(base, ids, k) -> None:
    wedge = 360.0 / k
    base = sorted({a % wedge for a in base})
    assume(all(b - a > 1e-3 for a, b in zip(base, base[1:], strict=False)))
    assume(not base or wedge - base[-1] + base[0] > 1e-3)
    angles = [a + j * wedge for j in range(k) for a in base]
    labels = [ids[i % len(base)] for j in range(k) for i in range(len(base))]
    b = periods_of(angles, labels)
    assert b % k == 0
    items = list(zip(angles, labels, strict=True))
    q = len(items)
    smallest = next((j for j in range(1, q) if _invariant(items, 360.0 * j / q)), q)
    assert b == q // smallest


@pytest.mark.parametrize("n", [5, 40, 3000])
def test_radius_and_diameter_from_support_vertices_match_every_vertex(n, monkeypatch) -> None:
    # Past SUPPORT_MATRIX_MAX the functions find each direction's support vertex by a binary
    # search over the edge normals (a dense outline's wells asked for 25 GiB): the same values
    # as projecting every vertex, at the edge normals themselves too.
    import importlib

    push = importlib.import_module("feederkit.mechanics.push")  # the package has push()
    rng = np.random.default_rng(n)
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, n))
    radii = rng.uniform(20.0, 30.0, n)
    points = np.c_[radii * np.cos(angles), radii * np.sin(angles)].tolist()
    part = make_part(make_outline(f"random-{n}", points))
    normals = np.asarray(push.edge_normals(part.hull))
    phis = np.concatenate([rng.uniform(-720.0, 720.0, 500), normals, normals + 360.0])
    want_r, want_w = push.radius(part, phis), push.diameter(part, phis)
    one = push.radius(part, 37.0)
    monkeypatch.setattr(push, "SUPPORT_MATRIX_MAX", 0)
    assert np.allclose(push.radius(part, phis), want_r, rtol=0.0, atol=1e-9)
    assert np.allclose(push.diameter(part, phis), want_w, rtol=0.0, atol=1e-9)
    got = push.radius(part, 37.0)
    assert isinstance(got, float) and got == pytest.approx(one, abs=1e-9)
