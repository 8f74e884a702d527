"""The largest margin any plan can keep (section 3.2.2: a minimum size for overlap ranges).

With a margin floor some sets may have no plan at all. ``largest_margin`` finds the largest
``t`` such that every root set can be oriented using only actions of margin at least ``t``:
the bottleneck value of the AND/OR graph over sets. It inserts actions in decreasing
margin order (sets are discovered as they become reachable, so an action found later may be
wider than one inserted before), and marks a set solved as soon as one inserted action has
all its branch sets solved; the smallest margin inserted when the last root is solved is
the answer. Only actions of margin at least the answer are ever inserted.
"""

from __future__ import annotations

import heapq
import itertools
import math

from feederkit.planning.andor import Deadline
from feederkit.planning.problem import Problem


def largest_margin(problem: Problem, roots: list[int], deadline: Deadline | None = None) -> float:
    """Largest ``t`` with a plan for every root using only actions of margin >= ``t``.

    inf when no root needs an action; -inf when some root has no plan at all.

    ``problem`` should have no margin floor of its own.
    """
    deadline = deadline or Deadline(None)
    solved: set[int] = set()
    pending: dict[int, list[list]] = {}  # child -> edges waiting on it
    seen: set[int] = set()
    heap: list[tuple[float, int, int, tuple[int, ...]]] = []
    tick = itertools.count()
    open_roots = {r for r in roots if not problem.is_goal(r)}
    if not open_roots:
        return math.inf

    def discover(mask: int) -> None:
        if mask in seen:
            return
        # A set's exact actions are the work here: polled per set (a 50-part mix has
        # hundreds of roots, each tens of milliseconds).
        deadline.check()
        seen.add(mask)
        if problem.is_goal(mask):
            solved.add(mask)
            return
        for act in problem.choices.exact_actions(mask, deadline.limits):
            heapq.heappush(heap, (-act.action.margin, next(tick), mask, act.children))

    for r in open_roots:
        discover(r)
    floor = math.inf  # the smallest margin inserted so far
    while heap:
        deadline.check()
        neg, _, mask, children = heapq.heappop(heap)
        floor = min(floor, -neg)
        if mask in solved:
            continue
        for c in children:
            discover(c)
        waiting = [c for c in set(children) if c not in solved]
        if waiting:
            edge = [mask, len(waiting)]
            for c in waiting:
                pending.setdefault(c, []).append(edge)
            continue
        stack = [mask]
        while stack:
            s = stack.pop()
            if s in solved:
                continue
            solved.add(s)
            open_roots.discard(s)
            for edge in pending.pop(s, ()):
                edge[1] -= 1
                if edge[1] == 0 and edge[0] not in solved:
                    stack.append(edge[0])
        if not open_roots:
            return floor
    return -math.inf
