"""Importer defects of review 56 (docs/import.md): nested references under a non-uniform
scale, fit-point splines in scaled blocks, hidden-line loops, counterbores, and messages.

Each drawing is built here with ezdxf and its part compared with the one shapely draws.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import path as dxfpath
from shapely import affinity
from shapely.geometry import Point, Polygon
from shared import run_cli

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts

L_BRACKET = [(0, 0), (60, 0), (60, 15), (15, 15), (15, 40), (0, 40)]


def new_doc() -> ezdxf.document.Drawing:
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    return doc


def imported(path: Path, **options):
    """The first part of ``path`` and its warnings (the file's included)."""
    _, parts = import_parts(path, ImportOptions(**options))
    return parts[0], parts[0].warnings


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


# Loops drawn in hidden, dashed or centre linetypes are no through holes.

PLATE_PTS = [(0, 0), (80, 0), (80, 40), (0, 40)]
PLATE_WITH_HOLE = Polygon(PLATE_PTS).difference(Point(60, 20).buffer(4, 512))


def plate_with(path: Path, build) -> Path:
    """An 80 x 40 plate with an R4 through hole at (60, 20), and what ``build`` adds."""
    doc = new_doc()
    doc.layers.add("HIDDEN", linetype="HIDDEN")
    doc.layers.add("CENTER", linetype="CENTER")
    msp = doc.modelspace()
    msp.add_lwpolyline(PLATE_PTS, close=True)
    msp.add_circle((60, 20), 4)
    build(doc, msp)
    doc.saveas(path)
    return path


def _hidden_layer(doc, msp):
    return msp.add_circle((20, 20), 12, dxfattribs={"layer": "HIDDEN"})


def _dashed_entity(doc, msp):
    return msp.add_circle((20, 20), 12, dxfattribs={"linetype": "DASHEDX2"})


def _iso_dashed(doc, msp):
    doc.linetypes.add("ACAD_ISO02W100", pattern=[15.0, 12.0, -3.0], description="ISO dash")
    return msp.add_circle((20, 20), 12, dxfattribs={"linetype": "ACAD_ISO02W100"})


def _hidden_rectangle_of_lines(doc, msp):
    corners = [(10, 10), (35, 10), (35, 30), (10, 30)]
    lines = [
        msp.add_line(a, b, dxfattribs={"layer": "HIDDEN", "linetype": "HIDDEN2"})
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
    ]
    return lines[0]


def _byblock_in_a_block(doc, msp):
    block = doc.blocks.new("POCKET")
    circle = block.add_circle((0, 0), 12, dxfattribs={"linetype": "BYBLOCK"})
    msp.add_blockref("POCKET", (20, 20), dxfattribs={"linetype": "PHANTOM"})
    return circle


def _bylayer_in_a_block_on_a_hidden_layer(doc, msp):
    block = doc.blocks.new("POCKET")
    circle = block.add_circle((0, 0), 12)  # layer "0", ByLayer: the reference's layer
    msp.add_blockref("POCKET", (20, 20), dxfattribs={"layer": "HIDDEN"})
    return circle


@pytest.mark.parametrize(
    ("build", "linetype"),
    [
        (_hidden_layer, "HIDDEN"),
        (_dashed_entity, "DASHEDX2"),
        (_iso_dashed, "ACAD_ISO02W100"),
        (_hidden_rectangle_of_lines, "HIDDEN2"),
        (_byblock_in_a_block, "PHANTOM"),
        (_bylayer_in_a_block_on_a_hidden_layer, "HIDDEN"),
    ],
    ids=["layer", "entity", "iso", "lines", "byblock", "block-on-hidden-layer"],
)
def test_hidden_loops_are_left_out_with_a_warning(tmp_path, build, linetype):
    drawn = []
    path = plate_with(tmp_path / "hidden.dxf", lambda d, m: drawn.append(build(d, m)))
    ip, warnings = imported(path)
    assert_same_part(ip, PLATE_WITH_HOLE)
    (note,) = [w for w in warnings if "hidden, dashed or centre linetype" in w]
    entity = drawn[0]
    assert f"{entity.dxftype()} {entity.dxf.handle}" in note
    assert f"(linetype {linetype})" in note
    assert f"--keep-linetype {linetype}" in note


def test_keep_linetype_keeps_a_hidden_loop_as_a_hole(tmp_path):
    path = plate_with(tmp_path / "hidden.dxf", _hidden_layer)
    ip, warnings = imported(path, keep_linetypes=("hidden",))
    assert_same_part(ip, PLATE_WITH_HOLE.difference(Point(20, 20).buffer(12, 512)))
    assert not [w for w in warnings if "linetype" in w]


def test_centre_lines_and_continuous_loops_are_read_as_before(tmp_path):
    def centre_lines(doc, msp):
        msp.add_line((-5, 20), (85, 20), dxfattribs={"layer": "CENTER"})
        msp.add_circle((20, 20), 5, dxfattribs={"linetype": "Continuous", "layer": "HIDDEN"})

    ip, warnings = imported(plate_with(tmp_path / "cl.dxf", centre_lines))
    assert_same_part(ip, PLATE_WITH_HOLE.difference(Point(20, 20).buffer(5, 512)))
    assert not [w for w in warnings if "linetype" in w]


def test_a_drawing_all_in_hidden_lines_is_refused_naming_the_option(tmp_path):
    doc = new_doc()
    doc.modelspace().add_lwpolyline(PLATE_PTS, close=True, dxfattribs={"linetype": "DASHED"})
    doc.saveas(tmp_path / "all.dxf")
    with pytest.raises(InputError, match=r"hidden, dashed or centre .*--keep-linetype DASHED"):
        imported(tmp_path / "all.dxf")
    ip, _ = imported(tmp_path / "all.dxf", keep_linetypes=("DASHED",))
    assert_same_part(ip, Polygon(PLATE_PTS))


def test_keep_linetype_on_the_command_line(tmp_path, capsys):
    path = plate_with(tmp_path / "hidden.dxf", _hidden_layer)
    for args, expected in (
        ((), PLATE_WITH_HOLE),
        (("--keep-linetype", "HIDDEN"), PLATE_WITH_HOLE.difference(Point(20, 20).buffer(12, 512))),
    ):
        code, out, err = run_cli(capsys, "part", "analyze", str(path), "--json", *args)
        assert code == 0
        assert ("--keep-linetype HIDDEN" in err) == (not args)
        com = json.loads(out)[0]["com"]
        assert np.hypot(com[0] - expected.centroid.x, com[1] - expected.centroid.y) <= 0.02


# A hole drawn as concentric loops is a counterbore (or a construction circle) around the
# through hole, not a part cut from the hole.


def _circles(*radii: float, layer: str = "0"):
    def build(doc, msp):
        for r in radii:
            msp.add_circle((20, 20), r, dxfattribs={"layer": layer})

    return build


def _slot(msp, r: float) -> None:
    """A slot from (15, 20) to (25, 20) drawn as a closed polyline with two bulges."""
    msp.add_lwpolyline(
        [
            (15, 20 - r, 0, 0, 0),
            (25, 20 - r, 0, 0, 1),
            (25, 20 + r, 0, 0, 0),
            (15, 20 + r, 0, 0, 1),
        ],
        format="xyseb",
        close=True,
    )


@pytest.mark.parametrize(
    ("build", "through", "outer"),
    [
        (_circles(4, 7), 4, 7),
        (_circles(4, 10, layer="CENTER_LINES"), 4, 10),  # a construction circle, Continuous
        (_circles(4, 7, 10), 4, 10),
    ],
    ids=["counterbore", "construction-circle", "two-steps"],
)
def test_concentric_circles_make_the_inner_one_the_through_hole(tmp_path, build, through, outer):
    ip, warnings = imported(plate_with(tmp_path / "cb.dxf", build))
    expected = PLATE_WITH_HOLE.difference(Point(20, 20).buffer(through, 512))
    assert_same_part(ip, expected)
    (note,) = [w for w in warnings if "concentric loops" in w]
    assert "counterbore" in note and "innermost loop" in note
    assert f"{2 * outer:g} mm across" in note and f"{2 * through:g} mm across" in note
    assert "linetype Continuous" in note and "on layer '" in note
    cut = PLATE_WITH_HOLE.difference(Point(20, 20).buffer(outer, 512)).centroid
    assert f"({cut.x:.2f}, {cut.y:.2f})" in note
    assert not [w for w in warnings if "cut sheet" in w or "separate parts" in w]


def test_a_counterbored_slot_is_a_slot_through(tmp_path):
    def build(doc, msp):
        _slot(msp, 3)
        _slot(msp, 6)

    ip, warnings = imported(plate_with(tmp_path / "slot.dxf", build))
    slot = Point(15, 20).buffer(3, 512).union(Point(25, 20).buffer(3, 512))
    slot = slot.union(Polygon([(15, 17), (25, 17), (25, 23), (15, 23)]))
    assert_same_part(ip, PLATE_WITH_HOLE.difference(slot))
    assert [w for w in warnings if "concentric loops" in w]


def test_a_square_part_in_a_round_hole_is_still_a_cut_sheet(tmp_path):
    def build(doc, msp):
        msp.add_circle((20, 20), 12)
        msp.add_lwpolyline([(15, 15), (25, 15), (25, 25), (15, 25)], close=True)

    ip, warnings = imported(plate_with(tmp_path / "sheet.dxf", build))
    assert_same_part(ip, PLATE_WITH_HOLE.difference(Point(20, 20).buffer(12, 512)))
    assert [w for w in warnings if "cut sheet" in w]
    assert not [w for w in warnings if "concentric" in w]


# Messages: the loop named is the likeliest construction geometry, in words, with the file.


def flange(path: Path, bore: bool, centre_lines: bool, layer: str = "0") -> Path:
    """A disc R30 with four R3 bolt holes on an R20 circle drawn on ``layer`` (Continuous)."""
    doc = new_doc()
    msp = doc.modelspace()
    msp.add_circle((0, 0), 30)
    if bore:
        msp.add_circle((0, 0), 8)
    for x, y in ((20, 0), (0, 20), (-20, 0), (0, -20)):
        msp.add_circle((x, y), 3)
    msp.add_circle((0, 0), 20, dxfattribs={"layer": layer})
    if centre_lines:
        msp.add_line((-35, 0), (35, 0))
        msp.add_line((0, -35), (0, 35))
    doc.saveas(path)
    return path


def bolt_circle(path: Path) -> str:
    doc = ezdxf.readfile(path)
    (circle,) = [e for e in doc.modelspace() if e.dxftype() == "CIRCLE" and e.dxf.radius == 20]
    return f"CIRCLE {circle.dxf.handle}"


@pytest.mark.parametrize("centre_lines", [False, True])
def test_the_bolt_circle_is_named_as_crossing_the_bolt_holes(tmp_path, centre_lines):
    path = flange(tmp_path / "flange.dxf", False, centre_lines, layer="CENTER")
    with pytest.raises(InputError) as err:
        imported(path)
    message = str(err.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    assert f"{bolt_circle(path)} on layer 'CENTER'" in message
    assert "crosses 4 other loops" in message and "--layer" in message
    assert "Self-intersection" not in message


def test_crossing_loops_left_after_centre_lines_are_named_in_words(tmp_path):
    path = flange(tmp_path / "flange.dxf", False, True)
    with pytest.raises(InputError) as err:
        imported(path)
    message = str(err.value)
    assert f"{bolt_circle(path)} on layer '0', linetype Continuous crosses 4 other loops" in (
        message
    )
    assert "Self-intersection" not in message and "near (" in message


def test_an_outline_drawn_twice_slightly_shifted_is_named(tmp_path):
    doc = new_doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(L_BRACKET, close=True)
    msp.add_lwpolyline([(x + 0.03, y) for x, y in L_BRACKET], close=True)
    msp.add_circle((47, 7.5), 3.5)
    doc.saveas(tmp_path / "twice.dxf")
    with pytest.raises(InputError, match=r"the outline seems drawn twice, 0\.03 mm apart"):
        imported(tmp_path / "twice.dxf")


HOLE = [[2, 2], [4, 2], [4, 4]]
BIG = [[2, 2], [20, 2], [20, 20]]


@pytest.mark.parametrize(
    ("vertices", "holes", "words"),
    [
        ([[0, 0], [10, 0], [0, 10], [10, 10]], [], "crosses itself near (5, 5)"),
        (PLATE_PTS, [HOLE, HOLE], "hole 1 is listed twice"),
        (PLATE_PTS, [[[5, 5], [95, 5], [95, 8]]], "hole 0 crosses the outline near (80, "),
        (PLATE_PTS, [[[90, 5], [95, 5], [95, 8]]], "hole 0 lies outside the outline"),
        (PLATE_PTS, [[[2, 2], [9, 2], [9, 9]], [[5, 1], [8, 1], [8, 8]]], "holes 0 and 1 overlap"),
        (PLATE_PTS, [BIG, [[9, 4], [12, 4], [12, 7]]], "hole 1 lies inside hole 0"),
    ],
)
def test_outline_file_faults_in_words_naming_the_file(tmp_path, vertices, holes, words):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"name": "x", "vertices": vertices, "holes": holes}))
    with pytest.raises(InputError) as err:
        imported(path)
    message = str(err.value)
    assert message.startswith(f"{path}: x: ") and words in message
    assert "Self-intersection" not in message and "[" not in message


