"""Push-align mechanics under uncertainty: physical resting states, bands and outcome sets.

The ideal model (section 3) knows the part exactly. Here (design.md, "Uncertainty") every hull
vertex may lie within ``t`` mm of its drawn position, the COM within ``c`` mm, and the robot's
rotation is off by up to ``r`` degrees. Everything rests on three facts, with ``eps = t + c``:

* (F1) the perturbed radius function is within ``eps`` of the drawn one at every orientation;
* (F2) its local maxima lie in the directions from the perturbed COM to perturbed vertices, so
  within ``asin(eps / rho_j)`` of the drawn direction to vertex ``j`` (``rho_j`` its distance
  from the COM), and only vertices with ``rho_j >= R - 2 eps`` can hold the highest point of a
  hill of height ``R``;
* (F3) the part rests on a perturbed hull edge: a chord of drawn vertices ``a .. b`` whose
  intermediate vertices lie within ``2 t`` of it (they may fall inside), whose normal is within
  ``asin(2 t / |v_b - v_a|)`` of the chord's, and on which the COM's foot can fall.

A push descends the perturbed radius function and can never pass one of its local maxima, so
from a fence orientation it ends on a rest candidate (F3) between the nearest certain hills on
either side (F1, F2: a hilltop whose barriers both exceed ``2 eps``, or a run of hilltops whose
highest stands more than ``2 eps`` above the wells on either side), and never where the drawn
radius is more than ``2 eps`` above its start (F1); a push starting within ``PUSH_BAND_DEG``
of a hilltop (``SLENDER_BAND_DEG`` on a slender part checked at 20 mm), or beside a shallow
state or a near-metastable facet less than twice the vibration below it, may be carried over it
(the push bands, measured in the physics check), and may then go on over a near, low hilltop
beyond (``OVERSHOOT_BAND_DEG``, measured too).
With ``t = c = 0`` and no vibration every set here is the ideal one exactly; otherwise each is
a superset of what the perturbed parts can do (provably conservative), and the docstrings say
which.
docs/uncertainty.md gives the derivations and the measured price of conservatism.
"""

from __future__ import annotations

import bisect
import heapq
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.angles import norm360
from feederkit.errors import InputError
from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.part import Part
from feederkit.uncertainty import Uncertainty, check_for_part

_BISECT_STEPS = 48
BOUNDARY_EPS_DEG = 1e-9
"""Fence orientations this close to a cell's end count as on it (both sides' outcomes)."""
PUSH_BAND_DEG = 2.0
"""A push starting less than this many degrees from an ordinary hilltop may end on either side.

Measured, not derived (docs/uncertainty.md, "Push bands"): in the physics check
(docs/simulation.md, MuJoCo) the part hits the fence at the belt's speed and chatters, and
pushes starting up to 1.07 degrees from a divergent orientation on the angle block, and up to
1.5 degrees on plain corners, ended on the far side; 2 degrees is the margin. Angular, not a
depth, so parts with the same push function (Lemma 8, symmetric poses) get the same bands.
"""
PUSH_BAND_FACTOR = 2.0
"""Beside a shallow state a push starting less than this many vibrations below the hilltop may
end on either side (the depth rule).

Measured (docs/uncertainty.md, "Push bands"): on the gear, whose tooth tips are states 0.14
vibrations deep, starts up to 3.6 degrees (0.86-0.99 vibrations) below a hilltop beside a tip
were carried over it onto the tip; the factor 2 is the margin.
"""
OVERSHOOT_DEG_MM = 175.0
"""A push ending in a state may carry on over a hilltop less than ``OVERSHOOT_DEG_MM / size``
degrees from the state's normal (``size`` in mm, at least :data:`OVERSHOOT_MIN_SIZE_MM`),
into the state beyond, when it comes down a basin at least twice that wide.

Measured, not derived (docs/uncertainty.md, "Overshoot"): in the physics check at the belt's
0.1 m/s a part coming down a long basin turns at 150-230 degrees per second and carries on
past the normal: a 20 mm 12-gon whose state has its hilltop 5.7 degrees from its normal on
one side and 51 on the other was overshot into the neighbour in 4 of 100 and 15 of 105 pushes
from its basin (two sweeps), the same shape at 30 mm in 1 of 105 and at 40 mm in none; other
20 mm polygons with hilltops 4.4 and 6.1 degrees away too; the catalog's 60 mm l-bracket,
2.98 degrees, in none of 100. The turn the belt gives (about v / size) against the fence's
friction carries the part about ``v^2 / (g mu size)`` past the normal: inversely as the size.
The quasi-static model has no such term, and a vibration (a share of the size) cannot stand for it.
"""
OVERSHOOT_MIN_SIZE_MM = 20.0
"""Parts smaller than this are taken at this size for :data:`OVERSHOOT_DEG_MM`, as the physics
check simulates them (docs/simulation.md, "Scale"); a small part's own dynamics are not
modelled."""
OVERSHOOT_BAND_DEG = 6.0
"""A push starting less than this many degrees beside a hilltop (or inside its band) may come
down the basin on that side and go on over the far hilltop into the state beyond, when that
hilltop is near and low (:func:`_overshoot_chain`): the overshoot of a push started near a
hilltop, at any size.

Measured, not derived (docs/uncertainty.md, "Overshoot"; ``benchmarks/bench_overshoot.py``):
such pushes started at most 3 degrees from their hilltop (the notched tab, random polygons, at
20 mm; at most 0.5 at 100 and 150 mm); 6 is the margin. The tab's pushes from 5 to 30 degrees
below a hilltop never went over (6 frictions each): a push from deep in a basin is not carried
this way, which is :data:`OVERSHOOT_DEG_MM`'s case.
"""
OVERSHOOT_FAR_DEG = 28.5
"""A push started near a hilltop (:data:`OVERSHOOT_BAND_DEG`) may go over a far hilltop less
than this many degrees past the normal of the state it comes down to.

Measured (docs/uncertainty.md, "Overshoot"): far hilltops up to 27.4 degrees past the normal
were gone over (a random 20 mm polygon; the catalog's rectangle-2x1 26.6), the catalog
l-bracket's at 29.45 degrees not (0 of 99 pushes at 72 mm, none at 20 and 40 mm), whatever
the size: the notched tab went over the same hilltops at 20-150 mm, the chamfered plate at
20-100 mm. The measurements leave no room for a wide margin here (1.04 either side).
"""
OVERSHOOT_DOWN_DEG = 60.0
"""... when it comes down to that normal from a hilltop less than this many degrees before it:
a longer descent loses the turn (measured: gone over from up to 57.7 degrees, never from the
12 basins come down from 60.3-99.6 degrees with a far hilltop inside
:data:`OVERSHOOT_FAR_DEG`; no room for a margin: 1.04 and 1.005)."""
OVERSHOOT_CLIMB_REL = 1.5
"""... and when the far hilltop stands less than this many times as high above the state's
well as the hilltop it came down from (measured: gone over up to as high, the catalog octagon's
equal hilltops in 1-2 of 27-46 pushes each, a chamfered square's at 20 and 60 mm; 1.5 is the
margin)."""
OVERSHOOT_MAX_HILLTOPS = 4
"""... over at most this many hilltops in a row (measured: at most 2, on six random polygons
and the 12-gon of ``tests/test_overshoot.py``; rolling over a flattened arc's facets is
:data:`ROLL_WELL_FACTOR`'s). It also bounds the work on outlines with many near, low
hilltops (a fine flattening's)."""
SLENDER_GYRATION_REL = 0.27
"""A part whose radius of gyration about its COM (its hull as a plate, as the physics check
simulates it) is less than this share of its size is slender: its ordinary hilltops get
:data:`SLENDER_BAND_DEG` instead of :data:`PUSH_BAND_DEG` when it is checked at 20 mm.

Measured (docs/uncertainty.md, "Push bands"): pushes from 0.1-7 degrees either side of every
hilltop, 12 frictions, the parts simulated at 20 mm. Hulls with the radius of gyration at
0.215-0.251 of the size were carried over hilltops from 2.9-6.0 degrees (triangles 30-30-120,
30-60-90, 45-45-90, 75-75-30, the 45-degree triangle with its right angle cut, rhombi of 45
and 60 degrees), one at 0.264 (a 50-60-70 triangle) from 2.1; those at 0.285-0.306 (the
catalog's quadrilateral, rectangle-2x1, a square and the equilateral triangle) from 1.9 at
most. Per hilltop neither the corner's angle, its distance from the COM nor its wells
separate them (the 45-45-90 triangle's right angle was carried from 4.0 degrees, its
45-degree corners from 3.4; a 75-75-30 triangle's 30-degree tip from 2.0): the chatter at the
fence turns a part the farther, the less inertia it has for its size. 0.27 splits them but
for one: a 15 x 9 mm bracket at 0.2747 was carried from up to 5 degrees (an open gap,
docs/uncertainty.md, "Known gaps": with the split above it the bracket has no strong plan at
any rotation error).
"""
SLENDER_BAND_DEG = 8.0
"""The push band (deg) at an ordinary hilltop of a slender part (:data:`SLENDER_GYRATION_REL`)
checked at 20 mm; narrowed for larger ones (:func:`ordinary_push_band_deg`).

Measured: carried from up to 6.0 degrees (the cut triangle's 135-degree corner), 5.8 (the
30-30-120 triangle's tips), 4.7, 4.6, 4.3 and 4.0 on the others; 8 is the margin, as 2 is
over 1.5 for :data:`PUSH_BAND_DEG`. The catalog's isosceles right triangle's sensorless plan,
made with 2 degrees, failed 3 of 400 trials (drops 3.2-3.4 degrees before a hilltop).
"""
SLENDER_MAX_SIZE_MM = 30.0
"""Slender parts this large or larger get :data:`PUSH_BAND_DEG` (the physics check simulates
them at their own size, where the chatter is gone): the 45-45-90 triangle, carried from 4.0
degrees at 20 mm, was carried from 1.8 at most at 24 mm and 0.3 at 30 mm (docs/uncertainty.md,
"Push bands"); between 20 mm and this the band falls linearly, above what was measured."""
ROLL_WELL_FACTOR = 5.0
"""A push ending in a state may roll on over a neighbouring hilltop less than this many
vibrations above the state's well (plus twice ``t + c``), into the state beyond, and on from
there by the same rule (an outcome, as a carry crossing: a part at rest stays). For parts
larger than :data:`OVERSHOOT_MIN_SIZE_MM` the factor falls as the square of the size: the
turn a part carries on by falls as the size (:data:`OVERSHOOT_DEG_MM`), the height of a
hilltop that far from a normal as its square over the size, and the vibration grows as the
size (the 20 mm 12-gon of ``tests/test_overshoot.py``, its state 7 a hilltop 1.8 vibrations
above its well, was carried over in 4-15 of 100 pushes at 20 mm, 1 of 105 at 30 mm, none at
40 mm).

Measured (docs/uncertainty.md, "Rolling over shallow wells"; ``benchmarks/parts/``): a 12 mm
D-washer whose arc is drawn as 24 facets missed the model's outcome sets in 571 of 840 pushes
near its hilltops (its LED plan failed 39 of 200 trials), each push rolling down one facet's
basin and on over the next low hilltops; with this rule at 2 vibrations 266 missed, at 2.5
none. Drawn as 18 facets: 311 of 760 missed, 125 at 3.5 vibrations, none at 4.5 (it rolled
over a hilltop 3.69 vibrations above a well, not over one at 5.42). 5 is the factor (as
``SHALLOW_WELL_FACTOR``, the same shallowness): a margin of 1.35 over the largest crossing
measured, less than the other constants' 2, and conservative elsewhere (the 12-facet arc's
wells of 2.4-3.5 vibrations did not roll: the facets' angular width matters too, which the
rule does not read). The quasi-static push stops at the first stable orientation; on the belt
the part arrives turning, and a well this shallow does not stop it.
"""
SHALLOW_WELL_FACTOR = 5.0
"""A state whose well beside a hilltop (the hilltop's radius minus the radius at the state's
normal) is less than this many vibrations deep is shallow: that hilltop gets the depth rule.

Chosen from the gear (docs/uncertainty.md, "Push bands"): its tooth tips, 0.14 vibrations
deep, carried pushes over both their hilltops; its roots are 8.6 deep. Over the catalog and the
sample drawings the wells lie below 2.2 vibrations (tips, arc facets) or above 9.5, with the
gear's roots the only ones between; 5 splits them with a margin on each side.
"""


