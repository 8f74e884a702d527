"""Drawings CAD shows otherwise than their raw entities (docs/import.md, "Planes and
hidden layers"): a part drawn in a plane not parallel to XY, and entities CAD does not
show (on a frozen or off layer, or invisible).

A part in a plane tilted 50 degrees came in as its top view, 36 % short, without a word, and
one in the XZ plane was refused as "all geometry lies on a line"; a circle on a frozen layer
or with the invisible flag came in as a hole, and a stock rectangle on a frozen or off layer
as the part. Each drawing is built here with ezdxf and checked against shapely's figures.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import pytest
from ezdxf.math import OCS, Vec3
from shapely.geometry import Point, Polygon

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts

PLATE = [(0, 0), (80, 0), (80, 40), (30, 40), (30, 25), (0, 25)]
HOLE_AT, HOLE_R = (60.0, 20.0), 6.0
TRUTH = Polygon(PLATE).difference(Point(HOLE_AT).buffer(HOLE_R, quad_segs=1024))
STOCK = [(-5, -5), (85, -5), (85, 45), (-5, 45)]


def _new():
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    return doc, doc.modelspace()


def _save(doc, path: Path) -> Path:
    doc.saveas(path)
    return path


def _plate(msp, layer: str = "0") -> None:
    msp.add_lwpolyline(PLATE, close=True, dxfattribs={"layer": layer})
    msp.add_circle(HOLE_AT, HOLE_R, dxfattribs={"layer": layer})


def _one(path: Path, **options):
    (ip,) = import_parts(path, ImportOptions(**options))[1]
    return ip


def _is_the_plate(ip) -> None:
    assert len(ip.part.outline.holes) == 1
    assert ip.part.outline.polygon().area == pytest.approx(TRUTH.area, rel=2e-4)
    assert ip.part.com == pytest.approx((TRUTH.centroid.x, TRUTH.centroid.y), abs=2e-3)


# ---- planes ---------------------------------------------------------------------------------


def _tilted(path: Path, degrees: float, lines: bool) -> Path:
    """The plate in the plane tilted ``degrees`` about the x axis (its y axis turned up):
    as a closed LWPOLYLINE and a CIRCLE in that plane's OCS, or as LINEs whose z varies
    with y (and the CIRCLE)."""
    a = math.radians(degrees)
    normal = Vec3(0, -math.sin(a), math.cos(a))
    ocs = OCS(normal)

    def world(x: float, y: float) -> Vec3:
        return Vec3(x, y * math.cos(a), y * math.sin(a))

    doc, msp = _new()
    if lines:
        for p, q in zip(PLATE, PLATE[1:] + PLATE[:1], strict=True):
            msp.add_line(world(*p), world(*q))
    else:
        pts = [ocs.from_wcs(world(*p)) for p in PLATE]
        attribs = {"extrusion": normal, "elevation": pts[0].z}
        msp.add_lwpolyline([(p.x, p.y) for p in pts], close=True, dxfattribs=attribs)
    msp.add_circle(ocs.from_wcs(world(*HOLE_AT)), HOLE_R, dxfattribs={"extrusion": normal})
    return _save(doc, path)


@pytest.mark.parametrize("lines", [False, True], ids=["ocs", "lines"])
@pytest.mark.parametrize("degrees", [50.0, 10.0])
def test_a_part_in_a_tilted_plane_is_imported_true_to_shape(tmp_path, degrees, lines):
    ip = _one(_tilted(tmp_path / "tilted.dxf", degrees, lines))
    _is_the_plate(ip)  # turned about x: the plane's frame is the plate's own
    (note,) = [w for w in ip.warnings if "the drawing lies in" in w]
    assert f"a plane tilted {degrees:g} degrees to the XY plane" in note
    assert "true to shape" in note


def _vertical(path: Path, axis: str) -> Path:
    """The plate in the XZ plane (LINEs at y = 0, x along x and y along z) or the YZ plane
    (x = 5, x along y), the hole a CIRCLE in that plane's OCS."""

    def world(x: float, y: float) -> Vec3:
        return Vec3(x, 0, y) if axis == "y" else Vec3(5, x, y)

    normal = Vec3(0, -1, 0) if axis == "y" else Vec3(1, 0, 0)
    doc, msp = _new()
    for p, q in zip(PLATE, PLATE[1:] + PLATE[:1], strict=True):
        msp.add_line(world(*p), world(*q))
    centre = OCS(normal).from_wcs(world(*HOLE_AT))
    msp.add_circle(centre, HOLE_R, dxfattribs={"extrusion": normal})
    return _save(doc, path)


