"""The closed loops of a drawing's lines: found, healed, and refused when they cross.

Pure functions on polylines in millimetres (numpy arrays of shape (n, 2)). Loops are built
with ``shapely.polygonize`` per connected group of lines, so lines that cross a part (centre
lines, bend lines) do not split it. A closed entity (polyline, circle) or a loop of lines
joined end to end that crosses itself, or a closed entity crossing another loop, is refused
rather than merged: polygonizing would split a bow-tie into two parts and weld a crossing
circle onto the outline. A :class:`Region` is a part the loops make (its outer loop and its
holes); :mod:`.drawing` nests the loops into regions.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
import shapely.ops
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from shapely.geometry import LineString, Polygon

from feederkit.importers.budget import Budget
from feederkit.words import plural

Point = tuple[float, float]


TANGENT_SPREAD = 1.25
"""A closed line that comes within ``t`` (twice the flatten tolerance) of other lines is
tangent to them when its length within ``4 t`` of them is at least this many times its
length within ``t`` (:func:`_tangent`): a curve leaves a tangent curve or line gradually
(twice the length within four times the distance), a side drawn along another line stays
on it and then turns away."""


NEAR_COPY_SHARE = 0.01
"""Two closed lines within this share of their size of each other are one loop drawn twice."""


DRAWN_TWICE_SHARE = 0.05
"""A closed line and a loop of other lines it crosses, each within this share of the
closed line's size of the other and sharing :data:`DRAWN_TWICE_COMMON` of their area, are
one loop drawn twice (an outline pasted again as lines, shifted by a millimetre)."""

DRAWN_TWICE_COMMON = 0.8
"""The least share of two loops' union their intersection holds for them to be one loop
drawn twice (:data:`DRAWN_TWICE_SHARE`)."""

MOSTLY_INSIDE = 0.4
"""The share of a crossing loop's area inside the loop it crosses from which it is taken for
a hole across that loop's outline (a circle centred on the outline's edge has half of it
inside, a little less once flattened); below it on both sides, the two loops are shapes
that overlap (a T drawn as two rectangles, one a seventh inside the other)."""


@dataclass(frozen=True)
class Region:
    """A part found in a drawing: its outer loop and its holes (mm); ``area`` excludes holes."""

    shell: tuple[Point, ...]
    holes: tuple[tuple[Point, ...], ...]
    area: float
    loop_area: float
    enclosed: int = 0
    """Faces merged into the outer loop that share no stretch of its outline (:class:`Loop`)."""
    outside: tuple[tuple[float, float, float, float], ...] = ()
    """Bounds of the regions merged into the outer loop that open lines close against a closed
    line's edge from outside (:class:`Loop`)."""
    cut_off: tuple[tuple[float, float, float, float], ...] = ()
    """Bounds of the regions merged into the outer loop that an open line inside it cuts off,
    stopping on its outline at both ends (:class:`Loop`)."""


def snap_endpoints(lines: Sequence[np.ndarray], gap: float) -> list[np.ndarray]:
    """Move polyline endpoints closer than ``gap`` to each other onto their common mean.

    CAD drawings often leave tiny gaps between the ends of consecutive entities.
    """
    if gap <= 0.0 or not lines:
        return list(lines)
    sizes = np.fromiter((len(ln) for ln in lines), dtype=np.int64, count=len(lines))
    coords = np.concatenate(lines).astype(float, copy=False)
    first = np.concatenate(([0], np.cumsum(sizes)[:-1]))
    ends = np.empty((2 * len(lines), 2))
    ends[0::2] = coords[first]
    ends[1::2] = coords[first + sizes - 1]
    pairs = cKDTree(ends).query_pairs(gap, output_type="ndarray")
    if len(pairs) == 0:
        return list(lines)
    n = len(ends)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    sums = np.zeros((label.max() + 1, 2))
    np.add.at(sums, label, ends)
    snapped = (sums / np.bincount(label)[:, None])[label]
    moved = np.flatnonzero((snapped != ends).any(axis=1)) // 2
    out = list(lines)
    for k in np.unique(moved):
        ln = np.array(lines[k], dtype=float)
        ln[0], ln[-1] = snapped[2 * k], snapped[2 * k + 1]
        out[k] = ln
    return out


def along(lines: np.ndarray | shapely.Geometry, other: shapely.Geometry, tol: float) -> np.ndarray:
    """Which ``lines`` lie wholly within ``tol`` of ``other``: inside its buffer, so a chord's
    middle counts as well as its ends."""
    return shapely.covers(shapely.buffer(other, tol), lines)


def _exact_repeats(lines: Sequence[np.ndarray]) -> list[int]:
    """For each line, the first line with the same points (in either direction), or itself.

    A CAD copy flattens to the very same floats; found by hashing, so a thousand copies of
    one line cost no thousand squared comparisons.
    """
    first: dict[bytes, int] = {}
    out = []
    for k, ln in enumerate(lines):
        pts = np.ascontiguousarray(ln, dtype=float)
        key = min(pts.tobytes(), pts[::-1].tobytes())
        out.append(first.setdefault(key, k))
    return out


