"""Small inline-SVG drawings of parts for the HTML report: a part resting on the fence in a pose.

World frame (design.md): the fence is below the part, its contact normal points to world -y;
a part in pose ``P`` is its part frame rotated counter-clockwise by ``P``. SVG's y axis points
down, so world y is negated. Every piece of text that reaches the markup is escaped.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

Point = tuple[float, float]
Ring = Sequence[Point]

PART_COLOURS = (
    "#0072b2",
    "#d55e00",
    "#009e73",
    "#cc79a7",
    "#e69f00",
    "#56b4e9",
    "#7f3c8d",
    "#8c564b",
)
"""Colour of each part of a mix, in plan order (Okabe-Ito first; readable when printed grey)."""


def esc(text: object) -> str:
    """Text escaped for HTML content and attribute values."""
    return html.escape(str(text), quote=True)


def num(x: float, digits: int = 3) -> str:
    """A number with at most ``digits`` decimals, trailing zeros dropped (``-0`` becomes ``0``)."""
    s = f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def part_colour(index: int) -> str:
    """The colour of the ``index``-th part of the mix."""
    return PART_COLOURS[index % len(PART_COLOURS)]


def posed(points: Ring, com: Point, pose_deg: float) -> list[Point]:
    """World coordinates (COM at the origin) of part-frame points rotated by the pose (ccw)."""
    c, s = math.cos(math.radians(pose_deg)), math.sin(math.radians(pose_deg))
    out = []
    for x, y in points:
        dx, dy = x - com[0], y - com[1]
        out.append((c * dx - s * dy, s * dx + c * dy))
    return out


def reach(hull: Ring, com: Point) -> float:
    """The largest distance from the COM to a hull vertex (mm): a posed part fits in 2x this."""
    return max(math.hypot(x - com[0], y - com[1]) for x, y in hull)


def path_d(rings: Sequence[Ring]) -> str:
    """SVG path data of closed rings in world coordinates (y negated for SVG)."""
    parts = []
    for ring in rings:
        pts = " L ".join(f"{num(x, 4)} {num(-y, 4)}" for x, y in ring)
        parts.append(f"M {pts} Z")
    return " ".join(parts)


def pose_svg(
    rings: Sequence[Ring],
    hull: Ring,
    com: Point,
    pose_deg: float,
    *,
    radius_mm: float,
    colour: str,
    px: int,
    title: str,
) -> str:
    """An inline SVG of a part (outline rings, first outer, then holes) resting on the fence.

    ``radius_mm`` fixes the scale (use the same for a whole mix so sizes compare); ``px`` is the
    drawn width. The fence is the dark line under the part; the dot is the COM.
    """
    world_hull = posed(hull, com, pose_deg)
    lift = -min(y for _, y in world_hull)  # move the resting edge onto the fence, y = 0
    shifted = [[(x, y + lift) for x, y in posed(r, com, pose_deg)] for r in rings]
    r = radius_mm
    pad = 0.12 * r
    side = num(2 * r + 2 * pad, 4)
    box = f"{num(-r - pad, 4)} {num(-2 * r - pad, 4)} {side} {side}"
    dot = max(0.045 * r, 1e-6)
    return (
        f'<svg class="pose" viewBox="{box}" width="{px}" height="{px}" role="img" '
        f'xmlns="http://www.w3.org/2000/svg"><title>{esc(title)}</title>'
        f'<rect class="fence" x="{num(-r - pad, 4)}" y="0" width="{num(2 * r + 2 * pad, 4)}" '
        f'height="{num(pad, 4)}"/>'
        f'<path d="{path_d(shifted)}" fill="{colour}" fill-opacity="0.85" fill-rule="evenodd" '
        f'stroke="#222" stroke-width="1" vector-effect="non-scaling-stroke"/>'
        f'<circle cx="0" cy="{num(-lift, 4)}" r="{num(dot, 4)}" fill="#111" stroke="#fff" '
        f'stroke-width="1" vector-effect="non-scaling-stroke"/></svg>'
    )
