"""Messy drawings (docs/import.md, "Loops", "Parts and holes", "Drawing frames"): dimension
and extension lines drawn against the outline (a closed one or one of lines), an outline or
a hole left open, a drawing frame around a part on the part's own layer or holding a
free-standing title block, parts sharing a cut line, a view drawn against its part, and a
self-crossing outline of LINEs.

Each drawing is built here with ezdxf; each must import the drawn part or say what is doubtful.
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import pytest
from shapely.geometry import Point, Polygon, box

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts

L_PLATE = [(0, 0), (80, 0), (80, 40), (30, 40), (30, 25), (0, 25)]
"""An 80 x 40 L plate."""

WINDOW = [(50, 10), (70, 10), (70, 22), (50, 22)]
"""A 20 x 12 window in it."""

BRACKET = [(135, 100), (285, 100), (285, 140), (175, 140), (175, 200), (135, 200)]
"""A 150 x 100 L bracket, as drawn in an A3 frame."""


def drawing(path: Path, build, setup: bool = False) -> Path:
    """A millimetre drawing holding what ``build(msp)`` adds."""
    doc = ezdxf.new("R2010", setup=setup)
    doc.header["$INSUNITS"] = 4
    build(doc.modelspace())
    doc.saveas(path)
    return path


def parts(path: Path, **options):
    return import_parts(path, ImportOptions(**options))[1]


def area(ip) -> float:
    return float(ip.part.outline.polygon().area)


def noted(ip, *words: str) -> list[str]:
    """The part's warnings holding every one of ``words``."""
    return [w for w in ip.warnings if all(word in w for word in words)]


def _l_plate_with_hole(msp) -> None:
    msp.add_lwpolyline(L_PLATE, close=True)
    msp.add_circle((60, 20), 6)


def _lines(msp, points, close: bool = True) -> None:
    """LINEs from point to point (back to the first when ``close``)."""
    nexts = points[1:] + points[:1] if close else points[1:]
    for a, b in zip(points, nexts, strict=False):
        msp.add_line(a, b)


# ---- lines closing a region against the outline's edge from outside ------------------------


def _hand_dimension(msp) -> None:
    _l_plate_with_hole(msp)
    msp.add_line((0, 0), (0, -12))  # extension lines from the part's corners
    msp.add_line((80, 0), (80, -12))
    msp.add_line((0, -10), (80, -10))  # the dimension line


def _exploded_dimensions(msp, dimexo: float | None) -> None:
    _l_plate_with_hole(msp)
    override = {} if dimexo is None else {"dimexo": dimexo}
    msp.add_linear_dim(base=(0, -10), p1=(0, 0), p2=(80, 0), override=override).render()
    dim = msp.add_linear_dim(base=(90, 0), p1=(80, 0), p2=(80, 40), angle=90, override=override)
    dim.render()
    for entity in list(msp.query("DIMENSION")):
        entity.explode()
    for entity in list(msp.query("INSERT")):  # the arrow blocks
        entity.explode()


def test_dimension_lines_drawn_against_the_outline_are_named(tmp_path):
    (ip,) = parts(drawing(tmp_path / "hand.dxf", _hand_dimension))
    (note,) = noted(ip, "lines close 1 region against the outline's edge")
    assert "80 x 10 mm at x 0..80, y -10..0" in note and "dimension lines" in note
    assert area(ip) == pytest.approx(Polygon(L_PLATE).area + 800 - 113.0, abs=0.2)  # merged


def test_exploded_dimensions_touching_the_part_are_named(tmp_path):
    path = drawing(tmp_path / "dims.dxf", lambda msp: _exploded_dimensions(msp, 0.0), True)
    (ip,) = parts(path)
    (note,) = noted(ip, "lines close 2 regions against the outline's edge")
    assert "80 x 10 mm at x 0..80, y -10..0" in note
    assert "10 x 40 mm at x 80..90, y 0..40" in note


def test_exploded_dimensions_clear_of_the_part_say_nothing(tmp_path):
    path = drawing(tmp_path / "dims.dxf", lambda msp: _exploded_dimensions(msp, None), True)
    (ip,) = parts(path)
    truth = Polygon(L_PLATE).difference(Point(60, 20).buffer(6, 2048))
    assert area(ip) == pytest.approx(truth.area, rel=1e-4)
    assert not noted(ip, "outline's edge") and not noted(ip, "open outline")


