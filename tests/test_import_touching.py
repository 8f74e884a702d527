"""Importer defects of review 50 (docs/import.md): a hole touching the outline, a bare
single-line frame, a sliver loop made by closing a gap, and a damaged file.

Each drawing is built here with ezdxf; each must import the right part or say why it may not.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import pytest

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts

PLATE = 40.0 * 20.0


def parts(path: Path, **options):
    return import_parts(path, ImportOptions(**options))[1]


def area(ip) -> float:
    return float(ip.part.outline.polygon().area)


def plate(path: Path, build, layer: str = "0") -> Path:
    """A 40 x 20 mm plate centred on the origin, with what ``build(doc, msp)`` adds."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline(
        [(-20, -10), (20, -10), (20, 10), (-20, 10)], close=True, dxfattribs={"layer": layer}
    )
    build(doc, msp)
    doc.saveas(path)
    return path


def _circle(doc, msp):
    msp.add_circle((0, 6), 4)  # touches the top side at (0, 10)


def _ellipse(doc, msp):
    msp.add_ellipse((10, 0), major_axis=(10, 0), ratio=0.5)  # touches the right side


def _scaled_block(doc, msp):
    block = doc.blocks.new("HOLE")
    block.add_circle((0, 0), 5)
    msp.add_blockref("HOLE", (10, 0), dxfattribs={"xscale": 2, "yscale": 1})  # as the ellipse


def _crossed(doc, msp):
    msp.add_circle((0, 0), 4)
    msp.add_line((-25, 0), (25, 0))  # centre lines across the part and the hole
    msp.add_line((0, -15), (0, 15))


# ---- 1. a hole touching the outline is a hole ----------------------------------------------


@pytest.mark.parametrize(
    ("build", "hole", "com"),
    [
        (_circle, math.pi * 16, (0.0, -6 * math.pi * 16 / (PLATE - math.pi * 16))),
        (_ellipse, math.pi * 50, (-10 * math.pi * 50 / (PLATE - math.pi * 50), 0.0)),
        (_scaled_block, math.pi * 50, (-10 * math.pi * 50 / (PLATE - math.pi * 50), 0.0)),
        (_crossed, math.pi * 16, (0.0, 0.0)),
    ],
    ids=["circle", "ellipse", "scaled-block", "crossed-by-centre-lines"],
)
def test_a_closed_hole_touching_the_outline_stays_a_hole(tmp_path, build, hole, com):
    (ip,) = parts(plate(tmp_path / "p.dxf", build))
    assert len(ip.part.outline.holes) == 1
    assert area(ip) == pytest.approx(PLATE - hole, rel=2e-3)
    assert ip.part.com == pytest.approx(com, abs=5e-3)
    assert not any("frame" in w or "merged" in w for w in ip.warnings)


def test_a_hole_of_lines_touching_the_outline_is_named_when_merged(tmp_path):
    def diamond(doc, msp):  # four LINEs, one corner on the top side
        pts = [(0, 10), (4, 6), (0, 2), (-4, 6)]
        for a, b in zip(pts, pts[1:] + pts[:1], strict=True):
            msp.add_line(a, b)

    (ip,) = parts(plate(tmp_path / "p.dxf", diamond))
    notes = [w for w in ip.warnings if "merged into the part" in w]
    assert len(notes) == 1 and "COM may be off" in notes[0]


def test_a_centre_line_alone_still_does_not_cut_the_part(tmp_path):
    (ip,) = parts(plate(tmp_path / "p.dxf", lambda doc, msp: msp.add_line((-25, 0), (25, 0))))
    assert area(ip) == pytest.approx(PLATE)
    assert not ip.part.outline.holes
    assert not any("merged" in w for w in ip.warnings)


def _drawn(path: Path, build) -> Path:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    build(doc.modelspace())
    doc.saveas(path)
    return path


def _slot(msp):  # 60 x 20 mm: a 40 x 20 rectangle with round ends of radius 10
    pts = [(-20, -10, 0), (20, -10, 1), (20, 10, 0), (-20, 10, 1)]
    msp.add_lwpolyline(pts, format="xyb", close=True)


