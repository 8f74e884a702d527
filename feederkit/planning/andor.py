"""Minimum worst-case plan length by AND/OR search over sets of states (section 6.1).

A node is a set of states; an OR choice is a representative action; its AND children are the
sets the reading can leave. ``length(mask)`` is the smallest number of further push-align
operations that orient every state of ``mask`` (0 for a goal). The search is depth-first
iterative deepening with memoised proven bounds per set (a set that failed with ``k`` steps
is never retried with ``k``), so repeated sets and repeated depths cost nothing.

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 6.1 (AND/OR search).
"""

from __future__ import annotations

import time

from feederkit.planning.problem import Act, Problem


class Timeout(Exception):
    """The search ran out of its time limit."""


class Deadline:
    """A wall-clock limit checked every few search nodes."""

    def __init__(self, seconds: float | None) -> None:
        self.end = None if seconds is None else time.perf_counter() + seconds
        self._count = 0

    def check(self) -> None:
        """Raise Timeout once the limit has passed."""
        if self.end is None:
            return
        self._count += 1
        if self._count & 7 == 0 and time.perf_counter() > self.end:
            raise Timeout


class WorstCase:
    """Exact minimum worst-case lengths of sets, memoised.

    ``lb`` and ``ub`` are proven bounds per set; ``choice`` keeps, per set, the action that
    first proved the smallest bound (with that bound), so some plan can always be rebuilt.
    """

    def __init__(self, problem: Problem, deadline: Deadline | None = None) -> None:
        self.p = problem
        self.lb: dict[int, int] = {}
        self.ub: dict[int, int] = {}
        self.choice: dict[int, tuple[int, Act]] = {}
        self.exact: dict[int, int] = {}
        self.deadline = deadline or Deadline(None)

    def within(self, mask: int, k: int) -> bool:
        """Whether ``mask`` can be oriented in at most ``k`` operations."""
        if self.p.is_goal(mask):
            return True
        if k <= 0:
            return False
        e = self.exact.get(mask)
        if e is not None:
            return e <= k
        if self.lb.get(mask, 1) > k:
            return False
        if self.ub.get(mask, k + 1) <= k:
            return True
        self.deadline.check()
        for act in self.p.choices.search_actions(mask):
            ok = True
            for c in act.children:  # largest first: the likeliest to fail
                if not self.within(c, k - 1):
                    ok = False
                    break
            if ok:
                self.ub[mask] = k
                if mask not in self.choice or self.choice[mask][0] > k:
                    self.choice[mask] = (k, act)
                return True
        self.lb[mask] = k + 1
        return False

    def length(self, mask: int, limit: int | None = None) -> int:
        """The minimum worst-case number of operations for ``mask`` (iterative deepening).

        Raises ValueError when ``limit`` is given and exceeded.
        """
        if self.p.is_goal(mask):
            return 0
        e = self.exact.get(mask)
        if e is not None:
            return e
        k = self.lb.get(mask, 1)
        while not self.within(mask, k):
            k += 1
            if limit is not None and k > limit:
                raise ValueError(f"no plan within {limit} operations")
        self.exact[mask] = k
        return k
