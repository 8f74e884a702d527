"""A drawing's parts from its lines: loops nested into regions, frames and counterbores read.

:func:`drawing_from_lines` imports flattened lines: their loops found, and refused when they
cross (:mod:`.loops`), nested into parts with drawing frames dropped
(:func:`regions_from_loops`, :mod:`.frames`), with the warnings of :mod:`.drawingnotes`. A
loop inside a part is a hole, a loop inside a hole is a separate part. :func:`counterbores`
then reads a hole drawn as concentric loops as one hole.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import shapely
from shapely.geometry import Polygon

from feederkit.errors import InputError
from feederkit.importers.budget import Budget
from feederkit.importers.drawingnotes import (
    cut_off_note,
    ends_words,
    open_line_notes,
    outside_note,
    side_by_side_note,
    title_block_note,
)
from feederkit.importers.frames import frame_doubt, frame_kind, free_title_block
from feederkit.importers.loops import (
    CONSTRUCTION_LAYER,
    Loop,
    Point,
    Region,
    closed_loops,
    crossed_loops,
    crosses_the_outline,
    crossing_loop,
    drawn_twice,
    heal_gaps,
    inner_copy,
    is_closed,
    joined,
    line_cycles,
    lines_on,
    near_copy,
    open_ends,
    repeated_lines,
    self_crossing,
    shapes_overlap,
    snap_endpoints,
    without_slivers,
)
from feederkit.outline import invalid_words
from feederkit.words import plural

HEAL_GAP_REL = 0.002
"""Gaps between open line ends up to this share of the drawing's size are closed (0.2 %)."""


@dataclass(frozen=True)
class Drawing:
    """The parts of a drawing, largest loop first, what was skipped, and notes for the user.

    ``frames`` counts the drawing frames skipped; ``nested`` counts the parts lying in the
    first region's holes (a cut sheet); ``warnings`` say what was healed or guessed.
    """

    regions: tuple[Region, ...]
    frames: int
    nested: int = 0
    warnings: tuple[str, ...] = ()
    edges: tuple[EdgeLine, ...] = ()
    """The outlines drawn again just inside themselves (:func:`edge_line`), that line left
    out: a chamfer or deburred edge drawn in a top view."""


@dataclass(frozen=True)
class EdgeLine:
    """A part's outline drawn again ``band`` mm inside it all along: its bounds ``box``."""

    box: tuple[float, float, float, float]
    band: float


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


def _children(loops: Sequence[Polygon]) -> dict[int, list[int]]:
    children: dict[int, list[int]] = {}
    for i, p in enumerate(nest(loops)):
        children.setdefault(p, []).append(i)
    return children


EDGE_BAND_SHARE = 0.1
"""An edge line (:func:`edge_line`) runs at most this share of the outline's size inside it."""


EDGE_SPREAD = 1.5
"""Along an edge line the farthest point of either loop from the other is at most this many
times their nearest distance: a line offset with sharp corners lies sqrt(2) times the band
from the outline's corners."""


EDGE_MEAN_SPREAD = 1.25
"""Along an edge line the band's mean width (its area over the loops' mean length) is at most
this many times the nearest distance."""


def edge_line(outer: Polygon, inner: Polygon, gap: float) -> float | None:
    """The band's width when ``inner`` (a loop inside ``outer``) runs along it just inside
    it all along, as a chamfer or deburred edge is drawn in a top view: the band at most
    :data:`EDGE_BAND_SHARE` of the outline's size and of even width (:data:`EDGE_SPREAD`,
    :data:`EDGE_MEAN_SPREAD`); else None.

    >>> from shapely.geometry import box
    >>> edge_line(box(0, 0, 60, 40), box(1, 1, 59, 39), 0.01)
    1.0
    >>> edge_line(box(0, 0, 60, 40), box(20, 10, 40, 30), 0.01) is None  # a window
    True
    """
    x0, y0, x1, y1 = outer.bounds
    near = float(outer.exterior.distance(inner.exterior))
    if not 0.0 < near <= EDGE_BAND_SHARE * max(x1 - x0, y1 - y0):
        return None
    if outer.exterior.hausdorff_distance(inner.exterior) > EDGE_SPREAD * near + 2.0 * gap:
        return None
    mean = (outer.area - inner.area) / (0.5 * (outer.exterior.length + inner.exterior.length))
    return near if mean <= EDGE_MEAN_SPREAD * near + 2.0 * gap else None


