"""An outline drawn again just inside itself, an untrimmed corner, a bend line: plates, not
drawing frames or rings (docs/import.md, item 8).

A top view draws a chamfered or deburred edge as a second line just inside the outline; a
fillet drawn over a corner whose lines were not trimmed cuts a sliver off it; a flat pattern
carries bend lines across it. Each once made the importer take the part's window for the
part ("skipped 1 drawing frame"), or a 1 mm ring for it with its hole listed as a cut
sheet's piece. The true area and COM come from shapely here.
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import pytest
from shapely.geometry import Point, Polygon, box

from feederkit.importers import ImportOptions, import_parts

L_PLATE = Polygon([(0, 0), (80, 0), (80, 15), (15, 15), (15, 50), (0, 50)])


def _doc():
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    return doc, doc.modelspace()


def _ring(msp, poly: Polygon) -> None:
    msp.add_lwpolyline(list(poly.exterior.coords)[:-1], close=True)


def _rings(path: Path, *polys: Polygon):
    """A drawing of ``polys`` as closed polylines, imported: the part and every warning."""
    doc, msp = _doc()
    for poly in polys:
        _ring(msp, poly)
    doc.saveas(path)
    return _imported(path)


def _imported(path: Path):
    result, parts = import_parts(path, ImportOptions())
    (ip,) = parts
    return ip, " ".join([*result.warnings, *ip.warnings])


def _truth(ip, plate: Polygon) -> None:
    poly = ip.part.outline.polygon()
    assert poly.area == pytest.approx(plate.area, rel=1e-3)
    com = ip.part.com
    assert com[0] == pytest.approx(plate.centroid.x, abs=0.01)
    assert com[1] == pytest.approx(plate.centroid.y, abs=0.01)


@pytest.mark.parametrize("band", [1.0, 2.0])
def test_an_l_plate_with_its_edge_line_is_the_plate_with_its_hole(tmp_path, band):
    doc, msp = _doc()
    _ring(msp, L_PLATE)
    _ring(msp, L_PLATE.buffer(-band, join_style=2))
    msp.add_circle((7.5, 40), 3)
    path = tmp_path / "l.dxf"
    doc.saveas(path)
    ip, said = _imported(path)
    _truth(ip, L_PLATE.difference(Point(7.5, 40).buffer(3, 256)))
    assert f"drawn again {band:g} mm inside it all along" in said
    assert "cut sheet" not in said and "frame(s)" not in said


def test_a_small_rectangle_with_its_edge_line_is_no_drawing_frame(tmp_path):
    plate, window = box(0, 0, 60, 40), box(35, 22, 50, 30)
    ip, said = _rings(tmp_path / "rect.dxf", plate, box(1, 1, 59, 39), window)
    _truth(ip, plate.difference(window))
    assert "drawn again 1 mm inside" in said and "if the two lines are a drawing frame" in said


def test_a_thin_ring_holding_nothing_stays_a_ring(tmp_path):
    ip, said = _rings(tmp_path / "gasket.dxf", box(0, 0, 60, 40), box(1, 1, 59, 39))
    _truth(ip, box(0, 0, 60, 40).difference(box(1, 1, 59, 39)))
    assert "drawn again" not in said


def test_a_sheet_sized_double_line_frame_is_still_a_frame(tmp_path):
    part = box(100, 80, 150, 130)
    ip, said = _rings(tmp_path / "a4.dxf", box(0, 0, 297, 210), box(10, 10, 287, 200), part)
    _truth(ip, part)
    assert "skipped 1 drawing frame(s)" in said


@pytest.mark.parametrize("kind", ["untrimmed fillet", "bend line"])
def test_one_line_across_a_corner_or_the_plate_makes_no_title_block(tmp_path, kind):
    doc, msp = _doc()
    if kind == "untrimmed fillet":
        w, h = 60.0, 40.0
        msp.add_arc((52, 32), 8, 0, 90)  # drawn over the corner, its lines not trimmed back
    else:
        w, h = 100.0, 60.0
        msp.add_line((80, 0), (80, 60))  # a Continuous bend line across the flat pattern
    for a, b in (((0, 0), (w, 0)), ((w, 0), (w, h)), ((w, h), (0, h)), ((0, h), (0, 0))):
        msp.add_line(a, b)
    window = box(10, 10, 30, 22)
    _ring(msp, window)
    path = tmp_path / "plate.dxf"
    doc.saveas(path)
    ip, said = _imported(path)
    _truth(ip, box(0, 0, w, h).difference(window))
    assert "frame(s)" not in said and "cuts off 1 region" in said
