"""DXF import (ezdxf + shapely) and hull simplification, on drawings generated here."""

from __future__ import annotations

import math
import random
import time
from pathlib import Path

import ezdxf
import fixtures_cad as fx
import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.hull import clean_hull, contact_hull, convex_hull
from feederkit.importers import ImportOptions, import_parts, read_source
from feederkit.mechanics import push_function
from feederkit.mechanics.push import edge_normals


def one(path: Path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    return parts[0]


def area(ip) -> float:
    return ip.part.outline.polygon().area


def test_plate_with_bulges_hole_and_slot(tmp_path):
    ip = one(fx.write_plate(tmp_path / "plate.dxf"))
    assert area(ip) == pytest.approx(fx.PLATE_AREA, rel=2e-4)
    assert len(ip.part.outline.holes) == 2
    assert ip.source.source_units == "mm"
    # bulges are real arcs: the corners are flattened into many points
    assert len(ip.part.outline.vertices) > 20
    pf = push_function(ip.part)
    # four straight sides are the only stable edges; widths 40 and 60 exactly
    assert pf.n == 4
    assert sorted(round(s.diameter, 9) for s in pf.states) == [40, 40, 60, 60]
    assert ip.orientability.orientable
    assert ip.warnings == ()


@pytest.mark.parametrize(("version", "fmt"), [("R12", "asc"), ("R2000", "bin"), ("R2018", "bin")])
def test_r12_and_binary_dxf(tmp_path, version, fmt):
    ip = one(fx.write_plate(tmp_path / f"plate-{version}-{fmt}.dxf", version=version, fmt=fmt))
    assert area(ip) == pytest.approx(fx.PLATE_AREA, rel=2e-4)
    assert len(ip.part.outline.holes) == 2


def test_block_rotated_scaled_in_inches(tmp_path):
    ip = one(fx.write_rotated_block(tmp_path / "block.dxf"))
    assert ip.source.source_units == "in"
    assert area(ip) == pytest.approx(fx.BLOCK_AREA_IN * 25.4**2, rel=2e-4)
    assert len(ip.part.outline.holes) == 1
    normals = sorted(round(a, 6) % 360 for a in edge_normals(ip.part.hull))
    assert normals == pytest.approx([30.0, 120.0, 210.0, 300.0])
    # the hole's centre lands at insert point + R(30) * 2 * (5, 2.5), in mm
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    hx = (100 + 2 * (5 * c - 2.5 * s)) * 25.4
    hy = (50 + 2 * (5 * s + 2.5 * c)) * 25.4
    hole = shapely.Polygon(ip.part.outline.holes[0]).centroid
    assert (hole.x, hole.y) == pytest.approx((hx, hy), abs=1e-3)


def test_units_override(tmp_path):
    ip = one(fx.write_rotated_block(tmp_path / "block.dxf"), units="mm")
    assert area(ip) == pytest.approx(fx.BLOCK_AREA_IN, rel=1e-3)  # flattened at 0.01 "mm"
    with pytest.raises(InputError, match="unknown unit"):
        one(tmp_path / "block.dxf", units="furlong")


def test_nested_and_mirrored_inserts(tmp_path):
    ip = one(fx.write_nested_mirrored(tmp_path / "nested.dxf"))
    got = {(round(x, 9) + 0.0, round(y, 9) + 0.0) for x, y in ip.part.outline.vertices}
    assert got == {(float(x), float(y)) for x, y in fx.nested_mirrored_expected()}
    assert area(ip) == pytest.approx(6.0)


def test_fit_point_spline(tmp_path):
    ip = one(fx.write_fit_spline(tmp_path / "spline.dxf"))
    assert area(ip) == pytest.approx(fx.SPLINE_AREA, rel=2e-3)
    top = [p for p in ip.part.outline.vertices if p[1] > 10.5]
    assert len(top) >= 10  # the spline is flattened, not replaced by its fit points' polygon


def test_ellipse_hole(tmp_path):
    ip = one(fx.write_ellipse_hole(tmp_path / "ellipse.dxf"))
    assert area(ip) == pytest.approx(fx.ELLIPSE_AREA, rel=2e-4)
    (hole,) = ip.part.outline.holes
    assert shapely.Polygon(hole).area == pytest.approx(math.pi * 50, rel=1e-3)


def test_drawing_frame_is_skipped(tmp_path):
    ip = one(fx.write_framed(tmp_path / "framed.dxf"))
    assert area(ip) == pytest.approx(fx.FRAME_PART_AREA, rel=2e-4)
    assert len(ip.part.outline.holes) == 1
    assert any("frame" in w for w in ip.warnings)


def test_several_parts_largest_or_all(tmp_path):
    path = fx.write_two_parts(tmp_path / "two.dxf")
    ip = one(path)
    assert area(ip) == pytest.approx(800.0)
    assert any("2 separate parts" in w for w in ip.warnings)
    assert any("two-2" in w and "100.0 mm2" in w for w in ip.warnings)
    _, parts = import_parts(path, ImportOptions(all_parts=True))
    assert [p.part.name for p in parts] == ["two", "two-2"]
    assert [round(area(p), 6) for p in parts] == [800.0, 100.0]


def test_layers_select_geometry(tmp_path):
    def build(msp):
        msp.add_lwpolyline(
            [(0, 0), (10, 0), (10, 10), (0, 10)], close=True, dxfattribs={"layer": "CUT"}
        )
        msp.add_lwpolyline(
            [(-50, -50), (50, -50), (50, 50), (-50, 50)], close=True, dxfattribs={"layer": "NOTES"}
        )

    path = fx.write_entities(tmp_path / "layers.dxf", build)
    assert area(one(path)) == pytest.approx(10000.0 - 100.0)
    assert area(one(path, layers=("cut",))) == pytest.approx(100.0)
    with pytest.raises(InputError, match="no geometry on layer nope"):
        one(path, layers=("nope",))


def test_text_dimensions_and_hatches_are_skipped(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (20, 0), (20, 10), (0, 10)], close=True)
        msp.add_text("PART 7")
        msp.add_mtext("notes")
        hatch = msp.add_hatch()
        hatch.paths.add_polyline_path([(0, 0), (50, 0), (50, 50)], is_closed=True)
        msp.add_linear_dim(base=(0, -20), p1=(0, 0), p2=(20, 0)).render()

    ip = one(fx.write_entities(tmp_path / "annotated.dxf", build))
    assert area(ip) == pytest.approx(200.0)


