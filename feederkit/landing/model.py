"""Landings of a part: every way it can land on the belt, as values (design.md, Landings).

A flat outline lands ``up`` (as drawn) or ``down``: turned over, its outline is the mirror
image about the part frame's y axis (``x -> -x``, holes and COM mirrored, vertices reversed so
their orientation is kept). A mesh lands in one of its resting poses ``pose-K``
(:mod:`feederkit.landing.mesh`). Each landing is one more member of a product mix for the
planners (Akella & Mason, section 8): see :mod:`feederkit.landing.plan` and docs/landings.md.

Two landings are the same landing when their outlines are **congruent**: a rigid motion of
the plane (rotation and translation, no reflection) maps one outline, with its holes and its
COM, onto the other. The test is exact up to a length tolerance: the motion must take the
COM to the COM and each hull vertex to a hull vertex in the same cyclic order, so the
candidate rotations are the few that take hull vertex 0 to a hull vertex at the same
distance from the COM; each is checked on the whole hull and then on the outline with its
holes (their symmetric difference). The hull is the outline's exact hull
(:func:`exact_hull`), never the simplified contact hull, which need not keep the outline's
mirror symmetry. The push functions' rotation-invariant signature
(:mod:`feederkit.mix.signatures`) would not do: it sees the hull and the COM only, so two
sides that differ by a hole or a notch inside the hull would wrongly be merged. Landings
that are not congruent but that the fence and sensor cannot tell apart are kept apart and
reported as indistinguishable (:func:`feederkit.landing.plan.plan_landings`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from shapely import affinity

from feederkit.errors import InputError
from feederkit.hull import Point, convex_hull, number_hull
from feederkit.outline import Outline
from feederkit.part import Part

UP = "up"
DOWN = "down"
DEFAULT_SIDE_PROBABILITY = 0.5
"""The probability of ``up`` for a flat part unless the user gives another (design.md)."""

CONGRUENCE_REL_TOL = 1e-6
"""Lengths (of the part's size) and areas (of its area) within this are the same shape."""

_LANDING_RE = re.compile(r"^(up|down|pose-(0|[1-9][0-9]*))$")


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
    if not isinstance(name, str) or not _LANDING_RE.match(name):
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


def _centred(pts: Sequence[Point], com: Point) -> list[Point]:
    return [(x - com[0], y - com[1]) for x, y in pts]


def _rotate(p: Point, c: float, s: float) -> Point:
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def exact_hull(part: Part) -> tuple[Point, ...]:
    """The exact convex hull of the part's outline (collinear points dropped, nothing else).

    Congruence is decided on it, not on ``part.hull``: a simplified hull (``--hull-tolerance``)
    depends on the order in which :func:`feederkit.hull.clean_hull` merges an arc's chords,
    so a mirror-symmetric outline's simplified hull need not be symmetric (a 60 x 20 slot
    gave 40 vertices whose mirror image is another 40-gon), and a hull and its mirror would
    differ by up to the hull tolerance where the outlines coincide.
    """
    return number_hull(convex_hull(part.outline.vertices))


def _rotations(a: Part, b: Part, rel_tol: float) -> Iterator[float]:
    ha, hb = _centred(exact_hull(a), a.com), _centred(exact_hull(b), b.com)
    n = len(ha)
    if n != len(hb) or n < 3:
        return
    size = max(a.size, b.size)
    tol = rel_tol * size
    area_a, area_b = a.outline.polygon().area, b.outline.polygon().area
    if abs(area_a - area_b) > rel_tol * max(area_a, area_b):
        return
    r0 = math.hypot(*ha[0])
    for j in range(n):
        if abs(math.hypot(*hb[j]) - r0) > tol:
            continue
        phi = math.atan2(hb[j][1], hb[j][0]) - math.atan2(ha[0][1], ha[0][0])
        c, s = math.cos(phi), math.sin(phi)
        if all(
            math.dist(_rotate(ha[i], c, s), hb[(i + j) % n]) <= tol for i in range(n)
        ) and _same_outline(a, b, phi, rel_tol * max(area_a, area_b) + tol * size):
            yield math.degrees(phi) % 360.0


def congruence_rotations(a: Part, b: Part, rel_tol: float = CONGRUENCE_REL_TOL) -> list[float]:
    """Rotations (deg, about the COM) that map part ``a`` onto part ``b``; empty when none.

    A rotation counts when it takes every vertex of the exact hull of ``a``'s outline (about
    its COM, see :func:`exact_hull`) to the vertex of ``b``'s in the same cyclic order within
    ``rel_tol`` of the size, and the outlines with their holes then differ by at most
    ``rel_tol`` of the area.
    """
    return list(_rotations(a, b, rel_tol))


def _same_outline(a: Part, b: Part, phi: float, area_tol: float) -> bool:
    pa = affinity.translate(a.outline.polygon(), -a.com[0], -a.com[1])
    pa = affinity.rotate(pa, phi, origin=(0.0, 0.0), use_radians=True)
    pb = affinity.translate(b.outline.polygon(), -b.com[0], -b.com[1])
    return float(pa.symmetric_difference(pb).area) <= area_tol


def congruent(a: Part, b: Part, rel_tol: float = CONGRUENCE_REL_TOL) -> bool:
    """Whether a rigid motion of the plane maps ``a`` (outline, holes, COM) onto ``b``."""
    return next(_rotations(a, b, rel_tol), None) is not None


def landings_of_outline(
    part: Part, side_probability: float = DEFAULT_SIDE_PROBABILITY
) -> tuple[Landing, ...]:
    """The landings of a flat part: ``up`` and ``down``, or ``up`` alone when they are one.

    ``side_probability`` is the probability of ``up`` (0 < P < 1). When the mirror image is
    congruent to the part (a mirror-symmetric outline: its two sides are the same shape on
    the belt) there is one landing, ``up``, with probability 1.

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
    if congruent(part, down):
        return (Landing(part.name, UP, 1.0, up, merged=(DOWN,)),)
    return (Landing(part.name, UP, p, up), Landing(part.name, DOWN, 1.0 - p, down))


def merge_congruent(
    part_name: str, candidates: Sequence[tuple[str, float, Part]]
) -> tuple[Landing, ...]:
    """Landings from ``(name, probability, part)`` candidates, congruent ones merged.

    Each candidate joins the first earlier landing it is congruent to (its probability is
    added there and its name listed in ``merged``); the order of first appearance is kept.
    """
    groups: list[tuple[str, float, Part, list[str]]] = []
    for name, prob, part in candidates:
        for k, (gname, gprob, gpart, merged) in enumerate(groups):
            if congruent(part, gpart):
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