SLOT = 800 + math.pi * 100


def _less_hole(outer: float, radius: float, at: tuple[float, float]):
    """Area and COM of an outline of area ``outer`` centred on the origin less a round hole
    of ``radius`` centred ``at``: the COM from the moment of the hole."""
    hole = math.pi * radius**2
    return outer - hole, (-hole * at[0] / (outer - hole), -hole * at[1] / (outer - hole))


DISK = 400 * math.pi


@pytest.mark.parametrize(
    ("build", "outer", "radius", "at"),
    [
        (lambda m: (m.add_circle((0, 0), 20), m.add_circle((12, 0), 8)), DISK, 8, (12, 0)),
        (lambda m: (_slot(m), m.add_circle((24, 0), 6)), SLOT, 6, (24, 0)),  # at (30, 0)
        (lambda m: (m.add_circle((0, 0), 20), m.add_circle((0, 12), 8)), DISK, 8, (0, 12)),
        (lambda m: (m.add_circle((0, 0), 20), m.add_circle((0, 1), 19)), DISK, 19, (0, 1)),
        (  # a centre line through the point of contact changes nothing
            lambda m: (
                m.add_circle((0, 0), 20),
                m.add_circle((12, 0), 8),
                m.add_line((-25, 0), (25, 0)),
            ),
            DISK,
            8,
            (12, 0),
        ),
    ],
    ids=["disk", "slot-end-arc", "disk-at-90-deg", "disk-nearly-concentric", "disk-centre-line"],
)
def test_a_circle_tangent_inside_a_curved_outline_is_a_hole(tmp_path, build, outer, radius, at):
    """Both curves flattened, the hole's chords cross the outline's by a sliver (review 51):
    the hole was merged (a disk) or taken for a second part (the slot)."""
    path = _drawn(tmp_path / "t.dxf", build)
    want, com = _less_hole(outer, radius, at)
    for every in (False, True):
        (ip,) = parts(path, all_parts=every)
        assert len(ip.part.outline.holes) == 1
        assert area(ip) == pytest.approx(want, rel=2e-3)
        assert ip.part.com == pytest.approx(com, abs=5e-3)
        assert not any("merged" in w or "separate parts" in w for w in ip.warnings)


@pytest.mark.parametrize(("radius", "degrees"), [(1, 13), (5, 37), (15, 90), (19, 101.3)])
def test_a_hole_tangent_at_any_angle_to_a_curved_outline_is_a_hole(tmp_path, radius, degrees):
    d = 20 - radius
    at = (d * math.cos(math.radians(degrees)), d * math.sin(math.radians(degrees)))
    path = _drawn(
        tmp_path / "t.dxf", lambda m: (m.add_circle((0, 0), 20), m.add_circle(at, radius))
    )
    (ip,) = parts(path, all_parts=True)
    want, com = _less_hole(DISK, radius, at)
    assert len(ip.part.outline.holes) == 1
    assert area(ip) == pytest.approx(want, rel=2e-3)
    assert ip.part.com == pytest.approx(com, abs=5e-3)


@pytest.mark.parametrize("depth", [0.05, 0.5, 2.0])  # beyond twice the flatten tolerance
def test_a_hole_crossing_a_curved_outline_is_still_refused(tmp_path, depth):
    path = _drawn(
        tmp_path / "x.dxf", lambda m: (m.add_circle((0, 0), 20), m.add_circle((12 + depth, 0), 8))
    )
    with pytest.raises(InputError, match="a hole crosses the outline .CIRCLE 30"):
        parts(path)


# ---- 2. a bare single-line frame is said to be one ----------------------------------------


def _framed_part(path: Path, frame_layer: str) -> Path:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    pentagon = [(0, 0), (25, 0), (25, 8), (12, 14), (0, 8)]
    msp.add_lwpolyline(pentagon, close=True, dxfattribs={"layer": "CUT"})
    frame = [(-50, -50), (100, -50), (100, 100), (-50, 100)]
    msp.add_lwpolyline(frame, close=True, dxfattribs={"layer": frame_layer})
    doc.saveas(path)
    return path


