"""Part outlines: the flat shape as drawn, with holes, in millimetres (design.md, outline file).

An :class:`Outline` is a validated value. The outline file is feederkit's own JSON format::

    {"name": "bracket-a", "units": "mm", "vertices": [[x, y], ...],
     "holes": [[[x, y], ...], ...], "com": [x, y]}
"""

from __future__ import annotations

import json
import math
import numbers
import os
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from feederkit.errors import InputError
from feederkit.jsonio import read_json, write_text_atomic

Point = tuple[float, float]

UNIT_TO_MM: dict[str, float] = {
    "mm": 1.0,
    "cm": 10.0,
    "m": 1000.0,
    "in": 25.4,
    "inch": 25.4,
    "inches": 25.4,
    "ft": 304.8,
    "um": 0.001,
}


UNIT_ALIASES: dict[str, str] = {"inch": "in", "inches": "in"}


def unit_name(units: str) -> str:
    """The canonical name of ``units`` (``Inches`` is ``in``), as catalogs and messages give
    it; an unknown unit is bad input."""
    unit_scale(units)
    key = units.strip().lower()
    return UNIT_ALIASES.get(key, key)


def unit_scale(units: str) -> float:
    """Millimetres per unit of ``units``; an unknown unit is bad input."""
    try:
        return UNIT_TO_MM[units.strip().lower()]
    except KeyError:
        known = ", ".join(sorted(UNIT_TO_MM))
        raise InputError(f"unknown unit {units!r} (known: {known})") from None


@dataclass(frozen=True)
class Outline:
    """A flat part's outline in millimetres: outer boundary, holes, and an optional COM.

    The COM, when given, overrides the centroid of the uniform plate with its holes.
    """

    name: str
    vertices: tuple[Point, ...]
    holes: tuple[tuple[Point, ...], ...] = ()
    com: Point | None = None
    units: str = "mm"

    def polygon(self) -> Polygon:
        """The outline as a shapely polygon with its holes."""
        return Polygon(np.asarray(self.vertices), [np.asarray(h) for h in self.holes])


MAX_COORD_MM = 1e9
"""Coordinates beyond this many millimetres (1000 km) are taken for a broken file."""


def _as_list(raw: object) -> list | None:
    """``raw`` as a list when it is a sequence or an array (not a string), else None."""
    if isinstance(raw, str | bytes):
        return None
    tolist = getattr(raw, "tolist", None)
    if callable(tolist) and not isinstance(raw, Sequence):
        raw = tolist()
    return list(raw) if isinstance(raw, Sequence) else None


_PLAIN_PAIR = (list, tuple)
_PLAIN = (float, int)


def _coordinate(v: object) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError(v)
    return float(v)


def _points(raw: object, what: str, name: str) -> tuple[Point, ...]:
    seq = _as_list(raw)
    if seq is None:
        raise InputError(f"{name}: {what} must be a list of [x, y] points")
    pts: list[Point] = []
    for p in seq:
        if type(p) in _PLAIN_PAIR and len(p) == 2 and type(p[0]) in _PLAIN and type(p[1]) in _PLAIN:
            x, y = float(p[0]), float(p[1])  # the common case, without the ABC checks below
        else:
            xy = _as_list(p)
            if xy is None or len(xy) != 2:
                raise InputError(f"{name}: {what} must be a list of [x, y] points, got {p!r}")
            try:
                x, y = _coordinate(xy[0]), _coordinate(xy[1])
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"{name}: {what} has a non-numeric coordinate {p!r}") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(f"{name}: {what} has a NaN or infinite coordinate {p!r}")
        if abs(x) > MAX_COORD_MM or abs(y) > MAX_COORD_MM:
            raise InputError(f"{name}: {what} has a coordinate beyond 1e9 mm {p!r}")
        pts.append((x, y))
    return tuple(pts)


def _ring(pts: tuple[Point, ...], what: str, name: str) -> tuple[Point, ...]:
    """Drop a closing duplicate and consecutive repeats; demand three distinct points."""
    out: list[Point] = []
    for p in pts:
        if not out or p != out[-1]:
            out.append(p)
    if len(out) > 1 and out[0] == out[-1]:
        out.pop()
    if len(set(out)) < 3:
        raise InputError(
            f"{name}: {what} needs at least three distinct points, got {len(set(out))}"
        )
    return tuple(out)


GEOS_POINT = re.compile(r"\[\s*([-+0-9.eE]+)[\s,]+([-+0-9.eE]+)")
"""The location GEOS appends to its reason a geometry is invalid: ``Self-intersection[5 5]``."""