@dataclass(frozen=True)
class RestCandidate:
    """A perturbed edge the part may rest on (F3): the chord from hull vertex ``start`` to ``end``.

    Its normal lies within ``half_width_deg`` of ``normal_deg`` for every shape in the tolerance
    zone; ``basin`` is the ideal stable state whose resting range holds ``normal_deg``;
    ``height_mm`` the COM's distance from the drawn chord (the radius function at its normal is
    within ``[height, height + 2 t]``: intermediate vertices lie at most ``2 t`` outside it).
    """

    start: int
    end: int
    normal_deg: float
    half_width_deg: float
    basin: int
    height_mm: float


@dataclass(frozen=True)
class Band:
    """The band around a certain hill between ideal states ``left`` and ``right``
    (counter-clockwise; :func:`_certain_hills`): one divergent orientation, or a run of them
    with the states between (the slot's tip and its two hilltops); ``divergent_deg`` is its
    highest hilltop.

    Every perturbed shape has a local maximum of its radius function in ``[top_lo_deg,
    top_hi_deg]`` (the F2 band; ``top_lo <= divergent <= top_hi``, ``top_hi`` may pass 360):
    no push ends beyond it. ``[lo_deg, hi_deg]`` holds it (``lo <= top_lo``, ``top_hi <= hi``):
    a push starting inside may end on either side, one starting outside never crosses it.
    With the vibration on it is the F2 band widened by the push band (:data:`PUSH_BAND_DEG`,
    or the depth rule beside a shallow state or a near-metastable facet: :func:`_bands`); at
    ``t = c = 0`` and vibration 0 both are the point.
    """

    divergent_deg: float
    lo_deg: float
    hi_deg: float
    left: int
    right: int
    top_lo_deg: float
    top_hi_deg: float

    @property
    def half_width_deg(self) -> float:
        """The larger distance from the divergent orientation to an end of the band."""
        return max(self.divergent_deg - self.lo_deg, self.hi_deg - self.divergent_deg)


@dataclass(frozen=True)
class PhysicalState:
    """A physical resting state: a cluster of adjacent ideal stable states (``members``, CCW).

    ``rest_deg`` ``(lo, hi)``, ``hi`` may pass 360: where the resting edge's normal can lie
    (a point, the ideal normal, at zero uncertainty). ``capture_deg``: the union of the members'
    ideal resting ranges. ``diameter`` ``(lo, hi)``: every reading of the part resting here,
    the min and max of the width over ``rest_deg`` widened by ``2 t`` (exact at zero
    uncertainty: the ideal state's diameter).
    """

    id: int
    members: tuple[int, ...]
    rest_deg: tuple[float, float]
    capture_deg: tuple[float, float]
    diameter: tuple[float, float]


@dataclass(frozen=True)
class FenceCell:
    """Fence orientations from ``lo`` to ``hi`` (deg, ``hi`` may pass 360) all settling into
    ``targets`` (physical state ids) for every shape in the tolerance zone.

    ``closed`` cells are bands (ends included); open cells lie between two bands.
    """

    lo: float
    hi: float
    closed: bool
    targets: frozenset[int]


@dataclass(frozen=True)
class UncertainMechanics:
    """The mechanics of one part under one declared uncertainty (what a machine is built from).

    ``state_of[i]`` is the physical state holding ideal stable state ``i``, None for the
    facets of a hill (no resting state: see :func:`uncertain_mechanics`); ``destinations[i]``
    are the physical states a part coming to
    rest in ideal state ``i`` may end in (its own, and those vibration may carry it to over a
    barrier below ``merge_threshold_mm``, vibration plus ``2 (t + c)``).
    ``cells`` tile the circle of fence orientations, starting at the first band.
    """

    push: PushFunction
    uncertainty: Uncertainty
    vibration_mm: float
    merge_threshold_mm: float
    candidates: tuple[RestCandidate, ...]
    bands: tuple[Band, ...]
    states: tuple[PhysicalState, ...]
    state_of: tuple[int | None, ...]
    destinations: tuple[frozenset[int], ...]
    cells: tuple[FenceCell, ...]
    cell_los: tuple[float, ...] = ()
    """The cells' ``lo`` over two turns (sorted, for bisection)."""

    @property
    def part(self) -> Part:
        """The part."""
        return self.push.part

    @property
    def n(self) -> int:
        """Number of physical states."""
        return len(self.states)


# --- geometry helpers ---------------------------------------------------------------------


def _radius(hull: np.ndarray, com: np.ndarray, phi_deg: np.ndarray) -> np.ndarray:
    phi = np.radians(np.atleast_1d(np.asarray(phi_deg, dtype=float)))
    u = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    return (u @ (hull - com).T).max(axis=-1)


def _normals(hull: np.ndarray) -> np.ndarray:
    d = np.roll(hull, -1, axis=0) - hull
    return np.mod(np.degrees(np.arctan2(-d[:, 0], d[:, 1])), 360.0)


def _support_index(unwrapped: np.ndarray, phi_deg: np.ndarray) -> np.ndarray:
    """The hull vertex supporting direction ``phi``: the first edge normal at or past it."""
    n = len(unwrapped)
    x = unwrapped[0] + np.mod(np.asarray(phi_deg, dtype=float) - unwrapped[0], 360.0)
    return np.searchsorted(unwrapped, x, side="left") % n


def width_range(
    hull: Sequence[Sequence[float]], lo_deg: float, hi_deg: float
) -> tuple[float, float]:
    """Exact min and max of the width (diameter function) over fence orientations [lo, hi].

    The width is piecewise sinusoidal with breaks at the edge normals and their opposites; on
    each piece it is ``<v_a - v_b, u(phi)>`` for the two supporting vertices, so its minimum is
    at an end or a break and its maximum also where a piece peaks (the direction of
    ``v_a - v_b``). Supporting vertices are found by binary search on the unwrapped normals:
    O(k log n) for k breaks in the arc.
    """
    h = np.asarray(hull, dtype=float)
    span = min(hi_deg - lo_deg, 360.0)
    nrm = _normals(h)
    unwrapped = nrm[0] + np.concatenate([[0.0], np.cumsum(np.mod(np.diff(nrm), 360.0))])
    breaks = np.mod(np.concatenate([nrm, nrm + 180.0]) - lo_deg, 360.0)
    pts = np.unique(np.concatenate([[0.0, span], breaks[breaks < span]]))
    phi = lo_deg + pts
    ends = np.concatenate([phi, lo_deg + (pts[:-1] + pts[1:]) / 2.0])
    a = _support_index(unwrapped, ends)
    b = _support_index(unwrapped, ends + 180.0)
    gap = h[a] - h[b]
    rad = np.radians(ends)
    w = gap[:, 0] * np.cos(rad) + gap[:, 1] * np.sin(rad)
    k = len(pts)
    lo_w, hi_w = float(w[:k].min()), float(w[:k].max())
    if k > 1:
        piece = gap[k:]
        peak = np.mod(np.degrees(np.arctan2(piece[:, 1], piece[:, 0])) - lo_deg, 360.0)
        inside = (peak > pts[:-1]) & (peak < pts[1:])
        if inside.any():
            hi_w = max(hi_w, float(np.hypot(piece[inside, 0], piece[inside, 1]).max()))
    return lo_w, hi_w


