"""A lower bound on a set's length from a few of its states: the hardest subset found.

A plan that orients a set orients every subset of it (a subset's outcomes and readings lie
inside the set's: section 6.1, and under uncertainty the outcome sets of each member), so
the minimum worst-case length of any subset bounds the set's from below. The hardest pair
is the cheapest such bound (``WorstCase.pair_bound``); a handful of states that are pairwise
hard to tell apart is often much harder than any pair, and still a small set whose exact
length the AND/OR search proves in a fraction of the time the whole set would take.

:meth:`SubsetBound.bound` grows such a subset from the set's hardest pair, one state at a
time: the few states hardest to tell apart from those already in (by the pairs' lengths)
are tried, and the one whose subset needs the most operations is kept.
"""

from __future__ import annotations

import contextlib

from feederkit.machine import members
from feederkit.planning.andor import WorstCase
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.problem import Problem

MAX_STATES = 8
"""Subsets grow to at most this many states (their exact lengths stay cheap)."""

CANDIDATES = 3
"""States tried per growth step: those hardest to tell apart from the subset so far."""


class SubsetBound:
    """Lengths of small sets and of pairs up to ``cap`` (``cap + 1``: longer, or no plan),
    memoised, under one ``deadline`` (Timeout).

    ``bound(mask, goal)`` grows a subset of ``mask`` until it needs more than ``goal``
    operations or has ``MAX_STATES`` states, and returns the largest length it proved.
    """

    def __init__(self, problem: Problem, deadline: Deadline, cap: int) -> None:
        self.p = problem
        self.cap = cap
        # No pair bound inside: the pairs are ours.
        self.search = WorstCase(problem, deadline, pair_bound=False)
        self._pair: dict[tuple[int, int], int] = {}

    def length(self, mask: int) -> int:
        """The length of ``mask`` when it is at most ``cap``, else ``cap + 1`` (a lower bound:
        no plan, or none that short)."""
        try:
            return self.search.length(mask, self.cap)
        except ValueError:
            return self.cap + 1

    def pair(self, i: int, j: int) -> int:
        """:meth:`length` of the pair of states ``i < j`` (0 when inseparable)."""
        v = self._pair.get((i, j))
        if v is None:
            v = self._pair[(i, j)] = self.length((1 << i) | (1 << j))
        return v

    def bound(self, mask: int, goal: int) -> int:
        """A proven lower bound on the length of ``mask``: the length of a subset of it, grown
        from its hardest pair until that length exceeds ``goal`` or the subset has
        ``MAX_STATES`` states."""
        idx = members(mask)
        if len(idx) < 2:
            return 0
        best, a, b = max((self.pair(a, b), a, b) for x, a in enumerate(idx) for b in idx[x + 1 :])
        sub = (1 << a) | (1 << b)
        inside = [a, b]
        while best <= goal and len(inside) < min(MAX_STATES, len(idx)):
            rest = [x for x in idx if not sub >> x & 1]
            rest.sort(key=lambda x: -sum(self.pair(min(x, y), max(x, y)) for y in inside))
            tried = []
            for x in rest[:CANDIDATES]:
                grown = sub | 1 << x
                # A superset needs at least as many operations: its search starts there.
                self.search.lb[grown] = max(self.search.lb.get(grown, 1), best)
                tried.append((self.length(grown), x))
            best, x = max(tried)
            sub |= 1 << x
            inside.append(x)
        return best


def subset_lower_bound(
    problem: Problem, roots: list[int], proven: int, deadline: Deadline, goal: int
) -> int:
    """The largest root length proven by subsets (:class:`SubsetBound`), at least ``proven``
    (a bound already proven on the largest), stopping once it reaches ``goal`` (the length
    of a plan in hand) or ``deadline`` passes (what was proven by then).

    The roots are tried largest first: the hardest subsets hide in the largest sets.
    """
    best = proven
    if best >= goal:
        return best
    bounds = SubsetBound(problem, deadline, goal)
    with contextlib.suppress(Timeout):
        for r in sorted(roots, key=lambda m: -m.bit_count()):
            if best >= goal:
                break
            if not problem.is_goal(r):
                best = max(best, bounds.bound(r, best))
    return best