def test_a_com_outside_the_hull_names_the_file(tmp_path):
    path = tmp_path / "com.json"
    path.write_text(json.dumps({"name": "x", "vertices": PLATE_PTS, "com": [200, 5]}))
    with pytest.raises(
        InputError, match=rf"^{path}: x: the center of mass \(200, 5\) lies outside"
    ):
        imported(path)


def test_a_bolt_circle_around_a_bore_is_a_construction_circle(tmp_path):
    ip, warnings = imported(flange(tmp_path / "flange.dxf", True, True))
    part = Point(0, 0).buffer(30, 512).difference(Point(0, 0).buffer(8, 512))
    for x, y in ((20, 0), (0, 20), (-20, 0), (0, -20)):
        part = part.difference(Point(x, y).buffer(3, 256))
    assert_same_part(ip, part)
    (note,) = [w for w in warnings if "concentric loops" in w]
    assert "crossing other holes" in note and "construction circle" in note


@pytest.mark.parametrize(
    "linetype",
    ["CENTER", "HIDDEN"],
)
@pytest.mark.parametrize("x", [15.0, 20.0, 60.0])
def test_an_open_centre_or_hidden_line_across_a_plate_never_cuts_it(tmp_path, linetype, x):
    # A centre line through a hole, or a pocket's hidden step, across the plate: left to the
    # loop search it cut off a strip, the plate became a "drawing frame" and a hole the part.
    def line(doc, msp):
        msp.add_line((x, -5), (x, 45), dxfattribs={"layer": linetype})

    ip, warnings = imported(plate_with(tmp_path / "line.dxf", line))
    assert_same_part(ip, PLATE_WITH_HOLE)
    assert not [w for w in warnings if "frame" in w or "linetype" in w]


