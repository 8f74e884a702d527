"""A plan's statistics (the plan file's ``stats``): length, expected length, margin, class bound.

The class bound is the worst-case length of the part's polygon class (Fig. 14, section 6.2)
under the plan's sensor; it is defined for one part, so a mix's plan gives null there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from feederkit.mechanics.polygon_classes import polygon_class
from feederkit.mechanics.push import PushFunction

if TYPE_CHECKING:
    from feederkit.planning.tree import PlanResult


def plan_stats(result: PlanResult, parts: Sequence[PushFunction]) -> dict[str, Any]:
    """The ``stats`` object of the plan file.

    design.md's fields (``length``, ``expected_length``, ``min_margin_deg`` (null when the
    plan has no rotation), ``optimal``, ``lower_bound``) and feederkit's own: ``objective``,
    ``grouping``, ``class``, ``class_bound`` and ``meets_bound`` (``length <= class_bound``;
    all three null for a mix).
    """
    cls = polygon_class(parts[0], result.machine.sensor) if len(parts) == 1 else None
    return {
        "length": result.length,
        "expected_length": result.expected_length,
        "min_margin_deg": result.min_margin if math.isfinite(result.min_margin) else None,
        "optimal": result.optimal,
        "lower_bound": result.lower_bound,
        "objective": result.objective,
        "grouping": result.grouping,
        "class": None if cls is None else cls.number,
        "class_bound": None if cls is None else cls.bound,
        "meets_bound": None if cls is None else result.length <= cls.bound,
    }