def test_a_view_drawn_with_lines_against_a_plate_is_no_drawing_frame(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (80, 0), (80, 40), (0, 40)], close=True)
        msp.add_lwpolyline([(10, 10), (30, 10), (30, 22), (10, 22)], close=True)
        _lines(msp, [(80, 0), (85, 0), (85, 40), (80, 40)], close=False)

    (ip,) = parts(drawing(tmp_path / "view.dxf", build))
    assert area(ip) == pytest.approx(85 * 40 - 240)  # the plate and the view, not the window
    assert not noted(ip, "drawing frame")
    (note,) = noted(ip, "against the outline's edge")
    assert "5 x 40 mm at x 80..85, y 0..40" in note


def test_a_closed_cell_in_a_plate_of_lines_says_nothing(tmp_path):
    def build(msp):
        _lines(msp, [(0, 0), (80, 0), (80, 40), (0, 40)])
        msp.add_lwpolyline([(60, 0), (80, 0), (80, 10), (60, 10)], close=True)

    (ip,) = parts(drawing(tmp_path / "cell.dxf", build))
    assert area(ip) == pytest.approx(3200.0)
    assert not ip.warnings


# ---- the same against an outline drawn with lines -------------------------------------------


def _l_plate_of_lines(msp) -> None:
    _lines(msp, L_PLATE)
    msp.add_circle((60, 20), 6)


def test_dimension_lines_against_an_outline_of_lines_are_named(tmp_path):
    def build(msp):
        _l_plate_of_lines(msp)
        msp.add_line((0, 0), (0, -12))  # extension lines from the part's corners
        msp.add_line((80, 0), (80, -12))
        msp.add_line((0, -10), (80, -10))  # the dimension line

    (ip,) = parts(drawing(tmp_path / "hand.dxf", build))
    (note,) = noted(ip, "ends on it at both ends and cuts off 1 region")
    assert "80 x 10 mm at x 0..80, y -10..0" in note and "dimension lines" in note
    assert area(ip) == pytest.approx(Polygon(L_PLATE).area + 800 - 113.0, abs=0.2)  # merged


def test_exploded_dimensions_against_an_outline_of_lines_are_named(tmp_path):
    def build(msp):
        _l_plate_of_lines(msp)
        for base, p1, p2, angle in (
            ((0, -10), (0, 0), (80, 0), 0),
            ((90, 0), (80, 0), (80, 40), 90),
        ):
            dim = msp.add_linear_dim(base=base, p1=p1, p2=p2, angle=angle, override={"dimexo": 0})
            dim.render()
        for entity in list(msp.query("DIMENSION")):
            entity.explode()
        for entity in list(msp.query("INSERT")):
            entity.explode()

    (ip,) = parts(drawing(tmp_path / "dims.dxf", build, True))
    (note,) = noted(ip, "cuts off 2 regions")
    assert "80 x 10 mm at x 0..80, y -10..0" in note and "10 x 40 mm at x 80..90, y 0..40" in note


@pytest.mark.parametrize("closed", [False, True], ids=["lines", "polyline"])
def test_centre_lines_running_on_past_the_outline_say_nothing(tmp_path, closed):
    def build(msp):
        if closed:
            _l_plate_with_hole(msp)
        else:
            _l_plate_of_lines(msp)
        msp.add_line((60, -5), (60, 45))
        msp.add_line((45, 20), (85, 20))
        msp.add_line((-3, 12), (83, 12))  # across the whole part

    (ip,) = parts(drawing(tmp_path / "centre.dxf", build))
    truth = Polygon(L_PLATE).difference(Point(60, 20).buffer(6, 2048))
    assert area(ip) == pytest.approx(truth.area, rel=1e-3)
    assert not ip.warnings


def test_two_parts_of_lines_drawn_against_each_other_are_named(tmp_path):
    def build(msp):
        _lines(msp, [(0, 0), (50, 0), (50, 40), (0, 40)])
        _lines(msp, [(50, 0), (90, 0), (90, 40), (50, 40)], close=False)

    (ip,) = parts(drawing(tmp_path / "nest.dxf", build))
    (note,) = noted(ip, "cuts off 1 region", "another part drawn against it")
    assert "40 x 40 mm at x 50..90, y 0..40" in note
    assert area(ip) == pytest.approx(90 * 40)


# ---- an outline or a hole left open ---------------------------------------------------------


def _open_outline(msp, hole) -> None:
    ends = list(zip(L_PLATE, L_PLATE[1:] + L_PLATE[:1], strict=True))
    ends[0] = ((0, 0), (79.5, 0))  # the bottom LINE stops 0.5 mm short of its corner
    for a, b in ends:
        msp.add_line(a, b)
    hole(msp)