def near_point(reason: str) -> str:
    """`` near (x, y)`` for the location in a GEOS reason, or ""."""
    found = GEOS_POINT.search(reason)
    return f" near ({float(found[1]):.6g}, {float(found[2]):.6g})" if found else ""


def invalid_words(reason: str) -> str:
    """GEOS's reason a ring is invalid, in words: ``crosses itself near (5, 5)``."""
    kind = reason.split("[", 1)[0].strip().lower()
    if kind == "ring self-intersection":
        return f"touches itself{near_point(reason)}"
    if "self-intersection" in kind:
        return f"crosses itself{near_point(reason)}"
    return f"is invalid ({kind}){near_point(reason)}"


def _same_ring(a: Sequence[Point], b: Sequence[Point]) -> bool:
    """Whether two rings have the same points (in any order or direction)."""
    return sorted(a) == sorted(b)


def _near(where: shapely.Geometry) -> str:
    """`` near (x, y)`` for a point of ``where``, or "" when it is empty (no point to name)."""
    if where.is_empty:
        return ""
    point = where.representative_point()
    return f" near ({point.x:.6g}, {point.y:.6g})"


def hole_fault(shell: Polygon, holes: Sequence[Sequence[Point]]) -> str:
    """What is wrong with the holes of a valid ``shell``, in words naming the holes (by their
    index in the list): a hole crossing itself, listed twice, outside, enclosing or across
    the outline, inside or across another hole."""
    polys = [Polygon(np.asarray(h)) for h in holes]
    for i, poly in enumerate(polys):
        if not poly.is_valid:
            return f"hole {i} {invalid_words(shapely.is_valid_reason(poly))}"
    for i, poly in enumerate(polys):
        if not shell.intersects(poly) or shell.intersection(poly).area <= 0.0:
            return f"hole {i} lies outside the outline"
        if poly.covers(shell):
            if shell.covers(poly):
                return f"hole {i} is the outline itself (the same shape)"
            return f"hole {i} encloses the outline"
        if not shell.contains(poly):
            near = _near(shell.exterior.intersection(poly.exterior))
            return f"hole {i} crosses the outline{near}"
    for j, b in enumerate(polys):
        for i, a in enumerate(polys[:j]):
            if _same_ring(holes[i], holes[j]):
                return f"hole {j} is listed twice (the same points as hole {i})"
            if not a.intersects(b):
                continue
            if a.contains(b) or b.contains(a):
                inner, outer = (j, i) if a.contains(b) else (i, j)
                return f"hole {inner} lies inside hole {outer}"
            if a.intersection(b).area > 0.0:
                return f"holes {i} and {j} overlap{_near(a.exterior.intersection(b.exterior))}"
    reason = shapely.is_valid_reason(Polygon(shell.exterior, [list(h) for h in holes]))
    return f"the holes and the outline touch along a line or cut the part apart{near_point(reason)}"


def make_outline(
    name: str,
    vertices: Iterable[Sequence[float]],
    holes: Iterable[Iterable[Sequence[float]]] = (),
    com: Sequence[float] | None = None,
    units: str = "mm",
) -> Outline:
    """Validate raw coordinates (in ``units``) and return an :class:`Outline` in millimetres.

    Raises InputError for fewer than three distinct points, NaN or infinite coordinates,
    zero area, a self-intersecting boundary, or holes outside the boundary.
    """
    if not isinstance(name, str) or not name.strip():
        raise InputError("an outline needs a non-empty name")
    try:
        scale = unit_scale(units)
    except InputError as exc:
        raise InputError(f"{name}: {exc}") from None
    outer = _ring(_points(vertices, "vertices", name), "the outline", name)
    hole_list = _as_list(holes)
    if hole_list is None:
        raise InputError(f"{name}: 'holes' must be a list of point lists")
    hole_rings = tuple(
        _ring(_points(h, f"hole {i}", name), f"hole {i}", name) for i, h in enumerate(hole_list)
    )
    com_pt: Point | None = None
    if com is not None:
        xy = _as_list(com)
        if xy is None or len(xy) != 2:
            raise InputError(f"{name}: 'com' must be [x, y], got {com!r}")
        (com_pt,) = _points([xy], "com", name)
    if scale != 1.0:
        outer = tuple((x * scale, y * scale) for x, y in outer)
        hole_rings = tuple(tuple((x * scale, y * scale) for x, y in h) for h in hole_rings)
        if com_pt is not None:
            com_pt = (com_pt[0] * scale, com_pt[1] * scale)
    shell = Polygon(np.asarray(outer))
    bounds = shell.bounds
    size = max(bounds[2] - bounds[0], bounds[3] - bounds[1])
    tiny_area = 1e-12 * size * size
    if size <= 0.0 or shell.convex_hull.area <= tiny_area:
        raise InputError(f"{name}: the outline has zero area (its points are collinear)")
    if not shapely.is_valid(shell):
        reason = invalid_words(shapely.is_valid_reason(shell))
        raise InputError(f"{name}: the outline is self-intersecting (it {reason})")
    if shell.area <= tiny_area:
        raise InputError(f"{name}: the outline has zero area")
    if hole_rings and not Polygon(outer, [list(h) for h in hole_rings]).is_valid:
        raise InputError(
            f"{name}: {hole_fault(shell, hole_rings)} (each hole must lie inside the outline: "
            "no hole crosses it or another hole)"
        )
    return Outline(name=name, vertices=outer, holes=hole_rings, com=com_pt, units="mm")


