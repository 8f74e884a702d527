"""Choosing among plans of minimum worst-case length, and building the plan tree.

The order among plans of minimum length (docs/planning.md): the larger smallest margin
(the half-width of an action's overlap range), then the smaller expected number of
operations (the distribution of ``readings``), then smaller rotations (node by node from
the root). With
``objective="expected"`` the expected number of operations comes first, over plans of at
most ``EXPECTED_HORIZON`` times the minimum worst-case length, then the larger margin and
the smaller rotation of each action.

With action costs (:class:`~feederkit.planning.options.ActionCosts`), ties among equal
expected operation counts prefer the smaller expected seconds, before margin and rotation.
``timed`` (the ``time`` objective) minimises the expected seconds per part first (same
horizon as ``expected``), ties by the expected operations, margin, rotation. ``worst-time``
(:meth:`Refiner.worst_seconds`) keeps the minimum worst-case length and minimises the
seconds of the slowest path, every subtree itself fastest in its worst case, ties by the
larger margin and the smaller rotation. With costs the actions of a set are one per
distinct outcome with the cheapest rotation (then the widest) rather than the widest: the
rotation a plan uses is still its range's middle.

All the stages are exact searches over sets with a length budget: ``keeps(mask, k, m)``
says whether a plan of at most ``k`` operations keeps every margin at least ``m`` (an AND/OR
feasibility search, its bounds memoised per set and budget), and ``largest_floor`` raises
``m`` over the margins plans have until the root branches cannot keep more;
``expected(mask, masses, k)`` the smallest expected number of operations (memoised per set,
normalised masses and budget, with a branch-and-bound cut); ``worst_seconds(mask, k)`` the
fewest seconds of the slowest path (memoised per set and budget, cheapest action first).

Without a margin floor of the problem's, margins are monotone under subsets: a subset's
action-range boundaries are among the set's, so the set's cell around a rotation lies in
one of the subset's cells (as wide or wider, its image inside the set's image), and each
reading branch of a smaller image lies in one of the larger image's. A subset therefore
keeps every margin the set keeps within the same budget, and the maximal reading branches
decide a margin as they decide a length.

The ``worst`` objective's stages run under a
:class:`~feederkit.planning.budget.WorkBudget` (``plan`` gives them a bounded multiple of
the length proof's polls, so the same machine gives the same plan anywhere); out of it the
plan keeps the proven length and the margin decided or found so far.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from operator import itemgetter

from feederkit.angles import WIDTH_QUANTUM_DEG, norm360, width_key
from feederkit.machine import OverlapRange, ReadingBranch, members
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.choices import POLL_CELLS, spread
from feederkit.planning.options import ActionCosts
from feederkit.planning.problem import Act, Problem
from feederkit.planning.refuted import RefutedSets
from feederkit.planning.solved import SolvedSets
from feederkit.planning.tree import Leaf, Step, branch_pairs

EXPECTED_HORIZON = 2
"""``objective="expected"`` searches plans of at most this many times the minimum length."""

BOUNDS_PER_POLL = 8
"""The expected-operations stage polls its budget once per this many bounds it computes (as
well as once per set): a poll then costs about what a length proof's or a margin probe's
does (``python benchmarks/bench_tie_budget.py``)."""

_TIE = 1e-9

LEAP_MIN_DEG = 1e-6
"""The largest-floor search leaps (:meth:`Refiner.largest_floor`) while the margins between
the one every set keeps and the least one refuted span more than this many degrees."""

Masses = tuple[float, ...]
Value = tuple[float, float]
"""An expected figure and its tie-break: (operations, seconds), or (seconds, operations)
with the time objective; seconds are 0 without action costs."""
Cell = tuple[float, float, int]


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
    get = moved.get
    for b, idx, probs in table:
        ws = [get(s, 0.0) * p for s, p in zip(idx, probs, strict=True)]
        total = sum(ws)
        norm = tuple([w / total for w in ws]) if total > 0.0 else (1.0 / len(idx),) * len(idx)
        out.append((b, total, norm))
    return out


def _key(masses: Masses) -> tuple[float, ...]:
    return tuple(round(w, 12) for w in masses)


class Refiner:
    """The tie-breaking stages and the tree builder over one problem."""

    def __init__(
        self,
        problem: Problem,
        worst: WorstCase,
        deadline: Deadline | None = None,
        *,
        costs: ActionCosts | None = None,
        timed: bool = False,
    ) -> None:
        if timed and costs is None:
            raise ValueError("the time objective needs action costs")
        self.p = problem
        self.w = worst
        self.deadline = deadline or Deadline(None)
        self.floor = -math.inf
        self.floor_found = -math.inf
        """The largest margin every root set is proven to keep so far (:meth:`largest_floor`):
        what a plan keeps when the margin stage runs out of time."""
        self.costs = costs
        self.timed = timed
        self._monotone = problem.min_margin == 0.0 and not problem.sensorless
        """Margins and lengths are monotone under subsets: the maximal branches decide."""
        self._lo: dict[tuple[int, int], float] = {}
        # The first action (its cell) of the plan behind each ``_lo`` (:meth:`follow`).
        self._how: dict[tuple[int, int], Cell] = {}
        self._le: dict[tuple[int, int], float] = {}
        self._lt: dict[tuple[int, int], float] = {}
        # The sets of each budget no plan keeps a margin for, valued minus that margin
        # (``_lt``: at least it; ``_le``: above it), for the sets that hold them.
        self._lt_sets: dict[int, RefutedSets] = {}
        self._le_sets: dict[int, RefutedSets] = {}
        # The sets of each budget a probe found a plan for (``_lo``), for the sets inside them.
        self._kept_sets: dict[int, SolvedSets] = {}
        self._exp: dict[tuple[int, int, tuple[float, ...]], tuple[Value, Act | None]] = {}
        self._wsec: dict[tuple[int, int], tuple[float, Act | None]] = {}
        self._cheap: dict[tuple[int, bool, float], list[Cell]] = {}
        self._one: dict[tuple[int, float], tuple[Value, Act | None]] = {}
        self._bounds = 0  # expected-operations bounds computed (BOUNDS_PER_POLL)
        self._nodes: dict[tuple[object, ...], Step] = {}
        """The distinct steps :meth:`build` made, by action and branches (children that are
        steps by identity: they are distinct already)."""

    def seconds(self, act: Act) -> float:
        """Seconds of the operation ``act`` (0 without action costs)."""
        return 0.0 if self.costs is None else self.costs.seconds(act.rotation)

    def _step(self, act: Act) -> Value:
        """What one operation adds to the expected figure."""
        if self.timed:
            return (self.seconds(act), 1.0)
        return (1.0, self.seconds(act))

    def cells(self, mask: int, by_map: bool) -> list[Cell]:
        """The set's ranges to choose among, above the margin floor: without costs the
        problem's (``Choices.cells``); with costs one per distinct outcome (the map of the
        members with ``by_map``, else the image) with the cheapest rotation, then the
        widest, cheapest first, among those that keep the problem's and the refiner's
        margin floors (cached)."""
        if self.costs is None:
            return self.p.choices.cells(mask, useful=False)
        # The refiner's margin floor too: a cheaper range below it must not hide a wider one
        # with the same outcome.
        floor = 2.0 * max(self.p.min_margin, self.floor)
        key = (mask, by_map, floor)
        hit = self._cheap.get(key)
        if hit is not None:
            return hit
        costs = self.costs
        best: dict[object, tuple[float, float, float, Cell]] = {}
        for cell in self.p.choices.fixed_cells(mask):
            lo, hi, img = cell
            if hi - lo < floor:
                continue
            sa = OverlapRange(lo, hi, img)
            rot = sa.representative
            k: object = self.p.choices.targets(mask, sa) if by_map else img
            rank = (costs.seconds(rot), -width_key(hi - lo), norm360(rot), cell)
            old = best.get(k)
            if old is None or rank[:3] < old[:3]:
                best[k] = rank
        out = [r[3] for r in sorted(best.values(), key=lambda r: r[:3])]
        self._cheap[key] = out
        return out

    def feasible(self, act: Act, k: int) -> bool:
        """Whether every branch of ``act`` can be oriented in ``k`` more operations.

        Without a margin floor lengths are monotone under subsets, so the maximal branches
        decide.
        """
        if self.p.min_margin == 0.0 and not self.p.sensorless:
            return self.feasible_image(act.action.image, k)
        return all(self.w.within(c, k) for c in act.children)

    def feasible_image(self, image: int, k: int) -> bool | None:
        """:meth:`feasible` of an action with this image, from the image alone (its maximal
        branches), before its exact branches are made; None when the exact branches decide
        (a margin floor, or no sensor)."""
        if self.p.min_margin == 0.0 and not self.p.sensorless:
            return all(self.w.within(c, k) for c in self.p.readings.children(image))
        return None

    def allowed(self, act: Act, k: int) -> bool:
        """Whether a plan of at most ``k`` operations keeping ``floor`` can start with ``act``."""
        if act.action.margin < self.floor or not self.feasible(act, k - 1):
            return False
        return self._keeps_floor(act, k)

    def _keeps_floor(self, act: Act, k: int) -> bool:
        """:meth:`allowed` of an action already known :meth:`feasible` within ``k - 1``."""
        if act.action.margin < self.floor:
            return False
        if self.floor == -math.inf:
            return True
        return all(self.keeps(c, k - 1, self.floor) for c in self._deciding(act))

    def _deciding(self, act: Act) -> tuple[int, ...]:
        """The branches of ``act`` whose margins decide whether it keeps a floor: its
        maximal ones without a margin floor of the problem's (a subset keeps any margin
        the set keeps, see :meth:`keeps`), else all of them."""
        if self.p.min_margin == 0.0 and not self.p.sensorless:
            return self.p.readings.children(act.action.image)
        return act.children

    def keeps(self, mask: int, k: int, x: float, strict: bool = False) -> bool:
        """Whether some plan for ``mask`` within ``k`` keeps every margin at least ``x``
        (above ``x`` when ``strict``): the feasibility form of the largest smallest margin.

        Memoised per set and budget as bounds on that margin, each proven by a search: the
        smallest margin of a plan found (``_lo``, a lower bound) and the margins no plan
        reaches (``_le``: at most; ``_lt``: below), so probes at several margins share them.
        A goal keeps any margin (it needs no action).
        """
        if self.p.is_goal(mask):
            return True
        if k <= 0:
            return False
        key = (mask, k)
        lo = self._lo.get(key)
        if lo is not None and (lo > x or (lo == x and not strict)):
            return True
        le = self._le.get(key)
        if le is not None and (le < x or (le == x and strict)):
            return False
        lt = self._lt.get(key)
        if lt is not None and lt <= x:
            return False
        if self._short(mask, k):
            self._lt[key] = -math.inf
            return False
        self.deadline.check()
        if self._holds_refuted(mask, k, x, strict):
            return False
        if self._inside_kept(mask, k, x, strict):
            return True
        kept = self._keeping_plan(mask, k, x, strict)
        if kept is not None:
            found, cell = kept
            if lo is None or found > lo:
                self._lo[key], self._how[key] = found, cell
            if self._monotone:
                if k not in self._kept_sets:
                    self._kept_sets[k] = SolvedSets(self.p.machine.n)
                self._kept_sets[k].add(mask)
            return True
        if strict:
            self._le[key] = x if le is None else min(le, x)
        else:
            self._lt[key] = x if lt is None else min(lt, x)
        if self._monotone:
            sets = self._le_sets if strict else self._lt_sets
            if k not in sets:
                sets[k] = RefutedSets(self.p.machine.n)
            sets[k].add(mask, -x)
        return False

    def _inside_kept(self, mask: int, k: int, x: float, strict: bool) -> bool:
        """Whether ``mask`` lies inside a set for which a probe found a plan within ``k``
        keeping ``x`` (above ``x`` when ``strict``): margins are monotone under subsets, so
        that plan keeps it for ``mask`` too (:mod:`~feederkit.planning.solved`); its smallest
        margin and first cell become ``mask``'s (:meth:`follow` finds ``mask``'s own range
        around that cell)."""
        index = self._kept_sets.get(k) if self._monotone else None
        if index is None:
            return False
        lows = self._lo

        def fits(s: int) -> bool:
            lo = lows[(s, k)]
            return lo > x or (lo == x and not strict)

        s = index.holder(mask, fits)
        if s is None:
            return False
        key = (mask, k)
        lo = lows.get(key)
        if lo is None or lows[(s, k)] > lo:
            lows[key], self._how[key] = lows[(s, k)], self._how[(s, k)]
        return True

    def _holds_refuted(self, mask: int, k: int, x: float, strict: bool) -> bool:
        """Whether ``mask`` holds a set that no plan within ``k`` keeps ``x`` for (above
        ``x`` when ``strict``): margins are monotone under subsets, so neither does one for
        ``mask`` (:mod:`~feederkit.planning.refuted`); the refutation is memoised."""
        if not self._monotone:
            return False
        key = (mask, k)
        at_least = self._lt_sets.get(k)
        v = None if at_least is None else at_least.bound(mask, -x)
        if v is not None:  # no plan keeps -v <= x: nor x
            self._lt[key] = min(self._lt.get(key, math.inf), -v)
            return True
        above = self._le_sets.get(k) if strict else None
        v = None if above is None else above.bound(mask, -x)
        if v is not None:  # no plan keeps more than -v <= x
            self._le[key] = min(self._le.get(key, math.inf), -v)
            return True
        return False

    def _short(self, mask: int, k: int) -> bool:
        """Whether the length search has already proven that ``mask`` needs more than ``k``
        operations (its exact lengths, lower bounds, hardest pairs and the sets it refuted
        that ``mask`` holds: no search of the set itself, at most of a pair not asked
        before): then no plan within ``k`` keeps any margin."""
        w = self.w
        e = w.exact.get(mask)
        if e is not None:
            return e > k
        if w.lb.get(mask, 1) > k or mask in w.never or w.pair_bound(mask) > k:
            return True
        return w.holds_refuted(mask, k)

    def _keeping_plan(self, mask: int, k: int, x: float, strict: bool) -> tuple[float, Cell] | None:
        """The smallest margin of a plan for ``mask`` within ``k`` keeping ``x`` (as
        :meth:`keeps` says) and its first action's cell, or None when there is none; on the
        maximal reading branches without a margin floor (module docstring).

        Only the ranges wide enough to keep ``x`` can start such a plan, and among them the
        length search's order finds one soonest: a probe that succeeds stops at the first
        plan, one that fails tries them all in any order. Widest first instead, a probe of the
        20-part mix at 5 % polled 39,000-61,000 times at any margin; in this order, the
        length search asked as below, 2,100-3,700 (docs/performance.md, "Margin probes in
        the length search's order"). A plan keeping ``x`` within ``k`` is one within ``k`` at all,
        so the length search (its memo, pair bounds and refuted sets) is asked of each
        range's branches first.
        """
        choices = self.p.choices
        wide = [c for c in choices.cells(mask, useful=False) if _wide(c, x, strict)]
        keys = []
        for n, c in enumerate(wide):
            if n % POLL_CELLS == POLL_CELLS - 1:
                self.deadline.limits()  # a key not yet made is a reading split
            keys.append(choices.search_key(c))
        cells = [c for _key, c in sorted(zip(keys, wide, strict=True), key=itemgetter(0))]
        for cell in cells:
            m = (cell[1] - cell[0]) / 2.0
            if self.p.sensorless:
                # One branch per action, its image: no branch objects needed.
                children: tuple[int, ...] = (cell[2],)
                if not self.w.within(cell[2], k - 1):
                    continue
            elif self.p.min_margin == 0.0:
                children = self.p.readings.children(cell[2])
                if not all(self.w.within(c, k - 1) for c in children):
                    continue
            else:
                self.deadline.check()  # each action costs a reading split
                act = self.p.choices.act(mask, cell, exact=True)
                if not self.feasible(act, k - 1):
                    continue
                children = act.children
            val = m
            for c in children:
                if not self.keeps(c, k - 1, x, strict):
                    break
                if not self.p.is_goal(c):
                    val = min(val, self._lo[(c, k - 1)])
            else:
                return val, cell
        return None

    def margin(self, mask: int, k: int) -> float:
        """The largest smallest margin of plans for ``mask`` within ``k`` operations (inf
        for a goal, -inf when no plan is that short)."""
        return self.largest_floor([mask], k)

    def largest_floor(self, masks: list[int], k: int, planned: bool = False) -> float:
        """The largest ``m`` such that every set of ``masks`` has a plan within ``k`` whose
        margins are all at least ``m`` (inf when all are goals, -inf when one has no plan).

        Raised from below: while every set keeps a margin above ``m`` (:meth:`keeps`,
        strict), ``m`` becomes the least smallest margin of the plans found; the first set
        that cannot is at most ``m``, and every set keeps ``m``. Each step rises to a margin
        some plan has, and between steps the probes leap: halfway from ``m`` to the least
        margin not yet refuted (at first the widest first action's), ``m`` rises to what the
        plans found there keep while every set keeps the midpoint, and the first that does
        not refutes it (a mix of 240 states took 237 steps from below, 51-53 CPU seconds;
        22 with the leaps: docs/planning.md). The probes share one memo, and a set that
        refuted a margin is asked first next time.

        ``planned``: the caller knows every set has a plan within ``k`` (the length proof's
        root branches), so the first probe, for any plan at all, is left out and the first
        leap is from 0 (every margin is at least 0): on a 240-state mix that probe re-found
        the proof's plans, 28,172 polls of the stage's 68,346 (docs/planning.md).
        """
        open_ = sorted((r for r in masks if not self.p.is_goal(r)), key=lambda r: -r.bit_count())
        if not open_:
            return math.inf
        # No plan keeps more than its first action's margin: the widest one of each set
        # (a pass over each set's cells: polled per set, a 200-part mix has hundreds).
        top = math.inf
        for r in open_:
            self.deadline.limits()
            cells = self.p.choices.cells(r, useful=False)
            top = min(top, max(((c[1] - c[0]) / 2.0 for c in cells), default=0.0))
        x = -math.inf
        while True:
            if not planned:
                if not self._all_keep(open_, k, x, strict=True):
                    return x
                x = self._raise(open_, k)
            planned = False  # the next rounds start from a margin every set keeps
            while top - max(x, 0.0) > LEAP_MIN_DEG:
                mid = (max(x, 0.0) + top) / 2.0
                if not self._all_keep(open_, k, mid, strict=False):
                    top = mid  # some set keeps less than mid: the largest floor is below it
                    break
                x = self._raise(open_, k)

    def _all_keep(self, open_: list[int], k: int, x: float, strict: bool) -> bool:
        """Whether every set of ``open_`` keeps ``x`` within ``k``; the first that does not is
        moved to the front (it is asked first next time)."""
        for i, r in enumerate(open_):
            if not self.keeps(r, k, x, strict):
                open_.insert(0, open_.pop(i))
                return False
        return True

    def _raise(self, open_: list[int], k: int) -> float:
        """The least margin the plans found for ``open_`` keep (each set keeps it)."""
        x = min(self._lo[(r, k)] for r in open_)
        self.floor_found = max(self.floor_found, x)
        return x

    def expected(self, mask: int, masses: Masses, k: int) -> tuple[Value, Act | None]:
        """Fewest expected further operations (per unit mass) within ``k``, and the action.

        The value is ``(operations, seconds)``, or ``(seconds, operations)`` when
        ``timed``; the first is minimised, the second breaks ties (docstring above).
        """
        if self.p.is_goal(mask):
            return (0.0, 0.0), None
        if k == 1:
            # Every allowed action orients the set at once: one operation, so only ties
            # (its seconds, margin, rotation) are left, and the masses do not matter.
            one = self._one.get((mask, self.floor))
            if one is None:
                self.deadline.check()
                one = self._one[(mask, self.floor)] = self._one_step(mask)
            return one
        # Sensorless, a set has one path whatever its masses: its figure does not depend on them.
        weighed = len(masses) > 1 and not self.p.sensorless
        key = (mask, k, _key(masses) if weighed else ())
        hit = self._exp.get(key)
        if hit is not None:
            return hit
        self.deadline.check()
        best: Value = (math.inf, math.inf)
        best_act = None
        least = 1.0 if not self.timed else self.costs.least_s  # type: ignore[union-attr]
        options = []
        for cell in self.cells(mask, True):
            if (cell[1] - cell[0]) / 2.0 >= self.floor:
                # Every branch not yet oriented needs at least one more operation. The bounds
                # are the stage's work (a pass over the members each): every
                # BOUNDS_PER_POLL of them poll, so its budget of polls bounds it.
                self._bounds += 1
                if self._bounds % BOUNDS_PER_POLL == 0:
                    self.deadline.check()
                rot = norm360((cell[0] + cell[1]) / 2.0)  # the range's representative
                step = 1.0 if self.costs is None else self._step(Act(OverlapRange(*cell), ()))[0]
                bound = step + least * self._open_mass(mask, masses, cell, rot)
                options.append((bound, rot, cell))
        options.sort(key=lambda o: (o[0], o[1]))
        # Cheapest bound first; whether a plan within k can start with the action is only
        # asked of actions that could still win.
        shortcut = k == 2 and self.costs is None
        for bound, _rot, cell in options:
            if bound > best[0] + _TIE:
                break
            if self._monotone and self.floor > -math.inf:
                # Keeping the floor within k - 1 needs a plan within k - 1: the margin probes
                # on the maximal branches decide alone, before the exact branches are made.
                if not all(
                    self.keeps(c, k - 1, self.floor) for c in self.p.readings.children(cell[2])
                ):
                    continue
                self.deadline.check()
                act = self.p.choices.act(mask, cell, exact=True)
            else:
                by_image = self.feasible_image(cell[2], k - 1)
                if by_image is False:
                    continue  # not allowed: decided before making the exact branches
                self.deadline.check()
                act = self.p.choices.act(mask, cell, exact=True)
                if not (self._keeps_floor(act, k) if by_image else self.allowed(act, k)):
                    continue
            if shortcut:
                val = (bound, 0.0)  # each open branch then takes exactly one more operation
            else:
                first, second = self._step(act)
                for b, pb, ms in child_masses(self.p, mask, masses, act):
                    if pb > 0.0:
                        sub = self.expected(b.mask, ms, k - 1)[0]
                        first += pb * sub[0]
                        second += pb * sub[1]
                    if first > best[0] + _TIE:
                        break
                val = (first, second)
            if _better(val, best) or (_equal(val, best) and _prefer(act, best_act)):
                # Without costs keep the smaller of two tied figures (the memo is a bound).
                best = val if self.costs is not None else (min(val[0], best[0]), 0.0)
                best_act = act
        result = (best, best_act)
        self._exp[key] = result
        return result

    def _one_step(self, mask: int) -> tuple[Value, Act | None]:
        """:meth:`expected` within one operation: the first action (the cheapest, then the
        larger margin, then the smaller rotation) that orients the set at once."""
        if self.costs is None:
            # Without costs the cells' own order is (larger margin, smaller rotation):
            # make the exact branches only of the cells that can orient the set at once.
            # The margin floor and the image are asked first (``allowed`` asks them too).
            for n, c in enumerate(self.p.choices.cells(mask, useful=False)):
                if n % POLL_CELLS == POLL_CELLS - 1:
                    self.deadline.limits()
                if (c[1] - c[0]) / 2.0 < self.floor or self.feasible_image(c[2], 0) is False:
                    continue
                act = self.p.choices.act(mask, c, exact=True)
                if self.allowed(act, 1):
                    return self._step(act), act
            return (math.inf, math.inf), None
        made = []
        for n, c in enumerate(self.cells(mask, True)):
            if n % POLL_CELLS == POLL_CELLS - 1:
                self.deadline.limits()
            made.append(self.p.choices.act(mask, c, exact=True))
        for act in sorted(made, key=lambda a: (self.seconds(a), -a.action.margin, a.rotation)):
            if self.allowed(act, 1):
                return self._step(act), act
        return (math.inf, math.inf), None

    def worst_seconds(self, mask: int, k: int) -> tuple[float, Act | None]:
        """Fewest seconds of the slowest path of a plan for ``mask`` within ``k``, and its
        first action (the ``worst-time`` stage; needs action costs)."""
        if self.p.is_goal(mask):
            return 0.0, None
        if k <= 0:
            return math.inf, None
        key = (mask, k)
        hit = self._wsec.get(key)
        if hit is not None:
            return hit
        self.deadline.check()
        best, best_act = math.inf, None
        least = self.costs.least_s  # type: ignore[union-attr]
        for cell in self.cells(mask, False):  # cheapest first
            if (cell[1] - cell[0]) / 2.0 < self.floor:
                continue
            act = self.p.choices.act(mask, cell, exact=True)
            here = self.seconds(act)
            if here > best + _TIE:
                break  # the cells come cheapest first
            open_ = any(not self.p.is_goal(c) for c in act.children)
            if here + (least if open_ else 0.0) > best + _TIE or not self.allowed(act, k):
                continue
            val = here
            for c in act.children:
                val = max(val, here + self.worst_seconds(c, k - 1)[0])
                if val > best + _TIE:
                    break
            if val < best - _TIE or (val <= best + _TIE and _prefer(act, best_act)):
                best, best_act = min(val, best), act
        out = (best, best_act)
        self._wsec[key] = out
        return out

    def _open_mass(self, mask: int, masses: Masses, cell: Cell, rotation: float) -> float:
        """Probability that a reading after the action of ``cell`` (its representative
        ``rotation``) leaves a set not yet oriented."""
        image = cell[2]
        moved = spread(masses, self.p.choices.targets_at(mask, cell[0], rotation))
        fast = self.p.readings.open_mass(image, moved)
        if fast is not None:
            return fast
        total = 0.0
        for b, idx, probs in self.p.readings.branch_table(image):
            if not self.p.is_goal(b.mask):
                total += sum(moved.get(s, 0.0) * p for s, p in zip(idx, probs, strict=True))
        return total

    def choose_worst(self, mask: int, masses: Masses, k: int, tie: str) -> Act:
        """The action of a plan within ``k``; ``tie``: ``expected``, ``worst-time``,
        ``rotation`` or ``first``.

        ``"first"`` takes the first allowed action in the problem's order (no tie-breaking);
        ``"worst-time"`` the first action of :meth:`worst_seconds`.
        """
        if tie == "first":
            # The problem's order (Choices.exact_actions), made one action at a time: the
            # first allowed one usually comes early, and each costs a reading split.
            for cell in self.p.choices.cells(mask, useful=False):
                if self.feasible_image(cell[2], k - 1) is False:
                    continue  # decided before making the exact branches
                self.deadline.check()
                act = self.p.choices.act(mask, cell, exact=True)
                if self.allowed(act, k):
                    return act
            raise AssertionError("no feasible action within the proven length")
        if tie == "expected":
            act = self.expected(mask, masses, k)[1]
            assert act is not None
            return act
        if tie == "worst-time":
            act = self.worst_seconds(mask, k)[1]
            assert act is not None
            return act
        for n, cell in enumerate(
            sorted(self.p.choices.cells(mask, False), key=lambda c: norm360((c[0] + c[1]) / 2.0))
        ):
            if n % POLL_CELLS == POLL_CELLS - 1:
                self.deadline.limits()
            if (cell[1] - cell[0]) / 2.0 < self.floor:
                continue
            act = self.p.choices.act(mask, cell, exact=True)
            if act is not None and self.allowed(act, k):
                return act
        raise AssertionError("no feasible action within the proven length")

    def nodes(self) -> list[Step]:
        """The distinct steps :meth:`build` and :meth:`follow` made for the current tree."""
        return list(self._nodes.values())

    def new_tree(self) -> None:
        """Forget the steps :meth:`build` made: the next tree commits each of its own
        distinct steps to the deadline it is built under (one tree per deadline)."""
        self._nodes = {}

    def build(
        self,
        mask: int,
        masses: Masses,
        k: int,
        chooser: Callable[[int, Masses, int], Act],
    ) -> Step | Leaf:
        """The subtree orienting ``mask`` in at most ``k`` operations, actions from ``chooser``.

        Equal subtrees are one object (a DAG in memory: a chooser that reads the masses makes
        the same subtree on many paths), and each new node's branches are committed to the
        deadline (:meth:`~feederkit.planning.budget.Deadline.commit`): its verification walks
        each (node, state) pair of each distinct step once."""
        if self.p.is_goal(mask):
            return Leaf(mask)
        self.deadline.check()
        act = chooser(mask, masses, k)
        table = self.p.readings.branch_table(act.action.image)
        if all(self.p.is_goal(b.mask) for b, _idx, _probs in table):
            # Every branch is oriented: leaves, whose masses nothing reads.
            subs = [(b, Leaf(b.mask)) for b, _idx, _probs in table]
        else:
            subs = [
                (b, self.build(b.mask, ms, k - 1, chooser))
                for b, _pb, ms in child_masses(self.p, mask, masses, act)
            ]
        return self._node(act, subs)

    def follow(
        self,
        mask: int,
        k: int,
        witness: int | None = None,
        shared: dict[tuple[int, int, int | None], Step | Leaf] | None = None,
    ) -> Step | Leaf:
        """The subtree for ``mask`` within ``k`` keeping the floor that follows the plans the
        margin probes found (:meth:`keeps` keeps each one's first action), with no new search.

        ``witness`` is a set containing ``mask`` with such a plan (None: ``mask`` itself, as
        at a root branch the probes decided). With margins monotone under subsets (module
        docstring), ``mask``'s overlap range around the witness's rotation is as wide or
        wider, and each of its reading branches lies in one of the witness's maximal
        branches, whose plans go on. Where the probes recorded none, the length proof's
        plan (``WorstCase.choice``: proven on the maximal branches too) when it keeps the
        floor; else the first allowed action (:meth:`choose_worst` ``"first"``, a search).
        Equal subtrees are one object, each new node committed to the deadline as in
        :meth:`build`.
        """
        if self.p.is_goal(mask):
            return Leaf(mask)
        if shared is None:
            shared = {}
        key = (mask, k, witness)
        hit = shared.get(key)
        if hit is not None:
            return hit
        self.deadline.check()
        lender = mask if witness is None else witness
        cell = self._how.get((lender, k))
        act = None
        if self._monotone and cell is not None and self._lo[(lender, k)] >= self.floor:
            act = self._around(mask, cell)
        if act is None and self._monotone:
            # No probe's plan: the length proof's, when it keeps the floor (no search).
            proved = self.w.choice.get(lender)
            if proved is not None and proved[0] <= k:
                sa = proved[1].action
                cell = (sa.lo, sa.hi, sa.image)
                act = self._around(mask, cell)
        if act is None:
            act = self.choose_worst(mask, (), k, "first")
            cell = (act.action.lo, act.action.hi, act.action.image)
        maximal = self.p.readings.children(cell[2]) if self._monotone else ()
        subs: list[tuple[ReadingBranch, Step | Leaf]] = []
        for b, _idx, _probs in self.p.readings.branch_table(act.action.image):
            inside = next((m for m in maximal if b.mask & ~m == 0), None)
            subs.append((b, self.follow(b.mask, k - 1, inside, shared)))
        node = shared[key] = self._node(act, subs)
        return node

    def planned(self, mask: int, k: int) -> bool:
        """Whether :meth:`follow` has a plan of ``mask``'s own within ``k`` to follow: a
        margin probe's keeping the floor or the length proof's."""
        if (mask, k) in self._how and self._lo[(mask, k)] >= self.floor:
            return True
        proved = self.w.choice.get(mask)
        return proved is not None and proved[0] <= k

    def _node(self, act: Act, subs: list[tuple[ReadingBranch, Step | Leaf]]) -> Step:
        """The tree's node of ``act`` over ``subs``: one object per equal subtree, each new
        one's (node, state) pairs committed to the deadline."""
        key = (act.action, tuple((b, c if isinstance(c, Leaf) else id(c)) for b, c in subs))
        node = self._nodes.get(key)
        if node is None:
            node = self._nodes[key] = Step(act.action, tuple(subs))
            self.deadline.commit(branch_pairs(subs))
        return node

    def _around(self, mask: int, cell: Cell) -> Act | None:
        """The action of ``mask``'s overlap range that contains ``cell`` (an overlap range of
        a superset: ``mask``'s range boundaries are among the superset's), with every branch
        set; None when none does or it is narrower than the floor."""
        x = (cell[0] + cell[1]) / 2.0
        found = self.p.choices.cell_at(mask, norm360(x))  # no cell table of the set
        if found is not None:
            if (found[1] - found[0]) / 2.0 < self.floor:
                return None
            return self.p.choices.act(mask, found, exact=True)
        for lo, hi, img in self.p.choices.fixed_cells(mask):
            if any(lo <= y <= hi for y in (x, x - 360.0, x + 360.0)):
                if (hi - lo) / 2.0 < self.floor:
                    return None
                return self.p.choices.act(mask, (lo, hi, img), exact=True)
        return None


def _wide(cell: Cell, x: float, strict: bool) -> bool:
    """Whether the range ``cell`` keeps the margin ``x`` (above it when ``strict``)."""
    m = (cell[1] - cell[0]) / 2.0
    return m > x or (m == x and not strict)


def tie_floor(margin: float) -> float:
    """The margin floor a plan keeps once ``margin`` is the largest smallest margin: widths
    within ``WIDTH_QUANTUM_DEG`` of it count as keeping it (:func:`~feederkit.angles.width_key`),
    so a mirror-image range a rounding below it stays a choice on every machine."""
    return margin - WIDTH_QUANTUM_DEG if math.isfinite(margin) else margin


def _prefer(a: Act, b: Act | None) -> bool:
    """Between equally good actions: larger margin, then the smaller rotation."""
    if b is None:
        return True
    wa = width_key(a.action.hi - a.action.lo)
    wb = width_key(b.action.hi - b.action.lo)
    if wa != wb:
        return wa > wb
    return a.rotation < b.rotation


def _better(a: Value, b: Value) -> bool:
    """Whether ``a`` is smaller than ``b``: the first figure, then the second (1e-9 ties)."""
    if a[0] < b[0] - _TIE:
        return True
    return a[0] <= b[0] + _TIE and a[1] < b[1] - _TIE * max(1.0, abs(b[1]))


def _equal(a: Value, b: Value) -> bool:
    """Whether ``a`` and ``b`` tie on both figures (within 1e-9)."""
    return abs(a[0] - b[0]) <= _TIE and abs(a[1] - b[1]) <= _TIE * max(1.0, abs(b[1]))


def stage(objective: str, refiner: Refiner, every: list[int], budget: int) -> tuple[str, int]:
    """The tie rule and the horizon of ``objective``'s refinement stage over the root
    branches ``every`` (each with ``budget`` further operations); for ``worst`` it sets the
    refiner's margin floor first (docs/planning.md, "Which plan among the shortest").

    ``worst``: the largest smallest margin, then the expected operations (seconds break
    their ties when the refiner has costs; sensorless without costs: the smaller rotation);
    ``worst-time``: the fewest seconds on the slowest path; both within ``budget``.
    ``expected`` and ``time``: the expected figure within ``EXPECTED_HORIZON * budget``.
    """
    if objective == "worst":
        # The smallest margin over the root branches, as large as it can be.
        # The length proof gave every root branch a plan within ``budget``.
        refiner.floor = tie_floor(refiner.largest_floor(every, budget, planned=True))
        sensorless = refiner.p.sensorless and refiner.costs is None
        return ("rotation" if sensorless else "expected"), budget
    if objective == "worst-time":
        if refiner.costs is None:
            raise ValueError("the worst-time objective needs action costs")
        return "worst-time", budget
    return "expected", EXPECTED_HORIZON * budget