def repeated_lines(
    lines: Sequence[np.ndarray], tol: float, budget: Budget | None = None
) -> list[int]:
    """Indices of the lines that repeat an earlier line within ``tol``: each lies within
    ``tol`` of the other (a circle drawn twice, a CIRCLE over a closed polyline of two
    bulges, an outline LINE drawn twice).

    A repeat adds no geometry, but left in, its every stretch lies on two lines, as a
    title-block cell's side lies on the frame: a duplicated hole crossed by a centre line
    was taken for a face sharing lines and merged into the part. Equal lines have bounds
    equal within ``tol``, so only those pairs are compared; each line is compared with
    the later lines, each kept line in turn (a thousand copies cost a thousand comparisons).
    """
    if len(lines) < 2:
        return []
    first = _exact_repeats(lines)
    unique = [k for k, f in enumerate(first) if f == k and len(lines[k]) >= 2]
    repeats = {k for k, f in enumerate(first) if f != k}
    if tol <= 0.0 or len(unique) < 2:
        return sorted(repeats)
    bounds = _bounds([lines[k] for k in unique])
    tree = cKDTree(bounds)
    alone = tree.query_ball_point(bounds, tol, p=np.inf, return_length=True) == 1
    geoms: dict[int, shapely.Geometry] = {}

    def geom(k: int) -> shapely.Geometry:
        if k not in geoms:
            geoms[k] = shapely.linestrings(np.asarray(lines[k], dtype=float))
        return geoms[k]

    for a, i in enumerate(unique):  # i is kept: no kept line before it repeats it
        if alone[a] or i in repeats:
            continue
        for b in tree.query_ball_point(bounds[a], tol, p=np.inf):
            j = unique[b]
            if budget is not None:
                budget.check_time()
            if j > i and j not in repeats and _same(geom(i), geom(j), tol):
                repeats.add(j)
    return sorted(repeats)


def _bounds(lines: Sequence[np.ndarray]) -> np.ndarray:
    """Each line's bounds (x0, y0, x1, y1), one row per line."""
    pts = np.concatenate(lines).astype(float, copy=False)
    starts = np.concatenate(([0], np.cumsum([len(ln) for ln in lines])[:-1]))
    return np.hstack([np.minimum.reduceat(pts, starts), np.maximum.reduceat(pts, starts)])


def _same(a: shapely.Geometry, b: shapely.Geometry, tol: float) -> bool:
    """Whether two lines are equal within ``tol``: each lies within ``tol`` of the other."""
    return bool(along(a, b, tol)) and bool(along(b, a, tol))


