"""The contact hull: the convex hull of an outline, counter-clockwise, numbered as design.md says.

Pure functions on point tuples. Hull vertex 0 is the lowest-then-leftmost vertex; edge ``i``
joins vertex ``i`` to vertex ``i + 1``.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable, Sequence

import numpy as np
import shapely

Point = tuple[float, float]

REL_LENGTH_TOL = 1e-9
"""Default length tolerance of hull cleaning, relative to the part's size."""


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


COLLINEAR_REL = 1e-11
"""A vertex this close to the line of its neighbours (relative to the points' size) is
collinear with them: two edges whose normals differ by rounding alone cannot be told stable
or not by the push function (a vertex 1e-11 mm off a 10 mm edge failed it)."""


def convex_hull(points: Iterable[Sequence[float]]) -> list[Point]:
    """Andrew's monotone chain: the hull vertices counter-clockwise, collinear points dropped
    (within ``COLLINEAR_REL`` of the points' size of their neighbours' line).

    The exact chains come first and the collinear vertices are dropped from them: with the
    tolerance inside the chain, points of one edge whose x differ by rounding alone (a drawing
    converted from inches) were taken in the wrong order and a real corner was popped.

    >>> convex_hull([(75.0054901286538, 113.869), (75.00549012865379, 116.126),
    ...              (75.0054901286538, 126.383), (100, 113), (100, 127)])
    [(75.0054901286538, 113.869), (100.0, 113.0), (100.0, 127.0), (75.0054901286538, 126.383)]
    """
    pts = sorted({(float(p[0]), float(p[1])) for p in points})
    if len(pts) <= 2:
        return pts
    eps = COLLINEAR_REL * size_of(pts)

    def turns(o: Point, a: Point, b: Point, tol: float) -> bool:
        # Left of the line o -> b by more than tol (the cross product over the base length).
        return _cross(o, a, b) > tol * math.hypot(b[0] - o[0], b[1] - o[1])

    def chain(seq: Iterable[Point], tol: float) -> list[Point]:
        out: list[Point] = []
        for p in seq:
            while len(out) >= 2 and not turns(out[-2], out[-1], p, tol):
                out.pop()
            out.append(p)
        return out

    lower = chain(chain(pts, 0.0), eps)
    upper = chain(chain(reversed(pts), 0.0), eps)
    hull = lower[:-1] + upper[:-1]
    # The chains' ends (the leftmost and rightmost points) were never tested: drop them too
    # when they lie on their neighbours' line.
    dropped = True
    while dropped and len(hull) > 2:
        dropped = False
        for i in range(len(hull)):
            if not turns(hull[i - 1], hull[i], hull[(i + 1) % len(hull)], eps):
                del hull[i]
                dropped = True
                break
    if len(hull) < 3:
        # Collinear within the tolerance: the segment between the two points farthest apart
        # (the chains may have kept a middle point rounding put off the line as an end).
        b = max(pts, key=lambda p: math.dist(pts[0], p))
        c = max(pts, key=lambda p: math.dist(b, p))
        return sorted([b, c])
    return hull


def size_of(points: Sequence[Point]) -> float:
    """The larger side of the bounding box (a length scale for tolerances)."""
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return max(max(xs) - min(xs), max(ys) - min(ys))


def diameter_of(hull: Sequence[Point]) -> float:
    """The largest distance between two vertices of the convex polygon ``hull`` (mm): its
    diameter, the part's largest dimension, which turning the drawing does not change (the
    bounding box's larger side does, by up to a factor of sqrt 2). Rotating calipers over
    the antipodal pairs (Shamos), linear in the vertices.

    >>> diameter_of([(0.0, 0.0), (3.0, 0.0), (3.0, 4.0)])
    5.0
    """
    n = len(hull)
    if n < 3:
        return math.dist(hull[0], hull[-1]) if n else 0.0

    def twice_area(a: Point, b: Point, c: Point) -> float:
        return abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    best, j = 0.0, 1
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        for _ in range(n):  # the vertex farthest from edge i-(i+1), moving one way only
            if twice_area(a, b, hull[(j + 1) % n]) <= twice_area(a, b, hull[j]):
                break
            j = (j + 1) % n
        best = max(best, math.dist(a, hull[j]), math.dist(b, hull[j]))
    return best


def _chord_deviation(ring: Sequence[Point], i: int, k: int) -> float:
    """Largest distance from chord i-k of the ring points strictly between ``i`` and ``k``."""
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


