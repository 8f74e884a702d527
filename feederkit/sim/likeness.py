"""How a refused ``--part`` SOURCE differs from the plan's part when it is the plan's hull in
other units or in another part frame.

The match check (:func:`feederkit.sim.real.check_match`) compares hulls in the part frame,
where the push function lives (section 3.1: the fence's orientation is measured in the part's
frame; design.md: the part frame is the outline's own coordinates). A SOURCE drawn in inches
and read as millimetres, or exported turned or mirrored, is refused there as though it were
another part, and no hull tolerance helps. Here the SOURCE's hull is brought onto the plan's
by a similarity (scaled by the ratio of the hulls' sizes, its COM put on the plan's, turned
and perhaps mirrored to fit best), and what that takes names the remedy
(:func:`refusal_words`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.optimize import minimize_scalar

from feederkit.hull import hull_distance

Point = tuple[float, float]

SAMPLES = 720
"""Directions the hulls' support functions are compared in, for the first guess of the turn."""

UNIT_FACTORS = {"in": 25.4, "cm": 10.0, "m": 1000.0, "ft": 304.8, "um": 0.001}
"""Millimetres per unit of the units a file may be drawn in (``--units``)."""

UNIT_NAMES = {
    "in": "inches",
    "cm": "centimetres",
    "m": "metres",
    "ft": "feet",
    "um": "micrometres",
    "mm": "millimetres",
}

UNIT_MATCH_REL = 0.02
"""A size ratio within this fraction of a unit's factor is read as that unit."""

FAR_SCALE = 1.25
"""A size ratio beyond this (or below its inverse) is no manufacturing difference."""

SMALL_TURN_DEG = 0.01
"""A turn below this is no turn of the frame."""


@dataclass(frozen=True)
class Likeness:
    """The similarity that brings a SOURCE's hull onto the plan's: ``scale`` (the plan's size
    over the SOURCE's), then ``mirrored`` (``x -> -x`` about its COM), ``turn_deg`` (counter-
    clockwise about its COM) and ``shift`` (the plan's COM minus the SOURCE's, mm);
    ``distance_mm`` is the Hausdorff distance left between the hulls (the plan's mm)."""

    scale: float
    mirrored: bool
    turn_deg: float
    shift: Point
    distance_mm: float

    def motion_words(self, size_mm: float) -> str:
        """The rigid motion in a few words (``mirrored and turned by 90 deg about its COM,
        then moved by (3, 4) mm``); empty for none."""
        about = [
            w for w, on in (("mirrored", self.mirrored), (self._turn(), bool(self._turn()))) if on
        ]
        words = f"{' and '.join(about)} about its COM" if about else ""
        if math.hypot(*self.shift) > 1e-6 * size_mm:
            dx, dy = (round(c, 3) + 0.0 for c in self.shift)
            words += f"{', then ' if words else ''}moved by ({dx:g}, {dy:g}) mm"
        return words

    def _turn(self) -> str:
        return f"turned by {self.turn_deg:.4g} deg" if abs(self.turn_deg) >= SMALL_TURN_DEG else ""


def scale_of(plan_hull: Sequence[Point], hull: Sequence[Point]) -> float:
    """The plan's hull's size over ``hull``'s: the square root of their areas' ratio (which
    no frame changes)."""
    return math.sqrt(shapely.Polygon(plan_hull).area / shapely.Polygon(hull).area)


def _support(points: np.ndarray) -> np.ndarray:
    """The support function about the origin in :data:`SAMPLES` directions."""
    phi = np.linspace(0.0, 2.0 * math.pi, SAMPLES, endpoint=False)
    return np.max(points @ np.vstack([np.cos(phi), np.sin(phi)]), axis=0)


def _turned(points: np.ndarray, deg: float) -> np.ndarray:
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return points @ np.array([[c, s], [-s, c]])


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    """The Hausdorff distance of two convex polygons as regions (:func:`hull_distance`)."""
    return hull_distance(a, b)


def _best_turn(plan: np.ndarray, source: np.ndarray) -> tuple[float, float]:
    """The turn (deg) of ``source`` about the origin that fits ``plan`` best, and the distance
    left: the best cyclic shift of the sampled support functions (for convex regions the
    largest difference of the support functions is the Hausdorff distance), refined on the
    exact distance within a sample either side."""
    hp, hs = _support(plan), _support(source)
    gaps = [float(np.max(np.abs(hp - np.roll(hs, k)))) for k in range(SAMPLES)]
    step = 360.0 / SAMPLES
    guess = int(np.argmin(gaps)) * step
    found = minimize_scalar(
        lambda deg: _distance(plan, _turned(source, deg)),
        bounds=(guess - step, guess + step),
        method="bounded",
        options={"xatol": 1e-7},
    )
    turn = (float(found.x) + 180.0) % 360.0 - 180.0
    return turn, _distance(plan, _turned(source, turn))