def test_unitless_drawing_warns_and_reads_mm(tmp_path):
    path = fx.write_entities(
        tmp_path / "nounits.dxf",
        lambda m: m.add_lwpolyline([(0, 0), (4, 0), (4, 3)], close=True),
        units=0,
    )
    ip = one(path)
    assert area(ip) == pytest.approx(6.0)
    assert any("no units" in w for w in ip.warnings)


def test_small_gaps_between_entities_are_closed(tmp_path):
    def build(msp):
        msp.add_line((0, 0), (10, 0))
        msp.add_line((10.000001, 0), (10, 10))
        msp.add_line((10, 10), (0, 10.000002))
        msp.add_line((0, 10), (0, 0))

    assert area(one(fx.write_entities(tmp_path / "gaps.dxf", build))) == pytest.approx(
        100.0, rel=1e-5
    )


def test_crossing_centre_line_does_not_split_the_part(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (30, 0), (30, 10), (0, 10)], close=True)
        msp.add_line((15, -5), (15, 15))

    assert area(one(fx.write_entities(tmp_path / "centre.dxf", build))) == pytest.approx(300.0)


# ---- bad input: one clear line ----------------------------------------------------------


def bad(path: Path, match: str, **options) -> str:
    with pytest.raises(InputError, match=match) as info:
        read_source(path, ImportOptions(**options))
    message = str(info.value)
    assert "\n" not in message and str(path.name) in message
    return message


