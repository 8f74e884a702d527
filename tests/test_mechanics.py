"""Section 3 on parts with known answers: radius, push, diameters, actions, symmetry, classes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from feederkit.machine import build_machine, mask_of, overlap_ranges
from feederkit.mechanics import (
    PushFunction,
    StableState,
    action_ranges,
    diameter,
    polygon_class,
    push,
    push_diameter,
    push_diameter_period,
    push_function,
    push_period,
    radius,
    symmetry,
)
from feederkit.mechanics.analysis import analysis_to_dict, analyze_part
from feederkit.mechanics.push import edge_normals, edge_widths, resting_widths
from feederkit.mechanics.symmetry import periods_of
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import Part, make_part
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
LONG_EDGE_RANGE = 2 * math.degrees(math.atan(2.0))  # 126.87
SHORT_EDGE_RANGE = 2 * math.degrees(math.atan(0.5))  # 53.13


def part_of(vertices, com=None, name="p") -> Part:
    return make_part(make_outline(name, vertices), com)


def regular(n: int, r: float = 1.0, phase: float = 0.0) -> list[tuple[float, float]]:
    return [
        (r * math.cos(math.radians(phase + a)), r * math.sin(math.radians(phase + a)))
        for a in (360.0 * k / n for k in range(n))
    ]


RECT = part_of([(0, 0), (2, 0), (2, 1), (0, 1)], name="rectangle")
TRIANGLE = part_of([(0, 0), (1, 0), (0, 1)], name="triangle")
EQUILATERAL = part_of([(0, 0), (1, 0), (0.5, math.sqrt(3) / 2)], name="equilateral")


# --- the analytic cases of issue 2 -------------------------------------------------------


def test_centred_rectangle() -> None:
    pf = push_function(RECT)
    assert pf.n == 4
    by_edge = {s.edge: s for s in pf.states}
    assert sorted(by_edge) == [0, 1, 2, 3]
    for e in (0, 2):  # long edges (length 2)
        lo, hi = by_edge[e].resting_range_deg
        assert hi - lo == pytest.approx(LONG_EDGE_RANGE)
        assert round(hi - lo, 2) == 126.87
        assert by_edge[e].diameter == pytest.approx(1.0)
    for e in (1, 3):  # short edges
        lo, hi = by_edge[e].resting_range_deg
        assert round(hi - lo, 2) == 53.13
        assert by_edge[e].diameter == pytest.approx(2.0)
    assert by_edge[0].normal_deg == 270.0
    assert by_edge[0].resting_range_deg == pytest.approx((206.56505117707798, 333.434948822922))
    assert by_edge[0].pose_deg == 0.0  # -90 - 270
    assert by_edge[1].pose_deg == 270.0
    sym = symmetry(pf)
    assert sym.part_period_deg == pytest.approx(180.0)
    assert sym.push_period_deg == pytest.approx(180.0)
    assert (sym.kind, sym.period_deg) == ("symmetric", pytest.approx(180.0))
    assert analysis_to_dict(analyze_part(RECT))["symmetry_period_deg"] == pytest.approx(180.0)


def test_isosceles_right_triangle() -> None:
    pf = push_function(TRIANGLE)
    assert pf.n == 3
    assert sorted(s.diameter for s in pf.states) == pytest.approx([math.sqrt(0.5), 1.0, 1.0])
    assert round(min(s.diameter for s in pf.states), 4) == 0.7071
    assert push_period(pf) == 360.0
    assert symmetry(pf).part_period_deg == 360.0
    hyp = next(s for s in pf.states if s.edge == 1)
    assert hyp.normal_deg == pytest.approx(45.0)
    # Divergent orientations: the directions from the COM (1/3, 1/3) to (1, 0) and (0, 1).
    want = (-SHORT_EDGE_RANGE / 2, 90 + SHORT_EDGE_RANGE / 2)
    assert hyp.resting_range_deg == pytest.approx(want)


def test_equilateral_triangle_period_120() -> None:
    pf = push_function(EQUILATERAL)
    assert pf.n == 3
    assert push_period(pf) == pytest.approx(120.0)
    assert symmetry(pf).part_period_deg == pytest.approx(120.0)
    assert symmetry(pf).kind == "constant"
    assert push_diameter_period(pf) == 0.0
    assert resting_widths(pf) == pytest.approx([120.0] * 3)


@pytest.mark.parametrize("n", [4, 5, 8, 12, 1000])
def test_regular_polygons(n: int) -> None:
    pf = push_function(part_of(regular(n, 1.0, 90.0 + 180.0 / n)))
    assert pf.n == n
    assert push_period(pf) == 360.0 / n  # exactly: 360 k / n
    assert symmetry(pf).part_period_deg == 360.0 / n


def test_offset_regular_polygon_is_asymmetric() -> None:
    pf = push_function(part_of(regular(7), (0.13, 0.05)))
    assert push_period(pf) == 360.0
    assert polygon_class(pf, NoSensor()).number == 7
    assert polygon_class(pf, NoSensor()).bound == 2 * pf.n - 1


def test_radius_function_minima_are_the_stable_orientations() -> None:
    pf = push_function(RECT)
    for s in pf.states:
        r0 = radius(RECT, s.normal_deg)
        assert radius(RECT, s.normal_deg - 0.5) > r0 < radius(RECT, s.normal_deg + 0.5)
    for d in pf.divergent_deg:
        r0 = radius(RECT, d)
        assert radius(RECT, d - 0.5) < r0 > radius(RECT, d + 0.5)
    assert radius(RECT, 270.0) == pytest.approx(0.5)
    assert radius(RECT, math.degrees(math.atan2(0.5, 1.0))) == pytest.approx(math.hypot(1, 0.5))


def test_push_and_push_diameter() -> None:
    pf = push_function(RECT)
    assert push(pf, 300.0).edge == 0
    assert push(pf, 10.0).edge == 1
    assert push(pf, 100.0).edge == 2
    assert push(pf, 190.0).edge == 3
    assert push(pf, 300.0 + 720.0).edge == 0
    assert push_diameter(pf, 300.0) == pytest.approx(1.0)
    assert push_diameter(pf, 10.0) == pytest.approx(2.0)


def test_barrier_is_the_rise_to_the_lower_neighbouring_maximum() -> None:
    pf = push_function(RECT)
    long, short = pf.states[0], pf.states[1]
    assert long.barrier_mm == pytest.approx(math.hypot(1, 0.5) - 0.5)
    assert short.barrier_mm == pytest.approx(math.hypot(1, 0.5) - 1.0)


def test_edge_widths_match_the_diameter_function() -> None:
    part = part_of(regular(9, 3.0, 11.0), (0.4, -0.2))
    want = diameter(part, np.array(edge_normals(part.hull)))
    assert edge_widths(part.hull) == pytest.approx(want, abs=1e-12)


# --- metastable and near-metastable edges -------------------------------------------------


def test_exactly_metastable_edge() -> None:
    # The COM (2, 0.5) stands right above vertex 1 = (2, 0): edge 0's foot is that vertex.
    part = part_of([(0, 0), (2, 0), (3, 1), (0, 1)], (2.0, 0.5))
    pf = push_function(part)
    assert pf.edge_kinds[0] == "metastable"
    assert 0 not in [s.edge for s in pf.states]
    assert 0 in pf.near_metastable_edges
    assert sum(resting_widths(pf)) == pytest.approx(360.0)
    # Fence orientations around edge 0's normal settle on a neighbour, never on edge 0.
    assert push(pf, 270.0).edge != 0


def test_near_metastable_edge_is_analysed_and_flagged() -> None:
    part = part_of([(0, 0), (2, 0), (2, 1), (0, 1)], (1.999, 0.5))
    a = analyze_part(part)
    assert a.push.n == 4
    assert a.push.edge_kinds[0] == "stable"
    flagged = {n.edge: n for n in a.near_metastable}
    assert set(flagged) == {0, 2}
    assert flagged[0].vertex == 1 and flagged[2].vertex == 2
    assert flagged[0].margin_deg == pytest.approx(math.degrees(math.atan(0.001 / 0.5)))
    assert a.push.states[0].near_metastable
    d = analysis_to_dict(a)
    assert [x["edge"] for x in d["near_metastable_edges"]] == [0, 2]


def test_near_metastable_unstable_edge() -> None:
    # The COM's foot on edge 0 falls 0.001 past vertex 1: unstable, but only just.
    part = part_of([(0, 0), (2, 0), (3, 1), (0, 1)], (2.001, 0.5))
    a = analyze_part(part)
    assert a.push.edge_kinds[0] == "unstable"
    near = {n.edge: n for n in a.near_metastable}
    assert near[0].vertex == 1 and near[0].kind == "unstable"
    assert near[0].margin_deg == pytest.approx(-math.degrees(math.atan(0.001 / 0.5)))
    assert push_function(RECT).near_metastable_edges == ()


# --- action and overlap ranges (section 3.2) ----------------------------------------------


def test_action_ranges_of_the_rectangle() -> None:
    pf = push_function(RECT)
    s0 = next(s for s in pf.states if s.edge == 0)
    ranges = action_ranges(pf, s0.id)
    assert len(ranges) == 4
    assert ranges[0].lo == pytest.approx(min(r.lo for r in ranges))
    total = sum(r.hi - r.lo for r in ranges)
    assert total == pytest.approx(360.0)
    for r, nxt in zip(ranges, ranges[1:], strict=False):
        assert r.hi == pytest.approx(nxt.lo)
    # A half turn puts the other long edge on the fence; no rotation keeps edge 0 within 63 deg.
    half = next(r for r in ranges if r.lo < 180.0 < r.hi)
    assert pf.states[half.target].edge == 2
    stay = next(r for r in ranges if pf.states[r.target].edge == 0)
    assert stay.hi - stay.lo == pytest.approx(LONG_EDGE_RANGE)
    # Definition 9: the range to s_j is (psi_i - hi_j, psi_i - lo_j) in design.md's sign.
    s1 = next(s for s in pf.states if s.edge == 1)
    to1 = next(r for r in ranges if r.target == s1.id)
    lo1, hi1 = s1.resting_range_deg
    assert (to1.lo % 360.0, to1.hi % 360.0) == pytest.approx(((270 - hi1) % 360, (270 - lo1) % 360))


def test_overlap_ranges_of_the_long_edges() -> None:
    pf = push_function(RECT)
    ids = [s.id for s in pf.states if s.edge in (0, 2)]
    machine = build_machine([pf], uncertainty=IDEAL)
    cells = overlap_ranges(machine, mask_of(ids))
    assert len(cells) <= len(ids) * pf.n
    assert sum(c.hi - c.lo for c in cells) == pytest.approx(360.0)
    for c in cells:
        a = c.representative
        assert c.margin == pytest.approx((c.hi - c.lo) / 2)
        got = {push(pf, pf.states[i].normal_deg - a).id for i in ids}
        assert mask_of(got) == c.image
        # The symmetric pair always lands on symmetric states: never on one state.
        assert c.image.bit_count() == 2


# --- symmetry (definitions 3, 6-8) on hand-made push functions ----------------------------


def synthetic(states: list[tuple[float, float]], divergent: list[float]) -> PushFunction:
    """A push function with these stable orientations and diameters, ranges between divergents."""
    div = sorted(divergent)
    m = len(div)
    out, range_state = [], [0] * m
    for sid, (psi, d) in enumerate(states):
        k = max(i for i in range(m) if div[i] < psi) if psi > div[0] else m - 1
        lo = div[k] if div[k] < psi else div[k] - 360.0
        hi = div[(k + 1) % m] if k + 1 < m else div[0] + 360.0
        range_state[k] = sid
        out.append(StableState(sid, sid, psi, (lo, hi), d, (-90.0 - psi) % 360.0))
    return PushFunction(RECT, tuple(out), tuple(div), tuple(range_state), (), ())


def test_quasi_symmetric_push_diameter_function() -> None:
    pf = synthetic([(45, 1), (135, 2), (200, 1), (315, 2)], [0, 90, 180, 270])
    sym = symmetry(pf)
    assert (sym.kind, sym.period_deg, sym.push_period_deg) == ("quasi-symmetric", 180.0, 360.0)
    c = polygon_class(pf, ToleranceSensor(0.1))
    assert (c.number, c.bound, c.m) == (4, 3, 2)


def test_symmetric_push_and_push_diameter() -> None:
    pf = synthetic([(45, 1), (135, 2), (225, 1), (315, 2)], [0, 90, 180, 270])
    sym = symmetry(pf)
    assert (sym.kind, sym.period_deg, sym.push_period_deg) == ("symmetric", 180.0, 90.0)
    assert sym.part_period_deg == 180.0
    c = polygon_class(pf, ToleranceSensor(0.1))
    assert (c.number, c.bound, c.p) == (5, 1, 2)


def test_symmetric_push_diameter_with_asymmetric_push() -> None:
    states = [(25, 1), (85, 1), (150, 2), (205, 1), (265, 1), (330, 2)]
    pf = synthetic(states, [0, 50, 120, 180, 250, 300])
    sym = symmetry(pf)
    assert (sym.kind, sym.period_deg, sym.push_period_deg) == ("symmetric", 180.0, 360.0)
    c = polygon_class(pf, ToleranceSensor(0.1))
    assert (c.number, c.bound, c.m) == (6, 7, 4)


def test_periods_of() -> None:
    assert periods_of([]) == 0
    assert periods_of([10.0]) == 1
    assert periods_of([0.0, 120.0, 240.0]) == 3
    assert periods_of([5.0, 95.0, 185.0, 275.0], [0, 1, 0, 1]) == 2
    assert periods_of([5.0, 95.0, 185.0, 275.0]) == 4
    assert periods_of([0.0, 100.0, 240.0]) == 1
    assert periods_of([359.99999999999, 120.0, 240.0]) == 3  # equal within ANGLE_EPS


# --- Fig. 14 classes ------------------------------------------------------------------------


def test_classes_of_the_paper_parts() -> None:
    rect = push_function(RECT)
    c = polygon_class(rect, ToleranceSensor(0.01))
    assert (c.number, c.bound, c.m, c.p) == (5, 1, 2, 2)
    sensorless = polygon_class(rect, NoSensor())
    assert (sensorless.number, sensorless.bound, sensorless.p) == (8, 3, 2)
    tri = push_function(TRIANGLE)
    c = polygon_class(tri, ToleranceSensor(0.01))
    assert (c.number, c.bound, c.m, c.n) == (2, 2, 2, 3)
    assert polygon_class(tri, NoSensor()).number == 7
    eq = polygon_class(push_function(EQUILATERAL), ToleranceSensor(0.01))
    assert (eq.number, eq.bound, eq.p) == (8, 1, 3)
    # Diameters 1 and 2 fall in one LED beam gap of 5 mm: no information.
    assert polygon_class(rect, LedSensor(5.0)).number == 8


def test_all_unique_diameters_is_class_1() -> None:
    pf = push_function(part_of([(0, 0), (3, 0), (2.4, 2), (0.5, 1.6)]))
    c = polygon_class(pf, ToleranceSensor(0.001))
    assert (c.number, c.bound, c.m) == (1, 1, 1)
    assert polygon_class(pf, ToleranceSensor(0.01)).number == 2


def test_off_centre_rectangle_is_aperiodic() -> None:
    pf = push_function(part_of([(0, 0), (2, 0), (2, 1), (0, 1)], (0.8, 0.4)))
    sym = symmetry(pf)
    assert sym.kind == "aperiodic" and sym.part_period_deg == 360.0
    c = polygon_class(pf, ToleranceSensor(0.01))
    assert (c.number, c.bound) == (3, 2)


# --- the sample catalog -----------------------------------------------------------------------


CATALOG_FILES = sorted(CATALOG.glob("*.json"))


@pytest.mark.parametrize("path", CATALOG_FILES, ids=[p.stem for p in CATALOG_FILES])
def test_catalog_parts_load_and_analyse(path: Path) -> None:
    raw = json.loads(path.read_text(encoding="utf-8"))
    assert raw["name"] == path.stem
    assert raw.get("units", "mm") == "mm"
    part = make_part(load_outline_json(path))
    d = analysis_to_dict(analyze_part(part, ToleranceSensor(0.01 * part.size)))
    assert d["stable_states"] and 1 <= d["class"] <= 8
    assert sum(d["resting_width_deg"]) == pytest.approx(360.0)


def test_catalog_paper_parts_match_the_paper() -> None:
    def pf_of(name: str) -> PushFunction:
        return push_function(make_part(load_outline_json(CATALOG / f"{name}.json")))

    assert pf_of("octagon").n == 8 and push_period(pf_of("octagon")) == pytest.approx(45.0)
    assert push_period(pf_of("equilateral-triangle")) == pytest.approx(120.0)
    assert pf_of("isosceles-right-triangle").n == 3
    rect = pf_of("rectangle-2x1")
    assert rect.part.com != (1.0, 0.5) and push_period(rect) == 360.0
    assert sorted(round(s.diameter, 9) for s in rect.states) == [1.0, 1.0, 2.0, 2.0]
    assert push_period(pf_of("quadrilateral")) == 360.0 and pf_of("quadrilateral").n == 4
