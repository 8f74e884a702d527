"""Outcome sets of push-align operations under uncertainty (the machine's transitions).

Where a push from a fence orientation can end (:func:`fence_outcomes`), where a rotation from
a physical state can end (:func:`outcome_set`, the robot off by up to the rotation error and
the part anywhere in its rest interval), and the piecewise-constant outcome sets of every
rotation (:func:`action_map`): at zero uncertainty the ideal action ranges of definition 9
(Akella & Mason 1999, section 5) with singleton targets, a superset otherwise
(:mod:`feederkit.mechanics.uncertain` gives the facts they rest on).
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

from feederkit.angles import norm360
from feederkit.mechanics.uncertain import BOUNDARY_EPS_DEG, UncertainMechanics


def fence_outcomes(mech: UncertainMechanics, lo_deg: float, hi_deg: float) -> frozenset[int]:
    """Physical states a push can end in from any fence orientation in the closed [lo, hi].

    Exact at zero uncertainty (the ideal push, both neighbours exactly at a divergent
    orientation, closed to within ``BOUNDARY_EPS_DEG`` so rounding cannot lose a side); a
    superset otherwise. O(log cells + cells met).
    """
    lo_deg, hi_deg = lo_deg - BOUNDARY_EPS_DEG, hi_deg + BOUNDARY_EPS_DEG
    cells = mech.cells
    q = len(cells)
    if hi_deg - lo_deg >= 360.0 or q == 1:
        return frozenset(t for cell in cells for t in cell.targets)
    los = mech.cell_los
    base = los[0]
    x = base + norm360(lo_deg - base)
    y = x + (hi_deg - lo_deg)
    i = bisect.bisect_right(los, x) - 1
    if i > 0 and not cells[i].closed and x <= cells[i - 1].hi:
        i -= 1  # x closes the band before this open cell
    j = bisect.bisect_right(los, y) - 1
    if j >= 0 and j < len(los) and not cells[j % q].closed and y <= los[j]:
        j -= 1  # an open cell starting at y does not hold it
    out: set[int] = set()
    for k in range(i, j + 1):
        out |= cells[k % q].targets
    return frozenset(out)


def rest_window(
    mech: UncertainMechanics, state: int, action: float, err: float
) -> tuple[float, float]:
    """The fence orientations physical ``state`` can reach after rotating by ``action`` with
    the robot off by up to ``err``: its rest interval turned back by ``action +- err``."""
    rest_lo, rest_hi = mech.states[state].rest_deg
    return rest_lo - action - err, rest_hi - action + err


def outcome_set(
    mech: UncertainMechanics, state: int, action_deg: float, rotation_error_deg: float | None = None
) -> frozenset[int]:
    """Physical states the part can end in from physical ``state`` after the rotation ``action``.

    The robot turns by ``action +- rotation_error`` (closed; default the declared error) and
    the part rests anywhere in its rest interval; ``theta' = theta - a`` (design.md).
    """
    err = mech.uncertainty.rotation_error_deg if rotation_error_deg is None else rotation_error_deg
    return fence_outcomes(mech, *rest_window(mech, state, action_deg, err))


def action_map(
    mech: UncertainMechanics, state: int, rotation_error_deg: float | None = None
) -> tuple[tuple[float, float, frozenset[int]], ...]:
    """The piecewise-constant outcome sets of every rotation from physical ``state``.

    Sorted ``(lo, hi, targets)``: every rotation strictly inside ``(lo, hi)`` (``lo`` in
    [0, 360), ``hi`` may pass 360) has the outcome set ``targets``; together they cover the
    circle. At zero uncertainty these are the ideal action ranges (definition 9) with
    singleton targets; at a boundary itself :func:`outcome_set` gives the union of both sides.
    """
    err = mech.uncertainty.rotation_error_deg if rotation_error_deg is None else rotation_error_deg
    x, y = rest_window(mech, state, 0.0, err)
    if y - x >= 360.0 or len(mech.cells) == 1:
        return ((0.0, 360.0, fence_outcomes(mech, 0.0, 360.0)),)
    ends = sorted({v for cell in mech.cells for v in (cell.lo, cell.hi)})
    cuts = sorted({norm360(x - e) for e in ends} | {norm360(y - e) for e in ends})
    merged: list[float] = []
    for v in cuts:
        if not merged or v - merged[-1] > 1e-12:
            merged.append(v)
    if len(merged) > 1 and merged[0] + 360.0 - merged[-1] <= 1e-12:
        merged.pop()
    out: list[tuple[float, float, frozenset[int]]] = []
    for k, lo in enumerate(merged):
        hi = merged[k + 1] if k + 1 < len(merged) else merged[0] + 360.0
        mid = (lo + hi) / 2.0
        targets = fence_outcomes(mech, x - mid, y - mid)
        if out and out[-1][2] == targets:
            out[-1] = (out[-1][0], hi, targets)
        else:
            out.append((lo, hi, targets))
    if len(out) > 1 and out[0][2] == out[-1][2]:
        first = out.pop(0)
        out[-1] = (out[-1][0], first[1] + 360.0, first[2])
    return tuple(out)


def outcome_at(
    amap: Sequence[tuple[float, float, frozenset[int]]], action_deg: float
) -> frozenset[int]:
    """The outcome set of a rotation strictly inside one of ``amap``'s ranges."""
    a = norm360(action_deg)
    los = [lo for lo, _, _ in amap]
    k = bisect.bisect_right(los, a) - 1
    return amap[k][2] if k >= 0 else amap[-1][2]


__all__ = ["action_map", "fence_outcomes", "outcome_at", "outcome_set", "rest_window"]
