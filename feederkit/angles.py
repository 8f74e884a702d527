"""Angles in degrees on the circle: normalisation and comparisons with a tolerance."""

from __future__ import annotations

import math

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


def ccw_delta(a: float, b: float) -> float:
    """Counter-clockwise distance from angle a to angle b, in [0, 360)."""
    return norm360(b - a)


def angle_close(a: float, b: float, eps: float = ANGLE_EPS) -> bool:
    """Whether two angles are the same on the circle within eps degrees."""
    d = norm360(a - b)
    return d < eps or 360.0 - d < eps


def in_open_arc(x: float, lo: float, hi: float) -> bool:
    """Whether x lies strictly inside the counter-clockwise arc from lo to hi."""
    span = ccw_delta(lo, hi)
    if span == 0.0:
        span = 360.0
    d = ccw_delta(lo, x)
    return 0.0 < d < span


def deg_atan2(y: float, x: float) -> float:
    """atan2 in degrees, in [0, 360)."""
    return norm360(math.degrees(math.atan2(y, x)))