@pytest.mark.parametrize("frame_layer", ["FRAME", "CUT"])
def test_a_bare_single_line_frame_imports_as_a_plate_with_a_warning(tmp_path, frame_layer):
    path = _framed_part(tmp_path / "f.dxf", frame_layer)
    (ip,) = parts(path)
    assert area(ip) == pytest.approx(150 * 150 - 275.0)  # the plate, as the doc says
    (note,) = [w for w in ip.warnings if "drawing frame" in w]
    assert "150 x 150 mm rectangle" in note and "--layer" in note
    if frame_layer == "FRAME":  # named with the layer that leaves it out
        assert "on layer FRAME" in note and "--layer CUT" in note
        (part,) = parts(path, layers=("CUT",))
        assert area(part) == pytest.approx(275.0)
        assert not any("drawing frame" in w for w in part.warnings)


def test_a_plate_with_a_round_hole_is_not_taken_for_a_frame(tmp_path):
    (ip,) = parts(plate(tmp_path / "p.dxf", lambda doc, msp: msp.add_circle((-10, 0), 3)))
    assert not any("frame" in w for w in ip.warnings)


# ---- 3. closing a gap makes no sliver part -------------------------------------------------


def test_a_sliver_made_by_closing_a_gap_is_never_a_part(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 1  # inches: the 0.005 gaps become 0.13 mm
    msp = doc.modelspace()
    pts = [(0, 0), (40, 0), (40, 10), (25, 10), (25, 30), (0, 30)]
    for a, b in zip(pts, pts[1:] + pts[:1], strict=True):
        msp.add_line(a, (b[0] + 0.004, b[1] - 0.003))  # each line overshoots its corner
    path = tmp_path / "gappy.dxf"
    doc.saveas(path)
    for every in (False, True):
        (ip,) = parts(path, all_parts=every)
        assert area(ip) == pytest.approx(900 * 25.4**2, rel=1e-3)
        (note,) = [w for w in ip.warnings if "no area to speak of" in w]
        assert "left out 1 closed loop" in note
        assert not any("separate parts" in w for w in ip.warnings)


# ---- 4. a damaged file is refused (or read) as damaged -------------------------------------


def test_a_damaged_file_is_refused_as_damaged(tmp_path):
    path = tmp_path / "broken.dxf"
    path.write_text("0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nabc\n")
    with pytest.raises(InputError, match="damaged DXF file .missing ENDSEC tag."):
        parts(path)


def test_a_recovered_file_says_it_was_damaged(tmp_path):
    whole = plate(tmp_path / "whole.dxf", lambda doc, msp: msp.add_circle((-10, 0), 3))
    text = whole.read_text()
    cut = tmp_path / "cut.dxf"
    cut.write_text(text[: text.index("OBJECTS") + 20])  # the file ends inside OBJECTS
    (ip,) = parts(cut)
    assert area(ip) == pytest.approx(area(parts(whole)[0]))
    assert any(w.startswith("damaged DXF file") for w in ip.warnings)
    assert not any("damaged" in w for w in parts(whole)[0].warnings)


def test_closed_title_block_cells_stay_in_their_frame(tmp_path):
    """Closed rectangles sharing sides (a title block's cells) are not holes of the frame."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()

    def rect(x0, y0, x1, y1):
        msp.add_lwpolyline([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], close=True)

    rect(0, 0, 297, 210)
    for i in range(3):
        for j in range(3):
            rect(200 + i * 97 / 3, j * 10, 200 + (i + 1) * 97 / 3, (j + 1) * 10)
    rect(100, 80, 150, 130)
    msp.add_circle((125, 105), 10)
    doc.saveas(tmp_path / "framed.dxf")
    (ip,) = parts(tmp_path / "framed.dxf")
    assert area(ip) == pytest.approx(2500 - math.pi * 100, rel=1e-3)
    assert any("skipped 1 drawing frame" in w for w in ip.warnings)
    assert not any("left out" in w or "merged" in w for w in ip.warnings)
