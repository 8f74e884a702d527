"""The one budget a plan is computed under: a wall-clock deadline and a memory limit.

``plan`` makes a :class:`Deadline` on its first line, from ``PlanningOptions.time_limit_s``
and ``memory_limit_mb``; every stage that can run long (the inseparability fixpoint, the
exact searches, the tie-breaking stages, the fallbacks) polls it with :meth:`Deadline.check`
and stops with :class:`Timeout` when either limit is passed. Stages get shares of one budget
(:meth:`Deadline.until`), so the clock started before the first of them holds for the last
(docs/planning.md, "Time and memory limits").

The check is cheap: a clock read per call (well under a microsecond; a search node costs
tens of microseconds or more, so reading it less often only lets a stage of expensive nodes
overrun) and the resident set size (``/proc/self/statm``, one small read) at most every
:data:`MEMORY_POLL_S` seconds.
"""

from __future__ import annotations

import gc
import os
import resource
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

MEMORY_POLL_S = 0.02
"""``check`` reads the resident set size at most this often (seconds)."""

RELEASE_S_PER_MB = 0.001
"""Seconds a deadline keeps in hand per MB the process grew under it: letting go of a
search's tables (millions of small objects, freed one by one by reference counting once
the search stops) takes time after the last poll. The 50-part mix at 5 % under 1 degree
with a 60 s limit grew by about 2 GB, and 2.4 s passed between the searches' Timeout and
the answer (0.9 s of it in the lumping stage's return, 1.5 s unwinding the planner); a
dictionary of 6 million tuples (1.9 GB) takes 0.4 CPU s to free."""

SLOWNESS_MIN_S = 0.25
"""A budget measures its :meth:`Deadline.slowness` once this many wall seconds have passed
(before that it is 1: too little to tell)."""

SLOWNESS_MAX = 4.0
"""The largest :meth:`Deadline.slowness` a budget counts (a process that waited rather than
computed would otherwise keep most of its limit back)."""

_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


def rss_mb() -> float:
    """The process's resident set size in MB (its peak where ``/proc`` is missing)."""
    try:
        with open("/proc/self/statm", "rb") as f:
            return int(f.read().split()[1]) * _PAGE / 1e6
    except (OSError, ValueError, IndexError):
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / 1e3  # kilobytes on Linux


class Timeout(Exception):
    """A search ran out of its budget; ``reason`` is ``"time"``, ``"memory"`` or ``"work"``
    (a :class:`WorkBudget`'s polls)."""

    def __init__(self, reason: str = "time") -> None:
        super().__init__(reason)
        self.reason = reason


