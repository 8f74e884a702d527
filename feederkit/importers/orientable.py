"""Whether pushing can orient a part: at least one stable edge the fence really feels.

A stable state is useful when its resting range is at least :data:`MIN_RESTING_RANGE_DEG`
wide and its potential well is deeper than the hull tolerance: the radius function rises by
more than the tolerance from the stable edge to both divergent orientations beside it. A
disk, flattened and simplified, has many stable edges, but their wells are no deeper than
the simplification error, so none is useful.
"""

from __future__ import annotations

from dataclasses import dataclass

from feederkit.hull import REL_LENGTH_TOL
from feederkit.mechanics import push_function, radius
from feederkit.part import Part

MIN_RESTING_RANGE_DEG = 2.0
"""A stable state whose resting range is narrower than this keeps no useful margin."""


@dataclass(frozen=True)
class Orientability:
    """Verdict on a part: ``orientable`` and, when not, the ``reason`` in one line.

    ``useful_states`` counts the stable states that keep a useful margin; ``widest_range_deg``
    and ``deepest_well_mm`` are the best resting range and well depth over all states.
    """

    orientable: bool
    reason: str | None
    useful_states: int
    widest_range_deg: float
    deepest_well_mm: float


def well_depth(part: Part, normal_deg: float, lo_deg: float, hi_deg: float) -> float:
    """How far the radius function rises from a stable normal to the lower of its range's ends."""
    r = radius(part, [normal_deg, lo_deg, hi_deg])
    return float(min(r[1], r[2]) - r[0])


def orientability(part: Part, hull_tolerance: float | None) -> Orientability:
    """Decide whether ``part`` can be oriented by pushing (see the module docstring)."""
    tol = REL_LENGTH_TOL * part.size if hull_tolerance is None else hull_tolerance
    pf = push_function(part)
    widest, deepest, useful = 0.0, 0.0, 0
    for state in pf.states:
        lo, hi = state.resting_range_deg
        width = hi - lo
        depth = well_depth(part, state.normal_deg, lo, hi)
        widest, deepest = max(widest, width), max(deepest, depth)
        if width >= MIN_RESTING_RANGE_DEG and depth > tol:
            useful += 1
    if useful:
        return Orientability(True, None, useful, widest, deepest)
    reason = (
        f"no stable edge keeps a useful margin (a resting range of at least "
        f"{MIN_RESTING_RANGE_DEG:g} deg and a well deeper than {tol:.3g} mm; widest "
        f"{widest:.2f} deg, deepest {deepest:.3g} mm): the part is disk-like"
    )
    return Orientability(False, reason, 0, widest, deepest)
