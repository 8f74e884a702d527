"""The one-line warnings of a drawing's import: regions merged, outlines read apart, lines open.

Regions merged into a part by lines drawn against it, closed outlines lying side by side
read as parts of their own, and open lines that may be an outline left open: each said in
words with where it lies (boxes and line ends in mm), so the user can find it in the drawing.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon

from feederkit.importers.loops import Region, components
from feederkit.words import plural


def merged_note(enclosed: int) -> str:
    """The warning for a part whose outline holds faces enclosed by lines inside it."""
    return (
        f"lines inside the part enclose {plural(enclosed, 'region')} touching its outline at "
        "a point or joined to it by other lines (a hole drawn with lines and touching the "
        "outline, or crossed by a centre line?): merged into the part, so its area and COM "
        "may be off if they are holes; check the drawing or leave construction lines out "
        "with --layer"
    )


NEARLY_CLOSED = 0.25
"""Open lines nearly close a loop when their two free ends lie at most this share of their
size apart (an ARC of 330 degrees or more, four LINEs of a window one of which stops
short); a centre line, a centre mark or a bend line does not."""


def box_words(bounds: Sequence[float]) -> str:
    """A box in words: ``80 x 10 mm at x 0..80, y -10..0``."""
    x0, y0, x1, y1 = bounds
    return f"{x1 - x0:.4g} x {y1 - y0:.4g} mm at x {x0:.4g}..{x1:.4g}, y {y0:.4g}..{y1:.4g}"


def _boxes(bounds: Sequence[Sequence[float]]) -> str:
    """At most three boxes in words (:func:`box_words`), "; ..." when there are more."""
    return "; ".join(box_words(b) for b in bounds[:3]) + ("; ..." if len(bounds) > 3 else "")


def _merged_note(what: str, where: str, bounds: Sequence[Sequence[float]], cause: str) -> str:
    """A warning for regions merged into the part that lines drawn against it may have
    closed: ``what`` did it to the regions ``where`` (their ``bounds``), ``cause`` what
    they may be."""
    return (
        f"{what} {plural(len(bounds), 'region')}{where} ({_boxes(bounds)}): merged into the "
        f"part, so its area and COM are off if {cause}; delete such lines or leave their "
        "layer out with --layer"
    )


def outside_note(bounds: Sequence[Sequence[float]]) -> str:
    """The warning for regions that open lines close against the outline's edge from
    outside (:attr:`.loops.Loop.outside`), merged into the part."""
    return _merged_note(
        "lines close",
        " against the outline's edge from outside",
        bounds,
        "they are extension or dimension lines or a view drawn against it",
    )


def cut_off_note(bounds: Sequence[Sequence[float]]) -> str:
    """The warning for regions an open line inside the part cuts off
    (:attr:`.loops.Loop.cut_off`), merged into the part."""
    return _merged_note(
        "a line inside the outline ends on it at both ends and cuts off",
        "",
        bounds,
        "the region is closed by extension or dimension lines or is another part drawn against it",
    )


def side_by_side_note(bounds: Sequence[Sequence[float]]) -> str:
    """The warning for closed outlines lying side by side, read as separate parts
    (:attr:`.loops.Loop.split`)."""
    return (
        f"{plural(len(bounds), 'closed outline')} share edges side by side ({_boxes(bounds)}): "
        "read as separate parts, not merged into one (parts nested for common-line cutting, or "
        "a view drawn against its part?); if they are one part, draw its outline as one closed "
        "line"
    )


def title_block_note(bounds: Sequence[Sequence[float]]) -> str:
    """The note of title blocks drawn beside the part (no frame) and left out."""
    return (
        f"left out {plural(len(bounds), 'title block')} beside the part, a rectangle divided "
        f"into cells ({_boxes(bounds)}); if it is a part, draw it on a layer of its own and "
        "import that with --layer, or from a drawing of its own"
    )


def _free_ends(chain: shapely.Geometry) -> np.ndarray:
    """The ends of a group of noded open lines that no other of its lines meets."""
    parts = shapely.get_parts(chain)
    ends = np.concatenate([shapely.get_coordinates(shapely.get_point(parts, k)) for k in (0, -1)])
    _, first, counts = np.unique(ends, axis=0, return_index=True, return_counts=True)
    return ends[np.sort(first[counts == 1])]


def open_line_notes(
    dangles: Sequence[LineString], regions: Sequence[Region], gap: float
) -> list[str]:
    """Warnings for open lines (``dangles``, the lines no loop uses) that may be an outline
    left open: a connected group of them around the first part (its real outline open, so
    the part may be one of its holes), or one nearly closing a loop (:data:`NEARLY_CLOSED`)
    inside a part's material (a hole whose outline is open, left out).

    Each group is joined over its noded pieces, so an outline of six LINEs one of which
    stops short counts as one, as an open polyline does.
    """
    if not dangles or not regions:
        return []
    pieces = np.asarray(dangles, dtype=object)
    labels = components(pieces)
    groups = [shapely.multilinestrings(pieces[labels == lab]) for lab in np.unique(labels)]
    part = Polygon(regions[0].shell)
    notes: list[str] = []
    around = [g for g in groups if _around(g, part)]
    if around:
        ends = _free_ends(around[0])
        notes.append(
            f"an open outline ({ends_words(ends)}, too far apart to close) surrounds the imported "
            "part: the drawing's real outer outline may be open and the part one of its holes; "
            "close the outline in the drawing"
        )
    nearly: list[tuple[shapely.Geometry, np.ndarray]] = []
    for g in groups:
        ends = _free_ends(g)
        if _nearly_closed(g, ends, gap):
            nearly.append((g, ends))
    # An open outline beside the part that, closed between its ends, holds more than the
    # part: the drawing's real outline left open (a LINE stopping short, a polyline whose
    # closed flag is missing), and the part imported some other loop (a label box).
    larger = [
        (g, ends)
        for g, ends in nearly
        if not any(g is a for a in around) and _closed_area(g) > part.area
    ]
    if larger:
        g, ends = max(larger, key=lambda x: _closed_area(x[0]))
        notes.append(
            f"an open outline ({box_words(g.bounds)}, {ends_words(ends)}) lies beside the "
            f"imported part and, closed, would hold {_closed_area(g):.4g} mm², more than the "
            f"part's {part.area:.4g} mm²: the drawing's real outline may be open and the part "
            "imported another loop; close the outline in the drawing"
        )
    inside: list[tuple[shapely.Geometry, np.ndarray]] = []
    if nearly:
        solids = [Polygon(r.shell, r.holes) for r in regions]
        tree = shapely.STRtree(solids)
        for g, ends in nearly:
            hits = tree.query(g, predicate="intersects")
            if any(solids[int(j)].buffer(2.0 * gap).covers(g) for j in hits):
                inside.append((g, ends))
    if inside:
        g, ends = inside[0]
        more = f" and {len(inside) - 1} more" if len(inside) > 1 else ""
        notes.append(
            f"open lines inside the part nearly close {plural(len(inside), 'loop')} "
            f"({box_words(g.bounds)}, {ends_words(ends)}{more}), left out: if they are a hole "
            "whose outline is open, the part's area and COM are off; close the gap in the drawing"
        )
    return notes


def _around(group: shapely.Geometry, part: Polygon) -> bool:
    """Whether a connected group of open lines goes around ``part``: one of its lines holds
    the part's box strictly inside its own (an open polyline around it), or it is one chain
    that, closed between its two ends, holds the whole part (an outline of LINEs one of
    which stops short). Extension and dimension lines around a part branch: no chain."""
    x0, y0, x1, y1 = part.bounds
    for line in shapely.get_parts(group):
        lx0, ly0, lx1, ly1 = line.bounds
        if lx0 < x0 and ly0 < y0 and lx1 > x1 and ly1 > y1:
            return True
    chain = shapely.line_merge(group)
    if not isinstance(chain, LineString) or chain.is_closed or len(chain.coords) < 3:
        return False
    ring = shapely.node(shapely.linearrings(np.asarray(chain.coords)))
    inside = shapely.union_all(shapely.get_parts(shapely.polygonize(shapely.get_parts(ring))))
    return bool(inside.covers(part))


def ends_words(ends: np.ndarray, counted: bool = False) -> str:
    """Open ends in words: ``its ends 0.5 mm apart at (79.5, 0) and (80, 0)`` (``counted``:
    ``2 open ends, 0.5 mm apart at ...``)."""
    if len(ends) == 2:
        (ax, ay), (bx, by) = ends
        return (
            f"{'2 open ends,' if counted else 'its ends'} "
            f"{float(np.hypot(ax - bx, ay - by)):.3g} mm apart at "
            f"({ax:.4g}, {ay:.4g}) and ({bx:.4g}, {by:.4g})"
        )
    where = ", ".join(f"({x:.4g}, {y:.4g})" for x, y in ends[:3])
    return f"{plural(len(ends), 'open end')} at {where}{', ...' if len(ends) > 3 else ''}"


def _nearly_closed(group: shapely.Geometry, ends: np.ndarray, gap: float) -> bool:
    """Whether a connected group of open lines is one chain whose two ends lie at most
    :data:`NEARLY_CLOSED` of its size apart and which, closed there, encloses an area (not a
    line drawn there and back): a loop left open."""
    if len(ends) != 2:
        return False
    chain = shapely.line_merge(group)
    if not isinstance(chain, LineString) or len(chain.coords) < 3:
        return False
    x0, y0, x1, y1 = chain.bounds
    apart = float(np.hypot(*(ends[0] - ends[1])))
    if apart > NEARLY_CLOSED * max(x1 - x0, y1 - y0):
        return False
    return abs(float(shapely.area(Polygon(chain.coords)))) > gap * chain.length


def _closed_area(group: shapely.Geometry) -> float:
    """The area a connected group of open lines that is one chain holds when closed
    between its ends (0 for one that is no chain)."""
    chain = shapely.line_merge(group)
    if not isinstance(chain, LineString) or len(chain.coords) < 3:
        return 0.0
    return abs(float(shapely.area(Polygon(chain.coords))))


def edge_line_note(box: Sequence[float], band: float) -> str:
    """The warning for an outline drawn again just inside itself, that line left out
    (:func:`feederkit.importers.drawing.edge_line`): both readings of such a drawing named."""
    return (
        f"the outline ({box_words(box)}) is drawn again {band:.3g} mm inside it all along: "
        "taken for a chamfer or edge line drawn in a top view, not a hole, so the loops it "
        "holds are the part's holes; if the two lines are a drawing frame, the part is what "
        "they hold: leave the frame's layer out with --layer, or delete the frame"
    )
