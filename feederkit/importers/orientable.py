"""Whether pushing can orient a part: at least one stable well the fence really feels.

A potential well is a run of resting ranges of the radius function between two divergent
orientations. Each stable state starts as its own well; a well whose barrier (the rise of
the radius function from its bottom to the lower of the divergent orientations bounding it)
is no more than the hull tolerance is merged with the neighbour across that barrier, the
shallowest first, as their bottoms and barriers are below what the hull model resolves
(:func:`wells`). A well is useful when its resting range is at least
:data:`MIN_RESTING_RANGE_DEG` wide and it is deeper than the hull tolerance.

So a disk, flattened and simplified, has many stable edges whose wells are no deeper than
the simplification error: they all merge into one ring with no divergent orientation left to
climb to (the last one left is no deeper than the tolerance), and none is useful. An
ellipse's hull vertex at the end of its minor axis splits its deep well into two stable
states separated by a barrier of a few micrometres: they merge into one well, as deep as the
axes differ (a 60 x 30 ellipse: 15 mm, not 0.005 mm).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from feederkit.hull import REL_LENGTH_TOL
from feederkit.mechanics import PushFunction, push_function, radius
from feederkit.part import Part

MIN_RESTING_RANGE_DEG = 2.0
"""A stable state whose resting range is narrower than this keeps no useful margin."""


@dataclass(frozen=True)
class Orientability:
    """Verdict on a part: ``orientable`` and, when not, the ``reason`` in one line.

    ``useful_states`` counts the useful wells (stable states, merged across barriers no deeper
    than the hull tolerance: see :func:`wells`); ``widest_range_deg`` is the widest resting
    range of one stable state and ``deepest_well_mm`` the deepest well, merged or not.
    """

    orientable: bool
    reason: str | None
    useful_states: int
    widest_range_deg: float
    deepest_well_mm: float


@dataclass(frozen=True)
class Well:
    """A potential well: resting ranges from ``lo_deg`` to ``hi_deg`` (unwrapped, so
    ``hi_deg - lo_deg`` is its width), holding ``states`` (ids), its lowest radius ``bottom_mm``
    and the radius at its two bounding divergent orientations."""

    lo_deg: float
    hi_deg: float
    states: tuple[int, ...]
    bottom_mm: float
    r_lo_mm: float
    r_hi_mm: float

    @property
    def width_deg(self) -> float:
        return self.hi_deg - self.lo_deg

    @property
    def depth_mm(self) -> float:
        """The rise from the bottom to the lower bounding divergent orientation."""
        return min(self.r_lo_mm, self.r_hi_mm) - self.bottom_mm


def well_depth(part: Part, normal_deg: float, lo_deg: float, hi_deg: float) -> float:
    """How far the radius function rises from a stable normal to the lower of its range's ends."""
    r = radius(part, [normal_deg, lo_deg, hi_deg])
    return float(min(r[1], r[2]) - r[0])


def _join(a: Well, b: Well) -> Well:
    """Well ``a`` and its counter-clockwise neighbour ``b`` as one well."""
    return Well(
        a.lo_deg,
        a.lo_deg + a.width_deg + b.width_deg,
        a.states + b.states,
        min(a.bottom_mm, b.bottom_mm),
        a.r_lo_mm,
        b.r_hi_mm,
    )


def wells(pf: PushFunction, tol: float) -> tuple[tuple[Well, ...], float]:
    """The wells of a push function, stable states merged across barriers up to ``tol``.

    Starting from one well per resting range (counter-clockwise from ``divergent_deg[0]``),
    the shallowest well of depth ``<= tol`` is merged with its neighbour across its lower
    bounding divergent orientation, until every well is deeper than ``tol``; when the last
    well (bounded on both sides by the one divergent orientation left) is no deeper, the
    radius function is a ring within ``tol`` and there is no well. Also returns the depth of
    the deepest well met, merged ones included.
    Merging the shallowest first means a shallow well joins a deeper neighbour (a gear's tip
    land joins the gap beside it) instead of chaining deep wells together.
    """
    m = len(pf.divergent_deg)
    if m == 0:
        return (), 0.0
    div = np.asarray(pf.divergent_deg, dtype=float)
    peaks = np.asarray(radius(pf.part, div), dtype=float).reshape(-1)
    normals = np.asarray([pf.states[pf.range_state[k]].normal_deg for k in range(m)])
    bottoms = np.asarray(radius(pf.part, normals), dtype=float).reshape(-1)
    ring: dict[int, Well] = {}
    for k in range(m):
        hi = div[k + 1] if k + 1 < m else div[0] + 360.0
        ring[k] = Well(
            float(div[k]),
            float(hi),
            (pf.range_state[k],),
            float(bottoms[k]),
            float(peaks[k]),
            float(peaks[(k + 1) % m]),
        )
    prev = {k: (k - 1) % m for k in range(m)}
    nxt = {k: (k + 1) % m for k in range(m)}
    deepest = max(w.depth_mm for w in ring.values())
    heap = [(w.depth_mm, k, w) for k, w in ring.items()]
    heapq.heapify(heap)
    fresh = m
    while heap:
        depth, k, w = heapq.heappop(heap)
        if ring.get(k) is not w:
            continue  # stale: merged since
        if depth > tol:
            break
        if len(ring) == 1:  # no deeper than tol all round: a ring, no well
            return (), deepest
        # across the lower of its two bounding divergent orientations
        left, right = (prev[k], k) if w.r_lo_mm <= w.r_hi_mm else (k, nxt[k])
        before, after = prev[left], nxt[right]
        joined = _join(ring.pop(left), ring.pop(right))
        key, fresh = fresh, fresh + 1
        ring[key] = joined
        if ring.keys() == {key}:  # the last two: one well, bounded on both sides by one peak
            before = after = key
        prev[key], nxt[key] = before, after
        nxt[before], prev[after] = key, key
        deepest = max(deepest, joined.depth_mm)
        heapq.heappush(heap, (joined.depth_mm, key, joined))
    first = min(ring, key=lambda k: ring[k].lo_deg % 360.0)
    out, k = [], first
    for _ in range(len(ring)):
        out.append(ring[k])
        k = nxt[k]
    return tuple(out), deepest


def orientability(part: Part, hull_tolerance: float | None) -> Orientability:
    """Decide whether ``part`` can be oriented by pushing (see the module docstring)."""
    tol = REL_LENGTH_TOL * part.size if hull_tolerance is None else hull_tolerance
    pf = push_function(part)
    widest = max((s.resting_range_deg[1] - s.resting_range_deg[0] for s in pf.states), default=0.0)
    found, deepest = wells(pf, tol)
    useful = sum(1 for w in found if w.width_deg >= MIN_RESTING_RANGE_DEG and w.depth_mm > tol)
    if useful:
        return Orientability(True, None, useful, widest, deepest)
    reason = (
        f"no stable edge keeps a useful margin (a resting range of at least "
        f"{MIN_RESTING_RANGE_DEG:g} deg and a well deeper than {tol:.3g} mm, stable edges "
        f"separated by a barrier no deeper than that counted as one well; widest "
        f"{widest:.2f} deg, deepest {deepest:.3g} mm): the part is disk-like"
    )
    return Orientability(False, reason, 0, widest, deepest)
