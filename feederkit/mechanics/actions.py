"""Action ranges and overlap ranges (section 3.2).

An action ``a`` rotates the part counter-clockwise by ``a`` degrees before the next push, so
the fence orientation becomes ``theta - a`` (design.md). The action range from state ``s_i``
(stable orientation ``psi_i``) to state ``s_j`` (resting range ``(lo_j, hi_j)``) is the open
interval ``(psi_i - hi_j, psi_i - lo_j)`` (definition 9, in design.md's sign convention).
Overlap ranges of a set of states are the cells of the merged boundaries of their action
ranges; any action inside one has the same result for every state of the set.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.angles import ANGLE_EPS, norm360
from feederkit.mechanics.push import PushFunction, push


@dataclass(frozen=True)
class ActionRange:
    """Rotations ``lo < a < hi`` taking a state to ``target``.

    Degrees; ``lo`` in [0, 360), ``hi`` may pass 360.
    """

    lo: float
    hi: float
    target: int


@dataclass(frozen=True)
class RotationRange:
    """Rotations ``lo < a < hi`` (deg; ``hi`` may pass 360) that all have the same result.

    A plan rotates by the ``representative``, the middle; the ``margin``, the half-width, is
    the rotation error the action tolerates.
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
class OverlapRange(RotationRange):
    """A cell of the overlap of several states' action ranges (section 3.2.2).

    ``targets[k]`` is where the k-th state of the set goes for any rotation in ``(lo, hi)``.
    """

    targets: tuple[int, ...]


def action_ranges(pf: PushFunction, state: int) -> tuple[ActionRange, ...]:
    """The action ranges of ``state`` to every state (definition 9), smallest boundary first."""
    psi = pf.states[state].normal_deg
    bounds = sorted({norm360(psi - d) for d in pf.divergent_deg})
    out = []
    m = len(bounds)
    for k in range(m):
        lo = bounds[k]
        hi = bounds[(k + 1) % m] if k + 1 < m else bounds[0] + 360.0
        mid = (lo + hi) / 2.0
        out.append(ActionRange(lo, hi, push(pf, psi - mid).id))
    return tuple(out)


def merge_boundaries(
    boundary_lists: Sequence[Sequence[float]], eps: float = ANGLE_EPS
) -> list[float]:
    """Sorted union of boundary angles in [0, 360), angles within ``eps`` merged into one."""
    allb = sorted(norm360(b) for bl in boundary_lists for b in bl)
    out: list[float] = []
    for b in allb:
        if not out or b - out[-1] > eps:
            out.append(b)
    if len(out) > 1 and out[0] + 360.0 - out[-1] <= eps:
        out.pop()
    return out


def target_at(ranges: Sequence[ActionRange], action: float) -> int:
    """The target of a state's action ranges for a rotation strictly inside one of them."""
    a = norm360(action)
    los = [r.lo for r in ranges]
    k = bisect.bisect_right(los, a) - 1
    return ranges[k].target if k >= 0 else ranges[-1].target


def overlap_ranges(range_lists: Sequence[Sequence[ActionRange]]) -> list[OverlapRange]:
    """Overlap ranges of a set of states given each state's action ranges (section 3.2.2).

    A set of ``k`` states of a part with ``n`` stable states has at most ``k n`` of them.
    """
    bounds = merge_boundaries([[r.lo for r in rl] for rl in range_lists])
    out = []
    m = len(bounds)
    for k in range(m):
        lo = bounds[k]
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        mid = (lo + hi) / 2.0
        out.append(OverlapRange(lo, hi, tuple(target_at(rl, mid) for rl in range_lists)))
    return out
