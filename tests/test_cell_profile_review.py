"""A cell profile's mistakes a review found passed over or named wrongly: an integer too
large for a float (a crash log and no field named), a key before any section (called an
unknown section), ``./feederkit.toml`` a folder (silently the built-in defaults), and an
infinite value refused as "not positive"."""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cell import CellProfileError, load_cell, parse_cell
from feederkit.errors import InputError

HUGE = int("1" * 300)


def test_a_huge_integer_is_named_as_a_bad_field():
    with pytest.raises(CellProfileError) as info:
        parse_cell({"robot": {"rotation_error_deg": HUGE}}, "big.toml")
    (line,) = info.value.problems
    assert line.startswith("robot.rotation_error_deg must be a number in [0, 90) of degrees")
    assert "(300 characters)" in line and len(line) < 150


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        ({"model": "tolerance"}, "model is a key outside any section: it goes in [sensor]"),
        ({"pick_place_s": 1.0}, "pick_place_s is a key outside any section: it goes in [robot]"),
        ({"foo": 1}, "foo is a key outside any section: it goes in one of [sensor], [robot]"),
        ({"sensor": 3}, "sensor must be a table ([sensor])"),
        ({"motor": {"x": 1}}, "unknown section [motor]"),
    ],
)
def test_a_key_outside_any_section_is_named_as_such(data, needle):
    with pytest.raises(CellProfileError, match=None) as info:
        parse_cell(data, "p.toml")
    assert any(needle in p for p in info.value.problems), info.value.problems


def test_an_infinite_value_is_not_finite_rather_than_not_positive():
    with pytest.raises(CellProfileError) as info:
        parse_cell({"robot": {"rotation_speed_deg_s": float("inf")}}, "p.toml")
    assert info.value.problems == (
        "robot.rotation_speed_deg_s must be a finite positive number of deg/s, got inf",
    )


def test_a_working_directory_profile_that_is_a_folder_is_refused(tmp_path: Path):
    (tmp_path / "feederkit.toml").mkdir()
    with pytest.raises(InputError, match="a folder, not a cell profile file"):
        load_cell(directory=tmp_path)