def _edge_lines(loops: list[Loop], gap: float) -> tuple[list[Loop], list[EdgeLine]]:
    """``loops`` without the edge lines of the outermost ones: a loop's largest inner loop
    that runs along it just inside it (:func:`edge_line`) and holds loops of its own (what
    the part's holes and windows are). Left in, the line made the part a 1 mm ring with its
    holes as parts cut from it, or a small plate a "drawing frame" around its window. An
    inner loop holding nothing is kept: a thin ring (a gasket) is a part."""
    polys = [lp.polygon for lp in loops]
    parent = nest(polys)
    kids: dict[int, list[int]] = {}
    for i, p in enumerate(parent):
        kids.setdefault(p, []).append(i)
    drop: set[int] = set()
    found = []
    for i in kids.get(-1, []):
        inside = kids.get(i, [])
        if not inside or not kids.get(inside[0]):
            continue
        band = edge_line(polys[i], polys[inside[0]], gap)
        if band is not None:
            drop.add(inside[0])
            found.append(EdgeLine(tuple(float(v) for v in polys[i].bounds), band))  # type: ignore[arg-type]
    return [lp for k, lp in enumerate(loops) if k not in drop], found


def regions_from_loops(
    found: Sequence[Loop | Polygon], budget: Budget | None = None, gap: float = 0.0
) -> Drawing:
    """Parts (largest loop first) from closed loops; skips drawing frames.

    A loop at even nesting depth is a part, the loops directly inside it are its holes; parts
    inside a part's holes (a cut sheet: pieces cut from a plate's window) are separate parts.
    Drawing frames (:func:`.frames.frame_kind`) around the parts are dropped; each one costs a
    nesting of all loops, so the deadline of ``budget`` is checked between them. Then an
    outermost loop's edge line (:func:`_edge_lines`; ``gap`` the flatten tolerance) is left
    out, so its holes are the part's.
    """
    loops = sorted(
        (lp if isinstance(lp, Loop) else Loop(lp, 1, lp.area) for lp in found),
        key=lambda p: -p.polygon.area,
    )
    frames = 0
    while loops:
        if budget is not None:
            budget.check_time()
        kids = _children([lp.polygon for lp in loops]).get(0, [])
        drop = frame_kind(loops[0], loops, kids)
        if not drop:
            break
        loops = [lp for k, lp in enumerate(loops) if k != 0 and (drop == 1 or k != kids[0])]
        frames += 1
    if budget is not None:
        budget.check_time()
    loops, edges = _edge_lines(loops, gap)
    polys = [lp.polygon for lp in loops]
    parent = nest(polys)
    depth = [0] * len(polys)
    for i, p in enumerate(parent):
        depth[i] = 0 if p < 0 else depth[p] + 1
    holes: dict[int, list[int]] = {}
    for i, p in enumerate(parent):
        if depth[i] % 2 == 1:
            holes.setdefault(p, []).append(i)
    regions: list[tuple[int, Region]] = []
    for i, loop in enumerate(polys):
        if depth[i] % 2:
            continue
        hole_loops = [polys[h] for h in holes.get(i, [])]
        area = loop.area - sum(h.area for h in hole_loops)
        region = Region(
            shell=_ring(loop),
            holes=tuple(_ring(h) for h in hole_loops),
            area=float(area),
            loop_area=float(loop.area),
            enclosed=loops[i].enclosed,
            outside=loops[i].outside,
            cut_off=loops[i].cut_off,
        )
        regions.append((i, region))
    regions.sort(key=lambda r: -r[1].loop_area)
    nested = 0
    if regions:
        first = regions[0][0]
        for i, _ in regions[1:]:
            k = parent[i]
            while k >= 0 and k != first:
                k = parent[k]
            nested += k == first
    return Drawing(
        regions=tuple(r for _, r in regions), frames=frames, nested=nested, edges=tuple(edges)
    )


