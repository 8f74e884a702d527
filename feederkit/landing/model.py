"""Landings of a part: every way it can land on the belt, as values (design.md, Landings).

A flat outline lands ``up`` (as drawn) or ``down``: turned over, its outline is the mirror
image about the part frame's y axis (``x -> -x``, holes and COM mirrored, vertices reversed so
their orientation is kept). A mesh lands in one of its resting poses ``pose-K``
(:mod:`feederkit.landing.mesh`). Each landing is one more member of a product mix for the
planners (Akella & Mason, section 8): see :mod:`feederkit.landing.plan` and docs/landings.md.

Two landings are the same landing when their outlines are **congruent**: a rotation about
the COM (the motion must take COM to COM; no reflection) brings one outline, with its holes,
within :data:`CONGRUENCE_TOL_MM` of the other (Hausdorff distance, of the regions and of their
boundaries), the precision a drawing carries and far below what a feeder or the next station
can tell. The rotation is found by branch and bound over the circle (:func:`congruent`), so
the verdict does not depend on how the outlines' curves were chorded. The push functions'
rotation-invariant signature (:mod:`feederkit.mix.signatures`) would not do: it sees the hull
and the COM only, so two sides that differ by a hole or a notch inside the hull would wrongly
be merged. Landings that are not congruent but that the fence and sensor cannot tell apart
are kept apart and reported as indistinguishable
(:func:`feederkit.landing.plan.plan_landings`).
"""

from __future__ import annotations

import heapq
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely import affinity

from feederkit.errors import InputError
from feederkit.hull import Point, number_hull
from feederkit.outline import Outline
from feederkit.part import Part

UP = "up"
DOWN = "down"
DEFAULT_SIDE_PROBABILITY = 0.5
"""The probability of ``up`` for a flat part unless the user gives another (design.md)."""

CONGRUENCE_TOL_MM = 0.005
"""Outlines within this Hausdorff distance (mm) of each other, turned about the COM, are one
shape: above what a drawing can tell, far below what a feeder can.

A drawing's sides of one shape differ by about a micrometre: coordinates written to 0.001 mm
lie up to 1.4 um from their mirror image's, a fine arc chorded from another angle by its
sagitta (hex_nut.real.json's hole: 0.27 um), float32 mesh vertices by 0.01 um. The feeder's
sensor reads to 0.1 mm and its contact hull is simplified to 0.05 mm, and the smallest real
difference between two sides to keep (a 0.05 mm chamfer on one corner) lies 35 um from the
mirror image, 7 times this tolerance.
"""

CONGRUENCE_REL_TOL = 1e-3
"""Below 5 mm the tolerance is this share of the part's size instead (as the importers' hull
tolerance shrinks for small parts): the sides of a 1 mm part must agree to 1 um."""

CONGRUENCE_MAX_WORK = 4_000_000
"""Vertex look-ups the rotation search makes at most (a few seconds; an outline of 1000
vertices gets 2000 intervals, the real parts take a few hundred): beyond them the outlines
count as different, two landings, as no outline is merged without a rotation that was
checked. Only outlines round to within the tolerance everywhere but one rotation, such as a
circle traced with noise of about the tolerance, come near it."""

_START_INTERVALS = 16
"""The circle of rotations is first cut into this many intervals."""

_LEAF_SHARE = 0.2
"""An interval is cut no further once turning by its half-width moves no vertex by more than
this share of the tolerance: any rotation within 3/4 of the tolerance is then found (the
grown outlines' chords take 0.5 % of it)."""

_POLISH_STEPS = 40
"""Golden-section steps that find the closest rotation of a run (0.618**40: 4e-9 of it)."""

_MAX_SAMPLES = 20000
"""At most this many points sample an outline's boundary for the search's bounds."""

LANDING_RE = re.compile(r"^(up|down|pose-(0|[1-9][0-9]*))$")
"""A landing's name (design.md, "Landings"): ``up``, ``down`` or ``pose-K``."""


