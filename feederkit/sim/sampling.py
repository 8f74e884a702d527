"""What nature draws per trial: the declared uncertainty and the friction, sampled.

A strong plan (design.md, "Uncertainty") must reach its result for every rotation error up to
``±r``, every hull vertex within ``t`` of its drawn position and the COM within ``c``. The
simulator checks that claim physically by drawing, per trial, one perturbed part (each hull
vertex displaced uniformly within the disc of radius ``t``, the COM within the disc of radius
``c``), the belt's and the fence's friction coefficients uniformly from their ranges, and, per
robot rotation, an error uniform in ``[-r, +r]`` (independently per operation). Under
``--ideal`` nothing is drawn: the drawn part, the nominal friction (the middle of each range,
:attr:`FrictionRange.nominal`) and exact rotations. Nature's draws come from their own
generator (:func:`nature_rng`), so the starts and parts of a seed are the same with and
without sampling.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.errors import InputError
from feederkit.mechanics.push import PushFunction, edge_normals, push
from feederkit.outline import make_outline
from feederkit.part import Part, make_part
from feederkit.plans.model import PlanPart
from feederkit.uncertainty import Uncertainty

Point = tuple[float, float]

MAX_FRICTION = 5.0
"""The largest friction coefficient the simulator accepts."""


@dataclass(frozen=True)
class FrictionRange:
    """A friction coefficient drawn uniformly from ``[lo, hi]`` per trial (``lo == hi``: fixed)."""

    lo: float
    hi: float

    @property
    def nominal(self) -> float:
        """The middle of the range: the value used when nothing is sampled."""
        return (self.lo + self.hi) / 2.0

    def text(self) -> str:
        """``LO:HI``, or the one value."""
        return f"{self.lo:g}" if self.lo == self.hi else f"{self.lo:g}:{self.hi:g}"


def friction_range(value: str | float | tuple[float, float], label: str) -> FrictionRange:
    """Parse ``LO:HI`` (or one number, a fixed coefficient) into a checked range.

    Both ends finite in [0, MAX_FRICTION] and ``lo <= hi``; anything else is bad input naming
    ``label`` (the option).
    """
    if isinstance(value, tuple):
        lo, hi = value
    elif isinstance(value, int | float) and not isinstance(value, bool):
        lo = hi = float(value)
    else:
        text = str(value).strip()
        pieces = text.split(":")
        try:
            if len(pieces) == 1:
                lo = hi = float(pieces[0])
            elif len(pieces) == 2:
                lo, hi = float(pieces[0]), float(pieces[1])
            else:
                raise ValueError
        except ValueError:
            raise InputError(
                f"{label} must be a friction coefficient or a range LO:HI, got {text!r}"
            ) from None
    for v in (lo, hi):
        if not (math.isfinite(v) and 0.0 <= v <= MAX_FRICTION):
            raise InputError(
                f"{label} must be friction coefficients in [0, {MAX_FRICTION:g}], got {v:g}"
            )
    if lo > hi:
        raise InputError(f"{label} range {lo:g}:{hi:g} has LO above HI")
    return FrictionRange(float(lo), float(hi))


@dataclass(frozen=True)
class TrialDraw:
    """Nature's draw for one trial: hull vertex displacements (mm, in hull order), the COM's
    displacement (mm) and the two friction coefficients."""

    vertex_offsets: tuple[Point, ...]
    com_offset: Point
    friction_belt: float
    friction_fence: float

    @property
    def perturbs_shape(self) -> bool:
        """Whether the part differs from the drawn one."""
        return any(dx or dy for dx, dy in self.vertex_offsets) or any(self.com_offset)

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form (the largest displacements, the friction)."""
        return {
            "max_vertex_offset_mm": round(
                max((math.hypot(dx, dy) for dx, dy in self.vertex_offsets), default=0.0), 6
            ),
            "com_offset_mm": [round(self.com_offset[0], 6), round(self.com_offset[1], 6)],
            "friction_belt": round(self.friction_belt, 6),
            "friction_fence": round(self.friction_fence, 6),
        }


def nature_rng(seed: int, trial: int) -> np.random.Generator:
    """The generator of nature's draws in trial ``trial`` (separate from starts and parts)."""
    return np.random.default_rng([seed, trial, 1])


def _in_disc(rng: np.random.Generator, radius: float) -> Point:
    """A point uniform in the closed disc of ``radius`` about the origin (no draw at 0)."""
    if radius == 0.0:
        return (0.0, 0.0)
    r = radius * math.sqrt(float(rng.uniform(0.0, 1.0)))
    a = float(rng.uniform(0.0, 2.0 * math.pi))
    return (r * math.cos(a), r * math.sin(a))


