"""A part: an outline, its center of mass and its contact hull (design.md conventions)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

from feederkit.errors import InputError
from feederkit.hull import (
    REL_LENGTH_TOL,
    Point,
    contact_hull,
    diameter_of,
    point_in_convex,
    size_of,
)
from feederkit.outline import Outline


@dataclass(frozen=True)
class Part:
    """A flat part as the fence feels it.

    ``hull`` is the contact polygon: the convex hull of the outline, counter-clockwise, vertex 0
    the lowest-then-leftmost. ``com`` is the area centroid of the plate with its holes unless
    the user gave one. Coordinates are the part frame, in millimetres.
    """

    name: str
    outline: Outline
    com: Point
    hull: tuple[Point, ...]
    revision: str | None = None

    @cached_property
    def size(self) -> float:
        """The hull's diameter, the part's largest dimension (mm): the length scale of
        tolerances (the vibration, near-symmetry, rounding), the same however the drawing
        turns the part (a bounding box's larger side is not)."""
        return diameter_of(self.hull)


def make_part(
    outline: Outline,
    com: Point | None = None,
    *,
    hull_tolerance: float | None = None,
    revision: str | None = None,
    name: str | None = None,
) -> Part:
    """Build a part from a validated outline.

    ``com`` overrides the outline's own COM, which overrides the plate centroid.
    ``hull_tolerance`` (mm) merges hull vertices closer than it to the line of their
    neighbours; by default a length tolerance of 1e-9 of the part's size.
    Raises InputError for a degenerate hull or a COM not strictly inside the hull.
    """
    pts = list(outline.vertices)
    hull = contact_hull(pts, hull_tolerance)
    label = name or outline.name
    if len(hull) < 3:
        raise InputError(f"{label}: the outline has zero area")
    if com is None:
        com = outline.com
    if com is None:
        c = outline.polygon().centroid
        com = (float(c.x), float(c.y))
    if not (math.isfinite(com[0]) and math.isfinite(com[1])):
        raise InputError(f"{label}: the center of mass has a NaN or infinite coordinate")
    com = (float(com[0]), float(com[1]))
    margin = REL_LENGTH_TOL * size_of(hull)
    if not point_in_convex(hull, com, margin):
        where = "on the boundary of" if point_in_convex(hull, com, -margin) else "outside"
        raise InputError(
            f"{label}: the center of mass ({com[0]:g}, {com[1]:g}) lies {where} the contact hull"
            " (it must lie strictly inside)"
        )
    return Part(name=label, outline=outline, com=com, hull=hull, revision=revision)
