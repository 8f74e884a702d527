"""Refusals that say what is there: an outline pasted again as lines and shifted is drawn
twice, two closed shapes that overlap (a T of two rectangles) are not a hole across the
outline (a rev93 review: both were blamed on construction geometry or a hole)."""

from __future__ import annotations

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts

T = [(0, 0), (70, 0), (70, 10), (40, 40), (0, 40)]


def _refusal(path) -> str:
    with pytest.raises(InputError) as info:
        import_parts(path, ImportOptions())
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("off", [0.02, 0.1, 0.3, 1.0])
def test_an_outline_pasted_again_as_lines_is_drawn_twice(tmp_path, off):
    def build(msp):
        msp.add_lwpolyline(T, close=True)
        msp.add_circle((15, 25), 5)
        for a, b in zip(T, T[1:] + T[:1], strict=True):
            msp.add_line((a[0] + off, a[1] + off), (b[0] + off, b[1] + off))

    path = fx.write_entities(tmp_path / "dup.dxf", build)
    message = _refusal(path)
    shift = f"{off * 2**0.5:.2g}"
    assert f"the outline seems drawn twice (a copy shifted by about {shift} mm: " in message
    assert "LWPOLYLINE" in message and "the loop of LINE" in message and "4 other lines" in message
    assert message.endswith("): delete one copy"), message
    assert "construction geometry" not in message
    assert main(["part", "analyze", str(path)]) == 2


def test_two_overlapping_rectangles_are_said_to_overlap(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 30), (60, 30), (60, 40), (0, 40)], close=True)
        msp.add_lwpolyline([(25, 0), (35, 0), (35, 35), (25, 35)], close=True)

    path = fx.write_entities(tmp_path / "t.dxf", build)
    message = _refusal(path)
    assert "two closed loops overlap (LWPOLYLINE" in message, message
    assert "neither inside the other): a part drawn as overlapping shapes?" in message
    assert "join them into one outline (e.g. a union)" in message
    assert "a hole crosses" not in message
    assert main(["part", "analyze", str(path)]) == 2


def test_a_circle_across_the_outline_is_still_a_hole_across_it(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
        msp.add_circle((38, 15), 5)

    assert "a hole crosses the outline (CIRCLE" in _refusal(
        fx.write_entities(tmp_path / "c.dxf", build)
    )