class Deadline:
    """A wall-clock deadline and a memory limit, either None (no limit).

    ``seconds`` counts from now, or ``end`` gives the :func:`time.perf_counter` instant
    itself (shares of one budget keep its start). ``memory_base`` is what the process held
    when the budget began (read now unless given): shares of the memory are shares of the
    growth from it to the limit. ``per_pair_s`` is what the caller needs after the planner
    per (node, state) pair of the plan it is handed, a state that can reach a node
    (verifying the plan walks each pair once; writing it grows with them): a planner that
    makes nodes says how many pairs (:meth:`commit`) and its deadline comes that much
    earlier, so a large plan leaves time for its own verification and file; that cost is
    measured idle, so it is scaled by the budget's :meth:`slowness`. ``clock_start`` is the
    (wall, CPU) instant the slowness counts from (now unless given: shares keep it).
    ``reserve_s`` is what the caller keeps after the end for work it may cut (a plan's
    certificate): a first plan's verification may take it instead (a plan whose certificate
    is cut beats none); shares keep it.
    """

    def __init__(
        self,
        seconds: float | None = None,
        memory_mb: float | None = None,
        *,
        end: float | None = None,
        start: float | None = None,
        memory_base: float | None = None,
        per_pair_s: float = 0.0,
        grace_s: float = 0.0,
        clock_start: tuple[float, float] | None = None,
        reserve_s: float = 0.0,
    ) -> None:
        now = time.perf_counter()
        self.clock_start = (now, time.process_time()) if clock_start is None else clock_start
        self.per_pair_s = per_pair_s
        self.grace_s = grace_s
        self.reserve_s = reserve_s
        self.start = now if start is None else start
        self.end = end if end is not None or seconds is None else now + seconds
        self.memory_mb = memory_mb
        self.memory_base = memory_base
        if memory_base is None and memory_mb is not None:
            self.memory_base = min(rss_mb(), memory_mb)
        elif memory_base is None and self.end is not None:
            self.memory_base = rss_mb()
        self._release_s = 0.0  # RELEASE_S_PER_MB of the growth at the last memory read
        self._next_memory = now
        self._limited = self.end is not None or memory_mb is not None
        self.polls = 0  # how often check() was called: the work done under this budget

    @property
    def limited(self) -> bool:
        """Whether any limit is set."""
        return self._limited

    def check(self) -> None:
        """Raise Timeout once the deadline (less the time to let go of what the process
        grew by, :data:`RELEASE_S_PER_MB`) or the memory limit has passed."""
        self.polls += 1
        if not self._limited:
            return
        now = time.perf_counter()
        if now >= self._next_memory and self.memory_base is not None:
            self._next_memory = now + MEMORY_POLL_S
            rss = rss_mb()
            self._release_s = RELEASE_S_PER_MB * max(0.0, rss - self.memory_base)
            if self.memory_mb is not None and rss > self.memory_mb:
                raise Timeout("memory")
        if self.end is not None and now > self.end - self._release_s:
            raise Timeout("time")

    def limits(self) -> None:
        """:meth:`check` not counted as a poll (nor against a work budget's allowance): for
        polls inside work a stage already counts once (a set's actions made one at a time,
        only when first asked), so the counts that size the tie-breaking stages' work do not
        depend on what a cache already holds.

        >>> budget = WorkBudget(Deadline(), 1)
        >>> budget.limits(); budget.limits(); budget.check()
        >>> budget.polls
        1
        """
        self.polls -= 1
        self.check()

    def expired(self) -> bool:
        """Whether a limit has passed (reads the clock and the memory now)."""
        return self.ran_out() is not None

    def ran_out(self) -> str | None:
        """Which limit has passed, as a Timeout names it (``"memory"``, else ``"time"``;
        reads the clock and the memory now), None when neither has."""
        self._next_memory = 0.0
        try:
            self.check()
        except Timeout as exc:
            return exc.reason
        return None

    def slowness(self) -> float:
        """Wall seconds per CPU second of this process since the budget began, between 1 and
        :data:`SLOWNESS_MAX` (1 in its first :data:`SLOWNESS_MIN_S`): on a loaded machine the
        work after the planner, whose cost per pair was measured idle, takes that much
        longer (two busy processes beside a plan on two cores make it about 1.5).

        >>> Deadline().slowness()
        1.0
        """
        wall0, cpu0 = self.clock_start
        wall = time.perf_counter() - wall0
        if wall < SLOWNESS_MIN_S:
            return 1.0
        cpu = time.process_time() - cpu0
        return min(SLOWNESS_MAX, max(1.0, wall / max(cpu, 1e-9)))

    def commit(self, pairs: int, stop: bool = True) -> None:
        """A planner has made plan nodes with ``pairs`` more (node, state) pairs (fewer when
        negative: a plan it no longer holds): the deadline moves ``per_pair_s`` times the
        :meth:`slowness` earlier for each (nothing without a deadline or a cost), past the
        first ``grace_s`` seconds of them. With ``stop``, Timeout is raised when that end has
        passed (a tree's last nodes need no poll after them to stop it); without, the end
        only moves (a plan already made and kept)."""
        if self.end is not None and self.per_pair_s:
            cost = self.seconds_for(pairs)
            if cost > 0.0 and self.grace_s > 0.0:
                free = min(cost, self.grace_s)
                self.grace_s -= free
                cost -= free
            self.end -= cost
            if stop and pairs > 0 and time.perf_counter() > self.end - self._release_s:
                raise Timeout("time")

    def seconds_for(self, pairs: int) -> float:
        """What the caller needs after the planner for a plan of ``pairs`` (node, state) pairs:
        ``per_pair_s`` each, scaled by the :meth:`slowness` (0 without a cost)."""
        return pairs * self.per_pair_s * self.slowness() if self.per_pair_s else 0.0

    def credit(self, seconds: float) -> None:
        """The deadline moves ``seconds`` later (earlier when negative): time the caller
        gives back, such as the part of its ``reserve_s`` a held plan's verification takes."""
        if self.end is not None:
            self.end += seconds

    def with_grace(self, seconds: float) -> Deadline:
        """A copy of this budget whose first ``seconds`` of committed pairs are free: a plan
        built under it may be verified that much past the end (:meth:`commit`)."""
        out = self.ending(None)
        out.grace_s = seconds
        return out

    def remaining(self) -> float | None:
        """Seconds left (never negative; None: no deadline)."""
        if self.end is None:
            return None
        return max(0.0, self.end - self._release_s - time.perf_counter())

    def until(self, time_share: float, memory_share: float = 1.0) -> Deadline:
        """A budget for one stage: ending ``time_share`` of the way from this budget's start
        to its end, and letting the process grow ``memory_share`` of the way from what it
        held at the start to the memory limit."""
        end = None if self.end is None else self.start + time_share * (self.end - self.start)
        memory = base = None
        if self.memory_mb is not None and self.memory_base is not None:
            base = self.memory_base
            memory = base + memory_share * (self.memory_mb - base)
        return Deadline(
            memory_mb=memory,
            end=end,
            start=self.start,
            memory_base=base,
            per_pair_s=self.per_pair_s,
            clock_start=self.clock_start,
            reserve_s=self.reserve_s,
        )

    def share_from_now(self, time_share: float) -> Deadline:
        """A budget for one stage that starts now: ending ``time_share`` of the whole limit
        from now (never past this budget's end), this budget's memory limit. A stage that a
        slow one before it must not starve (:meth:`until` counts from the start).

        >>> b = Deadline(10.0)
        >>> 0.0 < b.share_from_now(0.1).end - time.perf_counter() <= 1.0
        True
        >>> Deadline().share_from_now(0.1).end is None
        True
        """
        if self.end is None:
            return self.ending(None)
        return self.ending(
            min(self.end, time.perf_counter() + time_share * (self.end - self.start))
        )

    def ending(self, end: float | None) -> Deadline:
        """This budget's memory limit with the deadline ``end`` (a :func:`time.perf_counter`
        instant; None keeps this one's): a stage that must stop early."""
        return Deadline(
            memory_mb=self.memory_mb,
            end=self.end if end is None else end,
            start=self.start,
            memory_base=self.memory_base,
            per_pair_s=self.per_pair_s,
            clock_start=self.clock_start,
            reserve_s=self.reserve_s,
        )