def test_empty_and_corrupt_files(tmp_path):
    empty = tmp_path / "empty.dxf"
    empty.write_bytes(b"")
    bad(empty, "empty")
    corrupt = tmp_path / "corrupt.dxf"
    corrupt.write_bytes(bytes(random.Random(1).randrange(256) for _ in range(4000)))
    bad(corrupt, "not a DXF file")
    truncated = tmp_path / "truncated.dxf"
    full = fx.write_plate(tmp_path / "full.dxf").read_bytes()
    truncated.write_bytes(full[: len(full) // 3])
    with pytest.raises(InputError):
        read_source(truncated, ImportOptions())


def test_text_only(tmp_path):
    path = fx.write_entities(tmp_path / "text.dxf", lambda m: m.add_text("hello"))
    bad(path, "no outline geometry.*model space: only TEXT x1")
    bad(fx.write_plate(tmp_path / "plate.dxf"), "in the paper space: it is empty", space="paper")


def test_open_outline(tmp_path):
    def build(msp):
        msp.add_line((0, 0), (10, 0))
        msp.add_line((10, 0), (10, 10))
        msp.add_line((10, 10), (0, 10))

    bad(
        fx.write_entities(tmp_path / "open.dxf", build),
        r"no closed outline.*\(2 open ends, 10 mm apart at \(0, 10\) and \(0, 0\)\)",
    )


def test_an_open_polyline_has_two_open_ends(tmp_path):
    """Its two ends, counted as ends (not as the open pieces left over)."""

    def build(msp):
        msp.add_lwpolyline([(0, 0), (10, 0), (10, 5), (0, 5)], close=False)

    bad(
        fx.write_entities(tmp_path / "open.dxf", build),
        r"\(2 open ends, 5 mm apart at \(0, 0\) and \(0, 5\)\)$",
    )


def test_zero_area_outline(tmp_path):
    path = fx.write_entities(
        tmp_path / "flat.dxf", lambda m: m.add_lwpolyline([(0, 0), (10, 0), (20, 0)], close=True)
    )
    bad(path, "zero area")


def test_a_self_intersecting_polyline_is_refused_not_split(tmp_path):
    """A bow-tie is refused as the outline file is, naming the entity, not cut in two parts."""
    path = fx.write_entities(
        tmp_path / "bow.dxf",
        lambda m: m.add_lwpolyline([(0, 0), (10, 10), (10, 0), (0, 10)], close=True),
    )
    message = bad(path, "the outline is self-intersecting")
    assert "LWPOLYLINE" in message and "layer '0'" in message
    assert "crosses itself near (5, 5)" in message
    assert main(["part", "analyze", str(path)]) == 2


def _rectangle_lines(msp) -> None:
    for a, b in (((0, 0), (40, 0)), ((40, 0), (40, 30)), ((40, 30), (0, 30)), ((0, 30), (0, 0))):
        msp.add_line(a, b)


CROSSING = {
    "circle across a polyline": lambda m: (
        m.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True),
        m.add_circle((40, 15), 5),
    ),
    "circle across lines, beside a hole": lambda m: (
        _rectangle_lines(m),
        m.add_circle((40, 15), 5),
        m.add_circle((20, 15), 5),
    ),
    "overlapping outlines": lambda m: (
        m.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True),
        m.add_lwpolyline([(20, 10), (60, 10), (60, 50), (20, 50)], close=True),
    ),
}


@pytest.mark.parametrize("case", CROSSING)
def test_a_closed_loop_across_the_outline_is_refused(tmp_path, case):
    """A hole crossing the outline is refused as in an outline file, not welded onto the part;
    two outlines that overlap, each less than half inside the other, are said to overlap."""
    said = "two closed loops overlap" if case == "overlapping outlines" else "crosses the outline"
    message = bad(fx.write_entities(tmp_path / "cross.dxf", CROSSING[case]), said)
    assert "on layer '0'" in message
    if case.startswith("circle"):
        assert "CIRCLE" in message