def _simplify(ring: Sequence[Point], length_tol: float) -> list[int]:
    """Indices of the vertices :func:`clean_hull` keeps (see there), in ring order."""
    n = len(ring)
    if n <= 3:
        return list(range(n))
    prev = [(i - 1) % n for i in range(n)]
    nxt = [(i + 1) % n for i in range(n)]
    alive = [True] * n
    stamp = [0] * n

    def priority(i: int) -> float:
        a, b, c = ring[prev[i]], ring[i], ring[nxt[i]]
        return max(math.hypot(b[0] - a[0], b[1] - a[1]), math.hypot(c[0] - b[0], c[1] - b[1]))

    heap = [(priority(i), ring[i], i, 0) for i in range(n)]
    heapq.heapify(heap)
    count = n
    while heap and count > 3:
        _, _, i, version = heapq.heappop(heap)
        if not alive[i] or version != stamp[i]:
            continue  # stale entry
        if _chord_deviation(ring, prev[i], nxt[i]) > length_tol:
            continue  # kept unless a neighbour goes (then it is queued again)
        alive[i] = False
        count -= 1
        a, b = prev[i], nxt[i]
        nxt[a], prev[b] = b, a
        for j in (a, b):
            stamp[j] += 1
            heapq.heappush(heap, (priority(j), ring[j], j, stamp[j]))
    return [i for i in range(n) if alive[i]]


DOMINANT_SIDE = 0.9
"""A merged edge is a flat side when one original edge makes up this share of its length."""


def _flat_side(ring: Sequence[Point], a: int, b: int) -> tuple[float, float, float] | None:
    """The fence line (nx, ny, h), n.x = h, of the merged edge ring[a] -> ring[b] when it is a
    flat side, else None (a run of flattened-arc chords: the chord itself is kept).

    A flat side is one original edge that makes up at least :data:`DOMINANT_SIDE` of the
    merged edge (plus the first chords of the arcs beside it); the line keeps that edge's
    direction and touches the outermost covered point, as the fence does.
    """
    n = len(ring)
    (ax, ay), (bx, by) = ring[a], ring[b]
    chord = math.hypot(bx - ax, by - ay)
    longest, best, j = 0.0, (0.0, 0.0), a
    while j != b:
        k = (j + 1) % n
        ex, ey = ring[k][0] - ring[j][0], ring[k][1] - ring[j][1]
        length = math.hypot(ex, ey)
        if length > longest:
            longest, best = length, (ex, ey)
        j = k
    if longest < DOMINANT_SIDE * chord:
        return None
    nx, ny = best[1] / longest, -best[0] / longest
    h, j = -math.inf, a
    while True:
        h = max(h, nx * ring[j][0] + ny * ring[j][1])
        if j == b:
            return nx, ny, h
        j = (j + 1) % n


def _chord_line(p: Point, q: Point) -> tuple[float, float, float]:
    dx, dy = q[0] - p[0], q[1] - p[1]
    norm = math.hypot(dx, dy)
    nx, ny = dy / norm, -dx / norm
    return nx, ny, nx * p[0] + ny * p[1]


def _distance_to_segments(a: np.ndarray, b: np.ndarray, p: Point) -> float:
    """Distance from ``p`` to the nearest of the segments ``a[i] -> b[i]``."""
    d = b - a
    len2 = np.einsum("ij,ij->i", d, d)
    w = np.asarray(p, dtype=float) - a
    t = np.divide(np.einsum("ij,ij->i", w, d), len2, out=np.zeros_like(len2), where=len2 > 0)
    t = np.clip(t, 0.0, 1.0)
    return float(np.hypot(*(w - t[:, None] * d).T).min())


def _near_ring(ring: np.ndarray, p: Point, lo: int, hi: int, limit: float) -> bool:
    """Whether ``p`` lies within ``limit`` of the ring's boundary: the segments from vertex
    ``lo`` to vertex ``hi`` (cyclic, where ``p`` was made) are asked first, all of them only
    when those are farther. The answer is the whole ring's either way; asking every segment
    of a 400,000-point ellipse's hull for each refitted vertex took minutes."""
    n = len(ring)
    idx = np.arange(lo, lo + (hi - lo) % n + 1) % n
    if _distance_to_segments(ring[idx], ring[(idx + 1) % n], p) <= limit:
        return True
    return _distance_to_segments(ring, np.roll(ring, -1, axis=0), p) <= limit


