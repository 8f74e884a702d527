"""The contact hull: the convex hull of an outline, counter-clockwise, numbered as design.md says.

Pure functions on point tuples. Hull vertex 0 is the lowest-then-leftmost vertex; edge ``i``
joins vertex ``i`` to vertex ``i + 1``.
"""

from __future__ import annotations

import heapq
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


def _chord_deviation(ring: Sequence[Point], i: int, k: int) -> float:
    """Largest distance of ring points strictly between indices ``i`` and ``k`` (cyclic) from chord i-k."""
    n = len(ring)
    a, c = ring[i], ring[k]
    dx, dy = c[0] - a[0], c[1] - a[1]
    length = math.hypot(dx, dy)
    worst = 0.0
    j = (i + 1) % n
    while j != k:
        p = ring[j]
        if length > 0.0:
            d = abs(dx * (p[1] - a[1]) - dy * (p[0] - a[0])) / length
        else:
            d = math.hypot(p[0] - a[0], p[1] - a[1])
        worst = max(worst, d)
        j = (j + 1) % n
    return worst


def clean_hull(hull: Sequence[Point], length_tol: float) -> list[Point]:
    """Simplify a convex CCW ring: drop vertices while every original vertex stays within ``length_tol``.

    A vertex may go when the chord joining its kept neighbours passes within ``length_tol`` of
    every original hull vertex between them (the error is measured against the original
    points, so it cannot drift along a flattened arc). The cheapest removal goes first, ties
    broken by coordinates, so the result does not depend on where the ring starts. Kept
    vertices are original vertices: the result lies inside the hull, at most ``length_tol``
    from it, and stays convex.
    """
    ring = list(hull)
    n = len(ring)
    if n <= 3:
        return ring
    prev = [(i - 1) % n for i in range(n)]
    nxt = [(i + 1) % n for i in range(n)]
    alive = [True] * n
    cost = [_chord_deviation(ring, prev[i], nxt[i]) for i in range(n)]
    heap = [(cost[i], ring[i], i) for i in range(n)]
    heapq.heapify(heap)
    count = n
    while heap and count > 3:
        c, _, i = heapq.heappop(heap)
        if not alive[i] or c != cost[i]:
            continue  # stale entry
        if c > length_tol:
            break
        alive[i] = False
        count -= 1
        a, b = prev[i], nxt[i]
        nxt[a], prev[b] = b, a
        for j in (a, b):
            cost[j] = _chord_deviation(ring, prev[j], nxt[j])
            heapq.heappush(heap, (cost[j], ring[j], j))
    return [p for i, p in enumerate(ring) if alive[i]]


def number_hull(hull: Sequence[Point], length_tol: float = 0.0) -> tuple[Point, ...]:
    """Rotate a counter-clockwise ring so vertex 0 is the lowest-then-leftmost vertex.

    Vertices whose y is within ``length_tol`` of the lowest count as lowest.
    """
    ymin = min(p[1] for p in hull)
    candidates = [i for i, p in enumerate(hull) if p[1] <= ymin + length_tol]
    start = min(candidates, key=lambda i: (hull[i][0], hull[i][1]))
    return tuple(hull[start:]) + tuple(hull[:start])


def contact_hull(points: Iterable[Sequence[float]], length_tol: float | None = None) -> tuple[Point, ...]:
    """The contact polygon of a set of outline points: convex, CCW, simplified, numbered.

    ``length_tol`` (mm) is the simplification tolerance of :func:`clean_hull`; by default
    ``REL_LENGTH_TOL`` of the part's size (exact up to rounding).
    """
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
