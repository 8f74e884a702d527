"""The planning options, validated once (design.md, "plan"; docs/planning.md).

One frozen value carries what a planner is asked for, from the command line or a library
caller down to :func:`feederkit.planning.api.plan`; strings are accepted for the enums and
normalised, so ``PlanningOptions(objective="expected")`` is the same value as
``PlanningOptions(objective=Objective.EXPECTED)``.

>>> PlanningOptions(objective="expected", min_margin_deg=2).objective is Objective.EXPECTED
True
>>> PlanningOptions(min_margin_deg=180)
Traceback (most recent call last):
...
feederkit.errors.InputError: the minimum margin must be in [0, 180) degrees, got 180
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from feederkit.errors import InputError
from feederkit.machine import Grouping

__all__ = ["Grouping", "Method", "Objective", "PlanningOptions"]


class Objective(StrEnum):
    """What a plan minimises: the worst-case number of operations (sections 4, 6), or the
    expected number over uniformly random starts and readings, among the shortest."""

    WORST = "worst"
    EXPECTED = "expected"


class Method(StrEnum):
    """Which search proves the minimum length.

    ``andor``: the AND/OR search of section 6.1; ``bottom-up``: the backward search of
    section 6.4; ``bfs`` and ``backchain``: breadth-first search and Goldberg's (1993)
    backchaining, for sensorless machines only; ``auto`` chooses.
    """

    AUTO = "auto"
    ANDOR = "andor"
    BOTTOM_UP = "bottom-up"
    BFS = "bfs"
    BACKCHAIN = "backchain"


def _enum(kind: type[StrEnum], value: object, what: str) -> StrEnum:
    """``value`` as a member of ``kind``; anything else is bad input naming the choices."""
    try:
        return kind(value)
    except ValueError:
        choices = ", ".join(m.value for m in kind)
        raise InputError(f"the {what} must be one of {choices}, got {value!r}") from None


@dataclass(frozen=True)
class PlanningOptions:
    """What to plan for.

    ``min_margin_deg``: use only rotations whose overlap range is at least twice this wide
    (the rotation error a plan tolerates, section 3.2.2); ``grouping``: how readings branch
    (:class:`Grouping`); ``time_limit_s``: give up proving optimality after this long (None:
    no limit).
    """

    objective: Objective = Objective.WORST
    min_margin_deg: float = 0.0
    grouping: Grouping = Grouping.EXACT
    time_limit_s: float | None = None
    method: Method = Method.AUTO

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "objective", _enum(Objective, self.objective, "objective"))
        set_(self, "grouping", _enum(Grouping, self.grouping, "reading grouping"))
        set_(self, "method", _enum(Method, self.method, "planning method"))
        m = self.min_margin_deg
        if isinstance(m, bool) or not isinstance(m, int | float) or not 0.0 <= m < 180.0:
            raise InputError(f"the minimum margin must be in [0, 180) degrees, got {m}")
        set_(self, "min_margin_deg", float(m))
        t = self.time_limit_s
        if t is not None:
            if (
                isinstance(t, bool)
                or not isinstance(t, int | float)
                or not (math.isfinite(t) and t > 0.0)
            ):
                raise InputError(f"the time limit must be a positive number of seconds, got {t}")
            set_(self, "time_limit_s", float(t))