@pytest.mark.parametrize(("axis", "plane"), [("y", "the XZ plane (y = 0 mm)"), ("x", "YZ")])
def test_a_part_in_a_vertical_plane_is_imported_not_refused_as_a_line(tmp_path, axis, plane):
    ip = _one(_vertical(tmp_path / "vertical.dxf", axis))
    assert len(ip.part.outline.holes) == 1
    assert ip.part.outline.polygon().area == pytest.approx(TRUTH.area, rel=2e-4)
    (note,) = [w for w in ip.warnings if "the drawing lies in" in w]
    assert plane in note and "turned 90 degrees" in note and "top view is a line" in note


def test_a_flat_drawing_with_short_steps_out_of_its_plane_is_read_as_drawn(tmp_path):
    # A 100 x 60 plate of LINEs in XY with 0.013 mm vertical LINEs at its corners: the top
    # view shortens those by more than the flatten tolerance, but the plane that fits is
    # horizontal; it was "turned" about a zero axis (every coordinate NaN, exit 70).
    doc, msp = _new()
    corners = [(0, 0), (100, 0), (100, 60), (0, 60)]
    for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
        msp.add_line((*a, 0), (*b, 0))
    for x, y in corners:
        msp.add_line((x, y, 0), (x, y, 0.013))
    result, (ip,) = import_parts(_save(doc, tmp_path / "steps.dxf"), ImportOptions())
    assert ip.part.outline.polygon().area == pytest.approx(6000.0, rel=1e-9)
    assert not any("plane" in w for w in result.warnings)


def test_geometry_in_no_one_plane_is_refused_naming_the_entity_off_it(tmp_path):
    doc, msp = _new()
    _plate(msp)
    line = msp.add_line((0, -10, 0), (80, -10, 40))  # a stray 3D line below the plate
    with pytest.raises(InputError, match="lies in no one plane") as info:
        import_parts(_save(doc, tmp_path / "3d.dxf"), ImportOptions())
    assert f"LINE {line.dxf.handle}" in str(info.value)
    assert "\n" not in str(info.value)


def test_entities_mirrored_by_a_minus_z_extrusion_stay_as_drawn(tmp_path):
    """The common mirrored OCS: x runs the other way, the plane is still XY."""
    ocs = OCS((0, 0, -1))
    doc, msp = _new()
    pts = [ocs.from_wcs(Vec3(x, y, 0)) for x, y in PLATE]
    minus_z = {"extrusion": (0, 0, -1)}
    msp.add_lwpolyline([(p.x, p.y) for p in pts], close=True, dxfattribs=minus_z)
    msp.add_circle(ocs.from_wcs(Vec3(*HOLE_AT, 0)), HOLE_R, dxfattribs=minus_z)
    ip = _one(_save(doc, tmp_path / "mirrored.dxf"))
    _is_the_plate(ip)
    assert not any("plane" in w for w in ip.warnings)


def test_a_wireframe_in_planes_parallel_to_xy_is_read_in_its_top_view(tmp_path):
    """Top and bottom faces 5 mm apart, the corners joined by vertical LINEs, the hole at
    the top face's height: every line is parallel to XY or seen end-on."""
    doc, msp = _new()
    _plate(msp)
    msp.add_lwpolyline(PLATE, close=True, dxfattribs={"elevation": 5.0})
    for x, y in PLATE:
        msp.add_line((x, y, 0), (x, y, 5))
    msp.add_circle((*HOLE_AT, 5.0), HOLE_R)
    ip = _one(_save(doc, tmp_path / "wireframe.dxf"))
    _is_the_plate(ip)
    assert not any("plane" in w for w in ip.warnings)


# ---- frozen and off layers, invisible entities ------------------------------------------------


def _with_layer(state: str, name: str):
    doc, msp = _new()
    layer = doc.layers.add(name)
    {"frozen": layer.freeze, "off": layer.off}[state]()
    return doc, msp


@pytest.mark.parametrize("state", ["frozen", "off"])
def test_a_hole_on_a_hidden_layer_is_left_out_with_a_warning(tmp_path, state):
    doc, msp = _with_layer(state, "CONSTR2")
    _plate(msp)
    msp.add_circle((15, 12), 5, dxfattribs={"layer": "CONSTR2"})
    ip = _one(_save(doc, tmp_path / "hidden.dxf"))
    _is_the_plate(ip)
    (note,) = [w for w in ip.warnings if "CAD does not show" in w]
    assert f"left out 1 entity CAD does not show: 1 on {state} layer 'CONSTR2'" in note
    assert "--layer CONSTR2" in note


