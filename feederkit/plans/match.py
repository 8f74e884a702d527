"""Which of a plan's parts a given part is: the same hull and COM in the part frame, within
the shape and COM tolerances the plan declares (design.md, "Uncertainty": the plan reaches
its result for every part within them)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from feederkit.errors import InputError
from feederkit.part import Part
from feederkit.plans.model import Plan, PlanPart
from feederkit.plans.readplan import as_plan
from feederkit.uncertainty import IDEAL, Uncertainty

MATCH_REL_TOL = 1e-6
"""Hull vertices and COM must agree within this fraction of the part's size."""


def same_geometry(part: Part, entry: PlanPart, uncertainty: Uncertainty = IDEAL) -> bool:
    """Whether ``part`` has the hull (same vertices, same numbering) and COM of a plan's part:
    each vertex within the declared shape tolerance, the COM within the declared COM
    tolerance (``uncertainty``), both plus :data:`MATCH_REL_TOL` of the part's size."""
    hull_off, com_off = geometry_offsets(part, entry)
    tol = MATCH_REL_TOL * part.size
    return (
        hull_off <= tol + uncertainty.shape_tolerance_mm
        and com_off <= tol + uncertainty.com_tolerance_mm
    )


def geometry_offsets(part: Part, entry: PlanPart) -> tuple[float, float]:
    """How far (mm) ``part``'s hull vertices (the farthest; infinite for another number of
    vertices) and COM lie from a plan's part's."""
    com = math.hypot(part.com[0] - entry.com[0], part.com[1] - entry.com[1])
    if len(entry.hull) != len(part.hull):
        return math.inf, com
    pairs = zip(part.hull, entry.hull, strict=True)
    far = max(math.hypot(a[0] - b[0], a[1] - b[1]) for a, b in pairs)
    return far, com


def offsets_words(part: Part, entry: PlanPart, uncertainty: Uncertainty) -> str:
    """How far ``part`` lies from the plan's part against what the plan declares, in words."""
    hull_off, com_off = geometry_offsets(part, entry)
    hull = (
        f"{len(part.hull)} hull vertices, the plan's {len(entry.hull)}"
        if math.isinf(hull_off)
        else f"hull vertices up to {hull_off:.4g} mm off"
    )
    return (
        f"{hull}, COM {com_off:.4g} mm off; the plan declares shape tolerance "
        f"{uncertainty.shape_tolerance_mm:g} mm, COM tolerance {uncertainty.com_tolerance_mm:g} mm"
    )


def match_part(plan: Plan | Mapping[str, Any], part: Part, source: str) -> int:
    """The index of the plan's part with ``part``'s hull and COM; InputError when there is none.

    Among parts of the same geometry (look-alikes), the one of the same name is preferred.
    """
    plan = as_plan(plan)
    unc = plan.uncertainty
    alike = [k for k, entry in enumerate(plan.parts) if same_geometry(part, entry, unc)]
    for k in alike:
        if plan.parts[k].name == part.name:
            return k
    if alike:
        return alike[0]
    names = ", ".join(dict.fromkeys(p.name for p in plan.parts))  # each part once
    named = [p for p in plan.parts if p.name == part.name]
    if named:
        raise InputError(
            f"{source}: part {part.name!r} differs from the plan's part of that name "
            f"({offsets_words(part, named[0], unc)})"
        )
    raise InputError(f"{source}: part {part.name!r} is not one of the plan's parts ({names})")


def leaf_part_pairs(plan: Plan | Mapping[str, Any]) -> list[tuple[str, str]]:
    """Pairs of members that some result lists together: the plan cannot tell them apart.

    Members are named by their labels (``NAME``, or ``NAME (LANDING)`` in plans over
    landings, so two landings of one part lumped together are a pair too). Each pair once,
    in the plan's part order.
    """
    plan = as_plan(plan)
    pairs: set[tuple[str, str]] = set()
    label = {p.key: p.label for p in plan.parts}
    order = {p.label: k for k, p in enumerate(plan.parts)}
    for leaf in plan.leaves():
        names = sorted({label[e.key] for e in leaf.results}, key=order.__getitem__)
        pairs.update((a, b) for i, a in enumerate(names) for b in names[i + 1 :])
    return sorted(pairs, key=lambda ab: (order[ab[0]], order[ab[1]]))
