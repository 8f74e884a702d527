"""Radius, diameter, push and push-diameter functions of a part (section 3.1), exactly.

Angles are degrees. ``theta`` is the direction, in the part frame, of the fence's contact
normal pointing from the COM toward the fence (design.md). Edge ``i`` rests on the fence when
``theta`` equals its outward normal.

The radius function is piecewise sinusoidal: on the normal cone of hull vertex ``v`` it is
``|v - c| cos(phi - angle(v - c))``, whose slope falls across the cone, and its slope jumps up
by the edge's length at each edge normal. So its local minima are the stable edges (the COM's
foot strictly inside the edge) and its local maxima the directions from the COM to the
vertices where the slope changes sign inside the cone (the divergent orientations).
Everything is computed from the hull in O(n log n) with numpy; nothing is sampled.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from feederkit.angles import norm360
from feederkit.part import Part

METASTABLE_SNAP_DEG = 1e-9
"""An edge whose COM foot, seen from the COM, is within this angle of a vertex is metastable."""

NEAR_METASTABLE_DEG = 1.0
"""An edge whose COM foot, seen from the COM, is within this angle of a vertex is flagged.

It is the rotation by which the part would have to be off for it to settle on the other side
of that vertex: in practice such an edge may rest on either neighbour.
"""


@dataclass(frozen=True)
class StableState:
    """A stable state: edge ``edge`` on the fence, a local minimum of the radius function.

    ``resting_range_deg`` is ``(lo, hi)`` with ``lo < normal_deg < hi``: every fence orientation
    strictly inside it settles here. ``pose_deg`` is the part's rotation in the world,
    ``-90 - normal`` (design.md). ``near_metastable``: the COM's foot is within
    NEAR_METASTABLE_DEG (seen from the COM) of an end of the edge. ``barrier_mm``: how far the
    radius function (the COM's distance from the fence) rises from this minimum to the lower
    of its two enclosing maxima before the part tips out of this state; a state whose barrier
    is small against the part's tolerances is shallow and fragile.
    """

    id: int
    edge: int
    normal_deg: float
    resting_range_deg: tuple[float, float]
    diameter: float
    pose_deg: float
    near_metastable: bool = False
    barrier_mm: float = 0.0


@dataclass(frozen=True)
class PushFunction:
    """The push function of a part and, with its states' diameters, its push-diameter function.

    ``divergent_deg`` are the divergent orientations (local maxima of the radius function),
    sorted in [0, 360); resting range ``k`` runs from ``divergent_deg[k]`` counter-clockwise to
    the next one and holds state ``range_state[k]``. Per hull edge: ``edge_kinds`` is
    ``"stable"``, ``"unstable"`` or ``"metastable"``; ``edge_margin_deg`` the signed angle, seen
    from the COM, from the edge's normal to the nearer end of the edge (negative when the foot
    falls outside the edge: unstable); ``near_metastable_edges`` the edges with
    ``|margin| < NEAR_METASTABLE_DEG``.
    """

    part: Part
    states: tuple[StableState, ...]
    divergent_deg: tuple[float, ...]
    range_state: tuple[int, ...]
    edge_kinds: tuple[str, ...]
    near_metastable_edges: tuple[int, ...]
    edge_margin_deg: tuple[float, ...] = ()

    @property
    def n(self) -> int:
        """Number of stable states."""
        return len(self.states)


Hull = tuple[tuple[float, float], ...] | np.ndarray


def _edge_arrays(hull: Hull) -> tuple[np.ndarray, np.ndarray]:
    h = np.asarray(hull, dtype=float)
    return h, np.roll(h, -1, axis=0) - h


def edge_normals(hull: tuple[tuple[float, float], ...]) -> list[float]:
    """Outward normal direction (deg, [0, 360)) of each hull edge ``i`` (vertex i to i+1)."""
    return _normals(hull).tolist()


def _normals(hull: Hull) -> np.ndarray:
    _, d = _edge_arrays(hull)
    out = np.mod(np.degrees(np.arctan2(-d[:, 0], d[:, 1])), 360.0) + 0.0
    out[out >= 360.0] = 0.0
    return out


def _foot_angles(hull: Hull, com: tuple[float, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per edge: the angles (deg), seen from the COM, from the edge's normal to its start and end.

    Positive when the COM's foot lies on the edge's side of that end, zero when metastable
    (snapped within METASTABLE_SNAP_DEG). Also the edge's lengths.
    """
    h, d = _edge_arrays(hull)
    length = np.hypot(d[:, 0], d[:, 1])
    rel = np.asarray(com, dtype=float) - h
    along = (rel[:, 0] * d[:, 0] + rel[:, 1] * d[:, 1]) / length  # foot's distance from the start
    height = (rel[:, 1] * d[:, 0] - rel[:, 0] * d[:, 1]) / length  # COM's distance from the edge
    to_start = np.degrees(np.arctan2(along, height))
    to_end = np.degrees(np.arctan2(length - along, height))
    to_start[np.abs(to_start) < METASTABLE_SNAP_DEG] = 0.0
    to_end[np.abs(to_end) < METASTABLE_SNAP_DEG] = 0.0
    return to_start, to_end, length


