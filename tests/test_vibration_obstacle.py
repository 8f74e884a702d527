""" "No strong plan" names the vibration, not the rotation error, when only the ideal model has
a plan (docs/uncertainty.md, "Push bands")."""

from __future__ import annotations

import pytest

from feederkit.errors import PlanningError
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


def plate_with_hole():
    """A 45 x 28 plate with an 8 x 8 hole off centre: states 0 and 2 (1 and 3) are told apart
    by rotations whose ideal windows are 1.67 degrees wide, inside any push band."""
    hole = [(8, 8), (16, 8), (16, 16), (8, 16)]
    outline = make_outline("plate-hole", [(0, 0), (45, 0), (45, 28), (0, 28)], holes=[hole])
    return push_function(make_part(outline))


def test_the_vibration_not_the_rotation_error_is_named_when_only_the_ideal_model_plans():
    pf = plate_with_hole()
    sensor = ToleranceSensor(0.3)
    assert make_plan([pf], sensor, uncertainty=IDEAL, certify=False).plan["root"]
    with pytest.raises(PlanningError) as exc:
        make_plan([pf], sensor, uncertainty=Uncertainty(0.001, 0.0, 0.0), certify=False)
    text = str(exc.value)
    assert "no rotation error at all" not in text
    assert "a strong plan exists only on the ideal model (rotation error 0)" in text
    assert "not the rotation error but the feeder's vibration" in text
    assert "within 2° of a hilltop may end on either side, the push bands" in text
    assert "no smaller rotation error helps" in text
