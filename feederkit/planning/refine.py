"""Choosing among plans of minimum worst-case length, and building the plan tree.

The order among plans of minimum length (docs/planning.md): the larger smallest margin
(the half-width of an action's overlap range), then the smaller expected number of
operations (the distribution of ``readings``), then smaller rotations (node by node from
the root). With
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
from feederkit.machine import OverlapRange, ReadingBranch, members
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.choices import spread
from feederkit.planning.problem import Act, Problem
from feederkit.planning.tree import Leaf, Step

EXPECTED_HORIZON = 2
"""``objective="expected"`` searches plans of at most this many times the minimum length."""

_TIE = 1e-9

Masses = tuple[float, ...]


def child_masses(
    problem: Problem,
    mask: int,
    masses: Masses,
    act: Act | None,
    branches: tuple[ReadingBranch, ...] = (),
) -> list[tuple[ReadingBranch, float, Masses]]:
    """For each branch of ``act`` from ``mask``: its probability and its normalised masses.

    A member's mass moves to its successor; a state's mass then splits over the branches by
    the probability of its reading falling in each (``readings``). ``act`` None is the first
    alignment: nothing moves and ``branches`` are the readings.
    """
    if act is None:
        moved = dict(zip(members(mask), masses, strict=True))
    else:
        moved = spread(masses, problem.choices.targets(mask, act.action))
    out = []
    if act is None:
        table = [
            (b, members(b.mask), [problem.readings.probability(b, s) for s in members(b.mask)])
            for b in branches
        ]
    else:
        table = problem.readings.branch_table(act.action.image)
    for b, idx, probs in table:
        ws = [moved.get(s, 0.0) * p for s, p in zip(idx, probs, strict=True)]
        total = sum(ws)
        norm = tuple(w / total if total > 0.0 else 1.0 / len(idx) for w in ws)
        out.append((b, total, norm))
    return out


def _key(masses: Masses) -> tuple[float, ...]:
    return tuple(round(w, 12) for w in masses)


class Refiner:
    """The tie-breaking stages and the tree builder over one problem."""

    def __init__(
        self, problem: Problem, worst: WorstCase, deadline: Deadline | None = None
    ) -> None:
        self.p = problem
        self.w = worst
        self.deadline = deadline or Deadline(None)
        self.floor = -math.inf
        self._margin: dict[tuple[int, int], tuple[float, bool]] = {}
        self._exp: dict[tuple[int, int, tuple[float, ...]], tuple[float, Act | None]] = {}

    def feasible(self, act: Act, k: int) -> bool:
        """Whether every branch of ``act`` can be oriented in ``k`` more operations.

        Without a margin floor lengths are monotone under subsets, so the maximal branches
        decide.
        """
        if self.p.min_margin == 0.0 and not self.p.sensorless:
            return all(self.w.within(c, k) for c in self.p.readings.children(act.action.image))
        return all(self.w.within(c, k) for c in act.children)

    def allowed(self, act: Act, k: int) -> bool:
        """Whether a plan of at most ``k`` operations keeping ``floor`` can start with ``act``."""
        if act.action.margin < self.floor or not self.feasible(act, k - 1):
            return False
        if self.floor == -math.inf:
            return True
        return all(self.margin(c, k - 1, self.floor) >= self.floor for c in act.children)

    def margin(self, mask: int, k: int, cap: float = math.inf) -> float:
        """``min(cap, g)``: g the largest smallest margin of plans for ``mask`` within ``k``.

        A cap stops the search as soon as some plan keeps it (the callers only ask whether a
        margin can be kept); memo entries remember whether they are exact or lower bounds.
        """
        if self.p.is_goal(mask):
            return cap
        if k <= 0:
            return -math.inf
        key = (mask, k)
        hit = self._margin.get(key)
        if hit is not None:
            v, exact = hit
            if exact or v >= cap:
                return min(v, cap)
        self.deadline.check()
        best = -math.inf
        if self.p.sensorless:
            # One branch per action: walk the ranges widest first, no branch objects needed.
            for lo, hi, img in self.p.choices.cells(mask, useful=False):
                m = (hi - lo) / 2.0
                if m <= best or best >= cap:
                    break
                if self.w.within(img, k - 1):
                    best = max(best, self.margin(img, k - 1, min(m, cap)))
        else:
            for cell in self.p.choices.cells(mask, useful=False):  # widest first
                m = (cell[1] - cell[0]) / 2.0
                if m <= best or best >= cap:
                    break
                act = self.p.choices.act(mask, cell, exact=True)
                if not self.feasible(act, k - 1):
                    continue
                val = min(m, cap)
                for c in act.children:
                    val = self.margin(c, k - 1, val)
                    if val <= best:
                        break
                best = max(best, val)
        best = min(best, cap)
        self._margin[key] = (best, best < cap)
        return best

    def expected(self, mask: int, masses: Masses, k: int) -> tuple[float, Act | None]:
        """Fewest expected further operations (per unit mass) within ``k``, and the action."""
        if self.p.is_goal(mask):
            return 0.0, None
        key = (mask, k, _key(masses) if len(masses) > 1 else ())
        hit = self._exp.get(key)
        if hit is not None:
            return hit
        self.deadline.check()
        if k == 1:
            # Every allowed action orients the set at once: cost 1, so only ties are left.
            acts = self.p.choices.exact_actions(mask)
            for act in sorted(acts, key=lambda a: (-a.action.margin, a.rotation)):
                if self.allowed(act, 1):
                    self._exp[key] = (1.0, act)
                    return 1.0, act
            self._exp[key] = (math.inf, None)
            return math.inf, None
        best, best_act = math.inf, None
        options = []
        for cell in self.p.choices.cells(mask, useful=False):
            if (cell[1] - cell[0]) / 2.0 >= self.floor:
                # Every branch not yet oriented needs at least one more operation.
                sa = OverlapRange(*cell)
                options.append((1.0 + self._open_mass(mask, masses, sa), sa.representative, cell))
        options.sort(key=lambda o: (o[0], o[1]))
        # Cheapest bound first; whether a plan within k can start with the action is only
        # asked of actions that could still win.
        for bound, _rot, cell in options:
            if bound > best + _TIE:
                break
            act = self.p.choices.act(mask, cell, exact=True)
            if not self.allowed(act, k):
                continue
            if k == 2:
                val = bound  # each open branch then takes exactly one more operation
            else:
                val = 1.0
                for b, pb, ms in child_masses(self.p, mask, masses, act):
                    if pb > 0.0:
                        val += pb * self.expected(b.mask, ms, k - 1)[0]
                    if val > best + _TIE:
                        break
            if val < best - _TIE or (val <= best + _TIE and _prefer(act, best_act)):
                best, best_act = min(val, best), act
        out = (best, best_act)
        self._exp[key] = out
        return out

    def _open_mass(self, mask: int, masses: Masses, sa: OverlapRange) -> float:
        """Probability that a reading after the action leaves a set not yet oriented."""
        moved = spread(masses, self.p.choices.targets(mask, sa))
        fast = self.p.readings.open_probability(sa.image)
        if fast is not None:
            return sum(w * fast[t] for t, w in moved.items())
        total = 0.0
        for b, idx, probs in self.p.readings.branch_table(sa.image):
            if not self.p.is_goal(b.mask):
                total += sum(moved.get(s, 0.0) * p for s, p in zip(idx, probs, strict=True))
        return total

    def choose_worst(self, mask: int, masses: Masses, k: int, tie: str) -> Act:
        """The action of a plan within ``k``; ``tie``: ``expected``, ``rotation`` or ``first``.

        ``"first"`` takes the first allowed action in the problem's order (no tie-breaking).
        """
        if tie == "first":
            for act in self.p.choices.exact_actions(mask):
                if self.allowed(act, k):
                    return act
            raise AssertionError("no feasible action within the proven length")
        if tie == "expected":
            act = self.expected(mask, masses, k)[1]
            assert act is not None
            return act
        for cell in sorted(
            self.p.choices.cells(mask, False), key=lambda c: norm360((c[0] + c[1]) / 2.0)
        ):
            if (cell[1] - cell[0]) / 2.0 < self.floor:
                continue
            act = self.p.choices.act(mask, cell, exact=True)
            if act is not None and self.allowed(act, k):
                return act
        raise AssertionError("no feasible action within the proven length")

    def build(
        self, mask: int, masses: Masses, k: int, chooser: Callable[[int, Masses, int], Act]
    ) -> Step | Leaf:
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