@pytest.mark.parametrize("state", ["frozen", "off"])
def test_a_stock_rectangle_on_a_hidden_layer_is_not_the_part(tmp_path, state):
    doc, msp = _with_layer(state, "STOCK")
    _plate(msp)
    msp.add_lwpolyline(STOCK, close=True, dxfattribs={"layer": "STOCK"})
    ip = _one(_save(doc, tmp_path / "stock.dxf"))
    _is_the_plate(ip)
    assert any(f"1 on {state} layer 'STOCK'" in w for w in ip.warnings)


def test_an_invisible_circle_is_left_out_and_named(tmp_path):
    doc, msp = _new()
    _plate(msp)
    circle = msp.add_circle((15, 12), 5, dxfattribs={"invisible": 1})
    ip = _one(_save(doc, tmp_path / "invisible.dxf"))
    _is_the_plate(ip)
    (note,) = [w for w in ip.warnings if "CAD does not show" in w]
    assert f"CIRCLE {circle.dxf.handle} on layer '0', invisible" in note


def _block_of_holes(doc) -> None:
    """Block ``HOLES``: an R3 circle on layer 0 (drawn on the reference's layer) at
    (15, 12) and an R2 circle on layer ``OWN`` at (8, 6), both inside the plate."""
    block = doc.blocks.new("HOLES")
    block.add_circle((15, 12), 3)
    block.add_circle((8, 6), 2, dxfattribs={"layer": "OWN"})


def _referenced_on(state: str, tmp_path: Path):
    """The plate with block ``HOLES`` referenced on a layer ``REF`` in ``state``, imported."""
    doc, msp = _with_layer(state, "REF")
    doc.layers.add("OWN")
    _block_of_holes(doc)
    _plate(msp)
    msp.add_blockref("HOLES", (0, 0), dxfattribs={"layer": "REF"})
    return _one(_save(doc, tmp_path / f"{state}_ref.dxf"))


def test_a_block_reference_on_a_frozen_layer_hides_its_whole_block(tmp_path):
    ip = _referenced_on("frozen", tmp_path)
    _is_the_plate(ip)
    assert any(
        "left out 2 entities CAD does not show: 2 on frozen layer 'REF'" in w for w in ip.warnings
    )


def test_a_block_reference_on_an_off_layer_hides_only_its_layer_0_entities(tmp_path):
    ip = _referenced_on("off", tmp_path)
    want = TRUTH.difference(Point(8, 6).buffer(2, quad_segs=1024))
    assert len(ip.part.outline.holes) == 2
    assert ip.part.outline.polygon().area == pytest.approx(want.area, rel=2e-4)
    assert any(
        "left out 1 entity CAD does not show: 1 on off layer 'REF'" in w for w in ip.warnings
    )


def test_an_invisible_block_reference_hides_its_whole_block(tmp_path):
    doc, msp = _new()
    doc.layers.add("OWN")
    _block_of_holes(doc)
    _plate(msp)
    msp.add_blockref("HOLES", (0, 0), dxfattribs={"invisible": 1})
    ip = _one(_save(doc, tmp_path / "invisible_ref.dxf"))
    _is_the_plate(ip)
    assert any("left out 2 entities CAD does not show" in w for w in ip.warnings)


def test_a_hidden_layer_named_with_layer_is_read(tmp_path):
    doc, msp = _with_layer("frozen", "PART")
    _plate(msp, layer="PART")
    ip = _one(_save(doc, tmp_path / "named.dxf"), layers=("part",))
    _is_the_plate(ip)
    assert not any("CAD does not show" in w for w in ip.warnings)


def test_a_drawing_with_nothing_shown_is_refused_naming_the_layer(tmp_path):
    doc, msp = _with_layer("frozen", "PART")
    _plate(msp, layer="PART")
    with pytest.raises(InputError, match="shows no outline geometry") as info:
        import_parts(_save(doc, tmp_path / "all_frozen.dxf"), ImportOptions())
    assert "2 on frozen layer 'PART'" in str(info.value)
    assert "--layer PART" in str(info.value)
    assert "\n" not in str(info.value)


def test_a_refusal_of_what_is_shown_names_what_was_left_out(tmp_path):
    doc, msp = _with_layer("off", "PART")
    _plate(msp, layer="PART")
    msp.add_line((-5, 12), (85, 12))  # a centre line left on a layer that is on
    with pytest.raises(InputError, match="left out as not shown in CAD: 2 on off layer 'PART'"):
        import_parts(_save(doc, tmp_path / "all_off.dxf"), ImportOptions())
