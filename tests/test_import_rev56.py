"""Importer defects of review 56 (docs/import.md): nested references under a non-uniform
scale, fit-point splines in scaled blocks, hidden-line loops, counterbores, and messages.

Each drawing is built here with ezdxf and its part compared with the one shapely draws.
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import path as dxfpath
from shapely import affinity
from shapely.geometry import Point, Polygon

from feederkit.importers import ImportOptions, import_parts

L_BRACKET = [(0, 0), (60, 0), (60, 15), (15, 15), (15, 40), (0, 40)]


def new_doc() -> ezdxf.document.Drawing:
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    return doc


def imported(path: Path, **options):
    """The first part of ``path`` and the import's warnings (the part's and the file's)."""
    result, parts = import_parts(path, ImportOptions(**options))
    return parts[0], tuple(result.warnings) + tuple(parts[0].warnings)


def polygon(ip) -> Polygon:
    return ip.part.outline.polygon()


def assert_same_part(ip, expected: Polygon, rel_area: float = 1e-3, com: float = 0.02) -> None:
    got = polygon(ip)
    assert got.area == pytest.approx(expected.area, rel=rel_area)
    c = expected.centroid
    assert np.hypot(ip.part.com[0] - c.x, ip.part.com[1] - c.y) <= com
    assert got.convex_hull.hausdorff_distance(expected.convex_hull) <= 0.1
    assert len(ip.part.outline.holes) == len(expected.interiors)


@pytest.mark.parametrize(("rot", "sx", "sy"), [(30, 2, 3), (90, 2, 3), (90, 2, 1), (45, -1.5, 2)])
def test_rotated_block_inside_non_uniformly_scaled_block(tmp_path, rot, sx, sy):
    doc = new_doc()
    inner = doc.blocks.new("IN")
    inner.add_lwpolyline(L_BRACKET, close=True)
    inner.add_circle((47, 7.5), 3.5)
    outer = doc.blocks.new("OUT")
    outer.add_blockref("IN", (10, 0), dxfattribs={"rotation": rot})
    doc.modelspace().add_blockref("OUT", (5, 5), dxfattribs={"xscale": sx, "yscale": sy})
    doc.saveas(tmp_path / "nested.dxf")
    part = Polygon(L_BRACKET).difference(Point(47, 7.5).buffer(3.5, 512))
    world = affinity.rotate(part, rot, origin=(0, 0))
    world = affinity.scale(affinity.translate(world, 10, 0), sx, sy, origin=(0, 0))
    ip, _ = imported(tmp_path / "nested.dxf")
    assert_same_part(ip, affinity.translate(world, 5, 5))


def test_fit_point_spline_in_a_non_uniformly_scaled_block_is_transformed_as_a_curve(tmp_path):
    doc = new_doc()
    block = doc.blocks.new("S")
    fit = [(0, 0), (30, -8), (60, 5), (70, 30), (50, 50), (20, 45), (5, 25), (0, 0)]
    spline = block.add_spline(fit)
    doc.modelspace().add_blockref(
        "S", (20, 10), dxfattribs={"xscale": 1.4, "yscale": 0.6, "rotation": 15}
    )
    doc.saveas(tmp_path / "spline.dxf")
    own = Polygon([(v.x, v.y) for v in dxfpath.make_path(spline).flattening(0.001)])
    world = affinity.scale(own, 1.4, 0.6, origin=(0, 0))
    world = affinity.translate(affinity.rotate(world, 15, origin=(0, 0)), 20, 10)
    ip, _ = imported(tmp_path / "spline.dxf")
    assert_same_part(ip, world, rel_area=5e-4)


def test_minsert_cells_of_a_nested_block_land_in_their_cells(tmp_path):
    doc = new_doc()
    inner = doc.blocks.new("IN")
    inner.add_lwpolyline([(0, 0), (10, 0), (10, 4), (0, 4)], close=True)
    outer = doc.blocks.new("OUT")
    outer.add_blockref("IN", (0, 0), dxfattribs={"rotation": 90})
    ref = doc.modelspace().add_blockref("OUT", (0, 0), dxfattribs={"xscale": 2, "yscale": 3})
    ref.grid(size=(1, 3), spacing=(0, 100))  # 3 columns, 100 mm apart
    doc.saveas(tmp_path / "grid.dxf")
    _, parts = import_parts(tmp_path / "grid.dxf", ImportOptions(all_parts=True))
    boxes = sorted(tuple(round(v, 6) for v in polygon(p).bounds) for p in parts)
    assert boxes == [(-8.0 + 100 * k, 0.0, 100.0 * k, 30.0) for k in range(3)]
