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
from typing import Any

from feederkit.errors import InputError, PlanningError
from feederkit.machine import Grouping

__all__ = ["ActionCosts", "Grouping", "Lumping", "Method", "Objective", "PlanningOptions"]


class Objective(StrEnum):
    """What a plan minimises (docs/planning.md, "Which plan among the shortest").

    ``worst``: the worst-case number of operations (sections 4, 6); ``expected``: the
    expected number over the start states' weights and the readings; ``time``: the expected
    seconds per part under :class:`ActionCosts` (same horizon as ``expected``);
    ``worst-time``: among the plans of minimum worst-case length, the fewest seconds on the
    slowest path. The last two need ``costs``.
    """

    WORST = "worst"
    EXPECTED = "expected"
    TIME = "time"
    WORST_TIME = "worst-time"

    @property
    def timed(self) -> bool:
        """Whether the objective counts seconds (and so needs action costs)."""
        return self in (Objective.TIME, Objective.WORST_TIME)


def _seconds(value: object, what: str) -> float:
    """``value`` as a finite number of seconds >= 0, else bad input naming ``what``."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not (math.isfinite(value) and value >= 0.0)
    ):
        raise InputError(f"the {what} must be zero or a positive number of seconds, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class ActionCosts:
    """What one push-align operation costs in seconds (section 3.3; docs/cell.md).

    The first alignment (the part dropped from the feeder) costs ``drift_s``; every later
    operation costs ``pick_place_s + turn / rotation_speed_deg_s + drift_s``, with ``turn``
    the plan's rotation the shorter way round. ``rotation_speed_deg_s`` may be ``inf``
    (rotations cost nothing). The planners see only this value, never a cell profile.

    >>> ActionCosts(1.2, 180.0, 1.5).seconds(270.0)
    3.2
    """

    pick_place_s: float
    rotation_speed_deg_s: float
    drift_s: float

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "pick_place_s", _seconds(self.pick_place_s, "pick-and-place time"))
        set_(self, "drift_s", _seconds(self.drift_s, "drift time"))
        v = self.rotation_speed_deg_s
        if isinstance(v, bool) or not isinstance(v, int | float) or not v > 0.0:
            raise InputError(f"the rotation speed must be a positive number of deg/s, got {v!r}")
        set_(self, "rotation_speed_deg_s", float(v))

    @property
    def first_s(self) -> float:
        """Seconds of the first alignment (no pick, no rotation)."""
        return self.drift_s

    @property
    def least_s(self) -> float:
        """The fewest seconds any later operation takes (a rotation by 0)."""
        return self.pick_place_s + self.drift_s

    def seconds(self, rotation_deg: float | None) -> float:
        """Seconds of one operation rotating by ``rotation_deg`` (None: the first alignment)."""
        if rotation_deg is None:
            return self.first_s
        a = rotation_deg % 360.0
        turn = min(a, 360.0 - a)
        return self.pick_place_s + turn / self.rotation_speed_deg_s + self.drift_s


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


class Lumping(StrEnum):
    """Which states a plan may list together when no strong plan tells them apart (docs/planning.md,
    "Near-symmetric states under uncertainty").

    ``near-symmetric`` (the default): only poses of one part that look alike to the next
    station (their outlines on the fence differ by at most 1 % of the part's size, as the
    machine build records them), and states of different parts of a mix (reported as pairs
    of the mix no plan tells apart); a part whose unresolvable states look different has
    no strong plan. ``any``: every pair no strong plan resolves, even poses that look
    different (the plan then does not orient the part apart in them, and says so).
    ``none``: never; a plan orients every state up to inseparable ones, or there is none.
    """

    NEAR_SYMMETRIC = "near-symmetric"
    ANY = "any"
    NONE = "none"


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
    no limit); ``memory_limit_mb``: stop searching when the process holds more than this
    many megabytes (None: no limit), answering as at the time limit; ``costs``: the seconds
    of an operation (:class:`ActionCosts`), needed by the ``time`` and ``worst-time``
    objectives; with the operation objectives it breaks ties among equal operation counts
    toward less time; ``lumping``: which states no strong plan resolves a plan may list
    together under uncertainty (:class:`Lumping`); ``fallback``: past the exact search's
    share of a limit, answer with the best plan the fallback finds (not proven shortest);
    False: stop there with :class:`~feederkit.planning.fallback.NoFallback` instead (a
    sensor design, which is the unlimited one or nothing, wants no plan it would discard).
    """

    objective: Objective = Objective.WORST
    min_margin_deg: float = 0.0
    grouping: Grouping = Grouping.EXACT
    time_limit_s: float | None = None
    method: Method = Method.AUTO
    memory_limit_mb: float | None = None
    costs: ActionCosts | None = None
    lumping: Lumping = Lumping.NEAR_SYMMETRIC
    fallback: bool = True

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "objective", _enum(Objective, self.objective, "objective"))
        set_(self, "lumping", _enum(Lumping, self.lumping, "lumping"))
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
                raise InputError(
                    f"the time limit must be a finite positive number of seconds, got {t}"
                )
            set_(self, "time_limit_s", float(t))
        mem = self.memory_limit_mb
        if mem is not None:
            if (
                isinstance(mem, bool)
                or not isinstance(mem, int | float)
                or not (math.isfinite(mem) and mem > 0.0)
            ):
                raise InputError(
                    f"the memory limit must be a finite positive number of MB, got {mem}"
                )
            set_(self, "memory_limit_mb", float(mem))
        if not isinstance(self.fallback, bool):
            raise InputError(f"the fallback must be True or False, got {self.fallback!r}")
        if self.costs is not None and not isinstance(self.costs, ActionCosts):
            raise InputError(f"the action costs must be ActionCosts, got {self.costs!r}")
        if self.objective.timed and self.costs is None:  # type: ignore[attr-defined]
            raise InputError(
                f"the objective {self.objective.value!r} needs the seconds of an operation "
                "(action costs: pick-and-place time, rotation speed, drift time)"
            )


def out_of_budget(options: PlanningOptions, reason: str) -> str:
    """The limit that stopped a search, in words."""
    if reason == "memory" and options.memory_limit_mb is not None:
        return f"the memory limit of {options.memory_limit_mb:g} MB"
    return f"the time limit of {options.time_limit_s:g} s"


class OutOfBudget(PlanningError):
    """No plan, because a limit of the options ran out (``reason``: the Timeout's, ``"time"``
    or ``"memory"``) rather than because none exists: a caller with a budget of its own (the
    sensor design) tells the two apart by type, not by the message. ``lower_bound``: the
    operations any plan needs, the first alignment counted, where the search proved some."""

    def __init__(self, message: str, reason: str, lower_bound: int | None = None) -> None:
        super().__init__(message)
        self.reason = reason
        self.lower_bound = lower_bound

    def json_fields(self) -> dict[str, Any]:
        """``stopped_by`` (``"time"`` or ``"memory"``) and ``lower_bound`` (None: not known)."""
        return {"stopped_by": self.reason, "lower_bound": self.lower_bound}
