"""Action ranges of a part's stable states, from its push function (section 3.2.1).

An action ``a`` rotates the part counter-clockwise by ``a`` degrees before the next push, so
the fence orientation becomes ``theta - a`` (design.md). The action range from state ``s_i``
(stable orientation ``psi_i``) to state ``s_j`` (resting range ``(lo_j, hi_j)``) is the open
interval ``(psi_i - hi_j, psi_i - lo_j)`` (definition 9, in design.md's sign convention).
The overlap ranges of a set of states (section 3.2.2) are the machine's business:
:func:`feederkit.machine.overlap_ranges`; the range types live in :mod:`feederkit.angles`.
"""

from __future__ import annotations

from feederkit.angles import ActionRange, RotationRange, merge_boundaries, norm360
from feederkit.mechanics.push import PushFunction, push

__all__ = ["ActionRange", "RotationRange", "action_ranges", "merge_boundaries"]


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