CONCENTRIC_CENTRE = 0.02
"""Loops are concentric when their centroids lie within this share of the outer one's
equivalent diameter (plus twice the flatten tolerance)."""


CONCENTRIC_SPREAD = 1.1
"""Concentric loops are parallel (a counterbore, not a square in a round hole) when the
farthest point of one from the other is at most this many times their nearest distance."""


@dataclass(frozen=True)
class Counterbore:
    """A hole drawn as concentric loops: the ``outer`` loop the part's hole was, the
    ``inner`` loop taken as the through hole, and the loops of the stack (largest first)."""

    outer: tuple[Point, ...]
    inner: tuple[Point, ...]
    rings: tuple[tuple[Point, ...], ...]
    crosses: bool = False
    """Whether the outer loop crosses other holes of the part (a bolt circle)."""


def concentric(outer: Polygon, inner: Polygon, gap: float) -> bool:
    """Whether ``inner`` (inside ``outer``) is concentric with it and parallel to it: their
    centroids close (:data:`CONCENTRIC_CENTRE`), the band between them of even width
    (:data:`CONCENTRIC_SPREAD`), as a counterbore, countersink or chamfer is drawn."""
    size = 2.0 * np.sqrt(outer.area / np.pi)
    if outer.centroid.distance(inner.centroid) > CONCENTRIC_CENTRE * size + 2.0 * gap:
        return False
    near = outer.exterior.distance(inner.exterior)
    far = outer.exterior.hausdorff_distance(inner.exterior)
    return near > 0.0 and far <= CONCENTRIC_SPREAD * near + 2.0 * gap


def counterbores(drawing: Drawing, gap: float) -> tuple[Drawing, list[Counterbore]]:
    """The drawing with each hole that holds only loops concentric with it and parallel to it
    (:func:`concentric`) replaced by the smallest of them, those loops' parts dropped.

    A disc in a hole, concentric with it, is a counterbore (or countersink, chamfer,
    construction circle) drawn in a top view, not a part cut from a sheet: the through hole
    is the innermost loop and the part keeps the material under the counterbore.
    """
    regions = list(drawing.regions)
    dropped: set[int] = set()
    found: list[Counterbore] = []
    for i, region in enumerate(regions):
        if i in dropped:
            continue
        holes = list(region.holes)
        for h, hole in enumerate(holes):
            outer = Polygon(hole)
            inside = [
                j
                for j, other in enumerate(regions)
                if j != i and j not in dropped and outer.contains(Polygon(other.shell))
            ]
            rings = [ring for j in inside for ring in (regions[j].shell, *regions[j].holes)]
            if not rings or not all(concentric(outer, Polygon(r), gap) for r in rings):
                continue
            stack = sorted(rings, key=lambda r: -Polygon(r).area)
            holes[h] = stack[-1]
            dropped.update(inside)
            rim = outer.exterior
            crosses = any(rim.crosses(Polygon(o)) for k, o in enumerate(holes) if k != h)
            found.append(Counterbore(hole, stack[-1], (hole, *stack), crosses))
        if holes != list(region.holes):
            polys = [Polygon(r) for r in holes]
            area = Polygon(region.shell).area - sum(p.area for p in polys)
            regions[i] = replace(region, holes=tuple(holes), area=float(area))
    if not found:
        return drawing, []
    first = drawing.regions[0]
    nested = drawing.nested - sum(1 for j in dropped if _inside(first, regions[j]))
    kept = tuple(r for j, r in enumerate(regions) if j not in dropped)
    return replace(drawing, regions=kept, nested=max(0, nested)), found


def _inside(region: Region, other: Region) -> bool:
    """Whether ``other`` lies in one of ``region``'s holes."""
    shell = Polygon(other.shell)
    return any(Polygon(h).contains(shell) for h in region.holes)


