"""Choosing among plans of minimum worst-case length, and building the plan tree.

Issue 3's order among plans of minimum length: the larger smallest margin (the half-width of
an action's overlap range), then the smaller expected number of operations (the
distribution of ``readings``), then smaller rotations (node by node from the root). With
``objective="expected"`` the expected number of operations comes first, over plans of at
most ``EXPECTED_HORIZON`` times the minimum worst-case length, then the larger margin and
the smaller rotation of each action.

All three stages are exact searches over sets with a length budget: ``margin(mask, k)`` is
the largest smallest margin of a plan of at most ``k`` operations (a max-min recursion
memoised per set and budget); ``expected(mask, masses, k)`` the smallest expected number of
operations (memoised per set, normalised masses and budget, with a branch-and-bound cut).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from feederkit.angles import norm360
from feederkit.machine import Branch, members
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.problem import Act, Problem
from feederkit.planning.tree import Leaf, Step

EXPECTED_HORIZON = 2
"""``objective="expected"`` searches plans of at most this many times the minimum length."""

_TIE = 1e-9

Masses = tuple[float, ...]


def child_masses(
    problem: Problem, mask: int, masses: Masses, act: Act | None, branches: tuple[Branch, ...] = ()
) -> list[tuple[Branch, float, Masses]]:
    """For each branch of ``act`` from ``mask``: its probability and its normalised masses.

    A member's mass moves to its successor; a state's mass then splits over the branches by
    the probability of its reading falling in each (``readings``). ``act`` None is the first
    alignment: nothing moves and ``branches`` are the readings.
    """
    moved: dict[int, float] = {}
    targets = members(mask) if act is None else problem.targets(mask, act.action)
    for w, t in zip(masses, targets, strict=True):
        moved[t] = moved.get(t, 0.0) + w
    out = []
    for b in problem.act_branches(act) if act is not None else branches:
        idx = members(b.mask)
        ws = [moved.get(s, 0.0) * problem.probability(b, s) for s in idx]
        total = sum(ws)
        if total > 0.0:
            norm = tuple(w / total for w in ws)
        else:
            norm = tuple(1.0 / len(idx) for _ in idx)
        out.append((b, total, norm))
    return out


def _key(masses: Masses) -> tuple[float, ...]:
    return tuple(round(w, 12) for w in masses)


class Refiner:
    """The tie-breaking stages and the tree builder over one problem."""

    def __init__(self, problem: Problem, worst: WorstCase, deadline: Deadline | None = None) -> None:
        self.p = problem
        self.w = worst
        self.deadline = deadline or Deadline(None)
        self.floor = -math.inf
        self._margin: dict[tuple[int, int], float] = {}
        self._exp: dict[tuple[int, int, tuple[float, ...]], tuple[float, Act | None]] = {}

    def feasible(self, act: Act, k: int) -> bool:
        """Whether every branch of ``act`` can be oriented in ``k`` more operations."""
        return all(self.w.within(c, k) for c in act.children)

    def allowed(self, act: Act, k: int) -> bool:
        """Whether a plan of at most ``k`` operations keeping margin ``floor`` can start with ``act``."""
        if act.action.margin < self.floor or not self.feasible(act, k - 1):
            return False
        if self.floor == -math.inf:
            return True
        return all(self.margin(c, k - 1) >= self.floor for c in act.children)

    def margin(self, mask: int, k: int) -> float:
        """Largest smallest margin over plans orienting ``mask`` in at most ``k`` operations."""
        if self.p.is_goal(mask):
            return math.inf
        if k <= 0:
            return -math.inf
        key = (mask, k)
        v = self._margin.get(key)
        if v is not None:
            return v
        self.deadline.check()
        best = -math.inf
        if self.p.sensorless:
            # One branch per action: walk the ranges widest first, no branch objects needed.
            for lo, hi, img in self.p.cells(mask):
                m = (hi - lo) / 2.0
                if m <= best:
                    break
                if self.w.within(img, k - 1):
                    best = max(best, min(m, self.margin(img, k - 1)))
            self._margin[key] = best
            return best
        for act in sorted(self.p.actions(mask), key=lambda a: -a.action.margin):
            m = act.action.margin
            if m <= best:
                break
            if not self.feasible(act, k - 1):
                continue
            val = m
            for c in act.children:
                val = min(val, self.margin(c, k - 1))
                if val <= best:
                    break
            best = max(best, val)
        self._margin[key] = best
        return best

    def expected(self, mask: int, masses: Masses, k: int) -> tuple[float, Act | None]:
        """Smallest expected number of further operations (per unit mass) within ``k``, and the action."""
        if self.p.is_goal(mask):
            return 0.0, None
        key = (mask, k, _key(masses) if len(masses) > 1 else ())
        hit = self._exp.get(key)
        if hit is not None:
            return hit
        self.deadline.check()
        best, best_act = math.inf, None
        options = []
        for act in self.p.actions(mask):
            if not self.allowed(act, k):
                continue
            kids = child_masses(self.p, mask, masses, act)
            bound = 1.0 + sum(pb for b, pb, _ in kids if not self.p.is_goal(b.mask))
            options.append((bound, act.rotation, act, kids))
        options.sort(key=lambda o: (o[0], o[1]))
        for bound, _rot, act, kids in options:
            if bound > best + _TIE:
                break
            val = 1.0
            for b, pb, ms in kids:
                if pb > 0.0:
                    val += pb * self.expected(b.mask, ms, k - 1)[0]
                if val > best + _TIE:
                    break
            if val < best - _TIE or (val <= best + _TIE and _prefer(act, best_act)):
                best, best_act = min(val, best), act
        out = (best, best_act)
        self._exp[key] = out
        return out

    def choose_worst(self, mask: int, masses: Masses, k: int, tie: str) -> Act:
        """The action of a plan within ``k``: ``tie`` is ``"expected"``, ``"rotation"`` or ``"first"``.

        ``"first"`` takes the first allowed action in the problem's order (no tie-breaking).
        """
        if tie == "first":
            for act in self.p.actions(mask):
                if self.allowed(act, k):
                    return act
            raise AssertionError("no feasible action within the proven length")
        if tie == "expected":
            act = self.expected(mask, masses, k)[1]
            assert act is not None
            return act
        for cell in sorted(self.p.cells(mask), key=lambda c: norm360((c[0] + c[1]) / 2.0)):
            if (cell[1] - cell[0]) / 2.0 < self.floor:
                continue
            act = self.p.act(mask, cell)
            if act is not None and self.allowed(act, k):
                return act
        raise AssertionError("no feasible action within the proven length")

    def build(self, mask: int, masses: Masses, k: int, chooser: Callable[[int, Masses, int], Act]) -> Step | Leaf:
        """The subtree orienting ``mask`` in at most ``k`` operations, actions from ``chooser``."""
        if self.p.is_goal(mask):
            return Leaf(mask)
        act = chooser(mask, masses, k)
        subs = []
        for b, _pb, ms in child_masses(self.p, mask, masses, act):
            subs.append((b, self.build(b.mask, ms, k - 1, chooser)))
        return Step(act.action, tuple(subs))


def _prefer(a: Act, b: Act | None) -> bool:
    """Between equally good actions: larger margin, then the smaller rotation."""
    if b is None:
        return True
    if a.action.margin != b.action.margin:
        return a.action.margin > b.action.margin
    return a.rotation < b.rotation