def outline_from_dict(data: object, default_name: str = "part") -> Outline:
    """Read the outline file's JSON object (design.md) into a validated outline."""
    if not isinstance(data, dict):
        raise InputError(f"{default_name}: an outline file holds a JSON object")
    name = data.get("name", default_name)
    if not isinstance(name, str):
        raise InputError(f"{default_name}: 'name' must be a string")
    if "vertices" not in data:
        if data.get("format") == "feederkit-plan":
            raise InputError(f"{default_name}: a feederkit plan file, not an outline file")
        raise InputError(f"{name}: the outline file has no 'vertices'")
    units = data.get("units", "mm")
    if not isinstance(units, str):
        raise InputError(f"{name}: 'units' must be a string such as \"mm\"")
    holes = data.get("holes")
    if holes is None:
        holes = []
    if not isinstance(holes, list):
        raise InputError(f"{name}: 'holes' must be a list of point lists")
    return make_outline(name, data["vertices"], holes, data.get("com"), units)


def outline_to_dict(outline: Outline) -> dict[str, object]:
    """The outline file's JSON object for ``outline``."""
    out: dict[str, object] = {
        "name": outline.name,
        "units": "mm",
        "vertices": [list(p) for p in outline.vertices],
    }
    if outline.holes:
        out["holes"] = [[list(p) for p in h] for h in outline.holes]
    if outline.com is not None:
        out["com"] = list(outline.com)
    return out


def load_outline_json(path: str | os.PathLike[str], units: str | None = None) -> Outline:
    """Load an outline file; unreadable or malformed files are bad input. ``units``, when
    given, overrides the file's ``units`` (as ``--units`` does for every drawing)."""
    return read_outline_file(path, units)[0]


def read_outline_file(
    path: str | os.PathLike[str],
    units: str | None = None,
    count: Callable[[int], None] | None = None,
) -> tuple[Outline, str, bool]:
    """:func:`load_outline_json`, the unit its coordinates were read in (canonical name),
    which the catalog records as the source's units (the outline itself is in mm), and
    whether the file or ``units`` named it (else the coordinates were taken as mm).

    ``count`` is told the number of points the file lists (outline and holes) as soon as it
    is parsed, before they are checked and hulled: an import budget refuses a file of a
    million points in a moment, not after the work it would bound."""
    data = read_json(path, "file")
    if count is not None and isinstance(data, dict):
        count(_listed_points(data))
    if units is not None and isinstance(data, dict):
        data = {**data, "units": units}
    try:
        outline = outline_from_dict(data, default_name=Path(path).stem)
    except InputError as exc:  # name the file the user gave, not only the outline's name
        raise InputError(f"{os.fspath(path)}: {exc}") from None
    assert isinstance(data, dict)  # outline_from_dict refused anything else
    return outline, unit_name(str(data.get("units", "mm"))), "units" in data


def _listed_points(data: dict) -> int:
    """How many points an outline file's ``vertices`` and ``holes`` list (as given)."""
    rings = [data.get("vertices")]
    holes = data.get("holes")
    if isinstance(holes, list):
        rings += holes
    return sum(len(r) for r in rings if isinstance(r, list))


def save_outline_json(outline: Outline, path: str | os.PathLike[str]) -> None:
    """Write the outline file for ``outline`` atomically."""
    write_text_atomic(path, json.dumps(outline_to_dict(outline), indent=2) + "\n")
