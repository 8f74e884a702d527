"""Certificates of a plan: the largest uncertainty under which its actions keep their outcomes.

:func:`max_rotation_error` is exact for the model's fence cells; :func:`max_shape_tolerance`
bisects on :func:`~feederkit.mechanics.uncertain.uncertain_mechanics`, whose outcome sets grow
with the tolerance. A plan file states both (design.md, ``certificate``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from feederkit.angles import norm360
from feederkit.mechanics.outcomes import fence_outcomes, outcome_set, rest_window
from feederkit.mechanics.uncertain import BOUNDARY_EPS_DEG, UncertainMechanics, uncertain_mechanics
from feederkit.part import Part
from feederkit.uncertainty import Uncertainty
from feederkit.uncertainty import max_shape_tolerance as shape_tolerance_limit


def max_rotation_error(
    mech: UncertainMechanics,
    states: Iterable[int],
    action_deg: float,
    assumed: Mapping[int, frozenset[int]] | None = None,
) -> float:
    """The largest rotation error (deg, a supremum) keeping every outcome within the plan's sets.

    For each physical state ``s`` in ``states`` the plan assumes outcomes ``assumed[s]``
    (default: the outcome set at the declared error). Every error strictly below the result
    keeps ``outcome_set(s, action, err)`` within it: the distance from the action's window to
    the nearest cell whose targets leave the assumed set (bands included), less
    ``BOUNDARY_EPS_DEG`` (closer than that counts as touching). Exact for the model (the
    cells); 0 when even an exact rotation leaves the set; at most 90.
    """
    best = 90.0  # the smallest state's distance so far (before the boundary allowance)
    ends = {v for cell in mech.cells for v in (cell.lo, cell.hi)}
    for s in states:
        allowed = assumed[s] if assumed is not None else outcome_set(mech, s, action_deg)
        x0, y0 = rest_window(mech, s, action_deg, 0.0)
        dist = sorted({norm360(e - y0) for e in ends} | {norm360(x0 - e) for e in ends} | {0.0})
        dist = [d for d in dist if d < best] + [best]
        for k, d in enumerate(dist[:-1]):
            nxt = dist[k + 1]
            if not fence_outcomes(mech, x0 - d, y0 + d) <= allowed:
                best = d
                break
            mid = (d + nxt) / 2.0
            if not fence_outcomes(mech, x0 - mid, y0 + mid) <= allowed:
                best = d
                break
    # A window within BOUNDARY_EPS_DEG of a cell's end counts as on it (both sides'
    # outcomes), so the supremum the model can honour stops that far short. Taken once, of
    # the smallest distance, so the result is the same however the states are grouped.
    return best if best >= 90.0 else max(0.0, best - BOUNDARY_EPS_DEG)


def max_shape_tolerance(
    part: Part,
    base: Uncertainty,
    checks: Sequence[tuple[int, float, frozenset[int]]],
    *,
    rel_tol: float = 1e-3,
) -> float:
    """The largest shape tolerance (mm) under which every ``(ideal state, action, allowed)`` holds.

    A check holds when every ideal member of every outcome of the physical state holding the
    ideal state, after ``action`` at ``base``'s rotation error and COM tolerance, is in the
    ``allowed`` ideal ids. Found by bisection on :func:`uncertain_mechanics` (outcome sets grow
    with the tolerance) to ``rel_tol`` of the bound, half the smallest hull edge; returns the
    lower end of the final bracket, so the checks hold there; 0 when they fail at t = 0.
    """

    def holds(t: float) -> bool:
        unc = Uncertainty(base.rotation_error_deg, t, base.com_tolerance_mm)
        mech = uncertain_mechanics(part, unc)
        for ideal, action, allowed in checks:
            for start in mech.destinations[ideal]:
                out = outcome_set(mech, start, action)
                if any(mm not in allowed for p in out for mm in mech.states[p].members):
                    return False
        return True

    limit = shape_tolerance_limit(part)
    if not holds(0.0):
        return 0.0
    lo, hi = 0.0, limit * (1.0 - 1e-9)
    if holds(hi):
        return hi
    while hi - lo > rel_tol * limit:
        mid = (lo + hi) / 2.0
        lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    return lo


__all__ = ["max_rotation_error", "max_shape_tolerance"]