@pytest.mark.parametrize(
    "hole",
    [
        lambda msp: msp.add_lwpolyline(WINDOW, close=True),
        lambda msp: msp.add_circle((60, 20), 6),
    ],
    ids=["window", "circle"],
)
def test_an_open_outline_of_lines_is_said_to_surround_the_part(tmp_path, hole):
    (ip,) = parts(drawing(tmp_path / "open.dxf", lambda msp: _open_outline(msp, hole)))
    (note,) = noted(ip, "open outline", "surrounds the imported part")
    assert "0.5 mm apart" in note and "(79.5, 0)" in note


@pytest.mark.parametrize(
    "beside",
    [
        lambda msp: msp.add_lwpolyline([(110, 0), (140, 0), (140, 8), (110, 8)], close=True),
        lambda msp: msp.add_circle((130, 10), 6),
    ],
    ids=["label box", "washer"],
)
def test_an_open_outline_beside_a_smaller_loop_is_named(tmp_path, beside):
    # The plate's outline open by 0.5 mm and a label box (or a washer) beside it: the loop
    # was imported as the part with no word (the open lines were simply left out).
    (ip,) = parts(drawing(tmp_path / "open.dxf", lambda msp: _open_outline(msp, beside)))
    (note,) = noted(ip, "open outline", "lies beside the imported part")
    assert "0.5 mm apart" in note and "more than the part's" in note
    assert area(ip) < 300  # still the loop: the warning is what tells the user


@pytest.mark.parametrize(
    "hole",
    [
        lambda msp: _lines(msp, [*WINDOW, (50, 10.3)], close=False),  # the last LINE 0.3 short
        lambda msp: msp.add_arc((60, 20), 8, 5, 355),
    ],
    ids=["lines", "arc"],
)
def test_an_open_hole_inside_the_part_is_named(tmp_path, hole):
    def build(msp):
        msp.add_lwpolyline(L_PLATE, close=True)
        hole(msp)

    (ip,) = parts(drawing(tmp_path / "hole.dxf", build))
    assert area(ip) == pytest.approx(Polygon(L_PLATE).area)  # the hole is not guessed
    (note,) = noted(ip, "open lines inside the part nearly close 1 loop")
    assert "area and COM are off" in note
    assert "at x 50..70, y 10..22" in note or "1.39 mm apart" in note


def _centre_marks(msp) -> None:
    _l_plate_with_hole(msp)
    msp.add_line((52, 20), (68, 20))  # a centre mark across the hole
    msp.add_line((60, 12), (60, 28))
    msp.add_arc((15, 12), 5, 0, 180)  # half an arc
    _lines(msp, [(40, 5), (40, 15), (50, 15)], close=False)  # an L of two LINEs


def _arc_round_the_middle(msp) -> None:
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 60), (0, 60)], close=True)
    msp.add_arc((50, 30), 10, 0, 219.9)  # closed by its chord, it holds the plate's middle


@pytest.mark.parametrize(
    ("build", "holes"), [(_centre_marks, 1), (_arc_round_the_middle, 0)], ids=["marks", "arc"]
)
def test_open_lines_inside_the_part_that_close_no_loop_say_nothing(tmp_path, build, holes):
    (ip,) = parts(drawing(tmp_path / "marks.dxf", build))
    assert len(ip.part.outline.holes) == holes
    assert not ip.warnings


# ---- drawing frames -------------------------------------------------------------------------


def _frame(msp) -> None:
    msp.add_lwpolyline([(10, 10), (410, 10), (410, 287), (10, 287)], close=True)


def test_a_frame_holding_a_free_standing_title_block_is_named(tmp_path):
    def build(msp):
        _frame(msp)
        msp.add_lwpolyline([(220, 20), (400, 20), (400, 76), (220, 76)], close=True)
        msp.add_line((220, 40), (400, 40))
        msp.add_lwpolyline(BRACKET, close=True)

    (ip,) = parts(drawing(tmp_path / "frame.dxf", build))
    (note,) = noted(ip, "400 x 277 mm rectangle", "drawing frame")
    assert "divided like a title block (180 x 56 mm at x 220..400, y 20..76)" in note
    assert "delete the frame" in note


