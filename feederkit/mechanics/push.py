"""Radius, diameter, push and push-diameter functions of a part (section 3.1), exactly.

Angles are degrees. ``theta`` is the direction, in the part frame, of the fence's contact
normal pointing from the COM toward the fence (design.md). Edge ``i`` rests on the fence when
``theta`` equals its outward normal.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from feederkit.angles import ccw_delta, deg_atan2, norm360
from feederkit.part import Part

FOOT_SNAP = 1e-10
"""A COM foot within this fraction of an edge's length from a vertex is exactly metastable."""

NEAR_METASTABLE_DEG = 1.0
"""An edge whose COM foot is within this angle (seen from the COM) of a vertex is flagged."""


@dataclass(frozen=True)
class StableState:
    """A stable state: stable edge ``edge`` resting on the fence (a local minimum of the radius function).

    ``resting_range_deg`` is ``(lo, hi)`` with ``lo < normal_deg < hi``: every fence orientation
    strictly inside it settles here. ``pose_deg`` is the part's rotation in the world,
    ``-90 - normal`` (design.md).
    """

    id: int
    edge: int
    normal_deg: float
    resting_range_deg: tuple[float, float]
    diameter: float
    pose_deg: float
    near_metastable: bool = False


@dataclass(frozen=True)
class PushFunction:
    """The push function of a part and, with its states' diameters, its push-diameter function.

    ``divergent_deg`` are the divergent orientations (local maxima of the radius function),
    sorted in [0, 360); resting range ``k`` runs from ``divergent_deg[k]`` counter-clockwise to
    the next one and holds state ``range_state[k]``.
    """

    part: Part
    states: tuple[StableState, ...]
    divergent_deg: tuple[float, ...]
    range_state: tuple[int, ...]
    edge_kinds: tuple[str, ...]
    near_metastable_edges: tuple[int, ...]

    @property
    def n(self) -> int:
        """Number of stable states."""
        return len(self.states)


def edge_normals(hull: tuple[tuple[float, float], ...]) -> list[float]:
    """Outward normal direction (deg, [0, 360)) of each hull edge ``i`` (vertex i to i+1)."""
    n = len(hull)
    out = []
    for i in range(n):
        (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
        out.append(deg_atan2(-(x1 - x0), y1 - y0))
    return out


def com_feet(hull: tuple[tuple[float, float], ...], com: tuple[float, float]) -> list[float]:
    """Where the COM projects on each edge, as the fraction ``t`` from vertex i to vertex i+1.

    The edge is stable iff ``0 < t < 1``; values within FOOT_SNAP of 0 or 1 snap to them
    (metastable), so classification of edges and vertices stays consistent.
    """
    n = len(hull)
    feet = []
    for i in range(n):
        (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
        dx, dy = x1 - x0, y1 - y0
        t = ((com[0] - x0) * dx + (com[1] - y0) * dy) / (dx * dx + dy * dy)
        if abs(t) < FOOT_SNAP:
            t = 0.0
        elif abs(t - 1.0) < FOOT_SNAP:
            t = 1.0
        feet.append(t)
    return feet


def radius(part: Part, phi_deg: float | np.ndarray) -> float | np.ndarray:
    """Radius function r(phi): distance from the COM to the supporting line with normal phi."""
    v = np.asarray(part.hull, dtype=float) - np.asarray(part.com, dtype=float)
    phi = np.radians(np.asarray(phi_deg, dtype=float))
    u = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    r = (u @ v.T).max(axis=-1)
    return float(r) if np.ndim(r) == 0 else r


def diameter(part: Part, phi_deg: float | np.ndarray) -> float | np.ndarray:
    """Diameter function w(phi): the width between the two supporting lines with normal phi."""
    v = np.asarray(part.hull, dtype=float)
    phi = np.radians(np.asarray(phi_deg, dtype=float))
    u = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    proj = u @ v.T
    w = proj.max(axis=-1) - proj.min(axis=-1)
    return float(w) if np.ndim(w) == 0 else w


def _near_metastable(hull, com, normals, i) -> bool:
    """Whether the COM direction to either end of edge i is within NEAR_METASTABLE_DEG of its normal."""
    n = len(hull)
    for v in (hull[i], hull[(i + 1) % n]):
        a = deg_atan2(v[1] - com[1], v[0] - com[0])
        d = ccw_delta(normals[i], a)
        if min(d, 360.0 - d) < NEAR_METASTABLE_DEG:
            return True
    return False


def push_function(part: Part) -> PushFunction:
    """Stable states, divergent orientations and resting ranges of ``part``, exactly.

    Edge ``i`` is stable iff the COM's foot lies strictly inside it; hull vertex ``i+1`` (between
    edges ``i`` and ``i+1``) is a transition vertex iff the radius function rises at the start
    of its normal cone (``t_i < 1``) and falls at its end (``t_{i+1} > 0``); the divergent
    orientation is then the direction from the COM to the vertex.
    """
    hull, com = part.hull, part.com
    n = len(hull)
    normals = edge_normals(hull)
    feet = com_feet(hull, com)
    kinds = []
    for t in feet:
        if 0.0 < t < 1.0:
            kinds.append("stable")
        elif t in (0.0, 1.0):
            kinds.append("metastable")
        else:
            kinds.append("unstable")
    divergent: list[float] = []
    for i in range(n):
        j = (i + 1) % n
        if feet[i] < 1.0 and feet[j] > 0.0:
            v = hull[j]
            a = deg_atan2(v[1] - com[1], v[0] - com[0])
            # Clamp into the vertex's normal cone [normals[i], normals[j]] against rounding.
            width = ccw_delta(normals[i], normals[j])
            off = min(max(ccw_delta(normals[i], a), 0.0), width)
            if ccw_delta(normals[i], a) > width + (360.0 - width) / 2:
                off = 0.0
            divergent.append(norm360(normals[i] + off))
    near = tuple(i for i in range(n) if _near_metastable(hull, com, normals, i))
    stable_edges = [i for i in range(n) if kinds[i] == "stable"]
    divergent.sort()
    m = len(divergent)
    if m != len(stable_edges) or m == 0:
        raise AssertionError(
            f"{part.name}: {len(stable_edges)} stable edges but {m} divergent orientations"
        )
    diam = diameter(part, np.array([normals[i] for i in stable_edges]))
    states: list[StableState] = []
    range_state = [0] * m
    for sid, e in enumerate(stable_edges):
        psi = normals[e]
        k = bisect.bisect_right(divergent, psi) - 1  # range k starts at divergent[k] <= psi
        lo_d, hi_d = divergent[k % m], divergent[(k + 1) % m]
        lo = psi - ccw_delta(lo_d, psi)
        hi = psi + ccw_delta(psi, hi_d)
        if hi <= psi:
            hi += 360.0
        range_state[k % m] = sid
        states.append(
            StableState(
                id=sid,
                edge=e,
                normal_deg=psi,
                resting_range_deg=(lo, hi),
                diameter=float(diam[sid]),
                pose_deg=norm360(-90.0 - psi),
                near_metastable=e in near,
            )
        )
    return PushFunction(
        part=part,
        states=tuple(states),
        divergent_deg=tuple(divergent),
        range_state=tuple(range_state),
        edge_kinds=tuple(kinds),
        near_metastable_edges=near,
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


__all__ = [
    "FOOT_SNAP",
    "NEAR_METASTABLE_DEG",
    "PushFunction",
    "StableState",
    "com_feet",
    "diameter",
    "edge_normals",
    "push",
    "push_diameter",
    "push_function",
    "radius",
    "resting_widths",
    "rotation_after",
]