def test_loops_that_touch_or_nest_still_import(tmp_path):
    """A tab drawn against the outline, a hole inside, a separate part: no crossing."""

    def build(msp):
        msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
        msp.add_lwpolyline([(40, 10), (50, 10), (50, 20), (40, 20)])  # a tab on the side
        msp.add_circle((20, 15), 5)
        msp.add_lwpolyline([(60, 0), (70, 0), (70, 10), (60, 10)], close=True)

    ip = one(fx.write_entities(tmp_path / "tab.dxf", build))
    assert area(ip) == pytest.approx(1200.0 + 100.0 - math.pi * 25.0, rel=1e-3)
    assert len(ip.part.outline.holes) == 1
    assert any("2 separate parts" in w for w in ip.warnings)


def test_unknown_unit_code(tmp_path):
    path = fx.write_entities(
        tmp_path / "odd.dxf", lambda m: m.add_lwpolyline([(0, 0), (4, 0), (4, 3)], close=True)
    )
    doc = ezdxf.readfile(path)
    doc.header["$INSUNITS"] = 99
    doc.saveas(path)
    bad(path, "unsupported drawing unit")


def test_large_file_refused_unless_allowed(tmp_path):
    path = fx.write_plate(tmp_path / "plate.dxf")
    bad(path, "over the 0.001 MB limit.*--allow-large", max_file_mb=0.001)
    result = read_source(path, ImportOptions(max_file_mb=0.001, allow_large=True))
    assert result.parts[0].outline.polygon().area == pytest.approx(fx.PLATE_AREA, rel=2e-4)


def test_missing_and_unsupported_files(tmp_path):
    bad(tmp_path / "nope.dxf", "no such file")
    other = tmp_path / "part.step"
    other.write_text("ISO-10303-21;")
    bad(other, "unsupported file type")


# ---- hull simplification, gear and disk -------------------------------------------------


def arc_points(r: float, a0: float, a1: float, n: int) -> list[tuple[float, float]]:
    return [
        (
            r * math.cos(math.radians(a0 + (a1 - a0) * k / (n - 1))),
            r * math.sin(math.radians(a0 + (a1 - a0) * k / (n - 1))),
        )
        for k in range(n)
    ]


def dist_to_polygon(p, ring) -> float:
    return shapely.Polygon(ring).exterior.distance(shapely.Point(p))


def test_simplification_is_measured_against_the_original_points():
    # a finely flattened circle: neighbour-deviation cleaning would drift; ours stays within tol
    pts = arc_points(50.0, 0.0, 360.0, 2001)[:-1]
    tol = 0.05
    ring = convex_hull(pts)
    simple = clean_hull(ring, tol)
    assert max(dist_to_polygon(p, simple) for p in pts) <= tol + 1e-9
    # as few vertices as the tolerance allows: a chord of sagitta tol spans 2 acos(1 - tol/r)
    best = math.ceil(360.0 / math.degrees(2 * math.acos(1 - tol / 50.0)))
    assert best <= len(simple) <= 2 * best
    assert set(simple) <= set(ring)


def test_simplification_does_not_depend_on_the_start():
    pts = arc_points(20.0, 0.0, 360.0, 361)[:-1] + [(25.0, 0.0)]
    ring = convex_hull(pts)
    base = set(clean_hull(ring, 0.05))
    for shift in (1, 7, 100):
        assert set(clean_hull(ring[shift:] + ring[:shift], 0.05)) == base


def test_contact_hull_numbering_after_simplification():
    pts = arc_points(10.0, 180.0, 360.0, 200) + [(10.0, 5.0), (-10.0, 5.0)]
    hull = contact_hull(pts, 0.05)
    # vertex 0 is exactly the lowest, then leftmost (design.md), not within the tolerance
    assert hull[0] == min(hull, key=lambda p: (p[1], p[0]))
    assert shapely.Polygon(hull).exterior.is_ccw


