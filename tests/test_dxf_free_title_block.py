"""A title block drawn beside the part with no frame (a rectangle divided into cells) is no
part: the import takes the part, however much larger the block is, and says what it left out.
A review's drawing: a 30 x 20 mm clip with a hole and a 180 x 56 mm title block on layer TITLE
(three rows, one column line, a TEXT); before, the block was imported as the part."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fixtures_cad import write_entities
from shared import run_cli

from feederkit.sources import load_part_with_warnings


def _clip(msp) -> None:
    pts = [(20, 100, 0), (50, 100, 0), (50, 110, -0.4), (40, 120, 0), (20, 120, 0)]
    msp.add_lwpolyline(pts, format="xyb", close=True)
    msp.add_circle((28, 110), 3)


def _title_block(msp, rows: tuple[float, ...] = (14, 28, 42)) -> None:
    x0, y0, title = 100, 0, {"layer": "TITLE"}
    msp.add_lwpolyline([(x0, y0), (x0 + 180, y0), (x0 + 180, y0 + 56), (x0, y0 + 56)],
                       close=True, dxfattribs=title)  # fmt: skip
    for y in rows:
        msp.add_line((x0, y0 + y), (x0 + 180, y0 + y), dxfattribs=title)
    msp.add_line((x0 + 60, y0), (x0 + 60, y0 + 56), dxfattribs=title)
    msp.add_text("TITLE: CLIP", dxfattribs={**title, "height": 5}).set_placement((x0 + 65, 45))


@pytest.fixture()
def drawing(tmp_path):
    def build(msp):
        _clip(msp)
        _title_block(msp)

    return write_entities(tmp_path / "tb_free.dxf", build)


def test_the_part_is_imported_and_the_title_block_left_out(drawing, capsys):
    loaded = load_part_with_warnings(str(drawing))
    xs = [p[0] for p in loaded.part.hull]
    ys = [p[1] for p in loaded.part.hull]
    assert (min(xs), min(ys)) == pytest.approx((20, 100))
    assert max(xs) <= 50 + 1e-6 and max(ys) <= 120 + 1e-6
    words = " ".join(loaded.warnings)
    assert "left out 1 title block beside the part" in words and "180 x 56 mm" in words
    assert "imported the largest" not in words
    rc, _, err = run_cli(capsys, "part", "analyze", str(drawing))
    assert rc == 0 and "title block" in err


def test_a_drawing_of_title_blocks_alone_keeps_the_largest(tmp_path):
    # Nothing else to take: the rectangle is imported as it was (the part may be a table).
    path = write_entities(tmp_path / "only.dxf", _title_block)
    loaded = load_part_with_warnings(str(path))
    assert len(loaded.part.hull) == 4 and "title block" not in " ".join(loaded.warnings)


def _bent_plate(msp) -> None:
    """A 120 x 60 mm flat pattern with two bend lines across it and a hole."""
    msp.add_lwpolyline([(0, 0), (120, 0), (120, 60), (0, 60)], close=True)
    msp.add_line((40, 0), (40, 60))
    msp.add_line((80, 0), (80, 60))
    msp.add_circle((20, 30), 4)


def _box(loaded) -> tuple[float, float, float, float]:
    xs = [p[0] for p in loaded.part.hull]
    ys = [p[1] for p in loaded.part.hull]
    return min(xs), min(ys), max(xs), max(ys)


def test_a_plate_with_bend_lines_is_no_title_block(tmp_path):
    # Beside a washer: the plate stays the part (lines one way, and a hole).
    def build(msp):
        _bent_plate(msp)
        msp.add_circle((160, 30), 8)

    loaded = load_part_with_warnings(str(write_entities(tmp_path / "bent.dxf", build)))
    assert _box(loaded) == pytest.approx((0, 0, 120, 60))
    assert "title block" not in " ".join(loaded.warnings)


def test_beside_a_larger_title_block_the_bent_plate_is_the_part(tmp_path):
    def build(msp):
        _bent_plate(msp)
        msp.add_lwpolyline([(200, 0), (380, 0), (380, 56), (200, 56)], close=True)
        for y in (14, 28, 42):
            msp.add_line((200, y), (380, y))
        msp.add_line((260, 0), (260, 56))

    loaded = load_part_with_warnings(str(write_entities(tmp_path / "both.dxf", build)))
    assert _box(loaded) == pytest.approx((0, 0, 120, 60))
    assert "left out 1 title block beside the part" in " ".join(loaded.warnings)


def test_a_cut_sheet_beside_a_title_block_still_says_what_its_holes_hold(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (120, 0), (120, 60), (0, 60)], close=True)
        msp.add_lwpolyline([(20, 20), (60, 20), (60, 40), (20, 40)], close=True)  # a window
        msp.add_lwpolyline([(25, 25), (35, 25), (35, 35), (25, 35)], close=True)  # cut from it
        msp.add_lwpolyline([(200, 0), (380, 0), (380, 56), (200, 56)], close=True)
        for y in (14, 28, 42):
            msp.add_line((200, y), (380, y))
        msp.add_line((260, 0), (260, 56))

    loaded = load_part_with_warnings(str(write_entities(tmp_path / "sheet.dxf", build)))
    words = " ".join(loaded.warnings)
    assert _box(loaded) == pytest.approx((0, 0, 120, 60))
    assert "title block" in words and "the part's holes hold 1 other part(s)" in words


def test_cell_lines_a_few_degrees_apart_are_not_rows_and_columns():
    # Two slits drawn 14 and 16 degrees off the vertical run one way: no title block, however
    # the angles fall around any bucket's edge.
    from feederkit.importers.frames import free_title_block
    from feederkit.importers.loops import Region

    shell = ((0.0, 0.0), (100.0, 0.0), (100.0, 50.0), (0.0, 50.0))
    plate = Region(shell=shell, holes=(), area=5000.0, loop_area=5000.0)

    def slit(x: float, deg: float):
        dx = 20.0 * math.tan(math.radians(deg))
        return np.array([(x, 0.0), (x + dx, 20.0)])

    assert not free_title_block(plate, [slit(30.0, 14.0), slit(70.0, 16.0)], 1e-3)
    rows_and_column = [
        np.array([(0.0, 20.0), (100.0, 20.0)]),
        np.array([(40.0, 0.0), (40.0, 50.0)]),
    ]
    assert free_title_block(plate, rows_and_column, 1e-3)