def test_a_bolt_circle_across_its_holes_is_named_as_loops_crossing_inside(tmp_path):
    # A flange: disc, bore and four bolt holes on layer 0, the bolt circle drawn Continuous.
    doc = new_doc()
    msp = doc.modelspace()
    msp.add_circle((0, 0), 30)
    msp.add_circle((0, 0), 8)
    for x, y in ((20, 0), (0, 20), (-20, 0), (0, -20)):
        msp.add_circle((x, y), 3)
    bolt = msp.add_circle((0, 0), 20, dxfattribs={"layer": "CENTER"})
    doc.saveas(tmp_path / "flange.dxf")
    with pytest.raises(InputError) as exc:
        imported(tmp_path / "flange.dxf")
    text = str(exc.value)
    assert "loops cross inside the outline" in text and "crosses the outline" not in text
    assert f"CIRCLE {bolt.dxf.handle} on layer 'CENTER' crosses 4 other loops" in text
    assert "--layer" in text


def test_a_plate_with_rounded_corners_is_never_called_a_drawing_frame(tmp_path):
    # A 100 x 70 plate with R5 corners (bulges), a bore and a circle on another layer around
    # it: a frame has straight sides and square corners; the warning advised --layer CENTER,
    # which imported the circle as the part.
    doc = new_doc()
    msp = doc.modelspace()
    b = math.tan(math.radians(90) / 4)  # a quarter-circle bulge
    pts = [(5, 0, 0), (95, 0, b), (100, 5, 0), (100, 65, b), (95, 70, 0), (5, 70, b),
           (0, 65, 0), (0, 5, b)]  # fmt: skip
    msp.add_lwpolyline(pts, format="xyb", close=True)
    msp.add_circle((50, 35), 8)
    msp.add_circle((50, 35), 25, dxfattribs={"layer": "HOLES"})
    doc.saveas(tmp_path / "rounded.dxf")
    _ip, warnings = imported(tmp_path / "rounded.dxf")
    assert not [w for w in warnings if "drawing frame" in w]
