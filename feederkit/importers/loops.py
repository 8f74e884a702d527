"""From loose drawing lines to parts: closed loops, their nesting, holes, and drawing frames.

Pure functions on polylines in millimetres (numpy arrays of shape (n, 2)). Loops are built
with ``shapely.polygonize`` per connected group of lines, so lines that cross a part (centre
lines, bend lines) do not split it; a loop inside a part is a hole, a loop inside a hole is
a separate part.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from shapely.geometry import Polygon

from feederkit.errors import InputError

Point = tuple[float, float]

FRAME_FILL = 0.9
"""A drawing frame fills at least this share of its bounding box (it is a rectangle)."""


@dataclass(frozen=True)
class Region:
    """A part found in a drawing: its outer loop and its holes (mm); ``area`` excludes holes."""

    shell: tuple[Point, ...]
    holes: tuple[tuple[Point, ...], ...]
    area: float
    loop_area: float


@dataclass(frozen=True)
class Drawing:
    """The parts of a drawing, largest loop first, and how many drawing frames were skipped."""

    regions: tuple[Region, ...]
    frames: int


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


def _components(pieces: np.ndarray) -> np.ndarray:
    """Label of the connected group of each noded line piece."""
    tree = shapely.STRtree(pieces)
    left, right = tree.query(pieces, predicate="intersects")
    n = len(pieces)
    graph = coo_matrix((np.ones(len(left)), (left, right)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def closed_loops(lines: Sequence[np.ndarray]) -> tuple[list[Polygon], int]:
    """The closed loops the lines form (filled polygons, no holes) and the number of open ends."""
    lines = [ln for ln in lines if len(ln) >= 2]
    if not lines:
        return [], 0
    sizes = [len(ln) for ln in lines]
    geoms = shapely.get_parts(
        shapely.linestrings(np.concatenate(lines), indices=np.repeat(np.arange(len(lines)), sizes))
    )
    geoms = geoms[shapely.length(geoms) > 0.0]
    if len(geoms) == 0:
        return [], 0
    noded = shapely.union_all(geoms)
    pieces = np.array(shapely.get_parts(noded))
    pieces = pieces[shapely.get_type_id(pieces) == 1]  # LineStrings only
    if len(pieces) == 0:
        return [], 0
    labels = _components(pieces)
    loops: list[Polygon] = []
    dangles = 0
    for lab in np.unique(labels):
        group = pieces[labels == lab]
        faces, _cuts, dangle_geoms, _invalid = shapely.polygonize_full(group)
        dangles += len(shapely.get_parts(dangle_geoms))
        parts = shapely.get_parts(faces)
        if len(parts) == 0:
            continue
        merged = shapely.union_all(parts)
        for poly in shapely.get_parts(merged):
            if isinstance(poly, Polygon) and poly.area > 0.0:
                loops.append(Polygon(poly.exterior))
    return loops, dangles


def _is_frame(loop: Polygon) -> bool:
    """Whether a loop is shaped like a drawing frame: close to its bounding box."""
    x0, y0, x1, y1 = loop.bounds
    box = (x1 - x0) * (y1 - y0)
    return box > 0.0 and loop.area >= FRAME_FILL * box


def nest(loops: Sequence[Polygon]) -> list[int]:
    """For loops sorted by decreasing area: each one's smallest enclosing loop (-1: none)."""
    parent = [-1] * len(loops)
    if not loops:
        return parent
    tree = shapely.STRtree(list(loops))
    shapely.prepare(list(loops))
    for i, loop in enumerate(loops):
        point = loop.representative_point()
        best = -1
        for j in tree.query(point, predicate="within"):
            j = int(j)
            if j < i and loops[j].contains(loop) and (best < 0 or j > best):
                best = j
        parent[i] = best
    return parent


def _ring(poly: Polygon) -> tuple[Point, ...]:
    coords = np.asarray(poly.exterior.coords)[:-1]
    return tuple((float(x), float(y)) for x, y in coords)


def regions_from_loops(loops: Sequence[Polygon]) -> Drawing:
    """Parts (largest loop first) from closed loops; skips drawing frames.

    A loop at even nesting depth is a part, the loops directly inside it are its holes. The
    largest top-level loop is a drawing frame when it is a rectangle that holds a loop that
    itself holds loops (the real part and its holes); it is dropped. Title-block lines touch
    the frame, so they belong to its loop (see :func:`closed_loops`).
    """
    loops = sorted(loops, key=lambda p: -p.area)
    frames = 0
    while loops:
        parent = nest(loops)
        children: dict[int, list[int]] = {}
        for i, p in enumerate(parent):
            children.setdefault(p, []).append(i)
        grand = any(children.get(c) for c in children.get(0, []))
        if not (grand and _is_frame(loops[0])):
            break
        loops = loops[1:]
        frames += 1
    parent = nest(loops)
    depth = [0] * len(loops)
    for i, p in enumerate(parent):
        depth[i] = 0 if p < 0 else depth[p] + 1
    holes: dict[int, list[int]] = {}
    for i, p in enumerate(parent):
        if depth[i] % 2 == 1:
            holes.setdefault(p, []).append(i)
    regions = []
    for i, loop in enumerate(loops):
        if depth[i] % 2:
            continue
        hole_loops = [loops[h] for h in holes.get(i, [])]
        area = loop.area - sum(h.area for h in hole_loops)
        regions.append(
            Region(
                shell=_ring(loop),
                holes=tuple(_ring(h) for h in hole_loops),
                area=float(area),
                loop_area=float(loop.area),
            )
        )
    regions.sort(key=lambda r: -r.loop_area)
    return Drawing(regions=tuple(regions), frames=frames)


def drawing_from_lines(lines: Sequence[np.ndarray], gap: float, label: str) -> Drawing:
    """Parts of a drawing from its flattened lines (mm); InputError without a closed loop."""
    if not lines:
        raise InputError(f"{label}: the drawing has no lines, arcs or curves")
    pts = np.concatenate([np.asarray(ln, dtype=float) for ln in lines])
    extent = pts.max(axis=0) - pts.min(axis=0)
    if float(extent.max()) == 0.0 or float(extent.min()) <= 1e-12 * float(extent.max()):
        raise InputError(f"{label}: the outline has zero area (all geometry lies on a line)")
    loops, dangles = closed_loops(snap_endpoints(lines, gap))
    if not loops:
        detail = f" ({dangles} open ends)" if dangles else ""
        raise InputError(f"{label}: no closed outline: the lines do not close into a loop{detail}")
    drawing = regions_from_loops(loops)
    if not drawing.regions:
        raise InputError(f"{label}: no closed outline outside a drawing frame")
    return drawing