def test_exact_polygons_keep_their_vertices():
    square = [(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.0)]
    assert contact_hull(square) == ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def test_gear_keeps_one_stable_edge_per_tooth_pair(tmp_path):
    teeth = 12
    path = fx.write_gear(tmp_path / "gear.dxf", teeth=teeth)
    raw = one(path, hull_tolerance=0.0)
    ip = one(path)
    assert len(raw.part.hull) > 4 * teeth  # flattened tip arcs
    assert len(ip.part.hull) == 2 * teeth  # each tip arc is one chord
    assert ip.orientability.orientable
    assert ip.orientability.useful_states == teeth
    pf = push_function(ip.part)
    wide = [s for s in pf.states if s.resting_range_deg[1] - s.resting_range_deg[0] > 10]
    assert len(wide) == teeth
    pitch = 360.0 / teeth
    for s in wide:  # gap edges: their normals point between two teeth
        assert (s.normal_deg - pitch / 2) % pitch == pytest.approx(0.0, abs=1e-6) or (
            s.normal_deg - pitch / 2
        ) % pitch == pytest.approx(pitch, abs=1e-6)
        assert s.resting_range_deg[1] - s.resting_range_deg[0] == pytest.approx(
            pitch - 6.0, abs=0.3
        )
    diameters = {round(s.diameter, 6) for s in wide}
    assert len(diameters) == 1  # symmetric: every tooth pair alike


def test_disk_is_not_orientable(tmp_path):
    ip = one(fx.write_disk(tmp_path / "disk.dxf", radius=10.0))
    assert not ip.orientability.orientable
    assert "disk-like" in ip.orientability.reason
    assert any(w.startswith("not orientable by pushing") for w in ip.warnings)
    assert ip.orientability.deepest_well_mm <= 0.05


def test_square_with_rounded_corners_is_orientable(tmp_path):
    def build(msp):
        msp.add_lwpolyline(fx._rounded_rect(20, 20, 8), format="xyb", close=True)

    ip = one(fx.write_entities(tmp_path / "round-square.dxf", build))
    assert ip.orientability.orientable
    assert ip.orientability.useful_states == 4


