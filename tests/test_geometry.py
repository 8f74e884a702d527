"""Outlines, the contact hull and parts (design.md: outline file, hull numbering, COM)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from feederkit.errors import InputError
from feederkit.hull import contact_hull
from feederkit.outline import (
    load_outline_json,
    make_outline,
    outline_from_dict,
    outline_to_dict,
    save_outline_json,
)
from feederkit.part import make_part

TRIANGLE = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]


def square(cx: float, cy: float, half: float) -> list[tuple[float, float]]:
    return [
        (cx - half, cy - half),
        (cx + half, cy - half),
        (cx + half, cy + half),
        (cx - half, cy + half),
    ]


def test_outline_in_other_units_becomes_mm() -> None:
    o = make_outline("t", TRIANGLE, com=(0.25, 0.25), units="in")
    assert o.units == "mm"
    assert o.vertices[1] == pytest.approx((25.4, 0.0))
    assert o.com == pytest.approx((6.35, 6.35))


def test_closing_duplicate_and_repeats_are_dropped() -> None:
    o = make_outline("t", [(0, 0), (1, 0), (1, 0), (0, 1), (0, 0)])
    assert o.vertices == ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))


def test_numpy_input_is_accepted() -> None:
    o = make_outline("t", np.array(TRIANGLE), com=np.array([0.2, 0.2]))
    assert o.com == (0.2, 0.2)


def test_outline_file_round_trip(tmp_path) -> None:
    o = make_outline("plate", square(5, 5, 5), [square(3, 3, 1)], com=(5.5, 5.0))
    path = tmp_path / "plate.json"
    save_outline_json(o, path)
    assert load_outline_json(path) == o
    assert outline_from_dict(outline_to_dict(o)) == o


@pytest.mark.parametrize(
    ("data", "words"),
    [
        ({"vertices": [[0, 0], [1, 0]]}, "three distinct points"),
        ({"vertices": [[0, 0], [1, 0], [0, 0], [1, 0]]}, "three distinct points"),
        ({"vertices": [[0, 0], [1, 0], [2, 0]]}, "zero area"),
        ({"vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "self-intersecting"),
        ({"vertices": [[0, 0], [1, 0], [1, 1], [1, 0]]}, "self-intersecting"),
        ({"vertices": [[0, 0], [1, 0], [float("nan"), 1]]}, "NaN or infinite"),
        ({"vertices": [[0, 0], [1, 0], [0, float("inf")]]}, "NaN or infinite"),
        ({"vertices": [[0, 0], [1e300, 0], [0, 1]]}, "beyond"),
        ({"vertices": 5}, "list of [x, y] points"),
        ({"vertices": [[0, 0], [1, 0], [0, "a"]]}, "non-numeric"),
        ({"vertices": [[0, 0], [True, 0], [0, 1]]}, "non-numeric"),
        ({"vertices": [[0, 0], [1, 0, 2], [0, 1]]}, "list of [x, y] points"),
        ({"vertices": TRIANGLE, "holes": [5]}, "hole 0"),
        ({"vertices": TRIANGLE, "holes": "x"}, "'holes'"),
        ({"vertices": TRIANGLE, "holes": [[[2, 2], [3, 2], [2, 3]]]}, "hole crosses"),
        ({"vertices": TRIANGLE, "com": [1, 2, 3]}, "'com' must be [x, y]"),
        ({"vertices": TRIANGLE, "units": "parsec"}, "unknown unit"),
        ({"units": "mm"}, "no 'vertices'"),
        ([1, 2], "JSON object"),
    ],
)
def test_bad_outlines_are_input_errors(data, words: str) -> None:
    with pytest.raises(InputError) as err:
        outline_from_dict(data, default_name="bad")
    message = str(err.value)
    assert words in message
    assert "\n" not in message
    assert message.startswith("bad")


def test_unreadable_outline_files(tmp_path) -> None:
    with pytest.raises(InputError, match="no such file"):
        load_outline_json(tmp_path / "missing.json")
    (tmp_path / "broken.json").write_text("{not json", encoding="utf-8")
    with pytest.raises(InputError, match="not valid JSON"):
        load_outline_json(tmp_path / "broken.json")
    with pytest.raises(InputError, match="cannot read"):
        load_outline_json(tmp_path)
    (tmp_path / "binary.json").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(InputError, match="cannot read"):
        load_outline_json(tmp_path / "binary.json")


def test_hull_is_ccw_numbered_from_lowest_then_leftmost() -> None:
    pts = [(2, 3), (0, 1), (4, 1), (1, 1), (3, 0), (1, 0), (2, 2)]  # (1,1), (2,2) inside
    hull = contact_hull(pts)
    assert hull[0] == (1.0, 0.0)  # lowest, then leftmost of (1, 0) and (3, 0)
    area2 = sum(
        hull[i][0] * hull[(i + 1) % len(hull)][1] - hull[(i + 1) % len(hull)][0] * hull[i][1]
        for i in range(len(hull))
    )
    assert area2 > 0  # counter-clockwise
    assert set(hull) == {(1.0, 0.0), (3.0, 0.0), (4.0, 1.0), (2.0, 3.0), (0.0, 1.0)}


def test_hull_drops_collinear_and_duplicate_vertices() -> None:
    pts = [(0, 0), (1, 0), (2, 0), (2, 0), (2, 1), (1, 1 + 1e-13), (0, 1)]
    hull = contact_hull(pts)
    assert len(hull) == 4
    for got, want in zip(hull, [(0, 0), (2, 0), (2, 1), (0, 1)], strict=True):
        assert got == pytest.approx(want, abs=1e-9)


def test_hull_ignores_where_the_outline_starts_and_its_direction() -> None:
    ring = [(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)]
    ref = contact_hull(ring)
    for k in range(len(ring)):
        shifted = ring[k:] + ring[:k]
        assert contact_hull(shifted) == ref
        assert contact_hull(shifted[::-1]) == ref


def test_com_is_the_centroid_with_holes() -> None:
    o = make_outline("plate", square(0, 0, 2), [square(1, 0, 0.5)])
    part = make_part(o)
    # 16 - 1 area; the hole's centroid at (1, 0): the COM moves by -1/15 in x.
    assert part.com == pytest.approx((-1.0 / 15.0, 0.0), abs=1e-12)


def test_com_overrides() -> None:
    o = make_outline("t", TRIANGLE, com=(0.2, 0.1))
    assert make_part(o).com == (0.2, 0.1)
    assert make_part(o, (0.1, 0.3)).com == (0.1, 0.3)


def test_com_in_a_notch_but_inside_the_hull_is_fine() -> None:
    u_shape = [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
    part = make_part(make_outline("u", u_shape), (1.5, 2.0))
    assert len(part.hull) == 4


@pytest.mark.parametrize(
    ("com", "words"),
    [
        ((1.0, 1.0), "outside the contact hull"),
        ((0.5, 0.0), "on the boundary"),
        ((math.nan, 0.2), "NaN or infinite"),
        ((0.2, math.inf), "NaN or infinite"),
    ],
)
def test_bad_com(com, words: str) -> None:
    with pytest.raises(InputError, match=words):
        make_part(make_outline("t", TRIANGLE), com)


def test_com_outside_in_the_file(tmp_path) -> None:
    path = tmp_path / "t.json"
    path.write_text(json.dumps({"name": "t", "vertices": TRIANGLE, "com": [2, 2]}))
    with pytest.raises(InputError, match="outside"):
        make_part(load_outline_json(path))


def test_part_size_and_frame() -> None:
    part = make_part(make_outline("r", [(10, 10), (30, 10), (30, 20), (10, 20)]))
    assert part.size == pytest.approx(math.hypot(20.0, 10.0))  # its diameter, not its box
    c, s = math.cos(math.radians(37.0)), math.sin(math.radians(37.0))
    box = [(0, 0), (20, 0), (20, 10), (0, 10)]
    turned = make_part(make_outline("t", [(c * x - s * y, s * x + c * y) for x, y in box]))
    assert turned.size == pytest.approx(part.size)  # the drawing turned: the same size
    assert part.hull[0] == (10.0, 10.0)
    assert part.com == pytest.approx((20.0, 15.0))
