"""Messy drawings of review 52 (docs/import.md, loops): a curve drawn twice, or drawn over
with ARCs, and crossed by a centre line is still a hole.

A CAD duplicate alone or a centre line alone was handled; together, every stretch of the
hole lay on two lines, as a title-block cell's side lies on its frame, and the hole was
merged into the part (``m_e.dxf``: 1837.5 mm2, no hole, COM (25.408, 16.429) for shapely's
1809.23 mm2 and (25.649, 16.529)). Each drawing is built here with ezdxf and checked against
shapely's figures, computed here from the same dimensions.
"""

from __future__ import annotations

from pathlib import Path

import fixtures_cad as fx
import numpy as np
import pytest
from shapely import affinity
from shapely.geometry import Point, Polygon

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts
from feederkit.importers.loops import repeated_lines

L_PLATE = [(0, 0), (60, 0), (60, 15), (15, 40), (0, 40)]
HOLE_AT, HOLE_R = (10.0, 10.0), 3.0


def _outline(msp, twice: tuple[int, ...] = ()) -> None:
    """The L-plate drawn with LINEs; the sides in ``twice`` drawn twice."""
    for k, (a, b) in enumerate(zip(L_PLATE, L_PLATE[1:] + L_PLATE[:1], strict=True)):
        for _ in range(1 + (k in twice)):
            msp.add_line(a, b)


def _centre_line(msp, at: tuple[float, float] = HOLE_AT) -> None:
    """A centre line through the hole, out beyond the plate's left side."""
    msp.add_line((-5, at[1]), (25, at[1]), dxfattribs={"layer": "CENTER"})


def _circle(msp, at: tuple[float, float] = HOLE_AT) -> None:
    msp.add_circle(at, HOLE_R)


def _two_arcs(msp, split: float) -> None:
    msp.add_arc(HOLE_AT, HOLE_R, split, split + 180)
    msp.add_arc(HOLE_AT, HOLE_R, split + 180, split)


def _bulge_circle(msp) -> None:
    """The hole as a closed LWPOLYLINE of two half-circle bulges."""
    (x, y), r = HOLE_AT, HOLE_R
    msp.add_lwpolyline([(x + r, y, 1), (x - r, y, 1)], format="xyb", close=True)


def _ellipse(msp) -> None:
    msp.add_ellipse(HOLE_AT, major_axis=(4, 0), ratio=0.5)


def round_hole(at: tuple[float, float] = HOLE_AT) -> Polygon:
    return Point(at).buffer(HOLE_R, quad_segs=1024)


def elliptic_hole() -> Polygon:
    return affinity.scale(Point(HOLE_AT).buffer(1.0, quad_segs=1024), 4.0, 2.0)


CASES = {  # each draws the part but the centre line (:func:`_drawing` adds it)
    "circle-twice": (lambda m: (_outline(m), _circle(m), _circle(m)), round_hole()),
    "circle-twice-and-outline-lines-twice": (
        lambda m: (_outline(m, twice=(0, 2)), _circle(m), _circle(m)),
        round_hole(),
    ),
    "circle-three-times-two-centre-lines": (
        lambda m: (_outline(m), _circle(m), _circle(m), _circle(m), m.add_line((10, -5), (10, 25))),
        round_hole(),
    ),
    "two-arcs-under-a-circle": (
        lambda m: (_outline(m), _two_arcs(m, 0.0), _circle(m)),
        round_hole(),
    ),
    "two-arcs-split-at-30-deg-under-a-circle": (
        lambda m: (_outline(m), _two_arcs(m, 30.0), _circle(m)),
        round_hole(),
    ),
    "one-arc-under-a-circle": (
        lambda m: (_outline(m), m.add_arc(HOLE_AT, HOLE_R, 20, 100), _circle(m)),
        round_hole(),
    ),
    "circle-over-a-bulge-polyline": (
        lambda m: (_outline(m), _bulge_circle(m), _circle(m)),
        round_hole(),
    ),
    "circle-twice-within-the-tolerance": (
        lambda m: (_outline(m), _circle(m), m.add_circle((10.0003, 10.0), HOLE_R)),
        round_hole(),
    ),
    "ellipse-twice": (lambda m: (_outline(m), _ellipse(m), _ellipse(m)), elliptic_hole()),
    "circle-twice-touching-the-outline": (
        lambda m: (_outline(m), _circle(m, (3.0, 10.0)), _circle(m, (3.0, 10.0))),
        round_hole((3.0, 10.0)),
    ),
}