def _picked(values: Sequence[str] | None, keep: Sequence[int], n: int) -> list[str] | None:
    """``values[k]`` for each ``k`` in ``keep``; None unless there is one value per line."""
    return None if values is None or len(values) != n else [values[k] for k in keep]


def drawing_from_lines(
    lines: Sequence[np.ndarray],
    gap: float,
    label: str,
    budget: Budget | None = None,
    names: Sequence[str] | None = None,
    layers: Sequence[str] | None = None,
) -> Drawing:
    """Parts of a drawing from its flattened lines (mm); InputError without a closed loop.

    Line ends closer than ``gap`` (the flatten tolerance) are joined and a line repeating
    another within ``gap`` is left out (:func:`.loops.repeated_lines`); open ends up to
    :data:`HEAL_GAP_REL` of the drawing's size apart are bridged, with a warning, before the
    loops and holes are chosen. A closed line that crosses itself, or crosses another loop
    (a hole across the outline), is refused, as an outline file with those faults is;
    ``names[k]`` names line ``k`` in that error (an entity and its layer), ``layers[k]`` is
    its layer (:func:`.frames.frame_doubt`). A loop with no area to speak of
    (:func:`.loops.without_slivers`) is left out with a warning.
    """
    if not lines:
        raise InputError(f"{label}: the drawing has no lines, arcs or curves")
    pts = np.concatenate([np.asarray(ln, dtype=float) for ln in lines])
    extent = pts.max(axis=0) - pts.min(axis=0)
    if float(extent.max()) == 0.0 or float(extent.min()) <= 1e-12 * float(extent.max()):
        raise InputError(f"{label}: the outline has zero area (all geometry lies on a line)")
    snapped = snap_endpoints(lines, gap)
    repeats = set(repeated_lines(snapped, gap, budget))
    keep = [k for k in range(len(snapped)) if k not in repeats]
    snapped = [snapped[k] for k in keep]
    names, layers = _picked(names, keep, len(lines)), _picked(layers, keep, len(lines))

    def name(k: int) -> str:
        return names[k] if names is not None and k < len(names) else f"closed line {k + 1}"

    closed = [k for k, ln in enumerate(snapped) if is_closed(ln, gap)]
    for k in closed:
        reason = self_crossing(snapped[k])
        if reason is not None:
            raise InputError(
                f"{label}: the outline is self-intersecting ({name(k)} {invalid_words(reason)})"
            )
    for cycle in line_cycles(snapped, set(closed)):
        if budget is not None:
            budget.check_time()
        reason = self_crossing(joined(snapped, cycle))
        if reason is not None:
            raise InputError(
                f"{label}: the outline is self-intersecting (the loop of {name(cycle[0])} and "
                f"{plural(len(cycle) - 1, 'other line')} {invalid_words(reason)})"
            )
    healed, notes = heal_gaps(snapped, gap, HEAL_GAP_REL * float(extent.max()))
    if budget is not None:
        budget.check_time()
    loops, dangles = closed_loops(healed, budget, [healed[k] for k in closed], gap)
    if not loops:  # where the outline is open, so the user can find the gap in CAD
        lines = [np.asarray(d.coords) for d in dangles]
        found = [lines[e // 2][0 if e % 2 == 0 else -1] for e in open_ends(lines, gap)]
        detail = f" ({ends_words(np.asarray(found), counted=True)})" if found else ""
        raise InputError(f"{label}: no closed outline: the lines do not close into a loop{detail}")
    shells = [lp.polygon for lp in loops]
    copied = inner_copy(shells, HEAL_GAP_REL, gap)
    if copied is not None:
        raise InputError(
            f"{label}: the outline seems drawn twice, {copied:.2g} mm apart (a copy just inside "
            "it, which would make the two a drawing frame and the part what the copy holds): "
            "delete one copy"
        )
    found = crossing_loop(healed, closed, shells, gap, budget, layers)
    if found is not None:
        crossing, crossed = found
        copy = near_copy(healed, closed, crossing, gap)
        if copy is not None:
            largest = max(p.area for p in shells)
            what = "the outline" if Polygon(healed[crossing]).area >= 0.9 * largest else "a loop"
            raise InputError(
                f"{label}: {what} seems drawn twice, {copy[1]:.2g} mm apart ({name(copy[0])} "
                f"and {name(crossing)}): delete one copy"
            )
        crossing_poly = Polygon(healed[crossing])
        crossed_polys = crossed_loops(healed, crossing, gap)

        def loop_name(loop: Polygon) -> str:
            on = lines_on(healed[: len(snapped)], loop, gap, crossing)
            if not on:
                return "a loop of lines over it"
            if len(on) == 1:
                return name(on[0])
            return f"the loop of {name(on[0])} and {plural(len(on) - 1, 'other line')}"

        twin = drawn_twice(crossing_poly, crossed_polys)
        if twin is not None:
            largest = max(p.area for p in shells)
            what = "the outline" if crossing_poly.area >= 0.9 * largest else "a loop"
            raise InputError(
                f"{label}: {what} seems drawn twice (a copy shifted by about {twin[1]:.2g} mm: "
                f"{name(crossing)} and {loop_name(twin[0])}): delete one copy"
            )
        helper = layers is not None and bool(CONSTRUCTION_LAYER.search(layers[crossing]))
        if (
            crossed == 1
            and crossed_polys
            and not helper
            and shapes_overlap(crossing_poly, crossed_polys[0])
        ):
            raise InputError(
                f"{label}: two closed loops overlap ({name(crossing)} and "
                f"{loop_name(crossed_polys[0])}, neither inside the other): a part drawn as "
                "overlapping shapes? join them into one outline (e.g. a union) or put the stray "
                "one on another layer"
            )
        if crosses_the_outline(healed, closed, shells, crossing):
            raise InputError(
                f"{label}: a hole crosses the outline ({name(crossing)} crosses "
                f"{plural(crossed, 'other loop')}; leave construction geometry out with --layer)"
            )
        raise InputError(
            f"{label}: loops cross inside the outline ({name(crossing)} crosses "
            f"{plural(crossed, 'other loop')}: a bolt circle or other construction geometry? "
            "leave it out with --layer, or draw it in a centre linetype)"
        )
    bridged = max((float(np.hypot(*(b[-1] - b[0]))) for b in healed[len(snapped) :]), default=0.0)
    loops, slivers = without_slivers(loops, gap, bridged)
    if slivers:
        if not loops:
            raise InputError(
                f"{label}: the outline has zero area (its closed loops are no wider than the "
                f"flatten tolerance, {gap:.3g} mm)"
            )
        notes.append(slivers)
    split = [lp.polygon.bounds for lp in loops if lp.split]
    if split:
        notes.append(side_by_side_note(split))
    drawing = regions_from_loops(loops, budget, gap)
    if not drawing.regions:
        raise InputError(f"{label}: no closed outline outside a drawing frame")
    blocks = [free_title_block(r, healed[: len(snapped)], gap) for r in drawing.regions]
    if blocks[0] and not all(blocks):  # the largest loop a title block beside the part
        left = [r for r, b in zip(drawing.regions, blocks, strict=True) if b]
        notes.append(title_block_note([Polygon(r.shell).bounds for r in left]))
        kept = tuple(r for r, b in zip(drawing.regions, blocks, strict=True) if not b)
        # The parts in the new first part's holes (regions never overlap, so inside its
        # outer ring is inside a hole): counted again, the block had none.
        outer = Polygon(kept[0].shell)
        nested = sum(outer.contains(Polygon(r.shell).representative_point()) for r in kept[1:])
        drawing = replace(drawing, regions=kept, nested=int(nested))
    notes += [outside_note(r.outside) for r in drawing.regions if r.outside]
    notes += [cut_off_note(r.cut_off) for r in drawing.regions if r.cut_off]
    doubt = frame_doubt(drawing.regions[0], healed[: len(snapped)], gap, layers)
    if doubt:
        notes.append(doubt)
    notes += open_line_notes(dangles, drawing.regions, gap)
    return replace(drawing, warnings=tuple(notes))
