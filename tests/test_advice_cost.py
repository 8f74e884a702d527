"""The words given after a plan compare each pose once, not once per result.

A mix of three dense outlines of one shape under ``--time-limit 5`` answered after 34 s: the
warning on poses that do not look alike compared the outline's poses anew for every result
listing several states of a part (528 comparisons of a 20,000-point boundary). The words
must not cost more than the machine's build, which compares them once.
"""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans import advice
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor

symmetry = importlib.import_module("feederkit.mechanics.symmetry")


def _star(name: str, n: int, mirror: bool = False):
    radius = [40 + 8 * math.sin(3 * 2 * math.pi * k / n) for k in range(n)]
    pts = [
        (r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n))
        for k, r in enumerate(radius)
    ]
    if mirror:
        pts = [(-x, y) for x, y in reversed(pts)]
    return push_function(make_part(make_outline(name, pts)))


def test_unlike_poses_are_compared_once_per_pose(monkeypatch: pytest.MonkeyPatch) -> None:
    pfs = [_star("a", 60), _star("b", 90), _star("c", 60, mirror=True)]
    made = make_plan(pfs, ToleranceSensor(0.3), certify=False)
    placed: list[int] = []
    real = symmetry._placed

    def counting(pf, state):
        placed.append(state)
        return real(pf, state)

    monkeypatch.setattr(symmetry, "_placed", counting)
    assert advice.unlike_twins_words(made.result, pfs) == made.unoriented
    # Each part's poses are placed once for all the results (27 placements per leaf before).
    assert 0 < len(placed) <= sum(pf.n for pf in pfs)


def test_poses_differences_are_each_pairs_poses_difference() -> None:
    pf = _star("a", 60)
    sets = [((0,), (1,)), ((0, 1), (2,)), ((1,), (0, 2)), ((2,), (2,))]
    got = symmetry.poses_differences(pf, sets)
    want = [symmetry.poses_difference(pf, g, h) for g, h in sets]
    assert np.allclose(got, want, rtol=0.0, atol=1e-9)
    assert got[-1] == pytest.approx(0.0, abs=1e-12)
    assert max(got[:3]) > 0.01  # poses of a 60-point star differ a little