def _refit(ring: Sequence[Point], kept: list[int], length_tol: float) -> list[Point] | None:
    """Lay merged flat sides on their fence lines (see :func:`_flat_side`).

    Other edges stay chords between kept vertices; a vertex moves only when an edge beside it
    was refitted (to the intersection of the two lines). Returns None when the refit would
    not give a strictly convex ring within ``2 * length_tol`` of the original hull.
    """
    n, m = len(ring), len(kept)
    arr = np.asarray(ring, dtype=float)
    flats = [
        None
        if (kept[k] + 1) % n == kept[(k + 1) % m]
        else _flat_side(ring, kept[k], kept[(k + 1) % m])
        for k in range(m)
    ]
    if all(f is None for f in flats):
        return None
    out: list[Point] = []
    for k in range(m):
        before, after = flats[k - 1], flats[k]
        if before is None and after is None:
            out.append(ring[kept[k]])
            continue
        l1 = before or _chord_line(ring[kept[k - 1]], ring[kept[k]])
        l2 = after or _chord_line(ring[kept[k]], ring[kept[(k + 1) % m]])
        det = l1[0] * l2[1] - l1[1] * l2[0]
        if abs(det) < 1e-12:
            return None
        x = (l1[2] * l2[1] - l1[1] * l2[2]) / det
        y = (l1[0] * l2[2] - l1[2] * l2[0]) / det
        limit = 2 * length_tol + 1e-12 * (abs(x) + abs(y))
        if not _near_ring(arr, (x, y), kept[k - 1], kept[(k + 1) % m], limit):
            return None
        out.append((x, y))
    for i in range(m):
        if _cross(out[i - 1], out[i], out[(i + 1) % m]) <= 0:
            return None
    return out


def clean_hull(hull: Sequence[Point], length_tol: float) -> list[Point]:
    """Simplify a convex CCW ring so that a fence feels it within ``length_tol``.

    A vertex may go when the chord joining its kept neighbours passes within ``length_tol`` of
    every original hull vertex between them (the error is measured against the original
    points, so it cannot drift along a flattened arc). Vertices between the shortest edges go
    first (ties broken by coordinates, so the result does not depend on where the ring
    starts): runs of tiny chords merge among themselves before a long straight edge is
    touched. A merged edge that is mostly one flat side is then laid on that side's fence
    line (its direction, touching the outermost point it replaces), so flat sides keep their
    exact direction and distance; other vertices are unchanged original points.
    """
    ring = list(hull)
    kept = _simplify(ring, length_tol)
    if len(kept) == len(ring):
        return ring
    refit = _refit(ring, kept, length_tol) if len(kept) >= 3 else None
    return refit if refit is not None else [ring[i] for i in kept]


def number_hull(hull: Sequence[Point]) -> tuple[Point, ...]:
    """Rotate a counter-clockwise ring so vertex 0 is the lowest-then-leftmost vertex.

    Exact, as design.md states it (no tolerance): so a hull read back from a plan file is
    numbered as it was written.
    """
    start = min(range(len(hull)), key=lambda i: (hull[i][1], hull[i][0]))
    return tuple(hull[start:]) + tuple(hull[:start])


def contact_hull(
    points: Iterable[Sequence[float]], length_tol: float | None = None
) -> tuple[Point, ...]:
    """The contact polygon of a set of outline points: convex, CCW, simplified, numbered.

    ``length_tol`` (mm) is the simplification tolerance of :func:`clean_hull`; by default
    ``REL_LENGTH_TOL`` of the part's size (exact up to rounding).
    """
    raw = convex_hull(points)
    if len(raw) < 3:
        return tuple(raw)
    tol = REL_LENGTH_TOL * size_of(raw) if length_tol is None else length_tol
    return number_hull(clean_hull(raw, tol))


def point_in_convex(hull: Sequence[Point], p: Point, margin: float = 0.0) -> bool:
    """Whether p lies inside the CCW convex polygon, more than ``margin`` from every edge line."""
    n = len(hull)
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if _cross(a, b, p) / length <= margin:
            return False
    return True


def hull_distance(a: Sequence[Sequence[float]], b: Sequence[Sequence[float]]) -> float:
    """The Hausdorff distance (mm) between two convex polygons as regions.

    For convex regions it is the largest difference of their support functions over all
    directions: the most a fence, pushing either, can feel them differ. Exact: the farthest
    point of one region from the other is one of its vertices.

    >>> hull_distance([(0, 0), (2, 0), (2, 1), (0, 1)], [(0, 0), (2, 0), (2, 1.5), (0, 1.5)])
    0.5
    """
    pa, pb = shapely.Polygon(a), shapely.Polygon(b)
    da = shapely.distance(pb, shapely.points(np.asarray(a, dtype=float)))
    db = shapely.distance(pa, shapely.points(np.asarray(b, dtype=float)))
    return float(max(np.max(da), np.max(db)))
