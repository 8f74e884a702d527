"""The declared uncertainty of a feeder (design.md, "Uncertainty").

Three bounds, all nonnegative: the robot's rotation is off by up to ``rotation_error_deg``
(default 1 degree), every hull vertex lies within ``shape_tolerance_mm`` of its drawn position
and the COM within ``com_tolerance_mm`` of its nominal position (both default 0). With all
three zero the model is the paper's ideal one. The plan file stores the value under
design.md's names via :meth:`Uncertainty.to_dict`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feederkit.errors import InputError
from feederkit.part import Part

DEFAULT_ROTATION_ERROR_DEG = 1.0


def _check(value: float, what: str, unit: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number of {unit}, got {value!r}") from None
    if math.isnan(v) or math.isinf(v) or v < 0.0:
        raise InputError(f"{what} must be a finite nonnegative number of {unit}, got {value!r}")
    return v + 0.0


@dataclass(frozen=True)
class Uncertainty:
    """Bounds on the robot's rotation error (deg), the hull's shape and the COM (mm).

    Construction validates the values on their own (finite, nonnegative, rotation error below
    90 degrees); :func:`check_for_part` checks the shape tolerance against a part.
    """

    rotation_error_deg: float = DEFAULT_ROTATION_ERROR_DEG
    shape_tolerance_mm: float = 0.0
    com_tolerance_mm: float = 0.0

    def __post_init__(self) -> None:
        r = _check(self.rotation_error_deg, "rotation error", "degrees")
        if r >= 90.0:
            raise InputError(f"rotation error must be in [0, 90) degrees, got {r:g}")
        object.__setattr__(self, "rotation_error_deg", r)
        object.__setattr__(
            self, "shape_tolerance_mm", _check(self.shape_tolerance_mm, "shape tolerance", "mm")
        )
        object.__setattr__(
            self, "com_tolerance_mm", _check(self.com_tolerance_mm, "COM tolerance", "mm")
        )

    @property
    def is_ideal(self) -> bool:
        """Whether all three bounds are zero: the paper's ideal model."""
        return (
            self.rotation_error_deg == 0.0
            and self.shape_tolerance_mm == 0.0
            and (self.com_tolerance_mm == 0.0)
        )

    @property
    def radius_error_mm(self) -> float:
        """How far the radius function can move at any orientation: ``t + c`` (mm).

        The support function of the moved vertices is within ``t`` of the drawn one, and the COM
        moves by at most ``c`` along the fence normal.
        """
        return self.shape_tolerance_mm + self.com_tolerance_mm

    def to_dict(self) -> dict[str, float]:
        """The plan file's ``"uncertainty"`` object (design.md's names)."""
        return {
            "rotation_error_deg": self.rotation_error_deg,
            "shape_tolerance_mm": self.shape_tolerance_mm,
            "com_tolerance_mm": self.com_tolerance_mm,
        }

    @classmethod
    def from_dict(cls, data: object) -> Uncertainty:
        """Read the plan file's ``"uncertainty"`` object; missing keys take the defaults."""
        if not isinstance(data, dict):
            raise InputError(f"uncertainty must be an object, got {type(data).__name__}")
        known = {"rotation_error_deg", "shape_tolerance_mm", "com_tolerance_mm"}
        extra = sorted(set(data) - known)
        if extra:
            raise InputError(f"uncertainty has unknown key {extra[0]!r}")
        return cls(
            rotation_error_deg=data.get("rotation_error_deg", DEFAULT_ROTATION_ERROR_DEG),
            shape_tolerance_mm=data.get("shape_tolerance_mm", 0.0),
            com_tolerance_mm=data.get("com_tolerance_mm", 0.0),
        )


IDEAL = Uncertainty(0.0, 0.0, 0.0)
"""The paper's ideal model: exact rotations and shapes."""


def smallest_hull_edge(part: Part) -> float:
    """Length (mm) of the part's shortest hull edge."""
    h = np.asarray(part.hull, dtype=float)
    d = np.roll(h, -1, axis=0) - h
    return float(np.hypot(d[:, 0], d[:, 1]).min())


def max_shape_tolerance(part: Part) -> float:
    """The bound on the shape tolerance: half the part's smallest hull edge (mm).

    Below it no edge can turn by 90 degrees or more (its normal moves by at most
    ``asin(2 t / length)``), so the edges keep their order around the hull.
    """
    return smallest_hull_edge(part) / 2.0


def com_clearance(part: Part) -> float:
    """Distance (mm) from the part's COM to its hull's boundary: the bound on the COM
    tolerance (a COM displaced that far could leave the part, which no real part does).

    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> round(com_clearance(make_part(make_outline("sq", [(0, 0), (4, 0), (4, 4), (0, 4)]))), 9)
    2.0
    """
    h = np.asarray(part.hull, dtype=float)
    d = np.roll(h, -1, axis=0) - h
    c = np.asarray(part.com, dtype=float) - h
    cross = np.abs(d[:, 0] * c[:, 1] - d[:, 1] * c[:, 0])
    return float((cross / np.hypot(d[:, 0], d[:, 1])).min())


class ToleranceTooLarge(InputError):
    """A shape or COM tolerance a part cannot take (:func:`check_for_part`); ``field`` names
    which, as the plan file's ``"uncertainty"`` does (``shape_tolerance_mm`` or
    ``com_tolerance_mm``), so a caller can say where the value came from."""

    def __init__(self, message: str, field: str) -> None:
        super().__init__(message)
        self.field = field


def check_for_part(unc: Uncertainty, part: Part) -> Uncertainty:
    """Return ``unc`` if its shape tolerance is below half ``part``'s smallest hull edge and
    its COM tolerance below the COM's distance to the hull's boundary.

    Raises :class:`ToleranceTooLarge` (an InputError) naming the part and both lengths
    otherwise.
    """
    limit = max_shape_tolerance(part)
    if unc.shape_tolerance_mm >= limit:
        raise ToleranceTooLarge(
            f"{part.name}: shape tolerance {unc.shape_tolerance_mm:g} mm must be below half the "
            f"smallest hull edge ({limit:.4g} mm)",
            "shape_tolerance_mm",
        )
    clearance = com_clearance(part)
    if unc.com_tolerance_mm >= clearance:
        raise ToleranceTooLarge(
            f"{part.name}: COM tolerance {unc.com_tolerance_mm:g} mm must be below the COM's "
            f"distance to the hull's boundary ({clearance:.4g} mm)",
            "com_tolerance_mm",
        )
    return unc


__all__ = [
    "DEFAULT_ROTATION_ERROR_DEG",
    "IDEAL",
    "ToleranceTooLarge",
    "Uncertainty",
    "check_for_part",
    "com_clearance",
    "max_shape_tolerance",
    "smallest_hull_edge",
]