class Checkpoint(Deadline):
    """``outer``'s limits, ending at ``first`` (a :func:`time.perf_counter` instant) unless
    ``on_course()``, asked once when ``first`` passes, says True: then at ``end``.

    A stage that may not finish in its share gives the rest of it back early: the exact
    search of ``plan`` stops at ``first`` when it is not on course to finish by ``end``,
    and the fallback gets the time. ``on_course`` may be set after the budget is made
    (None when ``first`` passes: on course, nothing is judged yet); :meth:`go_on` moves the
    end to ``end`` at once (the stage is past what ``on_course`` judges). ``handed_over``
    tells whether it stopped at ``first``.

    >>> now = time.perf_counter()
    >>> budget = Checkpoint(Deadline(), now - 1.0, now + 60.0)
    >>> budget.on_course = lambda: False
    >>> budget.check()
    Traceback (most recent call last):
    ...
    feederkit.planning.budget.Timeout: time
    >>> budget.handed_over
    True
    """

    def __init__(
        self,
        outer: Deadline,
        first: float,
        end: float | None,
        on_course: Callable[[], bool] | None = None,
    ) -> None:
        super().__init__(
            memory_mb=outer.memory_mb,
            end=first,
            start=outer.start,
            memory_base=outer.memory_base,
            per_pair_s=outer.per_pair_s,
            clock_start=outer.clock_start,
            reserve_s=outer.reserve_s,
        )
        self.later = end
        self.on_course = on_course
        self.handed_over = False

    def commit(self, pairs: int, stop: bool = True) -> None:
        """:meth:`Deadline.commit` for both ends; a passed end is left to :meth:`check`,
        which asks whether the stage is on course (``stop`` has no effect here)."""
        self.credit(-self.seconds_for(pairs))

    def credit(self, seconds: float) -> None:
        """:meth:`Deadline.credit` for both ends."""
        if self.end is not None:
            self.end += seconds
        if self.later is not None:
            self.later += seconds

    def go_on(self) -> None:
        """The end is ``end`` from now on (no question asked at ``first``)."""
        if self.later is not None:
            self.end, self.later = self.later, None

    def check(self) -> None:
        """Raise Timeout past the deadline (``first``, or ``end`` once on course) or the
        memory limit."""
        try:
            super().check()
        except Timeout as exc:
            if exc.reason != "time" or self.later is None:
                raise
            if self.on_course is not None and not self.on_course():
                self.later = None
                self.handed_over = True
                raise
            self.go_on()
            self.polls -= 1  # one poll, checked again against the later end
            super().check()


