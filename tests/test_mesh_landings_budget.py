"""A mesh whose landings run out of the import's time says what it was doing.

A 320-facet icosphere (a ball) was refused "the import took longer than 30 s (use
--import-time-limit to allow more)", and a limit of 170 s did not help a 2,112-facet ball:
the time goes into comparing its hundreds of resting poses, none of which a fence orients.
"""

from __future__ import annotations

import dataclasses

import pytest

from feederkit.errors import InputError
from feederkit.importers.budget import Budget, ImportLimits
from feederkit.landing.mesh import ROUND_BODY_POSES, _naming_poses


def _spent(label: str) -> Budget:
    limits = dataclasses.replace(ImportLimits(), seconds=1.0, started=0.0)  # long past
    return Budget(limits, label)


def test_a_ball_out_of_time_is_named_a_near_round_body() -> None:
    check = _naming_poses(_spent("ball.stl"), 320)
    with pytest.raises(InputError) as exc:
        check()
    text = str(exc.value)
    assert text.startswith("ball.stl: the import took longer than 1 s")
    assert "comparing the mesh's 320 resting poses (a near-round body such as a ball" in text
    assert "\n" not in text


def test_a_mesh_of_few_poses_out_of_time_names_only_the_poses() -> None:
    check = _naming_poses(_spent("box.stl"), ROUND_BODY_POSES - 1)
    with pytest.raises(InputError, match=r"comparing the mesh's 99 resting poses$"):
        check()


def test_the_check_passes_while_time_is_left() -> None:
    _naming_poses(Budget(ImportLimits(), "ok.stl"), 500)()
