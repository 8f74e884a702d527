"""The contact hull: the convex hull of an outline, counter-clockwise, numbered as design.md says.

Pure functions on point tuples. Hull vertex 0 is the lowest-then-leftmost vertex; edge ``i``
joins vertex ``i`` to vertex ``i + 1``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

Point = tuple[float, float]

REL_LENGTH_TOL = 1e-9
"""Default length tolerance of hull cleaning, relative to the part's size."""


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull(points: Iterable[Sequence[float]]) -> list[Point]:
    """Andrew's monotone chain: the hull vertices counter-clockwise, collinear points dropped."""
    pts = sorted({(float(p[0]), float(p[1])) for p in points})
    if len(pts) <= 2:
        return pts
    lower: list[Point] = []
    for p in pts:
        while len(lower) >= 2 and _cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[Point] = []
    for p in reversed(pts):
        while len(upper) >= 2 and _cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def size_of(points: Sequence[Point]) -> float:
    """The larger side of the bounding box (a length scale for tolerances)."""
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return max(max(xs) - min(xs), max(ys) - min(ys))


def clean_hull(hull: Sequence[Point], length_tol: float) -> list[Point]:
    """Remove duplicate vertices and vertices within ``length_tol`` of the line of their neighbours.

    Repeats until stable, always removing the vertex that deviates least first, so that the
    result does not depend on where the ring starts.
    """
    ring = list(hull)
    changed = True
    while changed and len(ring) > 3:
        changed = False
        best_i, best_dev = -1, math.inf
        n = len(ring)
        for i in range(n):
            a, b, c = ring[i - 1], ring[i], ring[(i + 1) % n]
            ac = math.hypot(c[0] - a[0], c[1] - a[1])
            if math.hypot(b[0] - a[0], b[1] - a[1]) <= length_tol:
                dev = 0.0
            elif ac <= length_tol:
                dev = 0.0
            else:
                dev = abs(_cross(a, c, b)) / ac
            if dev < best_dev:
                best_i, best_dev = i, dev
        if best_dev <= length_tol:
            ring.pop(best_i)
            changed = True
    return ring


def number_hull(hull: Sequence[Point], length_tol: float = 0.0) -> tuple[Point, ...]:
    """Rotate a counter-clockwise ring so vertex 0 is the lowest-then-leftmost vertex.

    Vertices whose y is within ``length_tol`` of the lowest count as lowest.
    """
    ymin = min(p[1] for p in hull)
    candidates = [i for i, p in enumerate(hull) if p[1] <= ymin + length_tol]
    start = min(candidates, key=lambda i: (hull[i][0], hull[i][1]))
    return tuple(hull[start:]) + tuple(hull[:start])


def contact_hull(points: Iterable[Sequence[float]], length_tol: float | None = None) -> tuple[Point, ...]:
    """The contact polygon of a set of outline points: convex, CCW, cleaned, numbered."""
    raw = convex_hull(points)
    if len(raw) < 3:
        return tuple(raw)
    tol = REL_LENGTH_TOL * size_of(raw) if length_tol is None else length_tol
    return number_hull(clean_hull(raw, tol), tol)


def point_in_convex(hull: Sequence[Point], p: Point, margin: float = 0.0) -> bool:
    """Whether p lies inside the CCW convex polygon at least ``margin`` away from every edge line."""
    n = len(hull)
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if _cross(a, b, p) / length <= margin:
            return False
    return True
