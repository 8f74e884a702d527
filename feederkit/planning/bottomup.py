"""The bottom-to-top algorithm (section 6.4): a dynamic programme over all sets by size.

Every set a plan can meet is a subset of one of the root's reading sets (a reading names at
most the states that can give it). The programme finds the best action of every such subset,
smallest sets first; an action whose branches are all smaller is final at once, and the
paper's "second pass" for branches of the same size is a relaxation repeated until no value
changes. Exponential in the size of the largest reading set (``MAX_SUBSETS`` guards it).

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 6.4 (the bottom-to-top algorithm).
"""

from __future__ import annotations

import math
from itertools import combinations

from feederkit.errors import InputError
from feederkit.machine import members
from feederkit.planning.andor import Deadline
from feederkit.planning.problem import Problem

MAX_SUBSETS = 1 << 20
"""The most subsets the bottom-to-top algorithm will enumerate."""


def bottom_up_lengths(
    problem: Problem, roots: list[int], deadline: Deadline | None = None
) -> dict[int, int]:
    """Minimum worst-case number of operations of each root set, by the bottom-to-top algorithm."""
    deadline = deadline or Deadline(None)
    total = sum(1 << r.bit_count() for r in roots)
    if total > MAX_SUBSETS:
        raise InputError(
            f"the bottom-to-top algorithm would enumerate {total} sets (limit {MAX_SUBSETS}); "
            "use the AND/OR search"
        )
    levels: dict[int, set[int]] = {}
    for r in roots:
        idx = members(r)
        for size in range(1, len(idx) + 1):
            deadline.check()  # up to MAX_SUBSETS sets are listed before any search
            lev = levels.setdefault(size, set())
            for combo in combinations(idx, size):
                m = 0
                for i in combo:
                    m |= 1 << i
                lev.add(m)
    value: dict[int, float] = {}
    for size in sorted(levels):
        todo = []
        for s in levels[size]:
            if problem.is_goal(s):
                value[s] = 0
            else:
                value[s] = math.inf
                todo.append(s)
        changed = True
        while changed:
            changed = False
            for s in todo:
                deadline.check()
                best = value[s]
                for act in problem.choices.search_actions(s, deadline.limits):
                    v = 1 + max(value.get(c, math.inf) for c in act.children)
                    if v < best:
                        best = v
                if best < value[s]:
                    value[s] = best
                    changed = True
    out = {}
    for r in roots:
        v = value[r]
        if v == math.inf:
            raise ValueError("a reading set cannot be oriented")
        out[r] = int(v)
    return out