@dataclass(frozen=True)
class Landing:
    """One way a part lands: its name, prior probability, and the part as it then lies.

    ``name`` is ``up``, ``down`` or ``pose-K``; ``part`` is the landing's own part (outline,
    hull, COM in the landing's frame) named ``PART/LANDING``, so a plan over landings names
    the landing in its results. ``merged`` lists the other landings (mesh poses) congruent
    to this one whose probability was added to it.
    """

    part_name: str
    name: str
    probability: float
    part: Part
    merged: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """``PART/LANDING``: the name of the landing's part in plans."""
        return f"{self.part_name}/{self.name}"


def check_landing_name(name: str) -> str:
    """``name`` when it is ``up``, ``down`` or ``pose-K``, else InputError."""
    if not isinstance(name, str) or not LANDING_RE.match(name):
        raise InputError(
            f"invalid landing {name!r}: a landing is up, down or pose-K (K = 0, 1, ...)"
        )
    return name


def check_side_probability(p: object) -> float:
    """The probability of ``up`` for a flat part: a number strictly between 0 and 1."""
    if isinstance(p, bool) or not isinstance(p, int | float) or not 0.0 < float(p) < 1.0:
        raise InputError(
            f"the side probability (of landing up) must lie strictly between 0 and 1, got {p!r}"
        )
    return float(p)


def _mirror_ring(ring: Sequence[Point]) -> tuple[Point, ...]:
    """``x -> -x``, reversed so that the ring keeps its orientation."""
    return tuple((-x + 0.0, y) for x, y in reversed(ring))


def mirror_outline(outline: Outline) -> Outline:
    """The outline turned over: mirrored about the part frame's y axis, holes and COM too."""
    com = None if outline.com is None else (-outline.com[0] + 0.0, outline.com[1])
    return Outline(
        name=outline.name,
        vertices=_mirror_ring(outline.vertices),
        holes=tuple(_mirror_ring(h) for h in outline.holes),
        com=com,
        units=outline.units,
    )


def mirror_part(part: Part, name: str | None = None) -> Part:
    """The part lying face down: outline, hull and COM mirrored (``x -> -x``).

    The hull is mirrored exactly (not recomputed, so a simplified hull stays as simplified),
    reversed to stay counter-clockwise and renumbered from its lowest-then-leftmost vertex.
    """
    return Part(
        name=name or part.name,
        outline=mirror_outline(part.outline),
        com=(-part.com[0] + 0.0, part.com[1]),
        hull=number_hull(_mirror_ring(part.hull)),
        revision=part.revision,
    )


def renamed(part: Part, name: str) -> Part:
    """``part`` under another name (a landing's ``PART/LANDING``)."""
    return Part(
        name=name, outline=part.outline, com=part.com, hull=part.hull, revision=part.revision
    )


def congruence_tolerance(a: Part, b: Part) -> float:
    """The Hausdorff distance (mm) within which ``a`` and ``b`` are one shape:
    :data:`CONGRUENCE_TOL_MM`, or :data:`CONGRUENCE_REL_TOL` of the larger size when smaller."""
    return min(CONGRUENCE_TOL_MM, CONGRUENCE_REL_TOL * max(a.size, b.size))


class _Shape:
    """A part's outline about its COM, prepared for the rotation search.

    ``near`` (the region grown by the tolerance) and ``band`` (the boundary grown by it) are
    made when :func:`_within` first asks: on a plate of thousands of holes they cost
    seconds, and most comparisons end before any rotation is tried."""

    def __init__(self, part: Part, tol: float, spacing: float = 0.0) -> None:
        self.polygon = affinity.translate(part.outline.polygon(), -part.com[0], -part.com[1])
        boundary = self.polygon.boundary
        self.points = shapely.get_coordinates(boundary)  # (n, 2) the vertices of every ring
        self.radii = np.hypot(self.points[:, 0], self.points[:, 1])  # from the COM
        self.spacing = max(tol, boundary.length / _MAX_SAMPLES, spacing)
        # The boundary sampled every ``spacing`` at most.
        self.samples = cKDTree(shapely.get_coordinates(shapely.segmentize(boundary, self.spacing)))
        self.tol = tol

    @cached_property
    def near(self) -> shapely.Geometry:
        grown = shapely.buffer(self.polygon, self.tol)
        shapely.prepare(grown)
        return grown

    @cached_property
    def band(self) -> shapely.Geometry:
        grown = shapely.buffer(self.polygon.boundary, self.tol)
        shapely.prepare(grown)
        return grown