def test_minsert_grid_gives_separate_parts(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    blk = doc.blocks.new("SQ")
    blk.add_lwpolyline([(0, 0), (5, 0), (5, 5), (0, 5)], close=True)
    ref = doc.modelspace().add_blockref("SQ", (0, 0))
    ref.grid(size=(1, 3), spacing=(20, 20))
    path = tmp_path / "grid.dxf"
    doc.saveas(path)
    _, parts = import_parts(path, ImportOptions(all_parts=True))
    assert len(parts) == 3 and all(area(p) == pytest.approx(25.0) for p in parts)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=3, max_size=12, unique=True
    ),
    st.floats(0.5, 20.0),
    st.sampled_from([0.01, 0.05, 0.2]),
    st.integers(0, 50),
)
def test_simplified_hull_properties(corners, radius, tol, shift):
    # a polygon with rounded corners: corner points plus flattened arcs around each one
    pts = []
    for cx, cy in corners:
        pts += [(cx + x, cy + y) for x, y in arc_points(radius, 0.0, 360.0, 73)]
    ring = convex_hull(pts)
    if len(ring) < 3 or shapely.Polygon(ring).area < 1.0:
        return
    simple = clean_hull(ring, tol)
    poly = shapely.Polygon(simple)
    assert poly.is_valid and poly.exterior.is_ccw and len(simple) <= len(ring)
    n = len(simple)
    for i in range(n):  # strictly convex
        (ax, ay), (bx, by), (cx, cy) = simple[i - 1], simple[i], simple[(i + 1) % n]
        assert (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0
    assert shapely.Polygon(ring).exterior.hausdorff_distance(poly.exterior) <= 2 * tol + 1e-9
    k = shift % len(ring)

    def rounded(points):
        return {(round(x, 9), round(y, 9)) for x, y in points}

    assert rounded(clean_hull(ring[k:] + ring[:k], tol)) == rounded(simple)


# Flattening: feederkit's bounded subdivision gives ezdxf's vertices on real curves, and ends
# (refused in one line) where ezdxf's never returns (docs/import.md, budgets).

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "samples"
SAMPLE_DRAWINGS = sorted(SAMPLES.glob("*.dxf")) + sorted(SAMPLES.glob("*.DXF"))
FIXTURE_DRAWINGS = {
    "plate": fx.write_plate,
    "fit_spline": fx.write_fit_spline,
    "ellipse_hole": fx.write_ellipse_hole,
    "gap_spline": lambda p: fx.write_gap_spline(p, 0.1),
    "gear": fx.write_gear,
    "nested_mirrored": fx.write_nested_mirrored,
}


def drawing_paths(path: Path) -> list:
    from collections import Counter

    from feederkit.importers import dxf
    from feederkit.importers.budget import Budget, ImportLimits

    doc = dxf.read_document(path)
    found = dxf.explode(doc.modelspace(), "", 0, Counter(), Budget(ImportLimits(), str(path)))
    return [p for p in (dxf.curve_path(f.entity, f.matrix) for f in found) if p is not None]


def ezdxf_flattening(paths, distance, budget=None):
    """The reference: ezdxf's own ``Path.flattening`` of each sub-path (x y)."""
    out = []
    for path in paths:
        subs = [[(v.x, v.y) for v in sub.flattening(distance)] for sub in path.sub_paths()]
        out.append([np.array(s, dtype=float) for s in subs if len(s) >= 2])
    return out


@pytest.mark.parametrize("name", list(FIXTURE_DRAWINGS) + [p.name for p in SAMPLE_DRAWINGS])
def test_flattening_gives_ezdxfs_vertices(tmp_path, name):
    from feederkit.importers.dxf import flatten_paths

    if name in FIXTURE_DRAWINGS:
        path = FIXTURE_DRAWINGS[name](tmp_path / f"{name}.dxf")
    else:
        path = SAMPLES / name
    paths = drawing_paths(path)
    assert paths
    for distance in (0.001, 0.01, 0.1):
        ours, theirs = flatten_paths(paths, distance), ezdxf_flattening(paths, distance)
        assert len(ours) == len(theirs) == len(paths)
        for a, b in zip(ours, theirs, strict=True):
            assert [len(x) for x in a] == [len(y) for y in b]
            for x, y in zip(a, b, strict=True):
                np.testing.assert_allclose(x, y, rtol=0, atol=1e-9 * max(1.0, np.abs(y).max()))


@pytest.mark.skipif(not SAMPLE_DRAWINGS, reason=f"{SAMPLES} is absent")
@pytest.mark.parametrize("name", [p.name for p in SAMPLE_DRAWINGS])
def test_sample_hulls_as_with_ezdxfs_flattening(monkeypatch, name):
    from feederkit.importers import dxf

    options = ImportOptions(all_parts=True)
    _, ours = import_parts(SAMPLES / name, options)
    monkeypatch.setattr(dxf, "flatten_paths", ezdxf_flattening)
    _, theirs = import_parts(SAMPLES / name, options)
    assert len(ours) == len(theirs) >= 1
    for a, b in zip(ours, theirs, strict=True):
        ha, hb = np.array(a.part.hull), np.array(b.part.hull)
        size = float(np.ptp(hb, axis=0).max())
        assert ha.shape == hb.shape
        np.testing.assert_allclose(ha, hb, rtol=0, atol=1e-6 * size)


def test_flattening_stays_within_the_tolerance_of_the_true_curve():
    from feederkit.importers.flatten import bezier_points, cubic_flattening

    rng = np.random.default_rng(3)
    cp = rng.uniform(-50, 50, size=(40, 4, 2))
    piece, pts = cubic_flattening(cp, 0.01)
    for k in range(len(cp)):
        ring = np.vstack([cp[k, :1], pts[piece == k]])
        np.testing.assert_array_equal(ring[-1], cp[k, 3])  # ends on the last control point
        t = np.linspace(0, 1, 2001)
        curve = bezier_points(np.repeat(cp[k : k + 1], len(t), axis=0), t)
        gap = shapely.LineString(ring).hausdorff_distance(shapely.LineString(curve))
        assert gap < 0.05  # the midpoint test bounds the chord error to a few tolerances


def test_non_finite_curve_points_name_their_piece():
    from feederkit.importers.flatten import NonFiniteCurve, cubic_flattening

    cp = np.zeros((3, 4, 2))
    cp[:, :, 0] = [0, 1, 2, 3]
    cp[2, 1, 1] = np.nan
    with pytest.raises(NonFiniteCurve) as info:
        cubic_flattening(cp, 0.01)
    assert info.value.piece == 2


def test_flattening_stops_halving_at_the_level_cap(monkeypatch):
    from feederkit.importers import flatten

    monkeypatch.setattr(flatten, "MAX_LEVELS", 3)
    cp = np.array([[[0.0, 0.0], [3.0, 5.0], [6.0, -5.0], [9.0, 0.0]]])
    _, pts = flatten.cubic_flattening(cp, 1e-300)
    assert len(pts) == flatten.MIN_SEGMENTS * 2**3  # every segment halved 3 times, no more


def test_an_unreachable_tolerance_is_refused_by_the_vertex_budget():
    from feederkit.importers.budget import Budget, ImportLimits
    from feederkit.importers.flatten import cubic_flattening

    cp = np.array([[[1e6, 0.0], [1e6 + 3.0, 5.0], [1e6 + 6.0, -5.0], [1e6 + 9.0, 0.0]]])
    start = time.monotonic()
    with pytest.raises(InputError, match=r"more than 10,000 vertices after flattening"):
        cubic_flattening(cp, 1e-300, Budget(ImportLimits(vertices=10_000), "x.dxf"))
    assert time.monotonic() - start < 0.5
    with pytest.raises(InputError, match=r"the curve: more than 1,000,000 vertices"):
        cubic_flattening(cp, 1e-300)  # the default budget, not all the memory there is


def test_flattening_counts_vertices_against_the_budget():
    from feederkit.importers.budget import Budget, ImportLimits
    from feederkit.importers.flatten import cubic_flattening

    circle_ish = np.array([[[0.0, 0.0], [0.0, 100.0], [100.0, 100.0], [100.0, 0.0]]])
    with pytest.raises(InputError, match=r"more than 1,000 vertices after flattening"):
        cubic_flattening(circle_ish, 1e-6, Budget(ImportLimits(vertices=1000), "x.dxf"))
    budget = Budget(ImportLimits(), "x.dxf")
    _, pts = cubic_flattening(circle_ish, 1e-3, budget)
    assert budget.counts["vertices"] == len(pts)


@pytest.mark.parametrize("kind", fx.HOSTILE_CURVES)
@pytest.mark.parametrize("value", ["inf", "nan", "-inf"])
def test_curves_with_a_non_finite_number_are_refused_quickly(tmp_path, kind, value):
    # arc_z inf is fuzz seed 2, input 73: it sent ezdxf's flattening into 2**1000 calls
    path = fx.write_hostile_curve(tmp_path / "curve.dxf", kind, value)
    start = time.monotonic()
    words = r"[A-Z]+ \w+ has a NaN or infinite value \((center|control points|knots|ratio|points)\)"
    with pytest.raises(InputError, match=words) as info:
        import_parts(path, ImportOptions())
    assert time.monotonic() - start < 2.0
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("kind", fx.HOSTILE_CURVES)
def test_the_same_curves_with_a_plain_number_import(tmp_path, kind):
    path = fx.write_hostile_curve(tmp_path / "curve.dxf", kind, "0.5")
    shell = shapely.Polygon(one(path).part.outline.vertices)
    assert shell.area == pytest.approx(6000.0, rel=1e-6)  # the rectangle is the part


def test_a_z_of_1e20_is_beyond_any_part(tmp_path):
    path = fx.write_hostile_curve(tmp_path / "curve.dxf", "spline_z", "1e20")
    with pytest.raises(InputError, match=r"SPLINE \w+ has a coordinate of 1e\+20 mm, beyond any"):
        import_parts(path, ImportOptions())


def test_flattening_checks_the_deadline_at_every_level():
    from feederkit.importers.budget import Budget, ImportLimits
    from feederkit.importers.flatten import cubic_flattening

    budget = Budget(ImportLimits(seconds=1e-9), "x.dxf")
    time.sleep(0.001)
    cp = np.array([[[0.0, 0.0], [0.0, 100.0], [100.0, 100.0], [100.0, 0.0]]])
    with pytest.raises(InputError, match=r"x.dxf: the import took longer than 1e-09 s"):
        cubic_flattening(cp, 0.01, budget)