class WorkBudget(Deadline):
    """``outer``'s limits and at most ``polls`` more polls of this budget.

    A budget of work rather than of time: the searches poll once per node they expand, so
    the same input stops at the same node on any machine and under any load, and gives the
    same plan (the tie-breaking stages of ``plan``, docs/planning.md, "Which plan among the
    shortest"). ``outer``'s wall-clock deadline and memory limit still hold.

    >>> budget = WorkBudget(Deadline(), 2)
    >>> budget.check(); budget.check()
    >>> budget.check()
    Traceback (most recent call last):
    ...
    feederkit.planning.budget.Timeout: work
    """

    def __init__(self, outer: Deadline, polls: float) -> None:
        super().__init__(
            memory_mb=outer.memory_mb,
            end=outer.end,
            start=outer.start,
            memory_base=outer.memory_base,
            per_pair_s=outer.per_pair_s,
            clock_start=outer.clock_start,
            reserve_s=outer.reserve_s,
        )
        self.allowance = polls

    @property
    def limited(self) -> bool:
        """Always: the allowance of polls is a limit."""
        return True

    def check(self) -> None:
        """Raise Timeout past the allowance of polls (``"work"``) or one of ``outer``'s
        limits."""
        super().check()
        if self.polls > self.allowance:
            raise Timeout("work")


UNLIMITED = Deadline()
"""A budget with no limit (its checks return at once)."""


@contextmanager
def collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off for the block, as it was after it.

    A search builds tables of millions of small objects (memoised bounds, sets, actions)
    that hold no reference cycles, so reference counting frees them; but every full
    collection rescans all of them, and those come more often the more there are: on a
    50-part mix under a 25 s limit the collector took 11 of 29 seconds. The memory budget
    still polls the process's size, so cyclic garbage left for later is counted.

    When the block ends, what it made and still holds (a plan of 50,000 nodes and its file)
    is frozen (``gc.freeze``) before the collector resumes: else the first collection after
    it scans all of it at once (4 s after a large mix's plan). Frozen objects are freed by
    reference counting as ever; only cyclic garbage among them would stay, and the planners
    make none (tests/test_deadline.py).
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.freeze()
            gc.enable()