def _uniform(rng: np.random.Generator, fr: FrictionRange) -> float:
    return fr.lo if fr.lo == fr.hi else float(rng.uniform(fr.lo, fr.hi))


def draw_trial(
    rng: np.random.Generator,
    n_vertices: int,
    uncertainty: Uncertainty,
    friction_belt: FrictionRange,
    friction_fence: FrictionRange,
) -> TrialDraw:
    """Draw one trial's part perturbation and friction (see the module)."""
    t, c = uncertainty.shape_tolerance_mm, uncertainty.com_tolerance_mm
    offsets = tuple(_in_disc(rng, t) for _ in range(n_vertices))
    return TrialDraw(
        offsets, _in_disc(rng, c), _uniform(rng, friction_belt), _uniform(rng, friction_fence)
    )


def draw_rotation_error(rng: np.random.Generator, rotation_error_deg: float) -> float:
    """One robot rotation's error (deg), uniform in ``[-r, +r]`` (no draw when ``r`` is 0)."""
    if rotation_error_deg == 0.0:
        return 0.0
    return float(rng.uniform(-rotation_error_deg, rotation_error_deg))


@dataclass(frozen=True)
class PerturbedPart:
    """A trial's part: the drawn hull and COM displaced by a :class:`TrialDraw`.

    ``basin_of_edge[k]`` is the drawn part's stable state id for a rest on the perturbed
    hull's edge ``k``: the state of the drawn edge it is (the same two vertices, displaced),
    when that edge is a stable state's, else the state whose resting range holds its normal
    (the basin of a rest candidate, F3 of :mod:`feederkit.mechanics.uncertain`); None when no
    stable state's range holds it. A rest on a drawn stable edge is that state's pose however
    far its normal moved: near a metastable edge the displaced normal may leave the drawn
    resting range by a hundredth of a degree, and its basin would name the neighbour.
    """

    part: Part
    basin_of_edge: tuple[int | None, ...]


def perturbed_part(plan_part: PlanPart, nominal: PushFunction, draw: TrialDraw) -> PerturbedPart:
    """The part of one trial (its edges mapped to the drawn part's stable states).

    Raises InputError when the displaced vertices make no part (cannot happen below the
    shape-tolerance bound, half the smallest hull edge, which the plan file's check enforces).
    """
    verts = [
        (x + dx, y + dy)
        for (x, y), (dx, dy) in zip(plan_part.hull, draw.vertex_offsets, strict=True)
    ]
    com = [plan_part.com[0] + draw.com_offset[0], plan_part.com[1] + draw.com_offset[1]]
    part = make_part(make_outline(plan_part.name, [list(v) for v in verts], com=com))
    id_of_edge = {s.edge: s.id for s in nominal.states}
    # A stable edge by its two drawn vertices (indices into the plan's hull).
    drawn = _source_vertices(nominal.part.hull, plan_part.hull)
    m = len(drawn)
    by_ends = {(drawn[e], drawn[(e + 1) % m]): i for e, i in id_of_edge.items()}
    source = _source_vertices(part.hull, verts)
    basins: list[int | None] = []
    for k, normal in enumerate(edge_normals(part.hull)):
        ends = (source[k], source[(k + 1) % len(part.hull)])
        if None not in ends and ends in by_ends:
            basins.append(by_ends[ends])  # the drawn stable edge itself, displaced
        else:
            basins.append(id_of_edge.get(push(nominal, normal).edge))
    return PerturbedPart(part, tuple(basins))


def _source_vertices(hull: Sequence[Point], verts: Sequence[Point]) -> list[int | None]:
    """For each vertex of ``hull``, the index of the vertex of ``verts`` it is (a hull is
    renumbered and may drop a vertex that fell inside), None when none lies within rounding."""
    pts = np.asarray(verts, dtype=float)
    tol = 1e-9 * max(1.0, float(np.ptp(pts, axis=0).max()))
    out: list[int | None] = []
    for x, y in hull:
        d = np.hypot(pts[:, 0] - x, pts[:, 1] - y)
        i = int(np.argmin(d))
        out.append(i if d[i] <= tol else None)
    return out


__all__ = [
    "FrictionRange",
    "PerturbedPart",
    "TrialDraw",
    "draw_rotation_error",
    "draw_trial",
    "friction_range",
    "nature_rng",
    "perturbed_part",
]