def likeness(
    plan_hull: Sequence[Point], plan_com: Point, hull: Sequence[Point], com: Point, scale: float
) -> Likeness:
    """The similarity that brings ``hull`` (COM ``com``) closest to ``plan_hull`` (COM
    ``plan_com``): scaled by ``scale``, COM onto COM, the best turn with and without a
    mirror (the unmirrored one on a tie)."""
    plan = np.asarray(plan_hull, dtype=float) - np.asarray(plan_com, dtype=float)
    source = (np.asarray(hull, dtype=float) - np.asarray(com, dtype=float)) * scale
    shift = (plan_com[0] - com[0], plan_com[1] - com[1])
    best: Likeness | None = None
    for mirrored in (False, True):
        points = source[::-1] * np.array([-1.0, 1.0]) if mirrored else source
        turn, left = _best_turn(plan, points)
        if best is None or left < best.distance_mm - 1e-9:
            best = Likeness(scale, mirrored, turn, shift, left)
    assert best is not None
    return best


def likely_units(scale: float) -> tuple[str, str] | None:
    """``(drawn in, read as)`` when ``scale`` (the plan's size over the SOURCE's) is a unit's
    factor: 25.4 is a file in inches read as millimetres, 1/25.4 the reverse."""
    for unit, factor in UNIT_FACTORS.items():
        if abs(scale / factor - 1.0) <= UNIT_MATCH_REL:
            return unit, "mm"
        if abs(scale * factor - 1.0) <= UNIT_MATCH_REL:
            return "mm", unit
    return None


def _units_words(scale: float, source: str, name: str, is_file: bool, give: str | None) -> str:
    """The remedy for a SOURCE at another scale: its units; ``give`` how the command then
    takes the catalog part (default ``simulate``'s ``--part NAME=...``)."""
    size = f"{scale:.4g} times smaller" if scale >= 1.0 else f"{1.0 / scale:.4g} times larger"
    units = likely_units(scale)
    if units is None:
        why, option = "a scale no unit explains", "--units UNIT"
    else:
        drawn, read = (UNIT_NAMES[u] for u in units)
        why, option = f"likely in {drawn}, read as {read}", f"--units {units[0]}"
    where = source if is_file else "its file"
    return (
        f"; its hull is {size} than the plan's: the file's units differ from the plan's part "
        f"({why}): import it with `feederkit catalog add {where} {option} --name NAME` and "
        + (give or f"give --part {name}=NAME (simulate reads a file in its own units)")
    )


def _frame_words(found: Likeness, size_mm: float) -> str:
    """The remedy for a SOURCE in another part frame."""
    apart = round(found.distance_mm, 4) + 0.0
    return (
        f"; {found.motion_words(size_mm)}, its hull is the plan's (then {apart:g} mm apart): "
        "the part's frame differs from the plan's (a plan's part frame is its outline's own "
        "coordinates, as drawn, or as a mesh's pose lies): give the SOURCE the plan was made "
        "from (the same file or catalog revision), or the part exported in the plan's frame"
    )


def refusal_words(
    plan_hull: Sequence[Point],
    plan_com: Point,
    hull: Sequence[Point],
    com: Point,
    allowed_mm: float,
    *,
    source: str,
    name: str,
    is_file: bool,
    give: str | None = None,
) -> str | None:
    """Why a SOURCE whose hull the match check refused may still be the plan's part: in other
    units (its size a unit's factor from the plan's, or beyond :data:`FAR_SCALE`, and its
    shape fits once scaled), or in another frame (a turn, mirror or shift brings it within
    ``allowed_mm``); None when neither explains it. One clause, starting ``; ``."""
    scale = scale_of(plan_hull, hull)
    size = float(np.ptp(np.asarray(plan_hull, dtype=float), axis=0).max())
    units = likely_units(scale) is not None or not 1.0 / FAR_SCALE <= scale <= FAR_SCALE
    # Other units only when the shape fits once scaled: a size a unit's factor off alone is
    # another part as often as not.
    found = likeness(plan_hull, plan_com, hull, com, scale if units else 1.0)
    if found.distance_mm > allowed_mm:
        return None
    if units:
        return _units_words(scale, source, name, is_file, give)
    return _frame_words(found, size) if found.motion_words(size) else None


__all__ = ["Likeness", "likeness", "likely_units", "refusal_words", "scale_of"]
