"""Angles in degrees on the circle: normalisation, comparisons with a tolerance, and ranges
of rotations (the action and overlap ranges of section 3.2 are built on them)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

ANGLE_EPS = 1e-7
"""Angles closer than this (degrees) are the same angle."""


def norm360(a: float) -> float:
    """The angle in [0, 360)."""
    r = math.fmod(a, 360.0) + 0.0  # + 0.0 turns -0.0 into 0.0
    if r < 0.0:
        r += 360.0
    if r >= 360.0 - 1e-12:
        r = 0.0
    return r


def angle_close(a: float, b: float, eps: float = ANGLE_EPS) -> bool:
    """Whether two angles are the same on the circle within eps degrees."""
    d = norm360(a - b)
    return d < eps or 360.0 - d < eps


def merge_boundaries(
    boundary_lists: Sequence[Sequence[float]], eps: float = ANGLE_EPS
) -> list[float]:
    """Sorted union of boundary angles in [0, 360), angles within ``eps`` merged into one.

    The cells between consecutive merged boundaries are the overlap ranges of section 3.2.2
    when the lists are action-range boundaries.

    >>> merge_boundaries([[0.0, 90.0], [90.00000001, 180.0]])
    [0.0, 90.0, 180.0]
    """
    allb = sorted(norm360(b) for bl in boundary_lists for b in bl)
    out: list[float] = []
    for b in allb:
        if not out or b - out[-1] > eps:
            out.append(b)
    if len(out) > 1 and out[0] + 360.0 - out[-1] <= eps:
        out.pop()
    return out


@dataclass(frozen=True)
class RotationRange:
    """Rotations ``lo < a < hi`` (deg; ``hi`` may pass 360) that all have the same result.

    A plan rotates by the ``representative``, the middle; the ``margin``, the half-width, is
    the rotation error the action tolerates (Akella & Mason 1999, section 3.2.2).
    """

    lo: float
    hi: float

    @property
    def representative(self) -> float:
        """The middle of the range, in [0, 360)."""
        return norm360((self.lo + self.hi) / 2.0)

    @property
    def margin(self) -> float:
        """Half the width of the range (deg)."""
        return (self.hi - self.lo) / 2.0


@dataclass(frozen=True)
class ActionRange:
    """Rotations ``lo < a < hi`` taking a state to state ``target`` (definition 9).

    Degrees; ``lo`` in [0, 360), ``hi`` may pass 360.
    """

    lo: float
    hi: float
    target: int
