""" "No strong plan" names the vibration, not the rotation error, when only the ideal model has
a plan, with the push band the parts have (docs/uncertainty.md, "Push bands": 2 degrees, up to
8 on a small slender part)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from feederkit.errors import PlanningError
from feederkit.mechanics import push_function
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.uncertain import ordinary_push_band_deg
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.planning.options import PlanningOptions
from feederkit.plans.certify import largest_uncertainty, push_band_words
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
SENSOR = ToleranceSensor(0.3)


def plate_with_hole() -> PushFunction:
    """A 45 x 28 plate with an 8 x 8 hole off centre: states 0 and 2 (1 and 3) are told apart
    by rotations whose ideal windows are 1.67 degrees wide, inside any push band."""
    hole = [(8, 8), (16, 8), (16, 16), (8, 16)]
    outline = make_outline("plate-hole", [(0, 0), (45, 0), (45, 28), (0, 28)], holes=[hole])
    return push_function(make_part(outline))


def slender_rhombus() -> PushFunction:
    """A 60-degree rhombus of 10 mm sides with a 1 mm hole 1.5 mm off centre: slender (radius
    of gyration 0.236 of its size) and small, so its band is 8 degrees; the hole keeps its
    half-turn poses apart, which only the ideal model tells apart."""
    a = math.radians(60.0)
    c, s = 10.0 * math.cos(a), 10.0 * math.sin(a)
    hx, hy = (10.0 + c) / 2.0 + 1.5, s / 2.0
    hole = [(hx - 0.5, hy - 0.5), (hx + 0.5, hy - 0.5), (hx + 0.5, hy + 0.5), (hx - 0.5, hy + 0.5)]
    outline = make_outline("rhombus-hole", [(0, 0), (10, 0), (10 + c, s), (c, s)], holes=[hole])
    return push_function(make_part(outline))


def triangle() -> PushFunction:
    """The catalog's isosceles right triangle (1 mm legs): slender, radius of gyration 0.236."""
    path = CATALOG / "isosceles-right-triangle.json"
    return push_function(make_part(load_outline_json(path)))


def _no_plan_words(pfs: list[PushFunction]) -> str:
    assert make_plan(pfs, SENSOR, uncertainty=IDEAL, certify=False).plan["root"]
    with pytest.raises(PlanningError) as exc:
        make_plan(pfs, SENSOR, uncertainty=Uncertainty(0.001, 0.0, 0.0), certify=False)
    text = str(exc.value)
    assert "no rotation error at all" not in text
    assert "a strong plan exists only on the ideal model (rotation error 0)" in text
    assert "not the rotation error but the feeder's vibration" in text
    assert "no smaller rotation error helps" in text
    return text


def test_the_vibration_not_the_rotation_error_is_named_when_only_the_ideal_model_plans():
    text = _no_plan_words([plate_with_hole()])
    assert "(a push starting within 2° of a hilltop may end on either side, the push bands" in text


def test_a_small_slender_part_is_said_to_have_its_wider_band():
    pf = slender_rhombus()
    assert ordinary_push_band_deg(pf.part) == pytest.approx(8.0)
    text = _no_plan_words([pf])
    assert (
        "(a push starting within 8° of a hilltop (the band of a small slender part) may end on "
        "either side, the push bands" in text
    )
    assert "within 2°" not in text


def test_a_mix_names_the_range_of_bands_and_its_slender_part():
    """The plate keeps its plan only on the ideal model; the catalog's triangle beside it is
    slender (8 degrees), the plate not (2): the words give both and name the triangle."""
    tri = triangle()
    assert ordinary_push_band_deg(tri.part) == pytest.approx(8.0)
    text = _no_plan_words([plate_with_hole(), tri])
    assert (
        "a push starting within 2-8° of a hilltop (8° on isosceles-right-triangle, a small "
        "slender part) may end on either side" in text
    )


def test_the_tolerances_words_name_the_slender_band_too():
    """With a shape tolerance declared the cause is the same vibration, said with the band."""
    text = largest_uncertainty(
        [slender_rhombus()], SENSOR, Uncertainty(1.0, 0.001, 0.0), PlanningOptions()
    )
    assert "nor does any rotation error without it: what leaves none is the feeder's" in text
    assert "(a push starting within 8° of a hilltop (the band of a small slender part)" in text


def test_the_band_words_follow_the_parts():
    assert push_band_words([plate_with_hole()]) == (
        "a push starting within 2° of a hilltop may end on either side"
    )
    assert "within 8° of a hilltop (the band of a small slender part)" in push_band_words(
        [triangle(), slender_rhombus()]
    )