def _drawing(path: Path, build) -> Path:
    """What ``build`` draws and a centre line through the hole."""
    return fx.write_entities(path, lambda msp: (build(msp), _centre_line(msp)))


def test_the_expected_figures_are_the_reviewers():
    """m_e.dxf's part, by shapely: 1809.23 mm2, COM (25.649, 16.529)."""
    want = Polygon(L_PLATE).difference(round_hole())
    assert want.area == pytest.approx(1809.23, abs=0.01)
    assert (want.centroid.x, want.centroid.y) == pytest.approx((25.649, 16.529), abs=1e-3)


@pytest.mark.parametrize(("build", "hole"), CASES.values(), ids=CASES.keys())
def test_a_repeated_hole_crossed_by_a_centre_line_stays_a_hole(tmp_path, build, hole):
    want = Polygon(L_PLATE).difference(hole)
    path = _drawing(tmp_path / "messy.dxf", build)
    for every in (False, True):
        (ip,) = import_parts(path, ImportOptions(all_parts=every))[1]
        assert len(ip.part.outline.holes) == 1
        assert ip.part.outline.polygon().area == pytest.approx(want.area, rel=2e-4)
        assert ip.part.com == pytest.approx((want.centroid.x, want.centroid.y), abs=2e-3)
        assert not any("merged" in w or "separate parts" in w for w in ip.warnings)


def test_a_hole_drawn_with_arcs_only_and_crossed_is_merged_with_a_warning(tmp_path):
    """No closed curve to keep: the faces the ARCs enclose are merged, and the user is told."""
    path = _drawing(tmp_path / "arcs.dxf", lambda m: (_outline(m), _two_arcs(m, 30.0)))
    (ip,) = import_parts(path, ImportOptions())[1]
    assert not ip.part.outline.holes
    assert sum("merged into the part" in w for w in ip.warnings) == 1


def test_a_repeated_circle_across_the_outline_is_refused_as_one_is(tmp_path):
    def build(msp):
        msp.add_lwpolyline(L_PLATE, close=True)
        _circle(msp, (2.0, 10.0))
        _circle(msp, (2.0, 10.0))

    with pytest.raises(InputError, match="a hole crosses the outline .CIRCLE"):
        import_parts(fx.write_entities(tmp_path / "x.dxf", build), ImportOptions())


def _ring(at: tuple[float, float], r: float, start: float = 0.0, n: int = 64) -> np.ndarray:
    t = np.radians(start) + np.linspace(0.0, 2.0 * np.pi, n + 1)
    return np.column_stack([at[0] + r * np.cos(t), at[1] + r * np.sin(t)])


def test_repeated_lines_are_equal_ones_within_the_tolerance():
    line = np.array([[0.0, 0.0], [60.0, 0.0]])
    lines = [
        line,
        _ring((10, 10), 3),
        line[::-1].copy(),  # 2: the same LINE drawn the other way
        _ring((10, 10), 3, start=45.0),  # 3: the circle from another start
        _ring((10, 10), 3.005),  # 4: within 0.01 of the circle
        _ring((10, 10), 3.05),  # 5: not
        np.array([[0.0, 0.0], [30.0, 0.0]]),  # 6: on the LINE but only half of it
        line + [0.0, 0.02],  # 7: beside it, beyond the tolerance
        line.copy(),  # 8: an exact copy
    ]
    assert repeated_lines(lines, 0.01) == [2, 3, 4, 8]
    assert repeated_lines(lines, 0.0) == [2, 8]  # exact copies only
