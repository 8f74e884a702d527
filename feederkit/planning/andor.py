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

from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.problem import Act, Problem

__all__ = ["Deadline", "Timeout", "WorstCase"]


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

    def _known(self, mask: int, k: int) -> bool | None:
        """What the memo already says about ``within(mask, k)`` (None: search)."""
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
        return None

    def within(self, mask: int, k: int) -> bool:
        """Whether ``mask`` can be oriented in at most ``k`` operations.

        A depth-first AND/OR search kept on an explicit stack (a frame per open set: its
        budget, its action iterator, the action being tried and its next child), so a deep
        budget never meets Python's recursion limit.
        """
        known = self._known(mask, k)
        if known is not None:
            return known
        self.deadline.check()
        # frame: [mask, k, actions, act or None, index of the next child]
        stack: list[list] = [[mask, k, self.p.choices.search_actions(mask), None, 0]]
        result = False
        while stack:
            f = stack[-1]
            fmask, fk, acts, act, ci = f
            pushed = False
            while True:
                if act is None:
                    act = next(acts, None)
                    if act is None:
                        break  # every action failed
                    ci = 0
                children = act.children  # largest first: the likeliest to fail
                while ci < len(children):
                    c = children[ci]
                    known = self._known(c, fk - 1)
                    if known is None:
                        f[3], f[4] = act, ci
                        self.deadline.check()
                        stack.append([c, fk - 1, self.p.choices.search_actions(c), None, 0])
                        pushed = True
                        break
                    if not known:
                        break
                    ci += 1
                if pushed:
                    break
                if ci == len(children):
                    break  # every child within fk - 1: act works
                act = None  # a child failed: the next action
            if pushed:
                continue
            stack.pop()
            if act is not None:
                self.ub[fmask] = fk
                if fmask not in self.choice or self.choice[fmask][0] > fk:
                    self.choice[fmask] = (fk, act)
                result = True
            else:
                self.lb[fmask] = fk + 1
                result = False
            if stack:
                parent = stack[-1]
                if result:
                    parent[4] += 1  # that child is within: the parent's next child
                else:
                    parent[3] = None  # the parent's action failed: its next action
        return result

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