def components(pieces: np.ndarray) -> np.ndarray:
    """Label of the connected group of each noded line piece."""
    tree = shapely.STRtree(pieces)
    left, right = tree.query(pieces, predicate="intersects")
    n = len(pieces)
    graph = coo_matrix((np.ones(len(left)), (left, right)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def face_count(pieces: np.ndarray, labels: np.ndarray) -> int:
    """Faces the noded line pieces enclose, by Euler's formula: edges - nodes + components.

    Counted before polygonizing, so a plate with 20,000 holes or 2,000 crossing lines is
    refused in a moment instead of after minutes of polygonizing.
    """
    ends = np.concatenate([shapely.get_coordinates(shapely.get_point(pieces, k)) for k in (0, -1)])
    nodes = len(np.unique(ends, axis=0))
    return max(0, len(pieces) - nodes + len(np.unique(labels)))


@dataclass(frozen=True)
class Loop:
    """A closed loop of a drawing (filled, no holes) and how many faces it was merged from.

    ``faces`` above 1 means lines inside the loop touch its boundary: title-block cells in a
    drawing frame, or a centre line across a part.
    """

    polygon: Polygon
    faces: int
    largest_face: float
    enclosed: int = 0
    """Faces merged into the loop that touch its outline nowhere or at points only: what lines
    inside the part enclose (a hole drawn with lines that touch the outline or are crossed by
    a centre line): merged, so the part may have lost a hole (a warning says so)."""
    outside: tuple[tuple[float, float, float, float], ...] = ()
    """Bounds of the regions merged into the loop that lie outside every closed line of its
    group and that open lines close only against a closed line's edge (extension and
    dimension lines drawn against the outline): merged, with a warning."""
    cut_off: tuple[tuple[float, float, float, float], ...] = ()
    """Bounds of the regions merged into the loop that an open line inside it cuts off,
    stopping on its outline at both ends (:func:`_cut_off`: dimension lines drawn against an
    outline of lines, a part drawn against another): merged, with a warning."""
    split: bool = False
    """Whether the loop is one of several closed lines lying side by side (sharing edges)
    that tiled a group's merged loop and were read apart (parts nested for common-line
    cutting, a view drawn against its part)."""
    cells: tuple[tuple[float, float, float, float], ...] = ()
    """Bounds of the faces merged into the loop other than the largest: a drawing frame's
    title-block cells, or the strips between a plate's bend lines."""


def _near(lines: np.ndarray, others: np.ndarray, tol: float) -> bool:
    """Whether every point of ``lines`` lies within ``tol`` of one of ``others`` (checked on
    points at most ``tol`` apart along them; their midpoints first, cheaply)."""
    if len(others) == 0:
        return False
    tree = shapely.STRtree(others)
    mids = shapely.line_interpolate_point(lines, 0.5, normalized=True)
    if len(np.unique(tree.query(mids, predicate="dwithin", distance=tol)[0])) < len(mids):
        return False
    points = shapely.points(shapely.get_coordinates(shapely.segmentize(lines, tol)))
    hit = tree.query(points, predicate="dwithin", distance=tol)[0]
    return len(np.unique(hit)) == len(points)


def _tangent(ring: Polygon, others: np.ndarray, tol: float) -> bool:
    """Whether a closed line touching ``others`` within ``tol`` only touches them (a curve
    tangent to the outline: chords crossing chords) rather than running along them (a
    title-block cell's side drawn on the frame, a circle drawn over a round end): its length
    within ``4 tol`` of them is at least :data:`TANGENT_SPREAD` times that within ``tol``."""
    xy = shapely.get_coordinates(shapely.segmentize(ring.exterior, tol))
    seg = np.hypot(*np.diff(xy, axis=0).T)
    weight = (seg + np.roll(seg, 1)) / 2.0  # the length each vertex (not the last) stands for
    points = shapely.points(xy[:-1])
    k, j = shapely.STRtree(others).query(points, predicate="dwithin", distance=4.0 * tol)
    dist = np.full(len(points), np.inf)
    np.minimum.at(dist, k, shapely.distance(points[k], others[j]))
    close = float(weight[dist <= tol].sum())
    return close <= 0.0 or float(weight[dist <= 4.0 * tol].sum()) >= TANGENT_SPREAD * close


def _on_other_lines(
    ring: Polygon, on_line: csr_matrix, lines: np.ndarray, tol: float
) -> np.ndarray:
    """Whether each piece (a row of ``on_line``: the lines it lies on) lies on a line other
    than ``ring``'s own: one not wholly within ``tol`` of the ring. A line along the ring is
    the ring, or part of it, drawn again (ARCs under a CIRCLE): no stretch it shares with
    another line, as a title-block cell's side on the frame is."""
    cols = np.unique(on_line.indices)
    other = ~along(lines[cols], ring.exterior, tol)
    return np.asarray(on_line[:, cols[other]].sum(axis=1)).ravel() > 0


def _inner_closed(
    poly: Polygon,
    pieces: np.ndarray,
    mids: np.ndarray,
    on_line: csr_matrix,
    lines: np.ndarray,
    rings: Sequence[Polygon],
    eps: float,
    gap: float = 0.0,
) -> list[tuple[Polygon, list[Polygon]]]:
    """The closed lines of a group (``rings``) that lie inside its merged loop ``poly`` and
    share no stretch with its outline nor with any other line, each with its hole: holes,
    though they touch the outline at a point or lines inside the part (centre lines) join
    them to it.

    ``pieces`` are the group's noded pieces and ``mids`` their midpoints (a piece lies on a
    ring when its midpoint does); row ``i`` of ``on_line`` marks the drawing's ``lines``
    that piece ``i`` lies on. A closed line that shares a stretch of the outline or of
    another line (a title-block cell, a notch drawn closed, a tile of a grid) stays merged;
    a line running wholly along it (part of it drawn again, :func:`_on_other_lines`) is no
    other line. A curve tangent to a curved outline is flattened into chords that cross the
    outline's chords (two polygons approximating tangent circles overlap in a sliver): the
    stretches of it that the merged outline takes, or that noding merged with the
    outline's, are no stretch of the outline when they lie within twice the flatten
    tolerance ``gap`` of the other lines (:func:`_near`) and the curve leaves them as a
    tangent does (:func:`_tangent`), not as a side drawn along them (without ``gap`` any
    touch is a shared stretch). The hole is the closed line clipped to the loop shrunk by
    ``1000 eps`` (so a tangent hole never pokes outside the part nor touches its outline:
    nesting by containment then holds in floating point); it can split into pieces (a
    list, empty when nothing is left).
    """
    out: list[tuple[Polygon, list[Polygon]]] = []
    tiny = 1e-9 * poly.area
    tree = shapely.STRtree(mids)
    shrunk: Polygon | None = None
    length = shapely.length(pieces)
    tol = 2.0 * gap + eps
    for ring in rings:
        if ring.area >= poly.area - tiny or not poly.contains(ring.representative_point()):
            continue
        on = tree.query(ring.exterior, predicate="dwithin", distance=eps)
        shared = _on_other_lines(ring, on_line[on], lines, tol)  # of the pieces ``on`` it
        outside = on[~shared & shapely.dwithin(mids[on], poly.exterior, eps)]
        if shared.any() or len(outside):
            if gap <= 0.0:
                continue  # it shares a stretch of another line or of the outline
            if TANGENT_SPREAD * length[on[shared]].sum() > ring.length:
                continue  # it runs along other lines (a grid's tile, a title-block cell)
            rest = np.ones(len(pieces), dtype=bool)
            rest[on[~shared]] = False
            others = pieces[rest]  # the other lines
            if len(outside) and not _near(pieces[outside], others, tol):
                continue  # it is part of the outline
            if not _tangent(ring, others, tol):
                continue  # it runs along the outline or another line: drawn over it
        if poly.contains_properly(ring):
            out.append((ring, [ring]))
            continue
        if shrunk is None:
            shrunk = poly.buffer(-1e3 * eps, join_style="mitre")
        holes = shapely.get_parts(ring.intersection(shrunk))
        out.append((ring, [h for h in holes if isinstance(h, Polygon) and h.area > tiny]))
    return out


def _thin(polys: np.ndarray, gap: float) -> np.ndarray:
    """Which polygons are on average no thicker than twice ``gap`` (area at most ``gap``
    times the perimeter): slivers between two flattenings of one curve, never a part."""
    return shapely.area(polys) <= gap * shapely.length(polys)


def _enclosed_faces(poly: Polygon, faces: Sequence[Polygon], eps: float, gap: float = 0.0) -> int:
    """How many ``faces`` (of the loop ``poly``) share no stretch of its outline (longer than
    ``eps``): a face touching it at points only is enclosed by lines inside the loop. Slivers
    no thicker than twice the flatten tolerance ``gap`` (:func:`_thin`: an ARC drawn over a
    CIRCLE, its chords beside the circle's) are no hole and not counted."""
    if len(faces) < 2:
        return 0
    polys = np.asarray(faces, dtype=object)
    common = shapely.intersection(shapely.get_exterior_ring(polys), poly.exterior)
    return int(((shapely.length(common) <= eps) & ~_thin(polys, gap)).sum())


def _open_cover(group: np.ndarray, on_line: csr_matrix, lines: np.ndarray) -> shapely.Geometry:
    """The area the group's open lines enclose among themselves, without the closed lines:
    row ``i`` of ``on_line`` marks the drawing's ``lines`` that piece ``i`` of ``group`` lies
    on. A plate drawn with LINEs encloses itself; extension lines drawn against a closed
    outline enclose nothing without it."""
    closed = shapely.is_closed(lines) & (shapely.get_num_coordinates(lines) >= 4)
    on_open = np.asarray(on_line[:, np.flatnonzero(~closed)].sum(axis=1)).ravel() > 0
    if not on_open.any():
        return shapely.GeometryCollection()
    return shapely.union_all(shapely.get_parts(shapely.polygonize(group[on_open])))


def _closed_against(
    faces: Sequence[Polygon], rings: Sequence[Polygon], cover: shapely.Geometry, gap: float
) -> tuple[tuple[float, float, float, float], ...]:
    """Bounds of the regions that ``faces`` (of one merged loop) make outside every closed
    line ``rings`` and that the open lines alone (their area ``cover``, :func:`_open_cover`)
    do not enclose: open lines closing a region against a closed outline's edge, as
    extension and dimension lines drawn from the part's corners do. Slivers (:func:`_thin`)
    are none."""
    if len(faces) < 2 or not rings:
        return ()
    polys = np.asarray(faces, dtype=object)
    points = shapely.point_on_surface(polys)
    k, _ = shapely.STRtree(list(rings)).query(points, predicate="within")
    in_ring = np.zeros(len(polys), dtype=bool)
    in_ring[k] = True
    if not in_ring.any():
        return ()
    out = ~in_ring & ~shapely.contains(cover, points) & ~_thin(polys, gap)
    if not out.any():
        return ()
    regions = shapely.get_parts(shapely.union_all(polys[out]))
    return tuple(tuple(float(v) for v in shapely.bounds(r)) for r in regions)


def _cut_off(
    shape: Polygon, group: np.ndarray, rings: Sequence[Polygon], tol: float, gap: float
) -> tuple[tuple[float, float, float, float], ...]:
    """Bounds of the regions of the merged loop ``shape`` that an open line inside it cuts
    off while stopping on its outline at both ends (no line of ``group`` runs on outside it
    there): the part's own edge between it and extension or dimension lines drawn from its
    corners, when the part is drawn with lines, or a second part drawn against it. A centre
    line runs on beyond the outline; lines along a closed line (``rings``) are that line's
    (:func:`_closed_against` judges those). The largest region is the part; slivers
    (:func:`_thin`) are none."""
    group = group[shapely.intersects(shape, group)]
    mids = shapely.line_interpolate_point(group, 0.5, normalized=True)
    edge = shapely.distance(mids, shape.exterior) <= tol
    inner = shapely.contains(shape, mids) & ~edge
    for ring in rings:
        inner &= shapely.distance(mids, ring.exterior) > tol
    if not inner.any():
        return ()
    out = group[~inner & ~edge]
    chains = shapely.get_parts(shapely.line_merge(shapely.union_all(group[inner])))
    starts = shapely.get_point(chains, 0)
    ends = shapely.get_point(chains, -1)
    on_edge = (shapely.distance(starts, shape.exterior) <= tol) & (
        shapely.distance(ends, shape.exterior) <= tol
    )
    if len(out):
        tree = shapely.STRtree(out)
        for pts in (starts, ends):
            on_edge[np.unique(tree.query(pts, predicate="dwithin", distance=tol)[0])] = False
    if not on_edge.any():
        return ()
    pieces = shapely.get_parts(shapely.ops.split(shape, shapely.union_all(chains[on_edge])))
    pieces = np.asarray([p for p in pieces if isinstance(p, Polygon)], dtype=object)
    if len(pieces) < 2:
        return ()
    rest = np.ones(len(pieces), dtype=bool)
    rest[int(np.argmax(shapely.area(pieces)))] = False
    rest &= ~_thin(pieces, gap)
    if not rest.any():
        return ()
    regions = shapely.get_parts(shapely.union_all(pieces[rest]))
    return tuple(tuple(float(v) for v in shapely.bounds(r)) for r in regions)


def _side_by_side(faces: Sequence[Polygon], rings: Sequence[Polygon]) -> list[list[Polygon]]:
    """The faces of each closed line when two or more of ``rings`` lie side by side in one
    merged loop and tile it (every face inside exactly one of them, none inside another:
    parts nested for common-line cutting, a view drawn against its part), else [].

    Each is a part of its own: merging them made one part of two. A closed line inside
    another (a title-block cell in its frame, a notch drawn closed) is no such line.
    """
    if len(rings) < 2 or len(faces) < 2:
        return []
    points = shapely.point_on_surface(np.asarray(faces, dtype=object))
    ring, point = shapely.STRtree(points).query(np.asarray(rings), predicate="contains")
    inside: dict[int, set[int]] = {}
    for r, f in zip(ring.tolist(), point.tolist(), strict=True):
        inside.setdefault(r, set()).add(f)
    sets = {frozenset(fs) for fs in inside.values()}
    tops = sorted((s for s in sets if not any(s < t for t in sets)), key=min)
    if len(tops) < 2 or sum(len(s) for s in tops) != len(faces):
        return []
    if len(frozenset().union(*tops)) != len(faces):
        return []  # two of them overlap: a crossing, refused later
    return [[faces[i] for i in sorted(s)] for s in tops]


def closed_loops(
    lines: Sequence[np.ndarray],
    budget: Budget | None = None,
    closed: Sequence[np.ndarray] = (),
    gap: float = 0.0,
) -> tuple[list[Loop], list[LineString]]:
    """The closed loops the lines form, and the open lines (dangles) left over.

    The faces of each connected group of lines are merged (a centre line does not cut a
    part in two), except the closed lines (``closed``: circles, closed polylines) lying
    inside a merged loop that share no stretch of its outline nor of another line
    (:func:`_inner_closed`): each is a loop of its own (a hole tangent to the outline, or
    one a centre line crosses), not merged away; one whose flattened chords cross a curved
    outline's by no more than twice the flatten tolerance ``gap`` is tangent too, and its
    hole is clipped to the loop. Closed lines lying side by side that tile a merged loop are
    loops of their own (:func:`_side_by_side`). ``Loop.enclosed`` counts the faces still
    merged that touch the loop's outline at points only (:func:`_enclosed_faces`),
    ``Loop.outside`` those open lines close against a closed line's edge from outside
    (:func:`_closed_against`).
    """
    lines = [ln for ln in lines if len(ln) >= 2]
    if not lines:
        return [], []
    sizes = [len(ln) for ln in lines]
    geoms = shapely.get_parts(
        shapely.linestrings(np.concatenate(lines), indices=np.repeat(np.arange(len(lines)), sizes))
    )
    geoms = geoms[shapely.length(geoms) > 0.0]
    if len(geoms) == 0:
        return [], []
    if budget is not None:  # noding costs grow with the crossings: count them first (cheap)
        left, right = shapely.STRtree(geoms).query(geoms)
        budget.crossings(int((left < right).sum()))
    noded = shapely.union_all(geoms)
    pieces = np.array(shapely.get_parts(noded))
    pieces = pieces[shapely.get_type_id(pieces) == 1]  # LineStrings only
    if len(pieces) == 0:
        return [], []
    if budget is not None:
        budget.segments(int(shapely.get_num_coordinates(pieces).sum()) - len(pieces))
    labels = components(pieces)
    if budget is not None:
        budget.need("loops", face_count(pieces, labels), "closed loops (parts and holes)")
    x0, y0, x1, y1 = shapely.total_bounds(pieces)
    eps = 1e-9 * max(x1 - x0, y1 - y0, 1.0)
    rings = [Polygon(np.asarray(c, dtype=float)) for c in closed if len(c) >= 4]
    rings = [r for r in rings if r.is_valid and r.area > 0.0]
    ring_group: dict[int, list[Polygon]] = {}
    if rings:  # each closed line's group: the group of the piece on its first vertex
        lines_tree = shapely.STRtree(geoms)
        tree = shapely.STRtree(pieces)
        first = shapely.points([np.asarray(r.exterior.coords[0]) for r in rings])
        near = tree.query_nearest(first, all_matches=False)[1]
        for ring, k in zip(rings, near, strict=True):
            ring_group.setdefault(int(labels[k]), []).append(ring)
    loops: list[Loop] = []
    dangles: list[LineString] = []
    for lab in np.unique(labels):
        if budget is not None:
            budget.check_time()
        group = pieces[labels == lab]
        faces, _cuts, dangle_geoms, _invalid = shapely.polygonize_full(group)
        dangles.extend(shapely.get_parts(dangle_geoms))
        parts = shapely.get_parts(faces)
        if len(parts) == 0:
            continue
        if budget is not None:
            budget.loops(len(parts))
        merged = shapely.union_all(parts)
        candidates = ring_group.get(int(lab), []) if len(parts) > 1 else []
        cover: shapely.Geometry | None = None
        if candidates:
            mids = shapely.line_interpolate_point(group, 0.5, normalized=True)
            piece, line = lines_tree.query(mids, predicate="dwithin", distance=eps)
            on_line = csr_matrix(
                (np.ones(len(piece), dtype=bool), (piece, line)), shape=(len(mids), len(geoms))
            )
            cover = _open_cover(group, on_line, geoms)
        for poly in shapely.get_parts(merged):
            if budget is not None:
                budget.check_time()
            if not (isinstance(poly, Polygon) and poly.area > 0.0):
                continue
            outline = Polygon(poly.exterior)
            inner = (
                _inner_closed(outline, group, mids, on_line, geoms, candidates, eps, gap)
                if candidates
                else []
            )
            rings_in = [ring for ring, _ in inner]
            apart = (
                _side_by_side(
                    [f for f in parts if outline.contains(f.representative_point())],
                    [r for r in candidates if not any(r is h for h in rings_in)],
                )
                if len(candidates) >= 2
                else []
            )
            tiles = [shapely.union_all(fs) for fs in apart]
            if not all(isinstance(p, Polygon) for p in tiles):
                apart, tiles = [], []  # a closed line's faces in two: leave them merged
            outlines = [Polygon(p.exterior) for p in tiles] or [outline]
            shapes = [
                *((o, rings_in, True) for o in outlines),
                *((h, [], False) for _, hs in inner for h in hs),
            ]
            for shape, cut, outer in shapes:
                own = [
                    f
                    for f in parts
                    if shape.contains(f.representative_point())
                    and not any(r.contains(f.representative_point()) for r in cut)
                ]
                loops.append(
                    Loop(
                        polygon=shape,
                        faces=len(own),
                        largest_face=max((f.area for f in own), default=shape.area),
                        enclosed=_enclosed_faces(shape, own, 1e3 * eps, gap),
                        outside=(
                            _closed_against(own, candidates, cover, gap)
                            if outer and cover is not None
                            else ()
                        ),
                        cut_off=(
                            _cut_off(shape, group, ring_group.get(int(lab), []), 1e3 * eps, gap)
                            if outer and len(own) >= 2
                            else ()
                        ),
                        split=outer and bool(apart),
                        cells=_cells_of(own),
                    )
                )
    return loops, dangles


def _cells_of(faces: Sequence[Polygon]) -> tuple[tuple[float, float, float, float], ...]:
    """The bounds of every face but the largest (:attr:`Loop.cells`)."""
    if len(faces) < 2:
        return ()
    largest = max(range(len(faces)), key=lambda k: faces[k].area)
    return tuple(
        tuple(float(v) for v in f.bounds)  # type: ignore[misc]
        for k, f in enumerate(faces)
        if k != largest
    )


def open_ends(lines: Sequence[np.ndarray], tol: float) -> np.ndarray:
    """Indices (into the 2n polyline ends) of ends that meet no other end nor any line."""
    n = len(lines)
    ends = np.empty((2 * n, 2))
    for k, ln in enumerate(lines):
        ends[2 * k], ends[2 * k + 1] = ln[0], ln[-1]
    closed = [float(np.hypot(*(ln[0] - ln[-1]))) <= tol for ln in lines]
    counts = [len(c) for c in cKDTree(ends).query_ball_point(ends, tol)]
    candidates = [e for e in range(2 * n) if counts[e] == 1 and not closed[e // 2]]
    if not candidates:
        return np.zeros(0, dtype=np.int64)
    geoms = np.array([shapely.linestrings(np.asarray(ln, dtype=float)) for ln in lines])
    hit_p, hit_g = shapely.STRtree(geoms).query(
        shapely.points(ends[candidates]), predicate="dwithin", distance=tol
    )
    touching = {int(p) for p, g in zip(hit_p, hit_g, strict=True) if int(g) != candidates[p] // 2}
    return np.array([e for k, e in enumerate(candidates) if k not in touching], dtype=np.int64)


def heal_gaps(
    lines: Sequence[np.ndarray], snap: float, max_gap: float
) -> tuple[list[np.ndarray], list[str]]:
    """Bridge gaps of at most ``max_gap`` between open line ends (mutually nearest pairs).

    A CAD user's outline often misses closing by a hair more than the flatten tolerance
    (a spline ending 0.09 mm short of its start); unhealed, the outline is dropped and its
    hole taken for the part. Each gap closed is a straight bridge, and the user is told.
    """
    if max_gap <= snap or not lines:
        return list(lines), []
    ends_idx = open_ends(lines, snap)
    if len(ends_idx) < 2:
        return list(lines), []
    ends = np.array([lines[e // 2][0 if e % 2 == 0 else -1] for e in ends_idx], dtype=float)
    dist, nearest = cKDTree(ends).query(ends, k=2)
    bridges: list[np.ndarray] = []
    gaps: list[tuple[float, np.ndarray]] = []
    for a in range(len(ends)):
        b = int(nearest[a, 1])
        if a < b and int(nearest[b, 1]) == a and snap < dist[a, 1] <= max_gap:
            bridges.append(np.array([ends[a], ends[b]]))
            gaps.append((float(dist[a, 1]), (ends[a] + ends[b]) / 2))
    if not bridges:
        return list(lines), []
    worst, where = max(gaps, key=lambda g: g[0])
    note = (
        f"closed {len(bridges)} gap(s) between open line ends (largest {worst:.3g} mm, at "
        f"({where[0]:.1f}, {where[1]:.1f})); check the drawing"
    )
    return list(lines) + bridges, [note]


def closing_lines(lines: Sequence[np.ndarray], gap: float) -> list[int]:
    """Indices of the ``lines`` that close loops among themselves: each is a closed line or
    lies wholly on the rim of a face the lines enclose (ends closer than ``gap`` joined).

    A rectangle of four LINEs counts, a centre line crossing a circle does not.
    """
    if not lines:
        return []
    snapped = snap_endpoints(lines, gap)
    geoms = np.array([shapely.linestrings(np.asarray(ln, dtype=float)) for ln in snapped])
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.union_all(geoms))))
    if len(faces) == 0:
        return [k for k, ln in enumerate(snapped) if is_closed(ln, gap)]
    rims = shapely.union_all(shapely.boundary(faces))
    on_rim = along(geoms, rims, max(gap, 1e-9))
    return [k for k, ln in enumerate(snapped) if on_rim[k] or is_closed(ln, gap)]


def is_closed(line: np.ndarray, gap: float) -> bool:
    """Whether a polyline is a closed ring (its ends within ``gap``) with room for an area."""
    return len(line) >= 4 and float(np.hypot(*(line[0] - line[-1]))) <= gap


def self_crossing(line: np.ndarray) -> str | None:
    """Where a closed polyline crosses or touches itself (GEOS's reason), else None.

    A ring that encloses no area (a line drawn there and back) is no outline and is left to
    the loop search, which ignores it.
    """
    ring = shapely.linearrings(np.asarray(line, dtype=float))
    if shapely.is_simple(ring):
        return None
    if float(shapely.area(shapely.polygonize([shapely.node(ring)]))) <= 0.0:
        return None
    return shapely.is_valid_reason(Polygon(ring.coords))


def _overlap(a: Polygon, b: Polygon, tiny: float, reach: float = 0.0) -> bool:
    """Whether two filled loops cross: they share area and neither holds the other.

    What of one lies outside the other but within ``reach`` of it does not count: a curve
    tangent inside a curved outline, both flattened, pokes out of it by a sliver.
    """
    common = float(a.intersection(b).area)
    if not (common > tiny and a.area - common > tiny and b.area - common > tiny):
        return False
    return reach <= 0.0 or (_beyond(a, b, reach) and _beyond(b, a, reach))


def _beyond(a: Polygon, b: Polygon, reach: float) -> bool:
    """Whether some of ``a`` lies farther than ``reach`` outside ``b``."""
    out = a.difference(b)
    if out.area > reach * out.length:  # thicker on average than a sliver within reach
        return True
    edge = shapely.get_coordinates(shapely.segmentize(out.boundary, reach))
    return bool((shapely.distance(shapely.points(edge), b) > reach).any())


CONSTRUCTION_LAYER = re.compile(r"CENT(ER|RE)|CONSTR|HIDDEN|PHANTOM|DASH|AUX", re.IGNORECASE)
"""Layer names of construction geometry (bolt circles, centre lines, helper lines)."""


MAX_CROSSING_CANDIDATES = 50
"""Closed lines tried at most, once one is found crossing, to name the likeliest one."""


def crosses_the_outline(
    lines: Sequence[np.ndarray], closed: Sequence[int], shells: Sequence[Polygon], k: int
) -> bool:
    """Whether closed line ``k`` is a hole across the outline rather than a loop crossing
    others inside it (a bolt circle across its holes): True unless the outline is one closed
    line (holding nine tenths of the loops' area) and ``k`` lies inside it, or is it and no
    closed line crosses it."""
    rings = {j: Polygon(np.asarray(lines[j], dtype=float)) for j in closed}
    rings = {j: p for j, p in rings.items() if p.is_valid and p.area > 0.0}
    if k not in rings:
        return True
    outer = max(rings, key=lambda j: rings[j].area)
    if rings[outer].area < 0.9 * shapely.unary_union(list(shells)).area:
        return True  # the outline is drawn of several lines: say what was said before
    if k == outer:
        return any(rings[j].exterior.crosses(rings[outer].exterior) for j in rings if j != k)
    return not rings[outer].contains(rings[k])


def crossing_loop(
    lines: Sequence[np.ndarray],
    closed: Sequence[int],
    shells: Sequence[Polygon],
    gap: float,
    budget: Budget | None = None,
    layers: Sequence[str] | None = None,
) -> tuple[int, int] | None:
    """The closed line (index into ``lines``) that crosses other loops and how many it
    crosses, else None.

    Polygonizing merges crossing loops into one part, so a circle drawn across the outline
    (or two overlapping closed outlines) would silently change the part. A candidate is a
    closed line lying partly on a loop's boundary and partly inside it; it crosses when
    the other lines, without it, close a loop that it overlaps. Of those that cross, the
    one named is the likeliest construction geometry: on a construction layer
    (:data:`CONSTRUCTION_LAYER`, ``layers[k]`` is line ``k``'s), then crossing the most
    loops (a bolt circle across its holes), then the smallest (a circle across the outline
    rather than the outline).
    """
    if not shells:
        return None
    tree = shapely.STRtree(shells)
    candidates: list[tuple[float, int, Polygon]] = []
    for k in closed:
        ring = np.asarray(lines[k], dtype=float)
        poly = Polygon(ring)
        if not poly.is_valid or poly.area <= 0.0:
            continue
        points = shapely.points(ring[:-1])
        for j in tree.query(poly, predicate="intersects"):
            shell = shells[int(j)]
            if abs(shell.area - poly.area) <= 1e-9 * shell.area:
                continue  # the outline itself
            dist = shapely.distance(points, shell.exterior)
            inside = shapely.contains_xy(shell, ring[:-1, 0], ring[:-1, 1])
            if (dist <= gap).any() and (inside & (dist > gap)).any():
                candidates.append((poly.area, k, poly))
                break
    ranked: list[tuple[bool, int, float, int]] = []
    for tried, (area, k, poly) in enumerate(sorted(candidates, key=lambda c: c[:2])):
        if ranked and tried >= MAX_CROSSING_CANDIDATES:
            break  # enough found to name one; a crossing is never missed
        if budget is not None:
            budget.check_time()
        loops, _ = closed_loops([ln for i, ln in enumerate(lines) if i != k])
        tiny = 1e-9 * poly.area
        crossed = sum(_overlap(poly, lp.polygon, tiny, 2.0 * gap) for lp in loops)
        if crossed:
            helper = (
                layers is not None
                and k < len(layers)
                and bool(CONSTRUCTION_LAYER.search(layers[k]))
            )
            ranked.append((not helper, -crossed, area, k))
    if not ranked:
        return None
    best = min(ranked)
    return best[3], -best[1]


def near_copy(
    lines: Sequence[np.ndarray], closed: Sequence[int], k: int, gap: float
) -> tuple[int, float] | None:
    """Another closed line that line ``k`` nearly repeats (each within 1 % of its size of
    the other, farther apart than ``gap``: an outline pasted twice, slightly shifted), with
    their distance, else None."""
    ring = Polygon(np.asarray(lines[k], dtype=float))
    x0, y0, x1, y1 = ring.bounds
    reach = NEAR_COPY_SHARE * max(x1 - x0, y1 - y0)
    for j in closed:
        if j == k:
            continue
        other = Polygon(np.asarray(lines[j], dtype=float))
        if not other.is_valid or other.distance(ring) > reach:
            continue
        apart = float(ring.exterior.hausdorff_distance(other.exterior))
        if gap < apart <= reach:
            return j, apart
    return None


def inner_copy(shells: Sequence[Polygon], share: float, gap: float) -> float | None:
    """How far a loop lying inside the largest one stays from it all along, when that is at
    most ``share`` of its size and more than ``gap`` (the outline drawn twice, the copy
    offset inward), else None. Left to nesting, the two were a double-line drawing frame and
    what the copy holds was taken for the part."""
    if len(shells) < 2:
        return None
    big = max(range(len(shells)), key=lambda k: shells[k].area)
    outer = shells[big]
    x0, y0, x1, y1 = outer.bounds
    reach = share * max(x1 - x0, y1 - y0)
    for k, loop in enumerate(shells):
        a0, b0, a1, b1 = loop.bounds
        if k == big or max(a0 - x0, b0 - y0, x1 - a1, y1 - b1) > reach:
            continue
        apart = float(outer.exterior.hausdorff_distance(loop.exterior))
        if gap < apart <= reach and outer.covers(loop):
            return apart
    return None


def crossed_loops(lines: Sequence[np.ndarray], k: int, gap: float) -> list[Polygon]:
    """The loops the other lines close that closed line ``k`` crosses (as
    :func:`crossing_loop` found them), the one it shares most area with first."""
    poly = Polygon(np.asarray(lines[k], dtype=float))
    loops, _ = closed_loops([ln for i, ln in enumerate(lines) if i != k])
    tiny = 1e-9 * poly.area
    crossed = [lp.polygon for lp in loops if _overlap(poly, lp.polygon, tiny, 2.0 * gap)]
    return sorted(crossed, key=lambda p: -float(p.intersection(poly).area))


def drawn_twice(poly: Polygon, crossed: Sequence[Polygon]) -> tuple[Polygon, float] | None:
    """The loop of ``crossed`` that repeats ``poly``, shifted (each boundary within
    :data:`DRAWN_TWICE_SHARE` of ``poly``'s size of the other, sharing
    :data:`DRAWN_TWICE_COMMON` of their union), and how far its centroid lies from
    ``poly``'s, else None."""
    x0, y0, x1, y1 = poly.bounds
    reach = DRAWN_TWICE_SHARE * max(x1 - x0, y1 - y0)
    for other in crossed:
        if float(poly.exterior.hausdorff_distance(other.exterior)) > reach:
            continue
        if poly.intersection(other).area >= DRAWN_TWICE_COMMON * poly.union(other).area:
            return other, float(poly.centroid.distance(other.centroid))
    return None


def shapes_overlap(poly: Polygon, other: Polygon) -> bool:
    """Whether two crossing loops are shapes that overlap (each holds less than
    :data:`MOSTLY_INSIDE` of the other's area), not a hole across the other's outline."""
    common = float(poly.intersection(other).area)
    return common < MOSTLY_INSIDE * min(poly.area, other.area)


def lines_on(lines: Sequence[np.ndarray], loop: Polygon, gap: float, skip: int) -> list[int]:
    """The lines (but ``skip``) lying wholly on the outline of ``loop``, within ``gap``."""
    ring = loop.exterior
    return [
        j
        for j, ln in enumerate(lines)
        if j != skip
        and len(ln) >= 2
        and bool((shapely.distance(shapely.points(np.asarray(ln, dtype=float)), ring) <= gap).all())
    ]


def without_slivers(loops: Sequence[Loop], gap: float, bridged: float) -> tuple[list[Loop], str]:
    """The loops that have an area, and a warning naming those left out (or "").

    A loop is a sliver when it is on average no thicker than twice the flatten tolerance
    ``gap`` (area at most ``gap`` times its perimeter) or no wider than the largest gap
    closed (``bridged``): closing a gap beside a line end that overshoots makes such a
    triangle, which is never a part (nor a hole).
    """
    keep: list[Loop] = []
    out: list[Polygon] = []
    for lp in loops:
        poly = lp.polygon
        x0, y0, x1, y1 = poly.bounds
        if _thin(poly, gap) or max(x1 - x0, y1 - y0) <= bridged:
            out.append(poly)
        else:
            keep.append(lp)
    if not out:
        return keep, ""
    where = "; ".join(
        f"{p.area:.2g} mm2 at ({p.centroid.x:.1f}, {p.centroid.y:.1f})"
        for p in sorted(out, key=lambda p: -p.area)[:3]
    )
    more = "; ..." if len(out) > 3 else ""
    return keep, (
        f"left out {plural(len(out), 'closed loop')} with no area to speak of ({where}{more}): "
        f"no wider than the flatten tolerance ({gap:.3g} mm) or the gaps closed "
        f"({bridged:.3g} mm); not a part"
    )


def line_cycles(lines: Sequence[np.ndarray], skip: set[int]) -> list[list[int]]:
    """Loops of open lines joined end to end (each end shared by exactly two lines), in
    order along the loop: an outline drawn with LINEs and ARCs. ``skip`` holds the closed
    lines; ends are joined when their snapped coordinates are equal."""
    at: dict[bytes, list[int]] = {}
    ends: dict[int, tuple[bytes, bytes]] = {}
    for k, ln in enumerate(lines):
        if k in skip or len(ln) < 2:
            continue
        a = (np.asarray(ln[0], dtype=float) + 0.0).tobytes()  # + 0.0: -0.0 is 0.0
        b = (np.asarray(ln[-1], dtype=float) + 0.0).tobytes()
        if a == b:
            continue
        ends[k] = (a, b)
        at.setdefault(a, []).append(k)
        at.setdefault(b, []).append(k)
    seen: set[int] = set()
    cycles: list[list[int]] = []
    for start in ends:
        if start in seen:
            continue
        cycle, k, node = [start], start, ends[start][1]
        seen.add(start)
        while True:
            if len(at[node]) != 2:
                break
            k = at[node][0] if at[node][1] == k else at[node][1]
            if k == start:
                if len(at[ends[start][0]]) == 2:
                    cycles.append(cycle)
                break
            if k in seen:
                break
            seen.add(k)
            cycle.append(k)
            node = ends[k][1] if ends[k][0] == node else ends[k][0]
    return cycles


def joined(lines: Sequence[np.ndarray], cycle: Sequence[int]) -> np.ndarray:
    """The closed polyline of a loop of lines (:func:`line_cycles`), each turned to follow
    the one before."""
    out = [np.asarray(lines[cycle[0]], dtype=float)]
    if len(cycle) > 1:
        nxt = np.asarray(lines[cycle[1]], dtype=float)
        if not any(np.array_equal(out[0][-1], p) for p in (nxt[0], nxt[-1])):
            out[0] = out[0][::-1]
    for k in cycle[1:]:
        ln = np.asarray(lines[k], dtype=float)
        out.append((ln if np.array_equal(ln[0], out[-1][-1]) else ln[::-1])[1:])
    return np.concatenate(out)