@pytest.mark.parametrize(
    ("frame", "part"),
    [
        ([(10, 10), (410, 10), (410, 287), (10, 287)], BRACKET),
        (
            [(0, 0), (297, 0), (297, 210), (0, 210)],
            [(60, 60), (140, 60), (140, 100), (100, 140), (60, 140)],
        ),
    ],
    ids=["a3-bracket", "a4-pentagon"],
)
def test_a_bare_sheet_frame_on_the_parts_layer_is_named(tmp_path, frame, part):
    def build(msp):
        msp.add_lwpolyline(frame, close=True)
        msp.add_lwpolyline(part, close=True)

    (ip,) = parts(drawing(tmp_path / "frame.dxf", build))
    assert area(ip) == pytest.approx(Polygon(frame).area - Polygon(part).area)
    (note,) = noted(ip, "mm rectangle on layer 0 around 1 hole", "drawing frame")
    assert "delete the frame" in note


@pytest.mark.parametrize(
    ("outer", "hole"),
    [
        (box(0, 0, 100, 60), box(30, 20, 70, 40)),  # a bezel with a window (13 % of its box)
        (box(0, 0, 300, 200), Point(150, 100).buffer(40, 64)),  # a round hole
        (box(0, 0, 300, 200), box(60, 40, 240, 160)),  # a large window (36 %)
    ],
    ids=["bezel", "round", "large-window"],
)
def test_plates_with_one_hole_are_not_called_frames(tmp_path, outer, hole):
    def build(msp):
        msp.add_lwpolyline(list(outer.exterior.coords)[:-1], close=True)
        msp.add_lwpolyline(list(hole.exterior.coords)[:-1], close=True)

    (ip,) = parts(drawing(tmp_path / "plate.dxf", build))
    assert not noted(ip, "frame")


# ---- closed outlines side by side -----------------------------------------------------------

COMMON_L = [(0, 0), (50, 0), (50, 40), (20, 40), (20, 15), (0, 15)]


def _common_line(msp) -> None:
    msp.add_lwpolyline(COMMON_L, close=True)
    msp.add_lwpolyline([(50, 0), (90, 0), (90, 40), (50, 40)], close=True)  # shares x = 50
    msp.add_circle((70, 20), 5)


def test_parts_sharing_a_cut_line_are_separate_parts(tmp_path):
    path = drawing(tmp_path / "common.dxf", _common_line)
    (ip,) = parts(path)
    plate = box(50, 0, 90, 40).difference(Point(70, 20).buffer(5, 2048))
    assert area(ip) == pytest.approx(plate.area, rel=1e-4)  # the largest loop, with its hole
    (note,) = noted(ip, "2 closed outlines share edges")
    assert "50 x 40 mm at x 0..50, y 0..40" in note and "separate parts" in note
    assert noted(ip, "holds 2 separate parts")
    areas = sorted(area(p) for p in parts(path, all_parts=True))
    assert areas == pytest.approx(sorted([Polygon(COMMON_L).area, plate.area]), rel=1e-4)


@pytest.mark.parametrize("window", [True, False], ids=["window", "round-hole"])
def test_a_plate_with_a_closed_side_view_against_it_is_the_part(tmp_path, window):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (80, 0), (80, 40), (0, 40)], close=True)
        if window:
            msp.add_lwpolyline([(10, 10), (30, 10), (30, 22), (10, 22)], close=True)
        else:
            msp.add_circle((20, 20), 5)
        msp.add_lwpolyline([(80, 0), (85, 0), (85, 40), (80, 40)], close=True)  # the side view

    (ip,) = parts(drawing(tmp_path / "view.dxf", build))
    hole = box(10, 10, 30, 22) if window else Point(20, 20).buffer(5, 2048)
    truth = box(0, 0, 80, 40).difference(hole)
    assert area(ip) == pytest.approx(truth.area, rel=1e-4)
    assert ip.part.com == pytest.approx((truth.centroid.x, truth.centroid.y), abs=1e-3)
    assert not noted(ip, "drawing frame")
    assert noted(ip, "2 closed outlines share edges")


# ---- a self-crossing outline of LINEs -------------------------------------------------------


def test_a_bow_tie_of_lines_is_refused_as_self_intersecting(tmp_path):
    bow_tie = [(0, 0), (60, 30), (60, 0), (0, 30)]
    path = drawing(tmp_path / "bowtie.dxf", lambda msp: _lines(msp, bow_tie))
    with pytest.raises(
        InputError,
        match=r"self-intersecting \(the loop of LINE \w+ on layer '0' "
        r"and 3 other lines crosses itself near \(30, 15\)\)",
    ):
        parts(path)
    poly = drawing(tmp_path / "poly.dxf", lambda msp: msp.add_lwpolyline(bow_tie, close=True))
    with pytest.raises(InputError, match=r"self-intersecting .*crosses itself near \(30, 15\)"):
        parts(poly)
