"""Which of a plan's parts a given part is: the same hull and COM in the part frame."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from feederkit.errors import InputError
from feederkit.part import Part
from feederkit.plans.model import Plan, PlanPart
from feederkit.plans.readplan import as_plan

MATCH_REL_TOL = 1e-6
"""Hull vertices and COM must agree within this fraction of the part's size."""


def same_geometry(part: Part, entry: PlanPart) -> bool:
    """Whether ``part`` has the hull (same vertices, same numbering) and COM of a plan's part."""
    if len(entry.hull) != len(part.hull):
        return False
    tol = MATCH_REL_TOL * part.size
    pts = [*zip(part.hull, entry.hull, strict=True), (part.com, entry.com)]
    return all(math.hypot(a[0] - b[0], a[1] - b[1]) <= tol for a, b in pts)


def match_part(plan: Plan | Mapping[str, Any], part: Part, source: str) -> int:
    """The index of the plan's part with ``part``'s hull and COM; InputError when there is none.

    Among parts of the same geometry (look-alikes), the one of the same name is preferred.
    """
    plan = as_plan(plan)
    alike = [k for k, entry in enumerate(plan.parts) if same_geometry(part, entry)]
    for k in alike:
        if plan.parts[k].name == part.name:
            return k
    if alike:
        return alike[0]
    names = ", ".join(dict.fromkeys(p.name for p in plan.parts))  # each part once
    if any(p.name == part.name for p in plan.parts):
        raise InputError(
            f"{source}: part {part.name!r} differs from the plan's part of that name "
            "(its hull or COM is not the one the plan was made for)"
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
