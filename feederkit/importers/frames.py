"""Drawing frames and title blocks: the loops of a drawing that are its sheet, not a part.

A frame is a rectangle around the parts, a double line or a single line whose title-block
cells touch it: :func:`frame_kind` says how many loops it takes, so that nesting
(:mod:`.drawing`) drops them. A rectangle with holes and neither mark cannot be told from a
plate: it is kept, and :func:`frame_doubt` warns when it looks like a bare frame around a part.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
import shapely.affinity
from shapely.geometry import Polygon

from feederkit.importers.drawingnotes import box_words
from feederkit.importers.loops import Loop, Region, along
from feederkit.words import plural

FRAME_FILL = 0.9
"""A drawing frame fills at least this share of its bounding box (it is a rectangle)."""


FRAME_STRAIGHT_REL = 1e-3
"""A frame's sides are straight: its loop simplified to this share of its size has four
corners (rounded corners keep their arcs' points)."""


FRAME_MATERIAL = 0.2
"""A double-line frame border (outer minus inner rectangle) is at most this share of its box."""


TITLE_BLOCK_SHARE = 0.7
"""In a single-line frame the empty sheet is at least this share of the loop; the rest are
title-block cells (faces made by lines touching the border)."""


FRAME_DOUBLE_MIN_MM = 120.0
"""A double-line frame is at least this long, a drawing sheet's (A6 is 148 mm long; an A4
sheet's frame drawn at 2:1 is 148 mm): a smaller rectangle with a line just inside it is a
plate whose edge (a chamfer, a deburred edge) is drawn in a top view (:mod:`.drawing`'s
edge lines), as a 60 x 40 mm plate with a line 1 mm inside it is."""


TITLE_BLOCK_MIN_CELLS = 2
"""A single-line frame's title block has at least this many cells besides the sheet: one
face cut off a rectangle is a fillet drawn over an untrimmed corner, or a bend line's strip."""


FRAME_HOLE_SHARE = 0.1
"""A rectangle holding one hole whose box is at most this share of its own may be a bare
single-line drawing frame around one part: imported as a plate, with a warning."""


FRAME_SHEET_MM = 250.0
"""A rectangle at least this long is the size of a drawing sheet's frame (A4 is 297 x 210
mm, its frame a few mm in), far larger than a part for a parts feeder."""


FRAME_SHEET_HOLE_SHARE = 0.25
"""A sheet-sized rectangle holding one hole whose box is at most this share of its own may
be a bare single-line drawing frame around one part (an A3 frame around a 150 x 100 mm
bracket holds 14 %)."""


TITLE_BLOCK_CORNER = 0.05
"""A title block standing free of its frame lies within this share of the frame's size from
two adjacent sides of it."""


def _is_rectangle(loop: Polygon) -> bool:
    """Whether a loop is close to its bounding box and has four corners (a drawing frame, or
    a plate that could be one; a plate with rounded corners is no frame)."""
    x0, y0, x1, y1 = loop.bounds
    box = (x1 - x0) * (y1 - y0)
    if not (box > 0.0 and loop.area >= FRAME_FILL * box):
        return False
    sides = shapely.simplify(loop, FRAME_STRAIGHT_REL * max(x1 - x0, y1 - y0))
    return len(sides.exterior.coords) - 1 <= 4


def frame_kind(top: Loop, loops: Sequence[Loop], kids: Sequence[int]) -> int:
    """How many loops (from the largest) a drawing frame takes: 0 (not a frame), 1 or 2.

    A frame is a thin border, not a part: either a double line, a drawing sheet's size
    (:data:`FRAME_DOUBLE_MIN_MM`), whose border (outer minus the inner rectangle) is a small
    share of its box (2 loops), or a single rectangle whose title-block lines touch it (1
    loop: its sheet is one large face beside at least :data:`TITLE_BLOCK_MIN_CELLS` small
    cells, not all strips across it, inside the frame when the frame is one closed line;
    lines closing a face against a closed outline from outside are a view or dimension
    drawn against a part).
    A rectangle whose holes hold parts but which has neither mark is a plate: a cut sheet
    keeps its material.
    """
    if not kids or not _is_rectangle(top.polygon):
        return 0
    x0, y0, x1, y1 = top.polygon.bounds
    inner = loops[kids[0]]
    if (
        max(x1 - x0, y1 - y0) >= FRAME_DOUBLE_MIN_MM
        and _is_rectangle(inner.polygon)
        and inner.polygon.area >= (1.0 - FRAME_MATERIAL) * top.polygon.area
    ):
        return 2
    if (
        len(top.cells) >= TITLE_BLOCK_MIN_CELLS
        and not top.outside
        and top.largest_face >= TITLE_BLOCK_SHARE * top.polygon.area
        and not _strips(top.cells, top.polygon.bounds)
    ):
        return 1
    return 0


def _strips(cells: Sequence[tuple[float, float, float, float]], box: Sequence[float]) -> bool:
    """Whether every cell spans the rectangle ``box`` from side to side, all of them one way:
    the strips between lines running across it (a plate's bend lines or slits), not a title
    block's cells, which lie in a corner of the sheet."""
    x0, y0, x1, y1 = box
    tol = STRIP_SPAN * max(x1 - x0, y1 - y0)
    tall = all(c[1] <= y0 + tol and c[3] >= y1 - tol for c in cells)
    wide = all(c[0] <= x0 + tol and c[2] >= x1 - tol for c in cells)
    return tall or wide


STRIP_SPAN = 1e-3
"""A cell spans its rectangle when it reaches within this share of its size of both sides."""


def _round(poly: Polygon) -> bool:
    """Whether a loop is a circle or an axis-aligned ellipse (within 5 % of its area)."""
    x0, y0, x1, y1 = poly.bounds
    disk = shapely.affinity.scale(
        shapely.Point((x0 + x1) / 2, (y0 + y1) / 2).buffer(0.5, 64), x1 - x0, y1 - y0
    )
    return float(poly.symmetric_difference(disk).area) <= 0.05 * poly.area


def frame_doubt(
    region: Region, lines: Sequence[np.ndarray], gap: float, layers: Sequence[str] | None
) -> str:
    """A warning when the imported part may be a bare single-line drawing frame, else "".

    A rectangle with holes and without a title block touching it cannot be told from a
    plate (:func:`frame_kind`): it is imported as a plate, but said to be a likely frame
    when it is drawn on a layer none of its holes is on; when it holds a single hole that
    is not round (a circle or an axis-aligned ellipse: a plate's usual hole) and whose box
    is at most :data:`FRAME_HOLE_SHARE` of its own and lies at least its own size away from
    the rectangle, or, for a rectangle the size of a drawing sheet (:data:`FRAME_SHEET_MM`),
    at most :data:`FRAME_SHEET_HOLE_SHARE` and half its size away (one part drawn in a
    sheet's frame); or when one of its holes is a title block standing free of the frame
    (:func:`_title_block`).
    """
    shell = Polygon(region.shell)
    if not region.holes or not _is_rectangle(shell):
        return ""
    x0, y0, x1, y1 = shell.bounds
    box = (x1 - x0) * (y1 - y0)
    holes = [Polygon(h) for h in region.holes]
    hx0, hy0, hx1, hy1 = shapely.total_bounds(holes)
    hole_box = (hx1 - hx0) * (hy1 - hy0)
    size = max(hx1 - hx0, hy1 - hy0)
    sheet = max(x1 - x0, y1 - y0) >= FRAME_SHEET_MM
    small = (
        len(holes) == 1
        and not _round(holes[0])
        and (
            (hole_box <= FRAME_HOLE_SHARE * box and holes[0].distance(shell.exterior) >= size)
            or (
                sheet
                and hole_box <= FRAME_SHEET_HOLE_SHARE * box
                and holes[0].distance(shell.exterior) >= 0.5 * size
            )
        )
    )
    tol = max(2.0 * gap, 1e-9 * max(x1 - x0, y1 - y0))
    block = _title_block(shell, holes, lines, tol)
    own: set[str] = set()
    inner: set[str] = set()
    if layers is not None and len(layers) >= len(lines):
        rings = [shell.exterior, *(h.exterior for h in holes)]
        tree = shapely.STRtree(rings)  # a plate's 4,000 holes: only the rings near each line
        for k, ln in enumerate(lines):
            arr = np.asarray(ln, dtype=float)
            near = tree.query(shapely.box(*(arr.min(axis=0) - tol), *(arr.max(axis=0) + tol)))
            pts = shapely.points(arr)
            for j in sorted(int(i) for i in near):  # the shell first, as every ring was asked
                if shapely.dwithin(pts, rings[j], tol).all():
                    (own if j == 0 else inner).add(layers[k])
                    break
    apart = bool(own) and bool(inner) and not own & inner
    if not (small or apart or block is not None):
        return ""
    frame_layers = f" on layer {', '.join(sorted(own))}" if own else ""
    why = f", one of them divided like a title block ({box_words(block.bounds)})" if block else ""
    remedy = (
        f"leave the frame's layer out with --layer (--layer {' --layer '.join(sorted(inner))})"
        if apart
        else "delete the frame, or move it to a layer of its own and leave that out with --layer"
    )
    return (
        f"the part is a {x1 - x0:.4g} x {y1 - y0:.4g} mm rectangle{frame_layers} around "
        f"{plural(len(holes), 'hole')}{why}: if the rectangle is a drawing frame, the part is "
        f"what it holds: {remedy}"
    )


def _title_block(
    shell: Polygon, holes: Sequence[Polygon], lines: Sequence[np.ndarray], tol: float
) -> Polygon | None:
    """A hole of a rectangle that looks like a title block standing free of its frame, else
    None: a rectangle within :data:`TITLE_BLOCK_CORNER` of the frame's size from two of its
    adjacent sides, divided by lines running inside it from its sides (its cells)."""
    x0, y0, x1, y1 = shell.bounds
    reach = TITLE_BLOCK_CORNER * max(x1 - x0, y1 - y0)
    corner = [
        h
        for h in holes
        if _is_rectangle(h)
        and min(h.bounds[0] - x0, x1 - h.bounds[2]) <= reach
        and min(h.bounds[1] - y0, y1 - h.bounds[3]) <= reach
    ]
    if not corner or not lines:
        return None
    geoms = np.array(
        [shapely.linestrings(np.asarray(ln, dtype=float)) for ln in lines if len(ln) >= 2]
    )
    for hole in corner:
        if _cells(hole, geoms, tol).any():
            return hole
    return None


def _cells(rect: Polygon, geoms: np.ndarray, tol: float) -> np.ndarray:
    """Which of the lines ``geoms`` run inside the rectangle ``rect`` from its sides (a title
    block's cells)."""
    within = shapely.covers(rect.buffer(tol), geoms)
    cells = within & shapely.dwithin(geoms, rect.exterior, tol)
    return cells & ~along(geoms, rect.exterior, tol)


CELL_LINE_TURN_DEG = 30.0
"""Two cell lines whose directions differ by more than this run across each other (a row and
a column): a table, not a plate's parallel bend lines or slits."""


def free_title_block(region: Region, lines: Sequence[np.ndarray], gap: float) -> bool:
    """Whether a drawing's separate ``region`` is a title block drawn beside the part, with no
    frame: a rectangle without holes divided into cells by lines running inside it from its
    sides, rows and columns (two of them at least :data:`CELL_LINE_TURN_DEG` apart). A plate's
    bend lines or slits run one way, and a plate has holes more often than not."""
    shell = Polygon(region.shell)
    if region.holes or not _is_rectangle(shell):
        return False
    x0, y0, x1, y1 = shell.bounds
    tol = max(2.0 * gap, 1e-9 * max(x1 - x0, y1 - y0))
    arrays = [np.asarray(ln, dtype=float) for ln in lines if len(ln) >= 2]
    if not arrays:
        return False
    geoms = np.array([shapely.linestrings(a) for a in arrays])
    cells = _cells(shell, geoms, tol)
    ways = np.array(
        [np.arctan2(*(a[-1] - a[0])[::-1]) for a, c in zip(arrays, cells, strict=True) if c]
    )
    if len(ways) < 2:
        return False
    # The angle between two lines, whatever their directions: 0 (parallel) to 90 degrees.
    apart = np.abs(np.mod(np.degrees(ways[:, None] - ways[None, :]) + 90.0, 180.0) - 90.0)
    return bool((apart > CELL_LINE_TURN_DEG).any())
