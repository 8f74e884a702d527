"""Angles in degrees on the circle: normalisation, comparisons with a tolerance, and ranges
of rotations (the action and overlap ranges of section 3.2 are built on them)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

ANGLE_EPS = 1e-7
"""Angles closer than this (degrees) are the same angle."""

WIDTH_QUANTUM_DEG = 1e-9
"""Widths of rotation ranges are compared in whole multiples of this (degrees) when a plan
chooses among ranges: the mirror-image ranges of a symmetric part differ only by rounding,
and rounding differs between machines (numpy's vectorised trigonometry), so their margins
count as equal and the smaller rotation decides, the same plan everywhere."""


def width_key(width: float) -> int:
    """A range's width (deg) in whole ``WIDTH_QUANTUM_DEG``, to order ranges by (the larger
    key the wider; rounded half to even, as ``numpy.rint`` of ``width * 1e9``).

    >>> width_key(51.430321637587525) == width_key(51.43032163758751)
    True
    """
    return round(width * 1e9)


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


def boundary_cells(
    boundary_lists: Sequence[Sequence[float]], eps: float = ANGLE_EPS
) -> list[tuple[float, float]]:
    """The open cells between consecutive boundary angles that are wider than ``eps``.

    A cell runs from one boundary to the next (``lo`` in [0, 360), ``hi`` may pass 360), so
    no boundary lies inside it and its middle is half its width from the nearest boundary:
    for action-range boundaries these are the overlap ranges a plan can rotate in (section
    3.2.2), each with its true margin. Cells no wider than ``eps`` are left out: no robot
    holds such a rotation (docs/conventions.md, "Numeric tolerances"). With boundaries
    grouped as :func:`merge_boundaries` groups them, these are exactly the cells from the
    last boundary of one group to the first of the next that are wider than ``eps``.

    >>> boundary_cells([[10.0, 90.0], [90.00000005, 200.0]])
    [(10.0, 90.0), (90.00000005, 200.0), (200.0, 370.0)]
    >>> boundary_cells([[359.99999995, 0.0, 180.0]])
    [(0.0, 180.0), (180.0, 359.99999995)]
    """
    allb = sorted(norm360(b) for bl in boundary_lists for b in bl)
    return cells_between(allb, eps)


def cells_between(bounds: Sequence[float], eps: float = ANGLE_EPS) -> list[tuple[float, float]]:
    """:func:`boundary_cells` of boundaries already sorted in [0, 360)."""
    if not bounds:
        return []
    out = [(a, b) for a, b in zip(bounds, bounds[1:], strict=False) if b - a > eps]
    last, wrap = bounds[-1], bounds[0] + 360.0
    if wrap - last > eps:
        out.append((last, wrap))
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