def com_feet(hull: tuple[tuple[float, float], ...], com: tuple[float, float]) -> list[float]:
    """Where the COM projects on each edge, as the fraction ``t`` from vertex i to vertex i+1.

    The edge is stable iff ``0 < t < 1``; feet within METASTABLE_SNAP_DEG (seen from the COM)
    of an end snap to it (metastable), so edges and vertices are classified consistently.
    """
    h, d = _edge_arrays(hull)
    to_start, to_end, _ = _foot_angles(hull, com)
    rel = np.asarray(com, dtype=float) - h
    t = (rel[:, 0] * d[:, 0] + rel[:, 1] * d[:, 1]) / (d[:, 0] ** 2 + d[:, 1] ** 2)
    t[to_start == 0.0] = 0.0
    t[to_end == 0.0] = 1.0
    return t.tolist()


SUPPORT_MATRIX_MAX = 1_000_000
""":func:`radius` and :func:`diameter` project every hull vertex on every direction up to
this many products; past it, each direction's support vertex comes from a binary search over
the hull's edge normals (O((m + n) log n) time and O(m + n) memory for m directions and n
vertices: the wells of a 100,000-vertex circle asked for 25 GiB)."""


def _support(v: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """``max_k u(phi) . v[k]`` for directions ``phi`` (radians, any shape) over the
    counter-clockwise convex polygon ``v``: the vertex whose normal cone holds ``phi``
    (as :func:`edge_widths` finds it), and its two neighbours against rounding."""
    n = len(v)
    flat = phi.reshape(-1)
    u = np.stack([np.cos(flat), np.sin(flat)], axis=-1)
    if n * len(flat) <= SUPPORT_MATRIX_MAX:
        return (u @ v.T).max(axis=-1).reshape(phi.shape)
    d = np.roll(v, -1, axis=0) - v
    ang = np.arctan2(-d[:, 0], d[:, 1])
    unwrapped = ang[0] + np.concatenate([[0.0], np.cumsum(np.mod(np.diff(ang), 2 * np.pi))])
    x = unwrapped[0] + np.mod(flat - unwrapped[0], 2 * np.pi)
    j = np.searchsorted(unwrapped, x, side="right")
    best = np.full(len(flat), -np.inf)
    for k in (j - 1, j, j + 1):
        w = v[k % n]
        best = np.maximum(best, u[:, 0] * w[:, 0] + u[:, 1] * w[:, 1])
    return best.reshape(phi.shape)


def radius(part: Part, phi_deg: float | np.ndarray) -> float | np.ndarray:
    """Radius function r(phi): distance from the COM to the supporting line with normal phi.

    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> part = make_part(make_outline("rect", [(0, 0), (20, 0), (20, 10), (0, 10)]))
    >>> [round(float(r), 6) for r in radius(part, [0.0, 90.0])]
    [10.0, 5.0]
    """
    v = np.asarray(part.hull, dtype=float) - np.asarray(part.com, dtype=float)
    r = _support(v, np.radians(np.asarray(phi_deg, dtype=float)))
    return float(r) if np.ndim(r) == 0 else r


def diameter(part: Part, phi_deg: float | np.ndarray) -> float | np.ndarray:
    """Diameter function w(phi): the width between the two supporting lines with normal phi."""
    v = np.asarray(part.hull, dtype=float)
    phi = np.radians(np.asarray(phi_deg, dtype=float))
    if len(v) * phi.size <= SUPPORT_MATRIX_MAX:
        proj = np.stack([np.cos(phi), np.sin(phi)], axis=-1) @ v.T
        w = proj.max(axis=-1) - proj.min(axis=-1)
    else:
        w = _support(v, phi) + _support(v, phi + np.pi)
    return float(w) if np.ndim(w) == 0 else w


def edge_widths(hull: Hull) -> np.ndarray:
    """Width of the hull across each edge (the diameter with that edge on the fence), O(n log n).

    The farthest point from edge ``i`` is the vertex whose normal cone holds the opposite
    direction (rotating calipers, found by binary search on the unwrapped edge normals).
    """
    h, d = _edge_arrays(hull)
    n = len(h)
    ang = np.arctan2(-d[:, 0], d[:, 1])
    unwrapped = ang[0] + np.concatenate([[0.0], np.cumsum(np.mod(np.diff(ang), 2 * np.pi))])
    opposite = ang + np.pi
    opposite = unwrapped[0] + np.mod(opposite - unwrapped[0], 2 * np.pi)
    far = np.searchsorted(unwrapped, opposite, side="right") % n
    length = np.hypot(d[:, 0], d[:, 1])
    gap = h - h[far]
    return (gap[:, 0] * d[:, 1] - gap[:, 1] * d[:, 0]) / length


def push_function(part: Part, near_metastable_deg: float = NEAR_METASTABLE_DEG) -> PushFunction:
    """Stable states, divergent orientations and resting ranges of ``part``, exactly.

    Edge ``i`` is stable iff the COM's foot lies strictly inside it. Hull vertex ``j``, between
    edges ``i = j - 1`` and ``j``, holds a divergent orientation iff the radius function rises
    at the start of its normal cone (the foot on edge ``i`` falls before ``j``) and falls at its
    end (the foot on edge ``j`` falls after ``j``); the divergent orientation is then the
    direction from the COM to the vertex. Edges whose foot is within ``near_metastable_deg`` of
    an end are flagged (Akella & Mason 1999, section 3.1).

    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> pf = push_function(make_part(make_outline("rect", [(0, 0), (20, 0), (20, 10), (0, 10)])))
    >>> pf.n, [round(s.diameter, 6) for s in pf.states]
    (4, [10.0, 20.0, 10.0, 20.0])
    """
    hull = part.hull
    n = len(hull)
    h_arr = np.asarray(hull, dtype=float)
    c_arr = np.asarray(part.com, dtype=float)
    normals = _normals(h_arr)
    to_start, to_end, _ = _foot_angles(h_arr, part.com)
    stable = (to_start > 0.0) & (to_end > 0.0)
    meta = ~stable & ((to_start == 0.0) | (to_end == 0.0))
    kinds = tuple(
        "stable" if s else "metastable" if m else "unstable"
        for s, m in zip(stable.tolist(), meta.tolist(), strict=True)
    )
    margin = np.minimum(to_start, to_end)
    near = tuple(int(i) for i in np.flatnonzero(np.abs(margin) < near_metastable_deg))

    # Vertex j = i + 1 between edge i and edge j: rises at its start iff to_end[i] > 0, falls
    # at its end iff to_start[j] > 0. Its divergent direction lies to_end[i] past normal i.
    nxt = np.roll(np.arange(n), -1)
    transition = (to_end > 0.0) & (to_start[nxt] > 0.0)
    cone = np.mod(normals[nxt] - normals, 360.0)
    off = np.clip(to_end, 0.0, cone)
    divergent = np.mod(normals + off, 360.0)[transition]
    divergent[divergent >= 360.0] = 0.0
    order = np.argsort(divergent, kind="stable")
    divergent = divergent[order]
    peak = np.hypot(*(h_arr[nxt] - c_arr).T)[transition][order]  # r at each divergent orientation
    stable_edges = np.flatnonzero(stable)
    m = len(divergent)
    if m != len(stable_edges) or m == 0:
        raise AssertionError(
            f"{part.name}: {len(stable_edges)} stable edges but {m} divergent orientations"
        )
    psi = normals[stable_edges]
    widths = edge_widths(h_arr)[stable_edges]
    k = (np.searchsorted(divergent, psi, side="right") - 1) % m  # range k starts at divergent[k]
    lo = psi - np.mod(psi - divergent[k], 360.0)
    hi = psi + np.mod(divergent[(k + 1) % m] - psi, 360.0)
    hi = np.where(hi <= psi, hi + 360.0, hi)
    rel = c_arr - h_arr[stable_edges]
    d_st = h_arr[nxt[stable_edges]] - h_arr[stable_edges]
    height = (rel[:, 1] * d_st[:, 0] - rel[:, 0] * d_st[:, 1]) / np.hypot(d_st[:, 0], d_st[:, 1])
    barrier = np.minimum(peak[k], peak[(k + 1) % m]) - height
    range_state = [0] * m
    states: list[StableState] = []
    near_set = set(near)
    pose = np.mod(-90.0 - psi, 360.0) + 0.0
    pose[pose >= 360.0] = 0.0
    arrays = (stable_edges, psi, lo, hi, widths, k, barrier, pose)
    columns = zip(*(c.tolist() for c in arrays), strict=True)
    for sid, (e, p, a, b, w, kk, bar, ps) in enumerate(columns):
        range_state[kk] = sid
        states.append(
            StableState(
                id=sid,
                edge=e,
                normal_deg=p,
                resting_range_deg=(a, b),
                diameter=w,
                pose_deg=ps,
                near_metastable=e in near_set,
                barrier_mm=max(bar, 0.0),
            )
        )
    return PushFunction(
        part=part,
        states=tuple(states),
        divergent_deg=tuple(divergent.tolist()),
        range_state=tuple(range_state),
        edge_kinds=kinds,
        near_metastable_edges=near,
        edge_margin_deg=tuple(margin.tolist()),
    )


def push(pf: PushFunction, theta_deg: float) -> StableState:
    """The push function: the stable state a fence orientation ``theta`` settles into.

    At a divergent orientation itself (an unstable equilibrium) the counter-clockwise
    neighbouring range is taken.
    """
    t = norm360(theta_deg)
    k = bisect.bisect_right(pf.divergent_deg, t) - 1
    return pf.states[pf.range_state[k % len(pf.range_state)]]


def push_diameter(pf: PushFunction, theta_deg: float) -> float:
    """The push-diameter function d(theta) = w(p(theta)) (definition 5)."""
    return push(pf, theta_deg).diameter


def resting_widths(pf: PushFunction) -> list[float]:
    """Width (deg) of each state's resting range; they add up to 360."""
    return [s.resting_range_deg[1] - s.resting_range_deg[0] for s in pf.states]


def rotation_after(theta_deg: float, action_deg: float) -> float:
    """The fence orientation after rotating the part counter-clockwise by ``action_deg``."""
    return norm360(theta_deg - action_deg)


def nearer_vertices(pf: PushFunction) -> list[int]:
    """For each hull edge, the end vertex nearer to the COM's foot (seen from the COM)."""
    to_start, to_end, _ = _foot_angles(pf.part.hull, pf.part.com)
    n = len(pf.part.hull)
    nearer_start = np.abs(to_start) <= np.abs(to_end)
    return np.where(nearer_start, np.arange(n), (np.arange(n) + 1) % n).tolist()


__all__ = [
    "METASTABLE_SNAP_DEG",
    "NEAR_METASTABLE_DEG",
    "PushFunction",
    "StableState",
    "com_feet",
    "diameter",
    "edge_normals",
    "edge_widths",
    "nearer_vertices",
    "push",
    "push_diameter",
    "push_function",
    "radius",
    "resting_widths",
    "rotation_after",
]