def _chord_sagitta(h: np.ndarray) -> Callable[[int, np.ndarray, np.ndarray], np.ndarray]:
    """For the hull ``h``: a function of ``m`` and the chords ``d`` from every vertex ``i`` to
    vertex ``i + m`` (their ``length``) giving, per chord, the largest distance from it of the
    vertices between its ends (a chord the perturbed part may rest on keeps them within
    twice the shape tolerance, F3).

    Along a convex counter-clockwise chain the distance from its chord is concave, largest
    at the vertex where the edges' direction passes the chord's: a binary search on the
    unwrapped edge directions finds it, so each ``m`` costs O(n log n) instead of O(n m)
    (a 20,000-point arc at its shape-tolerance bound, whose chords hold about 200
    vertices: its uncertain mechanics 11 s -> 2 s). A hull that is not a convex
    counter-clockwise chain (a hand-written file) measures every vertex between the ends.
    """
    n = len(h)
    e = np.roll(h, -1, axis=0) - h
    ang = np.arctan2(e[:, 1], e[:, 0])
    turns = np.mod(np.diff(ang), 2.0 * math.pi)
    idx = np.arange(n)

    def dist(k: np.ndarray, d: np.ndarray, length: np.ndarray) -> np.ndarray:
        rel = h[k % n] - h
        return np.abs(d[:, 0] * rel[:, 1] - d[:, 1] * rel[:, 0]) / length

    closing = math.remainder(float(ang[0] - ang[-1]), 2.0 * math.pi) % (2.0 * math.pi)
    if n < 3 or np.any(turns >= math.pi) or closing >= math.pi or turns.sum() >= 2.0 * math.pi:

        def every(m: int, d: np.ndarray, length: np.ndarray) -> np.ndarray:
            return np.max([dist(idx + k, d, length) for k in range(1, m)], axis=0)

        return every
    unwrapped = ang[0] + np.concatenate([[0.0], np.cumsum(turns)])
    twice = np.concatenate([unwrapped, unwrapped + 2.0 * math.pi])  # edges i..i+m-1, wrapped

    def sagitta(m: int, d: np.ndarray, length: np.ndarray) -> np.ndarray:
        chord = np.arctan2(d[:, 1], d[:, 0])
        chord = unwrapped + np.mod(chord - unwrapped, 2.0 * math.pi)  # in edge i's frame
        # The first edge of the chain turned past the chord starts at the farthest vertex.
        j = np.searchsorted(twice, chord, side="right")
        j = np.clip(j, idx + 1, idx + m - 1)
        best = dist(j, d, length)
        for k in (np.maximum(j - 1, idx + 1), np.minimum(j + 1, idx + m - 1)):
            best = np.maximum(best, dist(k, d, length))
        return best

    return sagitta


def _rest_candidates(pf: PushFunction, t: float, c: float) -> list[RestCandidate]:
    """Every chord the perturbed part may rest on (F3); the ideal stable edges when t = c = 0."""
    if t == 0.0 and c == 0.0:
        n = len(pf.part.hull)
        heights = _radius(
            np.asarray(pf.part.hull, dtype=float),
            np.asarray(pf.part.com, dtype=float),
            np.asarray([s.normal_deg for s in pf.states]),
        ).tolist()
        return [
            RestCandidate(s.edge, (s.edge + 1) % n, s.normal_deg, 0.0, s.id, hh)
            for s, hh in zip(pf.states, heights, strict=True)
        ]
    h = np.asarray(pf.part.hull, dtype=float)
    com = np.asarray(pf.part.com, dtype=float)
    n = len(h)
    idx = np.arange(n)
    div = np.asarray(pf.divergent_deg, dtype=float)
    out: list[RestCandidate] = []
    valid = np.ones(n, dtype=bool)
    farthest = _chord_sagitta(h)
    for m in range(1, n - 1):
        b = (idx + m) % n
        d = h[b] - h
        length = np.hypot(d[:, 0], d[:, 1])
        if m > 1:
            valid &= farthest(m, d, length) <= 2.0 * t
            if not valid.any():
                break
        ratio = np.minimum(1.0, 2.0 * t / length)
        turn = np.where(ratio < 1.0, np.arcsin(ratio), math.pi)
        chord_slack = 2.0 * np.sin(turn / 2.0)
        unit = d / length[:, None]
        along = np.einsum("ij,ij->i", com - h, unit)
        ahead = np.einsum("ij,ij->i", h[b] - com, unit)
        slack_a = np.hypot(*(com - h).T) * chord_slack + t + c
        slack_b = np.hypot(*(h[b] - com).T) * chord_slack + t + c
        possible = valid & (along + slack_a > 0.0) & (ahead + slack_b > 0.0)
        normal = np.mod(np.degrees(np.arctan2(-d[:, 0], d[:, 1])), 360.0)
        normal[normal >= 360.0] = 0.0
        height = unit[:, 0] * (com[1] - h[:, 1]) - unit[:, 1] * (com[0] - h[:, 0])
        sel = np.flatnonzero(possible)
        k = (np.searchsorted(div, normal[sel], side="right") - 1) % len(div)
        basin = np.asarray(pf.range_state)[k]
        out.extend(
            RestCandidate(a, bb, nd, hw, bs, hh)
            for a, bb, nd, hw, bs, hh in zip(
                sel.tolist(),
                b[sel].tolist(),
                normal[sel].tolist(),
                np.degrees(turn[sel]).tolist(),
                basin.tolist(),
                height[sel].tolist(),
                strict=True,
            )
        )
    return out


