"""Plausibility of an imported part's size and units: say so when the scale looks wrong.

A header that says metres on a 200 mm plate gives a 200 m part; a housing modelled in
metres read as millimetres gives a 0.04 mm part. Either way the plan that follows would be
verified and wrong, so an import outside :data:`MIN_PLAUSIBLE_MM` .. :data:`MAX_PLAUSIBLE_MM`
is told what the part would measure in the other likely units, and how to choose one.
"""

from __future__ import annotations

import numpy as np
import shapely
import shapely.geometry

from feederkit.hull import convex_hull, diameter_of
from feederkit.outline import Outline, unit_scale

MIN_PLAUSIBLE_MM = 1.0
"""A feeder part smaller than 1 mm across is more likely a unit mistake."""

MAX_PLAUSIBLE_MM = 2000.0
"""A feeder part larger than 2 m across is more likely a unit mistake."""

LIKELY_UNITS = ("mm", "in", "m")
"""The units a CAD file is usually drawn in."""

METRIC = frozenset({"mm", "cm", "m", "km", "um", "dm"})
IMPERIAL = frozenset({"in", "ft", "mi", "yd", "mil", "microinch"})


def outline_size(outline: Outline) -> float:
    """The outline's largest dimension (mm): its convex hull's diameter, the part's size as
    ``Part.size`` takes it, the same however the drawing turns the part.

    The hull is GEOS's (a 400,000-point outline file's in 0.2 s, where the exact contact
    hull's chain takes 3.5 s, twice per import); a degenerate one is ours."""
    hull = shapely.convex_hull(shapely.multipoints(np.asarray(outline.vertices, dtype=float)))
    if not isinstance(hull, shapely.Polygon):
        return diameter_of(convex_hull(outline.vertices))
    ring = shapely.geometry.polygon.orient(hull, 1.0).exterior.coords[:-1]
    return diameter_of([(float(x), float(y)) for x, y in ring])


NAMED_MIN_MM = 0.01
"""An outline file that names its units is taken at its word down to this size (mm): the
paper's figures in ``catalog/`` are 1 mm across; no feeder carries a part of 10 µm."""

NAMED_MAX_MM = 10_000.0
"""... and up to this size (mm): no feeder carries a part 10 m across."""


def named_unit_warnings(size_mm: float, unit_name: str) -> list[str]:
    """:func:`size_warnings` for a file that names its units, only outside
    :data:`NAMED_MIN_MM` .. :data:`NAMED_MAX_MM` (a 1 nm or 1000 km part).

    >>> named_unit_warnings(1.0, "mm"), len(named_unit_warnings(1e-6, "mm"))
    ([], 1)
    """
    if NAMED_MIN_MM <= size_mm <= NAMED_MAX_MM:
        return []
    return size_warnings(size_mm, unit_name, False)


def size_warnings(size_mm: float, unit_name: str, given: bool, unitless: bool = False) -> list[str]:
    """A warning when a part of ``size_mm`` (read in ``unit_name``) is implausibly small or large.

    It names the size the part would have in the other likely units and the ``--units``
    option; ``given`` says the user chose the unit (the warning then says so), ``unitless``
    that the file carries none (a mesh: read as mm).
    """
    if MIN_PLAUSIBLE_MM <= size_mm <= MAX_PLAUSIBLE_MM:
        return []
    try:
        scale = unit_scale(unit_name)
    except Exception:  # noqa: BLE001 - units outside the table (miles, ...): the size alone
        scale = None
    how = (
        "as you chose with --units"
        if given
        else "as the file carries no units"
        if unitless
        else "from the file"
    )
    what = "smaller than 1 mm" if size_mm < MIN_PLAUSIBLE_MM else "larger than 2 m"
    alt = ""
    if scale is not None:
        drawn = size_mm / scale
        others = [f"{drawn * unit_scale(u):.4g} mm in {u}" for u in LIKELY_UNITS if u != unit_name]
        alt = f"; drawn in other units it would be {', '.join(others)}"
    return [
        f"the part is {size_mm:.4g} mm across ({what}), read in {unit_name} {how}{alt}: "
        "check the units (use --units)"
    ]


SMALL_UNITLESS_MM = 10.0
"""A part read from a file without units (a mesh) smaller than this across gets the size it
would have in inches too: a part modelled in inches and read as mm is 25.4 times too small,
yet above :data:`MIN_PLAUSIBLE_MM` (the angle block sample: 1.35 mm read as mm)."""


def unitless_warnings(size_mm: float) -> list[str]:
    """The note of a file that carries no units, read as mm: with the size it then has and,
    below :data:`SMALL_UNITLESS_MM`, the size drawn in inches would give. None outside the
    plausible sizes, where :func:`size_warnings` names the other units.

    >>> "48.26 mm" in unitless_warnings(1.9)[0], "inches" in unitless_warnings(60.0)[0]
    (True, False)
    """
    if not MIN_PLAUSIBLE_MM <= size_mm <= MAX_PLAUSIBLE_MM:
        return []
    note = f"the file carries no units: read as mm, the part is {size_mm:.4g} mm across"
    if size_mm < SMALL_UNITLESS_MM:
        note += (
            f" (in inches it would be {size_mm * unit_scale('in'):.4g} mm: use --units in if so)"
        )
    else:
        note += " (use --units)"
    return [note]


def measurement_warnings(doc: object, unit_name: str) -> list[str]:
    """A warning when ``$INSUNITS`` contradicts ``$MEASUREMENT`` (0 imperial, 1 metric)."""
    header = doc.header  # type: ignore[attr-defined]
    if "$MEASUREMENT" not in header:
        return []
    try:
        code = int(header.get("$MEASUREMENT"))
    except (TypeError, ValueError):
        return []
    system = {0: "imperial", 1: "metric"}.get(code)
    if system is None:
        return []
    if (system == "imperial" and unit_name in METRIC) or (
        system == "metric" and unit_name in IMPERIAL
    ):
        return [
            f"the drawing's unit ({unit_name}, $INSUNITS) contradicts its measurement system "
            f"({system}, $MEASUREMENT {code}): check the units (use --units)"
        ]
    return []
