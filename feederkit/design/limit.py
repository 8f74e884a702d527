"""The time limit of a sensor design, and its progress (docs/design.md, "Time limit").

A design is exact or it is nothing: a critical tolerance decided on a search cut short would
be understated, a length table cut short would stop at a step that is not the last. So a
design runs under one :class:`~feederkit.planning.budget.Deadline`: every loop of the design
polls it (per pair, per probe of the binary searches, per step of the table), every planner
search it calls gets it (the inseparability fixpoints, the AND/OR length oracle, the exact
solver, the verified plans through their own time limit), and a search that runs out raises
:class:`~feederkit.planning.budget.Timeout` through every cache (a probe that timed out is
never recorded as "not separable"). The design's entry points turn it into
:class:`DesignTimeout`, one line saying what was decided; no half-computed design is ever
returned.

Progress is a plain callback (no terminal library here): ``progress(what, done, total)``
each time a pair, a probe of the goal search, a run of the table or a pitch is decided.
"""

from __future__ import annotations

from collections.abc import Callable

from feederkit.errors import PlanningError
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import OutOfBudget, PlanningOptions
from feederkit.plans.make import MadePlan

Progress = Callable[[str, int, int], None]
"""``progress(what, done, total)``: ``done`` of ``total`` items of the stage ``what`` decided."""

PAIRS = "deciding the pairs' critical tolerances"
GOALS = "finding where the planner's goal changes"
LENGTHS = "tabulating the plan lengths"
PITCHES = "deciding the LED pitches"

_NOUNS = {
    PAIRS: "pairs",
    # Two passes over the intervals (goal_segments): a cut in the second reads "N of 2N".
    GOALS: "steps of the length table's goal search, two an interval",
    LENGTHS: "tolerance intervals of the length table",
    PITCHES: "LED pitches",
}


class DesignTimeout(PlanningError):
    """The sensor design did not finish within its time or memory limit (nothing partial is
    returned: a partial design, when asked for, is a ``ToleranceDesign`` whose ``stopped``
    holds this message); ``reason`` says which ("time" or "memory", as ``Timeout``'s).

    A :class:`~feederkit.errors.PlanningError` (exit 1), as ``plan``'s "no plan found within
    the time limit".
    """

    def __init__(self, message: str, reason: str = "time") -> None:
        super().__init__(message)
        self.reason = reason


def check_limits(
    seconds: float | None, megabytes: float | None
) -> tuple[float | None, float | None]:
    """The time limit (s) and memory limit (MB) as floats, each None for none; InputError in
    the planner's words unless positive finite numbers (validated once, by
    :class:`~feederkit.planning.options.PlanningOptions`)."""
    options = PlanningOptions(time_limit_s=seconds, memory_limit_mb=megabytes)
    return options.time_limit_s, options.memory_limit_mb


class DesignClock:
    """One design's budget (``time_limit_s`` seconds from now and a process size of
    ``memory_limit_mb``; None: no such limit) and where it stands: the stage running, how
    much of it is decided, the stages finished.

    Mutable on purpose (it counts as the design runs); a design makes its own.
    """

    def __init__(
        self,
        time_limit_s: float | None = None,
        progress: Progress | None = None,
        memory_limit_mb: float | None = None,
    ):
        self.time_limit_s, self.memory_limit_mb = check_limits(time_limit_s, memory_limit_mb)
        self.deadline = Deadline(self.time_limit_s, self.memory_limit_mb)
        self._progress = progress
        self.stage: str | None = None
        self.done = 0
        self.total = 0
        self.finished: list[tuple[str, int]] = []

    def check(self) -> None:
        """Raise Timeout once the time limit or the memory limit has passed."""
        self.deadline.check()

    def begin(self, stage: str, total: int) -> None:
        """Start ``stage`` of ``total`` items (the previous stage is finished)."""
        if self.stage is not None:
            self.finished.append((self.stage, self.total))
        self.stage, self.done, self.total = stage, 0, total
        self._report()

    def advance(self, count: int = 1) -> None:
        """``count`` more items of the stage decided."""
        self.done = min(self.total, self.done + count)
        self._report()

    def _report(self) -> None:
        if self._progress is not None and self.stage is not None:
            self._progress(self.stage, self.done, self.total)

    def timeout(self, reason: str = "time", partial: bool = False) -> DesignTimeout:
        """The one-line error of a design stopped at the limit ``reason`` names (``Timeout``'s:
        "time" or "memory"), naming what was decided; ``partial``: for a design given
        without its length table."""
        decided = [f"all {t} {_NOUNS[s]}" for s, t in self.finished]
        if self.stage is not None:
            done = "all" if self.done == self.total > 0 else f"{self.done} of"
            decided.append(f"{done} {self.total} {_NOUNS[self.stage]}")
        if not decided:
            decided = ["nothing yet"]
        what = " and ".join(filter(None, (", ".join(decided[:-1]), decided[-1])))
        memory = self.memory_limit_mb is not None and (
            reason == "memory" or self.time_limit_s is None
        )
        if memory:
            limit = f"the memory limit of {self.memory_limit_mb:g} MB"
        elif self.time_limit_s is not None:
            limit = f"the time limit of {self.time_limit_s:g} s"
        else:
            limit = "its limits"
        tail = "the length table is left out" if partial else "no partial design is given"
        return DesignTimeout(
            f"the sensor design did not finish within {limit} (it decided {what}); {tail}",
            "memory" if memory else "time",
        )

    def plan(self, make: Callable[[PlanningOptions | None], MadePlan]) -> MadePlan:
        """``make(options)`` (a verified plan) within what is left of the limit.

        Unlimited: ``make(None)``, the planner's defaults. Limited: the planner gets the time
        left and the memory limit as its own with its fallback off (its plan, not proven
        optimal, would be discarded after seconds of statistics and verification), so every
        plan it returns is the unlimited design's: proven shortest, its tie-breaks decided
        as far as the planner's work budget (the same on any computer) lets them. A limit
        running out is a Timeout here: :class:`~feederkit.planning.options.OutOfBudget` (the
        planner's exact stages, its goal relation or its lumping cut short; the fallback's
        :class:`~feederkit.planning.fallback.NoFallback` is one), a plan not proven optimal,
        and any PlanningError once the limit has passed. Any other PlanningError (no strong
        plan exists, say) is the design's answer.
        """
        if self.time_limit_s is None and self.memory_limit_mb is None:
            return make(None)
        self.check()
        left = self.deadline.remaining()
        if left is not None and left <= 0.0:
            raise Timeout("time")
        options = PlanningOptions(
            time_limit_s=left, memory_limit_mb=self.memory_limit_mb, fallback=False
        )
        try:
            made = make(options)
        except OutOfBudget as exc:  # a limit, not the problem, ended the planner
            raise Timeout(exc.reason) from None
        except PlanningError:
            ran_out = self.deadline.ran_out()
            if ran_out is not None:
                raise Timeout(ran_out) from None
            raise
        if not made.result.optimal:  # not with the fallback off: a limit must have cut it
            raise Timeout(self.deadline.ran_out() or "time")
        self.check()
        return made


__all__ = [
    "GOALS",
    "LENGTHS",
    "PAIRS",
    "PITCHES",
    "DesignClock",
    "DesignTimeout",
    "Progress",
    "check_limits",
]