def _level_crossing(
    hull: np.ndarray, com: np.ndarray, low: np.ndarray, high: np.ndarray, level: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bisection brackets of where r, monotone on [low, high], crosses ``level`` (vectorized).

    Returns ``(below, above)``: r(below) < level <= r(above) when r rises from low to high.
    The radius at each probe is the projection of its supporting vertex (a binary search on
    the unwrapped edge normals), so a step costs O(hills log n), not O(hills n).
    """
    nrm = _normals(hull)
    unwrapped = nrm[0] + np.concatenate([[0.0], np.cumsum(np.mod(np.diff(nrm), 360.0))])
    rel = hull - com

    def radius(phi_deg: np.ndarray) -> np.ndarray:
        v = rel[_support_index(unwrapped, phi_deg)]
        phi = np.radians(phi_deg)
        return v[:, 0] * np.cos(phi) + v[:, 1] * np.sin(phi)

    rising = radius(high) >= radius(low)
    a, b = low.copy(), high.copy()
    for _ in range(_BISECT_STEPS):
        mid = (a + b) / 2.0
        up = radius(mid) >= level
        go_low = up == rising  # the crossing lies between a and mid
        b = np.where(go_low, mid, b)
        a = np.where(go_low, a, mid)
    return a, b


def _certain_hills(peaks: np.ndarray, wells: np.ndarray, eps: float) -> list[tuple[int, int]]:
    """The certain hills: the minimal runs of hilltops that every perturbed part keeps.

    Hilltop ``k`` lies between the wells ``wells[k - 1]`` and ``wells[k]`` (the drawn radius
    at the normals of the states on either side). A run of hilltops ``k .. e`` (unwrapped,
    ``k`` in [0, m), at most ``m - 1`` of them) between the wells ``A = wells[k - 1]`` and
    ``B = wells[e]`` is **certain** when its highest hilltop ``R`` has ``R - max(A, B) > 2 eps``:
    then (F1) every perturbed radius function is at least ``R - eps`` there and at most
    ``max(A, B) + eps`` at the two wells' normals, so its maximum over the run is a local
    maximum strictly inside, which no push passes. A single certain hilltop is a sure one
    (both barriers above ``2 eps``); a run is certain also when its hilltops are not one by one,
    as the slot's two low hilltops beside its shallow tip state, between the flat sides' wells.

    Returns the **minimal** certain runs ``(k, e)`` (no shorter certain run inside), sorted by
    ``k``. They never overlap: two certain runs sharing a hilltop without one holding the other
    always hold a shorter certain run (docs/uncertainty.md, "Certain hills"). At ``eps = 0``
    every hilltop is one (the ideal model).
    """
    m = len(peaks)
    if m < 2:
        return []
    if eps == 0.0:
        return [(k, k) for k in range(m)]
    ends = np.full(2 * m, -1)
    for k in range(m):
        run = (k + np.arange(m - 1)) % m
        top = np.maximum.accumulate(peaks[run])
        ok = top - np.maximum(wells[(k - 1) % m], wells[run]) > 2.0 * eps
        if ok.any():
            ends[k] = k + int(np.argmax(ok))
            ends[k + m] = ends[k] + m
    hills: list[tuple[int, int]] = []
    for k in range(m):
        e = int(ends[k])
        inner = ends[k + 1 : e + 1]
        if e >= 0 and not ((inner >= 0) & (inner <= e)).any():
            hills.append((k, e))
    return hills


def _bands(
    pf: PushFunction,
    eps: float,
    hills: Sequence[tuple[int, int]],
    peaks: np.ndarray,
    heights: np.ndarray,
    vibration: float = 0.0,
) -> list[Band]:
    """Bands around the certain hills (F1, F2: :func:`_certain_hills`), widened by the push
    bands; the divergent orientations when eps = 0 and ``vibration`` = 0.

    A hill's F2 band holds every perturbed hilltop that bounds the pushes: the maximum of the
    perturbed radius over the hill (height at least ``R - eps``, ``R`` its highest hilltop)
    lies where the drawn radius is at least ``R - 2 eps`` (from the first hilltop reaching that
    level, on its rising flank, to the last one's falling flank) and near a vertex at least
    that far out (F2). With ``vibration > 0`` it is widened on each flank (a push starting
    there may be carried over the hill: docs/uncertainty.md, "Push bands") by the push band of
    the outermost of those hilltops on that flank: :data:`PUSH_BAND_DEG`, or beside a shallow
    state (a well on either side less than :data:`SHALLOW_WELL_FACTOR` vibrations deep,
    ``heights`` the radius at each state's normal) as far as the drawn radius stays within
    :data:`PUSH_BAND_FACTOR` vibrations of that hilltop, if that is wider. Clipped to the
    normals of the wells on either side of the hill; and holding the band each of the hill's
    lower hilltops would get if it were sure. A hill of one hilltop is the sure hilltop of
    before, its band unchanged.
    """
    div = np.asarray(pf.divergent_deg, dtype=float)
    m = len(div)
    rs = pf.range_state
    psi = np.asarray([s.normal_deg for s in pf.states])
    if not hills:
        return []
    first_k = np.asarray([k for k, _ in hills])
    last_k = np.asarray([e for _, e in hills])
    ks = np.asarray([k + int(np.argmax(peaks[np.arange(k, e + 1) % m])) for k, e in hills])
    left = np.asarray([rs[(k - 1) % m] for k in first_k])
    right = np.asarray([rs[e % m] for e in last_k])

    def pos(i: np.ndarray) -> np.ndarray:  # unwrapped divergent orientation of hilltop i
        return div[i % m] + 360.0 * (i // m)

    d = pos(ks)
    top = peaks[ks % m]
    lo, hi = d.copy(), d.copy()
    if eps == 0.0 and vibration == 0.0:
        return _band_list(d, lo, hi, left, right, lo, hi)
    h = np.asarray(pf.part.hull, dtype=float)
    com = np.asarray(pf.part.com, dtype=float)
    # The outermost hilltops that may hold the perturbed maximum (drawn height >= R - 2 eps).
    level = top - 2.0 * eps
    outer_lo = np.asarray(
        [
            next(i for i in range(k, e + 1) if peaks[i % m] >= lv)
            for (k, e), lv in zip(hills, level, strict=True)
        ]
    )
    outer_hi = np.asarray(
        [
            next(i for i in range(e, k - 1, -1) if peaks[i % m] >= lv)
            for (k, e), lv in zip(hills, level, strict=True)
        ]
    )
    d_lo, d_hi = pos(outer_lo), pos(outer_hi)
    lpsi = d_lo - np.mod(d_lo - psi[np.asarray([rs[(i - 1) % m] for i in outer_lo])], 360.0)
    rpsi = d_hi + np.mod(psi[np.asarray([rs[i % m] for i in outer_hi])] - d_hi, 360.0)
    well_lo = d - np.mod(d - psi[left], 360.0)  # the hill's ends: its wells' normals
    well_hi = d + np.mod(psi[right] - d, 360.0)
    if eps > 0.0:
        lo, _ = _level_crossing(h, com, lpsi, d_lo, level)
        _, hi = _level_crossing(h, com, d_hi, rpsi, level)
        rho = np.hypot(*(h - com).T)
        alpha = np.degrees(np.arctan2(h[:, 1] - com[1], h[:, 0] - com[0]))
        spread = np.degrees(np.arcsin(np.minimum(1.0, eps / rho)))
        for j in range(len(ks)):
            if max(d[j] - lo[j], hi[j] - d[j]) >= 90.0:
                continue  # offsets within +-180 could wrap: keep the level crossings
            # F2: the highest point of the perturbed hill is near a vertex almost as far out.
            far = rho >= level[j]
            off = np.mod(alpha[far] - d[j] + 180.0, 360.0) - 180.0
            a_lo = np.maximum(off - spread[far], lo[j] - d[j])
            a_hi = np.minimum(off + spread[far], hi[j] - d[j])
            keep = a_lo <= a_hi
            if keep.any():
                lo[j] = d[j] + min(float(a_lo[keep].min()), 0.0)
                hi[j] = d[j] + max(float(a_hi[keep].max()), 0.0)
    top_lo, top_hi = lo.copy(), hi.copy()  # the F2 band: every perturbed hilltop
    if vibration > 0.0:
        w_lo = _push_band(pf, outer_lo, peaks, heights, vibration, d_lo, lpsi, rising=True)
        w_hi = _push_band(pf, outer_hi, peaks, heights, vibration, d_hi, rpsi, rising=False)
        lo = np.maximum(well_lo, lo - w_lo)
        hi = np.minimum(well_hi, hi + w_hi)
        for j, (k, e) in enumerate(hills):
            # A hilltop of the hill too low to hold its maximum keeps its own push band (its
            # band as if it were sure), so no push from outside the band is carried over it.
            low = [i for i in range(k, e + 1) if not outer_lo[j] <= i <= outer_hi[j]]
            if low:
                own = _bands(pf, eps, [(i % m, i % m) for i in low], peaks, heights, vibration)
                turns = [360.0 * (i // m) for i in low]
                lo[j] = min(lo[j], *(b.lo_deg + tn for b, tn in zip(own, turns, strict=True)))
                hi[j] = max(hi[j], *(b.hi_deg + tn for b, tn in zip(own, turns, strict=True)))
    turn = 360.0 * np.floor(d / 360.0)  # a hill led by hilltop m - 1 may peak past 360
    return _band_list(d - turn, lo - turn, hi - turn, left, right, top_lo - turn, top_hi - turn)


def _push_band(
    pf: PushFunction,
    hilltops: np.ndarray,
    peaks: np.ndarray,
    heights: np.ndarray,
    vibration: float,
    d: np.ndarray,
    flank_end: np.ndarray,
    *,
    rising: bool,
) -> np.ndarray:
    """The push band (deg) of each hilltop on one flank (``d`` its unwrapped orientation,
    ``flank_end`` the neighbouring state's normal): :func:`ordinary_push_band_deg` (the fixed
    angle, or the slender band), or beside a shallow state or a near-metastable facet
    (:func:`_near_metastable_hills`) as far as the drawn radius stays within
    :data:`PUSH_BAND_FACTOR` vibrations of the hilltop, if that is wider (docs/uncertainty.md,
    "Push bands")."""
    m = len(peaks)
    rs = pf.range_state
    width = np.full(len(hilltops), ordinary_push_band_deg(pf.part))
    k = hilltops % m
    wells = np.minimum(
        peaks[k] - heights[np.asarray([rs[(i - 1) % m] for i in k])],
        peaks[k] - heights[np.asarray([rs[i] for i in k])],
    )
    near = np.flatnonzero((wells < SHALLOW_WELL_FACTOR * vibration) | _near_metastable_hills(pf)[k])
    if len(near):
        h = np.asarray(pf.part.hull, dtype=float)
        com = np.asarray(pf.part.com, dtype=float)
        level = peaks[k[near]] - PUSH_BAND_FACTOR * vibration
        if rising:
            p, _ = _level_crossing(h, com, flank_end[near], d[near], level)
            width[near] = np.maximum(width[near], d[near] - p)
        else:
            _, p = _level_crossing(h, com, d[near], flank_end[near], level)
            width[near] = np.maximum(width[near], p - d[near])
    return width


def gyration_rel(part: Part) -> float:
    """The radius of gyration of the part's hull, a uniform plate, about its COM, over its size
    (the plate the physics check simulates for a plan's part)."""
    h = np.asarray(part.hull, dtype=float) - np.asarray(part.com, dtype=float)
    x, y = h[:, 0], h[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2.0
    polar = (cross * (x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1)).sum() / 12.0
    return math.sqrt(max(polar / area, 0.0)) / part.size


def ordinary_push_band_deg(part: Part) -> float:
    """The push band (deg) at an ordinary hilltop of ``part``: :data:`PUSH_BAND_DEG`, or for a
    slender part (:data:`SLENDER_GYRATION_REL`) :data:`SLENDER_BAND_DEG` at 20 mm and below
    (:data:`OVERSHOOT_MIN_SIZE_MM`: smaller parts are checked at 20 mm), falling linearly to
    :data:`PUSH_BAND_DEG` at :data:`SLENDER_MAX_SIZE_MM`."""
    if gyration_rel(part) >= SLENDER_GYRATION_REL:
        return PUSH_BAND_DEG
    lo, hi = OVERSHOOT_MIN_SIZE_MM, SLENDER_MAX_SIZE_MM
    share = min(max((hi - part.size) / (hi - lo), 0.0), 1.0)
    return PUSH_BAND_DEG + (SLENDER_BAND_DEG - PUSH_BAND_DEG) * share


def _near_metastable_hills(pf: PushFunction) -> np.ndarray:
    """Per hilltop (``pf.divergent_deg``): whether a hull edge at its vertex is an unstable
    near-metastable facet (its COM's foot outside it by less than ``NEAR_METASTABLE_DEG``,
    at either end: section 3's metastable edge nearly), as a flattened arc's facet beside the
    hilltop: the radius function falls along it to almost a minimum, nearly a state, and the
    physics check carried pushes over such a hilltop from up to 2.45 degrees
    (docs/uncertainty.md, "Push bands"). A stable edge is a state, judged by its well."""
    h = np.asarray(pf.part.hull, dtype=float)
    com = np.asarray(pf.part.com, dtype=float)
    n = len(h)
    towards = np.degrees(np.arctan2(h[:, 1] - com[1], h[:, 0] - com[0]))
    # Unstable edges only: a stable one is a state, whose well the shallow-state rule judges.
    facets = {e for e in pf.near_metastable_edges if pf.edge_margin_deg[e] < 0.0}
    out = np.zeros(len(pf.divergent_deg), dtype=bool)
    for i, d in enumerate(pf.divergent_deg):
        j = int(np.argmin(np.abs(np.mod(towards - d + 180.0, 360.0) - 180.0)))
        out[i] = (j - 1) % n in facets or j in facets
    return out


def _band_list(
    d: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    left: np.ndarray,
    right: np.ndarray,
    top_lo: np.ndarray,
    top_hi: np.ndarray,
) -> list[Band]:
    return [
        Band(
            float(d[j]),
            float(lo[j]),
            float(hi[j]),
            int(left[j]),
            int(right[j]),
            float(top_lo[j]),
            float(top_hi[j]),
        )
        for j in range(len(d))
    ]


def _strong_components(edges: Sequence[set[int]]) -> list[int]:
    """Strong component id of every node of a small directed graph (iterative Kosaraju)."""
    n = len(edges)
    order: list[int] = []
    seen = [False] * n
    for root in range(n):
        if seen[root]:
            continue
        seen[root] = True
        stack = [(root, iter(sorted(edges[root])))]
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                stack.pop()
                order.append(node)
            elif not seen[nxt]:
                seen[nxt] = True
                stack.append((nxt, iter(sorted(edges[nxt]))))
    back: list[list[int]] = [[] for _ in range(n)]
    for i, out in enumerate(edges):
        for j in out:
            back[j].append(i)
    comp = [-1] * n
    label = 0
    for root in reversed(order):
        if comp[root] >= 0:
            continue
        comp[root] = label
        todo = [root]
        while todo:
            node = todo.pop()
            for j in back[node]:
                if comp[j] < 0:
                    comp[j] = label
                    todo.append(j)
        label += 1
    return comp


def _destinations(
    edges: Sequence[set[int]], comp: Sequence[int], pid_of: Mapping[int, int]
) -> list[frozenset[int]]:
    """For each ideal state, the physical states it may stay in or vibration may take it to:
    every component reachable over ``edges`` (which may join components both ways)."""
    labels = max(comp) + 1
    succ: list[set[int]] = [set() for _ in range(labels)]
    for i, out in enumerate(edges):
        for j in out:
            if comp[j] != comp[i]:
                succ[comp[i]].add(comp[j])
    reach: list[frozenset[int]] = []
    for cc in range(labels):
        seen, todo = {cc}, [cc]
        while todo:
            for nxt in succ[todo.pop()]:
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        reach.append(frozenset(pid_of[x] for x in seen if x in pid_of))
    return [reach[comp[i]] for i in range(len(edges))]


def _arc_hull(arcs: Sequence[tuple[float, float]], ref: float) -> tuple[float, float]:
    """Smallest arc ``(lo, hi)`` near ``ref`` holding every ``(centre, half_width)`` arc.

    ``lo`` is in [0, 360) and ``hi >= lo``; the ends are computed from the extreme arcs
    themselves, so zero-width arcs give their centres exactly.
    """
    offs = [norm360(cn - ref + 180.0) - 180.0 for cn, _ in arcs]
    first = min(range(len(arcs)), key=lambda i: offs[i] - arcs[i][1])
    last = max(range(len(arcs)), key=lambda i: offs[i] + arcs[i][1])
    lo = norm360(arcs[first][0] - arcs[first][1])
    span = (offs[last] + arcs[last][1]) - (offs[first] - arcs[first][1])
    hi = arcs[last][0] + arcs[last][1]
    while hi < lo:
        hi += 360.0
    while hi - lo > span + 1e-6:
        hi -= 360.0
    # norm360 puts an end within 1e-12 below 360 at 0 (a normal of 359.9999999999996 is 0):
    # the other end, from its own arc, would then lie that rounding below it, reversed.
    return lo, max(hi, lo)


@dataclass(frozen=True)
class _CandidateArrays:
    """Candidates' normals, half-widths and basins; ``ext_*`` sorted over three turns."""

    normal: np.ndarray
    half: np.ndarray
    basin: np.ndarray
    ext_normal: np.ndarray
    ext_half: np.ndarray
    ext_basin: np.ndarray
    widest: float


def _candidate_arrays(cands: Sequence[RestCandidate]) -> _CandidateArrays:
    normal = np.mod(np.asarray([x.normal_deg for x in cands], dtype=float), 360.0)
    half = np.asarray([x.half_width_deg for x in cands], dtype=float)
    basin = np.asarray([x.basin for x in cands], dtype=int)
    order = np.argsort(normal, kind="stable")
    ext = np.concatenate([normal[order] - 360.0, normal[order], normal[order] + 360.0])
    return _CandidateArrays(
        normal,
        half,
        basin,
        ext,
        np.tile(half[order], 3),
        np.tile(basin[order], 3),
        float(half.max()) if len(half) else 0.0,
    )


def _cell_targets(
    arr: _CandidateArrays, dest: Sequence[frozenset[int]], lo: float, hi: float
) -> frozenset[int]:
    """Physical states of the candidates whose normal arc meets the open arc (lo, hi)."""
    if hi - lo >= 360.0:
        basins = np.unique(arr.basin).tolist()
    else:
        # Shift by whole turns only (norm360 would put a ``lo`` just below 0 at 0 and so
        # move the arc's far end past a candidate lying exactly there).
        x = lo - 360.0 * math.floor(lo / 360.0)
        y = hi - 360.0 * math.floor(lo / 360.0)
        a = int(np.searchsorted(arr.ext_normal, x - arr.widest, side="left"))
        b = int(np.searchsorted(arr.ext_normal, y + arr.widest, side="right"))
        nrm, half = arr.ext_normal[a:b], arr.ext_half[a:b]
        hit = (nrm - half < y) & (nrm + half > x)
        basins = set(arr.ext_basin[a:b][hit].tolist())
    out: set[int] = set()
    for bs in basins:
        out |= dest[bs]
    return frozenset(out)


def _run(ks: Sequence[int], m: int) -> list[int]:
    """The resting ranges ``ks`` of a strong component of the crossing graph in CCW order: a
    component of this ring graph is a run of ranges, so it starts after its gap (all ``m`` from
    0)."""
    if len(ks) == m:
        return list(range(m))
    inside = set(ks)
    start = next(k for k in ks if (k - 1) % m not in inside)
    return [(start + i) % m for i in range(len(ks))]


def _barrier_growth(t: float, c: float, spans_rad: np.ndarray, rho_min: float) -> np.ndarray:
    """How much higher than drawn each of a run's barriers may stand for a shape within
    ``t`` and a COM within ``c`` (mm; ``spans_rad``: per state, the angle from its normal to
    the farther of its two hilltops; ``rho_min``: the COM's least distance to a vertex).

    A vertex moved by at most ``t`` moves each radius by at most ``t``: ``2 t``. A COM moved
    by ``d`` (``|d| <= c``) moves the radius at ``theta`` by ``-<d, u(theta)>`` (a hilltop's,
    the distance to its vertex, to second order: ``c^2 / (2 rho)``), so a barrier between a
    normal and a hilltop ``s`` radians away changes by at most ``c s`` plus that term, never
    more than ``2 c`` (F1): a smooth hilltop's chords stay a hill under a COM tolerance (a
    cam's R15 end at 0.1 mm rested on its top when ``2 (t + c)`` was counted)."""
    second = c * c / rho_min if rho_min > 0.0 else 2.0 * c
    return 2.0 * t + np.minimum(c * spans_rad + second, 2.0 * c)


def _hilltop_spans(pf: PushFunction, div: np.ndarray, order: Sequence[int]) -> np.ndarray:
    """Per resting range ``k`` of ``order``, the angle (radians) from its state's normal to
    the farther of the range's two hilltops (``div[k]`` and ``div[k + 1]``)."""
    m = len(div)
    ks = np.asarray(order)
    normals = np.asarray([pf.states[pf.range_state[k]].normal_deg for k in order])

    def apart(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.abs(np.mod(a - b + 180.0, 360.0) - 180.0)

    return np.radians(np.maximum(apart(normals, div[ks]), apart(div[(ks + 1) % m], normals)))


def _on_hill(peaks: np.ndarray, wells: np.ndarray, growth: np.ndarray, vibration: float) -> bool:
    """Whether a run of stable states (``wells``, the drawn radius at their normals, CCW;
    ``peaks`` at the hilltops around and between them, both ends included) is the facets of a
    hill, not a resting state: a part dropped there rolls off to a real minimum.

    That is a flattened arc's chords where its smooth radius function (through the chords'
    ends, the hilltops) has a maximum: every state's barrier is below the vibration for every
    shape (plus its ``growth``, :func:`_barrier_growth`, at most ``2 eps``: F1); a hilltop
    between them stands higher than ``noise`` (the largest drawn barrier) above both hilltops
    where the run is left; and no well sinks more than ``noise`` below the lower of those (a
    well that deep is a real minimum). A single stable state never is one (no hilltop lies
    between its two), nor a run down a slope.
    """
    barriers = np.minimum(peaks[:-1], peaks[1:]) - wells
    noise = float(barriers.max())
    top = float(peaks[1:-1].max(initial=-math.inf))
    low = float(min(peaks[0], peaks[-1]))
    return (
        float((barriers + growth).max()) < vibration
        and top - max(peaks[0], peaks[-1]) > noise
        and low - float(wells.min()) <= noise
    )


def uncertain_mechanics(
    part: Part, uncertainty: Uncertainty, *, vibration_mm: float | None = None
) -> UncertainMechanics:
    """The physical states, bands and fence cells of ``part`` under ``uncertainty``.

    Merge rule: the part resting in ideal state ``i`` can cross to the neighbour beyond a hill
    when a rest candidate of ``i``'s basin lies less than ``vibration + 2 (t + c)`` below the
    hilltop (F1: a barrier that high survives every shape and still holds against the
    vibration). The physical states are the strong components of the crossings from the
    basin's deepest candidate too (a part at rest anywhere in ``i`` may wander to the
    neighbour); a push that ends in a component may also end in any component those and the
    crossings from near-top candidates only (a fillet's short chords) reach. A state the part
    *should* leave (its barrier below the vibration) is kept as one it may stay in: the
    feeder's vibration is not known, and the physics check shows parts resting on such edges.
    Except the facets of a hill (:func:`_on_hill`: a flattened arc's chords where its radius
    function has a maximum): they are no resting state (``state_of`` None), and a part coming
    to rest there ends where the crossings take it.
    ``vibration_mm`` defaults to the fragile threshold (1e-3 of the part's size, a breath of
    vibration) unless the uncertainty is ideal,
    where it is 0 and every physical state is one ideal state. Bands: with the vibration on, a
    push starting within ``PUSH_BAND_DEG`` of a hilltop (wherever F2 puts it) may end on either
    side; at a hilltop beside a shallow state or a near-metastable facet, within
    ``PUSH_BAND_FACTOR`` vibrations of its height (:func:`_bands`). Overshoot: with the
    vibration on, a push ending in a state may also end beyond a hilltop close to its normal
    (:data:`OVERSHOOT_DEG_MM`; an outcome, as a carry crossing), and roll on over a hilltop
    standing less than :data:`ROLL_WELL_FACTOR` vibrations above its well; a push starting
    near a hilltop may also go over a near, low far hilltop (:data:`OVERSHOOT_BAND_DEG`:
    the cells there target the states beyond). Raises InputError
    for a shape tolerance of half the smallest hull edge or more.
    """
    check_for_part(uncertainty, part)
    pf = push_function(part)
    t, c = uncertainty.shape_tolerance_mm, uncertainty.com_tolerance_mm
    eps = t + c
    if vibration_mm is None:
        vibration_mm = 0.0 if uncertainty.is_ideal else FRAGILE_BARRIER_REL * part.size
    if vibration_mm < 0.0 or math.isnan(vibration_mm):
        raise InputError(f"vibration must be a nonnegative length in mm, got {vibration_mm!r}")
    h = np.asarray(part.hull, dtype=float)
    com = np.asarray(part.com, dtype=float)
    div = np.asarray(pf.divergent_deg, dtype=float)
    m = len(div)
    rs = pf.range_state
    heights = _radius(h, com, np.asarray([s.normal_deg for s in pf.states]))
    peaks = _radius(h, com, div)
    left = np.asarray([rs[(k - 1) % m] for k in range(m)])
    right = np.asarray(rs)
    threshold = vibration_mm + 2.0 * eps

    cands = _rest_candidates(pf, t, c)
    rho = np.hypot(*(h - com).T)
    rho_max, rho_min = float(rho.max()), float(rho.min())
    # Crossing graph: ideal state i -> its neighbour across a hill when some rest candidate in
    # i's basin may lie less than the vibration below that hilltop for some shape (F1: its
    # resting height is within r(normal) +- rho_max * half-width, r's slope bound, +- eps).
    # ``wander`` holds the crossings from i's deepest candidate too: a part at rest anywhere
    # in i may cross, so i and j are one state where they cross both ways. ``carry`` holds
    # those from candidates near the hilltop only (a short chord of a fillet tilted by the
    # shape tolerance): a push that ends there may end beyond, but a part at rest in i's
    # well stays, and the readings still tell i from j.
    wander: list[set[int]] = [set() for _ in range(pf.n)]
    carry: list[set[int]] = [set() for _ in range(pf.n)]
    if threshold > 0.0 and cands:
        arr = _candidate_arrays(cands)
        slack = rho_max * np.radians(arr.half)
        height = np.asarray([x.height_mm for x in cands])
        top = height + 2.0 * t + slack
        deepest = np.full(pf.n, np.inf)
        np.minimum.at(deepest, arr.basin, top)
        range_of = np.empty(pf.n, dtype=int)
        range_of[np.asarray(rs)] = np.arange(m)
        k = range_of[arr.basin]
        for hill, beyond in ((k, left[k]), ((k + 1) % m, right[(k + 1) % m])):
            other = beyond != arr.basin
            cross = other & (peaks[hill] - top < threshold)
            anywhere = peaks[hill] - deepest[arr.basin] < threshold
            for i, j, w in set(
                zip(
                    arr.basin[cross].tolist(),
                    beyond[cross].tolist(),
                    anywhere[cross].tolist(),
                    strict=True,
                )
            ):
                (wander if w else carry)[i].add(j)
    if vibration_mm > 0.0:
        # Overshoot (OVERSHOOT_DEG_MM): a push ending in a state whose hilltop lies close to
        # its normal, coming down a basin at least twice as wide, may carry on over it.
        reach = OVERSHOOT_DEG_MM / max(part.size, OVERSHOOT_MIN_SIZE_MM)
        normal = np.asarray([s.normal_deg for s in pf.states])
        for k in range(m):
            # Directed arcs along the state's resting range (its far side may pass 180).
            n_l, n_r = normal[left[k]], normal[right[k]]
            arcs = (
                (left[k], right[k], norm360(div[k] - n_l), norm360(n_l - div[(k - 1) % m])),
                (right[k], left[k], norm360(n_r - div[k]), norm360(div[(k + 1) % m] - n_r)),
            )
            for i, j, near_deg, far_deg in arcs:
                if i != j and near_deg < reach and far_deg >= 2.0 * near_deg:
                    carry[i].add(int(j))
    if vibration_mm > 0.0:
        # Rolling (ROLL_WELL_FACTOR): a push may roll on over a hilltop that stands only a few
        # vibrations above the well it ends in; _destinations chains the crossings.
        scale = OVERSHOOT_MIN_SIZE_MM / max(part.size, OVERSHOOT_MIN_SIZE_MM)
        roll = ROLL_WELL_FACTOR * scale * scale * vibration_mm + 2.0 * eps
        for k in range(m):
            a, b = int(left[k]), int(right[k])
            if a != b:
                if peaks[k] - heights[a] < roll:
                    carry[a].add(b)
                if peaks[k] - heights[b] < roll:
                    carry[b].add(a)
    comp = _strong_components(wander)
    first_member: dict[int, int] = {}
    for i in range(pf.n):
        first_member.setdefault(comp[i], i)
    ranges_of: dict[int, list[int]] = {}
    for k in range(m):
        ranges_of.setdefault(comp[rs[k]], []).append(k)
    runs = {cc: _run(ks, m) for cc, ks in ranges_of.items()}
    # No state is transient for the vibration alone: one the part *should* leave (its barrier
    # below the vibration) is kept as a state it may stay in, since how hard a feeder vibrates
    # is not known and the physics check shows parts resting on such edges; a push ending there
    # may end in it or in any state it can cross to (``destinations``). Only the facets of a
    # hill go (:func:`_on_hill`): there the part rolls off to a real minimum.
    leaves = {comp[i] for i in range(pf.n) for j in wander[i] if comp[j] != comp[i]}
    hills = {
        cc
        for cc, order in runs.items()
        if cc in leaves
        and len(order) < m
        and _on_hill(
            peaks[np.asarray([*order, (order[-1] + 1) % m])],
            heights[np.asarray([rs[k] for k in order])],
            _barrier_growth(t, c, _hilltop_spans(pf, div, order), rho_min),
            vibration_mm,
        )
    }
    kept = sorted(set(comp) - hills, key=first_member.__getitem__)
    pid_of = {cc: p for p, cc in enumerate(kept)}
    state_of = [pid_of.get(comp[i]) for i in range(pf.n)]
    destinations = _destinations([w | x for w, x in zip(wander, carry, strict=True)], comp, pid_of)

    states: list[PhysicalState] = []
    by_basin: dict[int, list[RestCandidate]] = {}
    for x in cands:
        by_basin.setdefault(x.basin, []).append(x)
    for pid, cc in enumerate(kept):
        ks = ranges_of[cc]
        order = runs[cc]
        members = tuple(rs[k] for k in order)
        cap_lo = float(div[order[0]])
        if len(ks) == m:
            cap_hi = cap_lo + 360.0
            rest = (cap_lo, cap_lo + 360.0)
        else:
            cap_hi = cap_lo + norm360(div[(order[-1] + 1) % m] - cap_lo)
            if cap_hi <= cap_lo:
                cap_hi += 360.0
            own = [x for s in members for x in by_basin.get(s, [])]
            rest = _arc_hull([(x.normal_deg, x.half_width_deg) for x in own], (cap_lo + cap_hi) / 2)
        if eps == 0.0 and len(members) == 1:
            d = pf.states[members[0]].diameter
            diam = (d, d)
        else:
            w_lo, w_hi = width_range(part.hull, rest[0], rest[1])
            exact = [pf.states[i].diameter for i in members]  # the same widths, rounded apart
            diam = (max(min(w_lo, *exact) - 2.0 * t, 0.0), max(w_hi, *exact) + 2.0 * t)
        states.append(PhysicalState(pid, members, rest, (cap_lo, cap_hi), diam))

    bands = _bands(
        pf, eps, _certain_hills(peaks, heights[right], eps), peaks, heights, vibration_mm
    )
    cells = _fence_cells(bands, cands, destinations, _profile(pf, eps) if eps > 0.0 else None)
    if vibration_mm > 0.0:
        # Overshoot from near a hilltop (OVERSHOOT_BAND_DEG, OVERSHOOT_FAR_DEG).
        cells = _overlay(cells, _band_overshoots(pf, peaks, heights, bands, destinations, eps))
    return UncertainMechanics(
        push=pf,
        uncertainty=uncertainty,
        vibration_mm=float(vibration_mm),
        merge_threshold_mm=float(threshold),
        candidates=tuple(cands),
        bands=tuple(bands),
        states=tuple(states),
        state_of=tuple(state_of),
        destinations=tuple(destinations),
        cells=cells,
        cell_los=tuple([cl.lo for cl in cells] + [cl.lo + 360.0 for cl in cells]),
    )


@dataclass(frozen=True)
class _Profile:
    """The drawn radius function's extrema (hilltops and state normals, over three turns,
    sorted; the radius is monotone between consecutive ones) and ``eps = t + c``."""

    hull: np.ndarray
    com: np.ndarray
    pos: np.ndarray
    val: np.ndarray
    eps: float


def _profile(pf: PushFunction, eps: float) -> _Profile:
    h = np.asarray(pf.part.hull, dtype=float)
    com = np.asarray(pf.part.com, dtype=float)
    ext = np.mod([*pf.divergent_deg, *(s.normal_deg for s in pf.states)], 360.0)
    ext = np.sort(ext)
    pos = np.concatenate([ext - 360.0, ext, ext + 360.0])
    return _Profile(h, com, pos, _radius(h, com, pos), eps)


def _descent_reach(
    prof: _Profile, start_lo: float, start_hi: float, reach_lo: float, reach_hi: float
) -> tuple[float, float]:
    """The reach ``(reach_lo, reach_hi)`` of pushes starting in ``[start_lo, start_hi]``, cut
    where they would have to climb.

    A push descends the perturbed radius function: from a start at most ``M + eps`` high (F1;
    ``M`` the drawn radius's maximum over the starts) it never reaches an orientation where
    the drawn radius exceeds ``M + 2 eps``. So the reach ends, on each side, at the first such
    orientation past the starts (found by bisection on a monotone piece, rounded outward).

    That is F1 alone for the quasi-static push. With the push bands (measured): a push from a
    band may be carried over its hill, whose top lies in the band, so ``M`` covers it; a push
    from outside a band is taken not to be carried over any maximum inside it (its push band
    holds the push band of every drawn hilltop of the hill; for a maximum a perturbed shape
    grows elsewhere in the band this is the model's reading of the push bands,
    docs/uncertainty.md, "Cells stop where a push would have to climb").
    """
    r0 = _radius(prof.hull, prof.com, np.asarray([start_lo, start_hi]))
    base = math.floor(start_lo / 360.0) * 360.0
    inside = prof.val[(prof.pos > start_lo - base) & (prof.pos < start_hi - base)]
    level = float(max(r0.max(), inside.max(initial=-math.inf))) + 2.0 * prof.eps
    return _cut_reach(prof, start_lo, start_hi, reach_lo, reach_hi, level)


def _cut_reach(
    prof: _Profile,
    start_lo: float,
    start_hi: float,
    reach_lo: float,
    reach_hi: float,
    level: float | None,
) -> tuple[float, float]:
    """The reach cut on each side where :func:`_climb` from that end of the starts stops."""
    base = math.floor(start_lo / 360.0) * 360.0
    hi = _climb(prof, start_hi, reach_hi, level, base)
    lo = _climb(prof, start_lo, reach_lo, level, base)
    return (
        reach_lo if lo is None else max(reach_lo, lo),
        reach_hi if hi is None else min(reach_hi, hi),
    )


def _gap_reach(
    prof: _Profile, start_lo: float, start_hi: float, reach_lo: float, reach_hi: float
) -> tuple[float, float]:
    """:func:`_descent_reach` for pushes starting in a gap between bands, which cross no
    hilltop (:func:`_fence_cells`): each leaves the gap through one of its ends and from
    there descends the perturbed radius function, so at an orientation it reaches the drawn
    radius is at most ``2 eps`` above its lowest on the way from that end (F1 at both
    points): the reach ends where the drawn radius first rises more than ``2 eps`` above
    that running minimum. Tighter than one level for the whole gap, whose highest start
    (beside another band) let a push from the gap's other end climb a shallow hill there
    (a cam's flank reached its round end's top facets)."""
    return _cut_reach(prof, start_lo, start_hi, reach_lo, reach_hi, None)


def _climb(
    prof: _Profile, start: float, limit: float, level: float | None, base: float
) -> float | None:
    """The first orientation from ``start`` toward ``limit`` where the drawn radius exceeds
    ``level`` (the far end of its bisection bracket, plus ``BOUNDARY_EPS_DEG``), or None.

    The radius at ``start`` is at most ``level``; it is monotone between consecutive extrema,
    so the first extremum (or ``limit``) above the level closes the piece holding the crossing.
    ``level`` None: the running minimum of the drawn radius from ``start`` on, plus ``2 eps``
    (:func:`_gap_reach`; the minimum of a monotone piece is at one of its ends).
    """
    step = 1.0 if limit >= start else -1.0
    s, lim = start - base, limit - base
    ahead = (prof.pos - s) * step
    mask = (ahead > 0.0) & ((lim - prof.pos) * step > 0.0)
    pts, vals = prof.pos[mask][:: int(step)], prof.val[mask][:: int(step)]
    pts = np.concatenate([pts, [lim]])
    vals = np.concatenate([vals, _radius(prof.hull, prof.com, np.asarray([lim]))])
    low = float(_radius(prof.hull, prof.com, np.asarray([s]))[0]) if level is None else 0.0
    x0 = s
    for p, v in zip(pts.tolist(), vals.tolist(), strict=True):
        top = low + 2.0 * prof.eps if level is None else level
        if v > top:
            lo, hi = np.asarray([min(x0, p)]), np.asarray([max(x0, p)])
            a, b = _level_crossing(prof.hull, prof.com, lo, hi, np.asarray([top]))
            far = max(a[0], b[0]) if step > 0 else min(a[0], b[0])
            return base + far + step * BOUNDARY_EPS_DEG
        low = min(low, v)
        x0 = p
    return None


def _fence_cells(
    bands: Sequence[Band],
    cands: Sequence[RestCandidate],
    dest: Sequence[frozenset[int]],
    profile: _Profile | None = None,
) -> tuple[FenceCell, ...]:
    """The circle of fence orientations cut at the band ends, each cell with its targets.

    A push cannot pass a local maximum of the perturbed radius function, and every one lies
    in a band's F2 part (``top_lo_deg .. top_hi_deg``). From a gap between bands ``j`` and
    ``j + 1`` the push starts outside both push bands, so it crosses neither hilltop: it rests
    between band ``j``'s F2 start and band ``j + 1``'s F2 end. From inside band ``j`` it may
    cross hilltop ``j`` but no other: it rests between band ``j - 1``'s F2 start and band
    ``j + 1``'s F2 end. (A push band reaches at most the neighbouring state's normal, so a
    state just beyond it, at that normal, is not reached from the gap: the push band only says
    where a push may be carried over *its own* hilltop.)

    With ``profile`` (``t + c > 0``) each reach is also cut where the push would have to
    climb: :func:`_descent_reach`.
    """
    arr = _candidate_arrays(cands)
    if not bands:
        return (FenceCell(0.0, 360.0, False, _cell_targets(arr, dest, 0.0, 360.0)),)
    base = bands[0].lo_deg
    lo = [base + norm360(b.lo_deg - base) for b in bands]
    hi = [lo[j] + (b.hi_deg - b.lo_deg) for j, b in enumerate(bands)]
    top_lo = [lo[j] + (b.top_lo_deg - b.lo_deg) for j, b in enumerate(bands)]
    top_hi = [lo[j] + (b.top_hi_deg - b.lo_deg) for j, b in enumerate(bands)]
    q = len(bands)

    def at(j: int) -> tuple[float, float, float, float]:
        turn = 360.0 * (j // q)
        k = j % q
        return lo[k] + turn, hi[k] + turn, top_lo[k] + turn, top_hi[k] + turn

    cells: list[FenceCell] = []
    for j in range(q):
        b_lo, b_hi, t_lo, _ = at(j)
        _, _, prev_top_lo, _ = at(j - 1)
        n_lo, _, _, next_top_hi = at(j + 1)
        region = (b_lo, b_lo + 360.0) if q == 1 else (prev_top_lo, next_top_hi)
        gap_region = (b_lo, b_lo + 360.0) if q == 1 else (t_lo, next_top_hi)
        if profile is not None and q > 1:
            region = _descent_reach(profile, b_lo, b_hi, *region)
            gap_region = _gap_reach(profile, b_hi, n_lo, *gap_region)
        cells.append(FenceCell(b_lo, b_hi, True, _cell_targets(arr, dest, *region)))
        cells.append(FenceCell(b_hi, n_lo, False, _cell_targets(arr, dest, *gap_region)))
    return tuple(cells)


def _overshoot_chain(
    pf: PushFunction,
    div: np.ndarray,
    peaks: np.ndarray,
    heights: np.ndarray,
    k: int,
    way: int,
    eps: float,
) -> list[int]:
    """The ideal states a push coming down from hilltop ``k`` (``way`` +1: counter-clockwise)
    may go on to over near, low hilltops: past the state below ``k`` over its far hilltop
    when that lies less than :data:`OVERSHOOT_FAR_DEG` past the state's normal, ``k`` less
    than :data:`OVERSHOOT_DOWN_DEG` before it, and the far hilltop stands less than
    :data:`OVERSHOOT_CLIMB_REL` times as high above the well as ``k`` (with ``2 eps`` to
    spare, F1); and on from the state beyond by the same rule, from ``k`` or from any
    hilltop gone over since (the turn the part came down with carries it on), over at most
    :data:`OVERSHOOT_MAX_HILLTOPS`. ``div``: the hilltops (``pf.divergent_deg``) as an array."""
    m = len(div)
    rs = pf.range_state
    out: list[int] = []
    tops = [k]  # the hilltops the part may be taken to have come down from
    r = k if way > 0 else (k - 1) % m  # the range below hilltop k on this side
    for _ in range(min(m - 2, OVERSHOOT_MAX_HILLTOPS)):
        far = (r + 1) % m if way > 0 else r
        s, beyond = rs[r], rs[(r + way) % m]
        if beyond == s:
            break
        nrm = pf.states[s].normal_deg
        far_deg = abs(norm360(div[far] - nrm + 180.0) - 180.0)
        climb = peaks[far] - heights[s] + 2.0 * eps
        if far_deg >= OVERSHOOT_FAR_DEG or not any(
            way * (nrm - div[top]) % 360.0 < OVERSHOOT_DOWN_DEG
            and climb < OVERSHOOT_CLIMB_REL * (peaks[top] - heights[s] - 2.0 * eps)
            for top in tops
        ):
            break
        out.append(beyond)
        tops.append(far)
        r = (r + way) % m
    return out


def _band_overshoots(
    pf: PushFunction,
    peaks: np.ndarray,
    heights: np.ndarray,
    bands: Sequence[Band],
    dest: Sequence[frozenset[int]],
    eps: float,
) -> list[tuple[float, float, frozenset[int]]]:
    """Fence intervals ``(lo, hi, extra)`` near hilltops from which a push may come down the
    basin beside the hilltop and go on over its far hilltop (docs/uncertainty.md,
    "Overshoot"): from less than :data:`OVERSHOOT_BAND_DEG` beside hilltop ``k`` on one side,
    or from inside its band (carried over it), a push may also end in the destinations of the
    states :func:`_overshoot_chain` reaches on that side. ``hi`` may pass 360."""
    div = np.asarray(pf.divergent_deg, dtype=float)
    out: list[tuple[float, float, frozenset[int]]] = []
    top_lo = np.array([b.top_lo_deg for b in bands], dtype=float)
    top_w = np.array([b.top_hi_deg - b.top_lo_deg for b in bands], dtype=float)
    for k, d in enumerate(div):
        lo, hi = d, d  # the band holding hilltop k (F2 and push band)
        # The bands that may hold it, found at once (a 5,000-gon has as many hilltops as
        # bands); each is then decided exactly as below, in order (the last one holds it).
        off = np.mod(d - top_lo + 1e-6, 360.0) - 1e-6
        near = np.flatnonzero((off <= top_w + 1e-6) | (off >= 360.0 - 1e-5))
        for b in (bands[i] for i in near):
            off = norm360(d - b.top_lo_deg + 1e-6) - 1e-6
            if off <= b.top_hi_deg - b.top_lo_deg:
                lo, hi = d - off - (b.top_lo_deg - b.lo_deg), d - off + (b.hi_deg - b.top_lo_deg)
        for way, zone in (
            (1, (lo, max(hi, d + OVERSHOOT_BAND_DEG))),
            (-1, (min(lo, d - OVERSHOOT_BAND_DEG), hi)),
        ):
            reached = _overshoot_chain(pf, div, peaks, heights, k, way, eps)
            if reached:
                out.append((*zone, frozenset().union(*(dest[i] for i in reached))))
    return out


def _overlay(
    cells: Sequence[FenceCell], zones: Sequence[tuple[float, float, frozenset[int]]]
) -> tuple[FenceCell, ...]:
    """``cells`` cut at the ends of ``zones`` (closed fence intervals ``(lo, hi, extra)``), each
    piece also targeting the ``extra`` of every zone holding it; a piece keeps its cell's
    ``closed``, and pieces of one cell with the same targets stay one cell."""
    if not zones:
        return tuple(cells)
    base = cells[0].lo
    spans: list[tuple[float, float, frozenset[int]]] = []
    for lo, hi, extra in zones:
        if hi - lo >= 360.0:
            spans.append((base, base + 360.0, extra))
            continue
        x = base + norm360(lo - base)
        y = x + (hi - lo)
        spans.append((x, min(y, base + 360.0), extra))
        if y > base + 360.0:
            spans.append((base, y - 360.0, extra))
    ends = sorted({v for a, b, _ in spans for v in (a, b)})
    pieces = [(cell, a, b) for cell in cells for a, b in _pieces(cell, ends)]
    covering = _covering([(a, b) for _cell, a, b in pieces], spans)
    out: list[FenceCell] = []
    for (cell, a, b), over in zip(pieces, covering, strict=True):
        targets = cell.targets.union(*(spans[i][2] for i in over))
        if (
            out
            and out[-1].hi == a
            and out[-1].closed == cell.closed
            and (out[-1].targets == targets)
            and out[-1].lo >= cell.lo
        ):
            out[-1] = FenceCell(out[-1].lo, b, cell.closed, targets)
        else:
            out.append(FenceCell(a, b, cell.closed, targets))
    return tuple(out)


def _pieces(cell: FenceCell, ends: Sequence[float]) -> list[tuple[float, float]]:
    """``cell`` cut at every one of ``ends`` (sorted, distinct) strictly inside it, in order."""
    inside = ends[bisect.bisect_right(ends, cell.lo) : bisect.bisect_left(ends, cell.hi)]
    cuts = sorted({cell.lo, cell.hi, *inside})
    return list(zip(cuts, cuts[1:], strict=False))


def _covering(
    pieces: Sequence[tuple[float, float]], spans: Sequence[tuple[float, float, frozenset[int]]]
) -> list[list[int]]:
    """Per piece ``(a, b)``, the indices of the spans ``(x, y, _)`` with ``x <= a`` and
    ``b <= y``, found by one sweep over the pieces' middles (no end of a span lies inside a
    piece, so a span holding its middle holds it); each found span is checked exactly, and a
    piece too short for a middle is checked against every span."""
    order = sorted(range(len(spans)), key=lambda i: spans[i][0])
    by_mid = sorted(range(len(pieces)), key=lambda k: (pieces[k][0] + pieces[k][1]) / 2.0)
    out: list[list[int]] = [[] for _ in pieces]
    active: dict[int, None] = {}
    ending: list[tuple[float, int]] = []
    nxt = 0
    for k in by_mid:
        a, b = pieces[k]
        mid = (a + b) / 2.0
        while nxt < len(order) and spans[order[nxt]][0] < mid:
            i = order[nxt]
            active[i] = None
            heapq.heappush(ending, (spans[i][1], i))
            nxt += 1
        while ending and ending[0][0] <= mid:
            active.pop(heapq.heappop(ending)[1], None)
        held = active if a < mid < b else range(len(spans))
        out[k] = sorted(i for i in held if spans[i][0] <= a and b <= spans[i][1])
    return out


def mechanics_to_dict(mech: UncertainMechanics) -> dict[str, object]:
    """The physical states and bands as JSON-ready lists (for ``part analyze`` and plan files)."""
    return {
        "uncertainty": mech.uncertainty.to_dict(),
        "merge_threshold_mm": mech.merge_threshold_mm,
        "physical_states": [
            {
                "id": s.id,
                "members": list(s.members),
                "rest_deg": list(s.rest_deg),
                "capture_deg": list(s.capture_deg),
                "diameter": list(s.diameter),
            }
            for s in mech.states
        ],
        "bands": [
            {"divergent_deg": b.divergent_deg, "band_deg": [b.lo_deg, b.hi_deg]} for b in mech.bands
        ],
    }


__all__ = [
    "PUSH_BAND_DEG",
    "PUSH_BAND_FACTOR",
    "ROLL_WELL_FACTOR",
    "SHALLOW_WELL_FACTOR",
    "SLENDER_BAND_DEG",
    "SLENDER_GYRATION_REL",
    "SLENDER_MAX_SIZE_MM",
    "Band",
    "FenceCell",
    "PhysicalState",
    "RestCandidate",
    "UncertainMechanics",
    "gyration_rel",
    "mechanics_to_dict",
    "ordinary_push_band_deg",
    "uncertain_mechanics",
    "width_range",
]