def _turned(points: np.ndarray, phi: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return points @ np.array([[c, s], [-s, c]])


def _gaps(a: _Shape, b: _Shape, phi: float, reach: float) -> np.ndarray:
    """Lower bounds on the distances from ``a``'s vertices turned by ``phi`` to ``b``'s
    boundary (a sample lies within half the spacing of every boundary point); infinite for
    the vertices farther than ``reach``."""
    d = b.samples.query(_turned(a.points, phi), distance_upper_bound=reach + b.spacing)[0]
    return d - b.spacing / 2


def _bound(a: _Shape, b: _Shape, phi: float, h: float, tol: float) -> float | None:
    """The largest of :func:`_gaps` at ``phi``, or None when no rotation within ``phi`` +-
    ``h`` can bring every vertex of ``a`` within ``tol`` of ``b``'s boundary (a vertex at
    radius r moves at most r h)."""
    gaps = _gaps(a, b, phi, tol + float(a.radii.max()) * h)
    if float(np.max(gaps - a.radii * h)) > tol:
        return None
    return float(gaps.max())


def _within(a: _Shape, b: _Shape, phi: float) -> bool:
    """Whether ``a`` turned by ``phi`` and ``b`` lie within the tolerance of each other,
    as regions and as boundaries (exact up to the grown shapes' chords, which err inwards)."""
    pa = affinity.rotate(a.polygon, phi, origin=(0.0, 0.0), use_radians=True)
    pb = affinity.rotate(b.polygon, -phi, origin=(0.0, 0.0), use_radians=True)
    return (
        b.band.covers(pa.boundary)
        and a.band.covers(pb.boundary)
        and b.near.covers(pa)
        and a.near.covers(pb)
    )


def _may_match(a: Part, b: Part, tol: float) -> bool:
    """Necessary conditions, cheap: extents about the COM and areas that agree."""
    pa, pb = a.outline.polygon(), b.outline.polygon()
    ra = float(np.max(np.hypot(*(shapely.get_coordinates(pa.exterior) - a.com).T)))
    rb = float(np.max(np.hypot(*(shapely.get_coordinates(pb.exterior) - b.com).T)))
    n = len(shapely.get_coordinates(pa)) + len(shapely.get_coordinates(pb))
    spread = 2.0 * tol * (pa.boundary.length + pb.boundary.length) + math.pi * tol * tol * n
    return abs(ra - rb) <= tol and abs(pa.area - pb.area) <= spread


_COARSE_REL = 1.0 / 128.0
""":func:`_ruled_out` samples the boundaries every this share of the part's size."""


def _ruled_out(a: Part, b: Part, tol: float, check: Callable[[], None] = lambda: None) -> bool:
    """Whether :func:`_bound` on coarsely sampled boundaries (every :data:`_COARSE_REL` of
    the size) already excludes every rotation. Its bounds stay valid lower bounds (a sample
    within half the spacing of every boundary point), only weaker: a part unlike its mirror
    image is told so at a few hundred samples instead of tens of thousands (the catalog
    lands every imported part)."""
    spacing = _COARSE_REL * max(a.size, b.size)
    if spacing <= 2.0 * tol:
        return False
    sa, sb = _Shape(a, tol, spacing), _Shape(b, tol, spacing)
    leaf = spacing / max(float(sa.radii.max()), float(sb.radii.max()))
    h0 = math.pi / _START_INTERVALS
    todo = [((2 * k + 1) * h0, h0) for k in range(_START_INTERVALS)]
    for _ in range(max(1, CONGRUENCE_MAX_WORK // (2 * len(sa.points)))):
        if not todo:
            return True
        check()
        phi, h = todo.pop()
        if _bound(sa, sb, phi, h, tol) is None:
            continue
        if h <= leaf:
            return False  # a rotation may work: the fine search decides
        todo += [(phi - h / 2, h / 2), (phi + h / 2, h / 2)]
    return False


def _search(
    a: Part, b: Part, tol: float, first: bool, check: Callable[[], None] = lambda: None
) -> list[float]:
    """Rotations (rad) about the COMs that bring ``a`` within ``tol`` of ``b``.

    Branch and bound over the circle: an interval is dropped when :func:`_bound` shows no
    rotation in it can work, the others are examined closest first (the largest vertex gap
    at their centre), within :data:`CONGRUENCE_MAX_WORK`; a rotation counts only when
    :func:`_within` holds there. ``first``: stop at the first; else one rotation per run of
    adjacent intervals that work, the closest within it (:func:`_polish`). ``check`` is
    called before each interval (a deadline: an outline of thousands of holes takes
    tenths of a second an interval).
    """
    if not _may_match(a, b, tol) or _ruled_out(a, b, tol, check):
        return []
    check()
    sa, sb = _Shape(a, tol), _Shape(b, tol)
    leaf = _LEAF_SHARE * tol / max(float(sa.radii.max()), float(sb.radii.max()))
    h0 = math.pi / _START_INTERVALS
    heap: list[tuple[float, float, float]] = []

    def push(phi: float, h: float) -> None:
        largest = _bound(sa, sb, phi, h, tol)
        if largest is not None:
            heapq.heappush(heap, (largest, phi, h))

    for k in range(_START_INTERVALS):
        push((2 * k + 1) * h0, h0)
    found: list[tuple[float, float, float]] = []
    for _ in range(max(1, CONGRUENCE_MAX_WORK // (2 * len(sa.points)))):
        if not heap:
            break
        check()
        largest, phi, h = heapq.heappop(heap)
        if largest <= tol and _within(sa, sb, phi):
            found.append((phi, h, largest))
            if first:
                break
        elif h > leaf:
            push(phi - h / 2, h / 2)
            push(phi + h / 2, h / 2)
    if first:
        return [phi for phi, _, _ in found]
    return [_polish(sa, sb, run) for run in _runs(found)]


def _runs(found: list[tuple[float, float, float]]) -> list[list[tuple[float, float, float]]]:
    """The intervals that work, grouped into runs of adjacent ones around the circle."""
    runs: list[list[tuple[float, float, float]]] = []
    for item in sorted(found):
        if runs and item[0] - item[1] <= runs[-1][-1][0] + runs[-1][-1][1] + 1e-12:
            runs[-1].append(item)
        else:
            runs.append([item])
    if len(runs) > 1:
        (p0, h0, _), (p1, h1, _) = runs[0][0], runs[-1][-1]
        if p0 - h0 <= 1e-12 and p1 + h1 >= 2 * math.pi - 1e-12:
            runs[0] = runs.pop() + runs[0]
    return runs


def _polish(a: _Shape, b: _Shape, run: list[tuple[float, float, float]]) -> float:
    """The rotation of a run that brings ``a`` closest to ``b``: a golden-section search of
    shapely's Hausdorff distance over the run's span, kept only if it works (else the run's
    best-scoring interval)."""
    phis = [run[0][0]]
    for phi, _, _ in run[1:]:
        phis.append(phi + 2 * math.pi if phi < phis[-1] else phi)
    lo, hi = phis[0] - run[0][1], phis[-1] + run[-1][1]

    def gap(phi: float) -> float:
        turned = affinity.rotate(a.polygon, phi, origin=(0.0, 0.0), use_radians=True)
        return float(shapely.hausdorff_distance(turned, b.polygon))

    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = gap(x1), gap(x2)
    for _ in range(_POLISH_STEPS):
        if f1 <= f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = gap(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = gap(x2)
    best = x1 if f1 <= f2 else x2
    return best if _within(a, b, best) else min(run, key=lambda x: x[2])[0]


def congruence_rotations(a: Part, b: Part, tol: float | None = None) -> list[float]:
    """Rotations (deg, about the COM) that map part ``a`` onto part ``b``; empty when none.

    A rotation counts when it brings ``a``'s outline (holes included) within ``tol`` (mm,
    default :func:`congruence_tolerance`) of ``b``'s, as regions and as boundaries. One
    rotation per run of rotations that work: six for a hex nut and its mirror image, one for
    a part round within the tolerance.
    """
    t = congruence_tolerance(a, b) if tol is None else tol
    degrees = (math.degrees(phi) % 360.0 for phi in _search(a, b, t, first=False))
    return sorted(0.0 if d > 360.0 - 1e-9 else d for d in degrees)


def congruent(
    a: Part, b: Part, tol: float | None = None, check: Callable[[], None] | None = None
) -> bool:
    """Whether a rigid motion of the plane maps ``a`` (outline, holes, COM) onto ``b``, up to
    ``tol`` (mm, default :func:`congruence_tolerance`; see :func:`congruence_rotations`);
    ``check`` is called as the search goes (a deadline, which raises)."""
    t = congruence_tolerance(a, b) if tol is None else tol
    return bool(_search(a, b, t, first=True, check=check or (lambda: None)))


def landings_of_outline(
    part: Part,
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
    check: Callable[[], None] | None = None,
) -> tuple[Landing, ...]:
    """The landings of a flat part: ``up`` and ``down``, or ``up`` alone when they are one.

    ``side_probability`` is the probability of ``up`` (0 < P < 1). When the mirror image is
    congruent to the part (a mirror-symmetric outline: its two sides are the same shape on
    the belt) there is one landing, ``up``, with probability 1. ``check`` is polled while
    the two are compared (an import's deadline: a plate of 4,900 holes took 19 s there).

    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> bar = make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)]))
    >>> [(x.name, x.probability) for x in landings_of_outline(bar)]
    [('up', 1.0)]
    >>> ring = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
    >>> ell = make_part(make_outline("ell", ring))
    >>> [(x.name, round(x.probability, 9)) for x in landings_of_outline(ell, 0.7)]
    [('up', 0.7), ('down', 0.3)]
    """
    p = check_side_probability(side_probability)
    up = renamed(part, f"{part.name}/{UP}")
    down = mirror_part(part, f"{part.name}/{DOWN}")
    if congruent(part, down, check=check):
        return (Landing(part.name, UP, 1.0, up, merged=(DOWN,)),)
    return (Landing(part.name, UP, p, up), Landing(part.name, DOWN, 1.0 - p, down))


def merge_congruent(
    part_name: str,
    candidates: Sequence[tuple[str, float, Part]],
    check: Callable[[], None] | None = None,
) -> tuple[Landing, ...]:
    """Landings from ``(name, probability, part)`` candidates, congruent ones merged.

    Each candidate joins the first earlier landing it is congruent to (its probability is
    added there and its name listed in ``merged``); the order of first appearance is kept.
    ``check`` is called before each comparison (an import's deadline: a near-round mesh of
    320 resting poses takes about 1,200 of up to 0.09 s each).
    """
    groups: list[tuple[str, float, Part, list[str]]] = []
    for name, prob, part in candidates:
        for k, (gname, gprob, gpart, merged) in enumerate(groups):
            if check is not None:
                check()
            if congruent(part, gpart, check=check):
                merged.append(name)
                groups[k] = (gname, gprob + prob, gpart, merged)
                break
        else:
            groups.append((name, prob, part, []))
    return tuple(
        Landing(part_name, name, prob, renamed(p, f"{part_name}/{name}"), tuple(merged))
        for name, prob, p, merged in groups
    )


def select_landings(
    landings: Sequence[Landing], which: str | Sequence[str] = "all"
) -> tuple[Landing, ...]:
    """The landings named by ``which``: ``"all"``, or landing names (``up``, ``pose-2``, ...).

    A name that is not a landing of the part (including one merged into another) is bad
    input, naming the landings there are and pointing to ``--accept`` (a mix of a mesh and a
    flat part has no landing name in common).
    """
    if which == "all":
        return tuple(landings)
    names = [which] if isinstance(which, str) else list(which)
    by_name = {x.name: x for x in landings}
    out = []
    for n in names:
        check_landing_name(n)
        if n not in by_name:
            merged = [x.name for x in landings if n in x.merged]
            where = f" (it is the same shape as {merged[0]})" if merged else ""
            known = ", ".join(by_name)
            part = landings[0].part_name if landings else "the part"
            raise InputError(
                f"{part} has no landing {n}{where}; its landings: {known} (the landings "
                "named are planned for every part; to plan every landing and reject some, "
                "name the ones the next station takes with --accept)"
            )
        if by_name[n] not in out:
            out.append(by_name[n])
    return tuple(out)
