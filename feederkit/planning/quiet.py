"""Readings that carry nothing on a machine of several parts: a sensorless problem in disguise.

When one reading is consistent with every state (a coarse sensor on near-round parts, or
both landings of one part, whose mirror images show the same diameters), nature may give
that reading after every operation and leave the whole image. Every set then needs exactly
as many operations as with no sensor, and a plan that takes the readings without using them
is as short as any (:func:`~feederkit.planning.methods.readings_carry_nothing`). With one
part Goldberg's backchaining answers at once (:class:`~feederkit.planning.sensorless.
BackchainWorst`); with several, a set's length is a shortest path over sets (section 4):
A* with each part's backchaining length as its heuristic
(:meth:`~feederkit.planning.andor.WorstCase.sensorless_length`). So

- :class:`QuietWorst` answers every set's length by that search, never by the AND/OR search
  over reading sets, which would explore every reading set for nothing (both landings of a
  random 1000-point outline at 3 % on the ideal model: the AND/OR search had proved 13 after
  a minute, A* proves 22 at once); where every part is a push function, by the same A* over
  the parts' arc hulls instead of sets (:mod:`~feederkit.planning.arcs`: exact, and on that
  outline 26 after the first alignment, proven in 1.8 s);
- :func:`widening_chains` finds plans fast when A* runs out: beams over sets, level by
  level, keeping the sets nearest a goal by the parts' backchaining lengths, each beam
  wider than the last; on that outline a plan of 27 operations (the first alignment
  included) after 17 s of beams, where the parts' chains in turn take 39;
- :func:`widest_chain` breaks the ties among the shortest chains by their smallest margin:
  "within the length with every margin at least ``m``?" is the same A* under a margin
  floor, bisected over ``m``;
- :func:`chain_plan` makes the plan of a path: one step per operation, every reading
  going on with the subplan of the step's whole image (a reading leaves a subset of it).

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 4.
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10.
Hart, P. E., Nilsson, N. J. and Raphael, B. (1968). A formal basis for the heuristic
determination of minimum cost paths. IEEE Transactions on Systems Science and Cybernetics
4(2) (A*).
Pohl, I. (1970). Heuristic search viewed as path finding in a graph. Artificial
Intelligence 1(3-4), 193-204 (weighted A*).
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np

from feederkit.machine import bit_rows
from feederkit.planning.andor import WorstCase, part_chains
from feederkit.planning.arcs import ArcSpace, arc_space
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.problem import Act, Problem
from feederkit.planning.tree import Leaf, Step, build_dag, root_step

CHAIN_WEIGHTS = (1.25, 1.1)
""":meth:`QuietWorst.weighted_chains` runs weighted A* over the arcs with these weights in
turn (each chain at most that many times as long as the shortest; Pohl 1970)."""

FIRST_WIDTH = 1
"""The first beam of :func:`widening_chains` keeps one set per level (the greedy path); each
next beam is ``WIDTH_FACTOR`` times as wide."""

WIDTH_FACTOR = 2

VECTOR_MIN = 16
""":meth:`QuietWorst.part_lengths_of` takes fewer new sets than this one at a time (the
arrays' fixed cost is then more than the loops')."""


class QuietWorst(WorstCase):
    """The worst-case oracle of a machine whose readings carry nothing: every set's length is
    its sensorless length (module docstring), searched by A* over the parts' arc hulls where
    that applies (:mod:`~feederkit.planning.arcs`), else by A* over sets (``arcs`` False:
    always over sets)."""

    SUBSET_SOLVES = False  # chain_plan follows each image's own chosen action

    def __init__(
        self,
        problem: Problem,
        deadline: Deadline | None = None,
        pair_bound: bool = True,
        arcs: bool = True,
    ) -> None:
        super().__init__(problem, deadline, pair_bound)
        self._quiet = _always
        # Per part: its mask, a table per byte of the machine's mask to the part's own
        # numbering, and its backchaining table (made when first asked).
        self._parts: list[tuple[int, list[list[int]], object]] | None = None
        self._lengths: dict[int, tuple[int, int]] = {}
        # Per part: its states' columns in its own numbering and its backchaining table
        # (part_lengths_of).
        self._columns: list[tuple[np.ndarray, object]] | None = None
        # The arc search (made when first asked; False: not used, ``arcs`` False or it does
        # not apply).
        self._arcs: ArcSpace | None | bool = None if arcs else False
        self.arc_misses = 0
        """Chains the arc search found that could not be followed on the machine (the set
        search answered instead); none is expected."""

    def sensorless_length(self, mask: int, cap: int | None = None) -> int | None:
        """:meth:`WorstCase.sensorless_length` by A* over the parts' arc hulls where it
        applies (:mod:`~feederkit.planning.arcs`: exact, and far fewer states than sets),
        else by A* over sets. The chain found is recorded as the set search records its
        path (``exact``, ``ub`` and ``choice`` of each set on it), each step the widest
        range of its set inside the chain's range (:meth:`_record_chain`)."""
        space = self.arc_space()
        if space is None:
            return super().sensorless_length(mask, cap)
        e = self.exact.get(mask)
        if e is not None:
            return e
        if self.p.is_goal(mask):
            return 0
        try:
            found = space.shortest_chain(mask, cap, self.deadline.check)
        except Timeout:
            self.lb[mask] = max(self.lb.get(mask, 1), space.reached)
            raise
        if found is None:
            if cap is not None and space.reached > cap:
                self.lb[mask] = max(self.lb.get(mask, 1), space.reached)
                return cap + 1
            self.never.add(mask)
            return None
        if not self._record_chain(mask, found):
            self.arc_misses += 1
            return super().sensorless_length(mask, cap)
        return len(found)

    def arc_space(self) -> ArcSpace | None:
        """The arc search of this problem (made once), None where it is not used."""
        if self._arcs is None:
            self._arcs = arc_space(self.p) or False
        return self._arcs or None

    def arc_chains(self, space: ArcSpace, roots, longest: int, floor: float) -> float | None:
        """The smallest margin of chains of every root within ``longest`` operations that
        the arc search finds with every range at least twice ``floor`` wide
        (:meth:`~feederkit.planning.arcs.ArcSpace.shortest_chain`), recorded as this
        search's choices (not as exact lengths: a chain under a floor need not be a
        shortest one); None when it finds none for some root (then no chain keeps
        ``floor``), -inf when one could not be followed on the machine."""
        self._arcs = space
        for r in roots:
            if self.p.is_goal(r):
                continue
            ranges = space.shortest_chain(r, longest, self.deadline.check, floor)
            if ranges is None:
                return None
            if not self._record_chain(r, ranges, exact=False):
                self.arc_misses += 1
                return -math.inf
        return _chain_margin(self, roots)

    def weighted_chains(self, roots, deadline: Deadline) -> int | None:
        """The longest over ``roots`` of the shortest chains weighted A* over the parts' arc
        hulls finds with each of ``CHAIN_WEIGHTS`` in turn under ``deadline``, recorded as
        this search's choices (not as exact lengths); None where the arc search does not
        apply or some root got no chain in time.

        A first plan when the exact search runs out: both landings of the random
        1000-point outline at 3 % on the ideal model, 26 operations after the first
        alignment (the shortest) in 0.3 s with weight 1.25; of the near-round 64-gon, 28
        (one above) in 0.14 s, then 27 (the shortest) with 1.1 in 1.4 s, where the widening
        beams over sets gave 31 in a 10 s run of the command.
        """
        space = self.arc_space()
        if space is None:
            return None
        best: dict[int, int] = {}
        todo = [r for r in roots if not self.p.is_goal(r)]
        with contextlib.suppress(Timeout):
            for weight in CHAIN_WEIGHTS:
                for r in todo:
                    ranges = space.shortest_chain(r, None, deadline.check, 0.0, weight)
                    if ranges is None:
                        return None  # none at all
                    if len(ranges) < best.get(r, len(ranges) + 1) and self._record_chain(
                        r, ranges, exact=False
                    ):
                        best[r] = len(ranges)
        if any(r not in best for r in todo):
            return None
        return max(best.values(), default=0)

    def _record_chain(
        self, mask: int, ranges: list[list[tuple[float, float]]], exact: bool = True
    ) -> bool:
        """Record the chain of ``ranges`` (the ranges of rotations of each step,
        :meth:`~feederkit.planning.arcs.ArcSpace.shortest_chain`) from ``mask`` as each of
        its sets' plan (with ``exact``, as their exact lengths too). Each step takes the
        widest range of its set whose image is that of one of its cells inside one of the
        step's ranges: any rotation there keeps the set inside the chain's arcs. False
        (nothing recorded) when some step has no such range or the chain ends outside a
        goal."""
        steps = []
        cur = mask
        for step in ranges:
            act = self._widest_inside(cur, step)
            if act is None:
                return False
            steps.append((cur, act))
            cur = act.action.image
        if not self.p.is_goal(cur):
            return False
        for t, (cur, act) in enumerate(steps):
            k = len(steps) - t
            if exact:
                self.exact[cur] = k
            self.ub[cur] = min(self.ub.get(cur, k), k)
            if cur not in self.choice or self.choice[cur][0] > k:
                self.choice[cur] = (k, act)
        return True

    def _widest_inside(self, mask: int, ranges: list[tuple[float, float]]) -> Act | None:
        """The action of the widest range of ``mask`` whose image is that of one of its
        cells inside one of the rotation ranges ``[lo, hi)`` (None: no cell there, or each
        image holds the set)."""
        choices = self.p.choices
        widest = {c[2]: c for c in choices.cells(mask, False)}  # the widest per image
        best: tuple[float, Act] | None = None
        for clo, chi, img in choices.fixed_cells(mask):
            mid = (clo + chi) / 2.0
            if not any((mid - lo) % 360.0 < hi - lo for lo, hi in ranges):
                continue
            cell = widest.get(img)
            if cell is None or (best is not None and cell[1] - cell[0] <= best[0]):
                continue
            act = choices.act(mask, cell)
            if act is not None:  # its image holds the set: no shortest chain does that
                best = (cell[1] - cell[0], act)
        return None if best is None else best[1]

    def part_lengths(self, mask: int) -> tuple[int, int]:
        """The largest and the sum, over the machine's parts, of the backchaining length of
        the set's states of that part: how far the set is from a goal by each part's chain
        (the largest is :meth:`part_bound`). Memoised: the beams meet each image often."""
        out = self._lengths.get(mask)
        if out is not None:
            return out
        if self._parts is None:
            self._make_tables()
        big = total = 0
        for part, tables, chain in self._parts:
            sub = mask & part
            if sub & (sub - 1):
                m = 0
                for k, table in enumerate(tables):
                    byte = sub >> (8 * k) & 255
                    if byte:
                        m |= table[byte]
                v = chain.length(m)  # type: ignore[attr-defined]
                if v < float("inf"):
                    big, total = max(big, int(v)), total + int(v)
        out = self._lengths[mask] = (big, total)
        return out

    def part_lengths_of(self, masks: list[int]) -> None:
        """:meth:`part_lengths` of many sets at once, into its memo: each part's states of
        every set as one boolean matrix and each part's backchaining lengths by array
        operations (:meth:`~feederkit.planning.sensorless.Backchain.lengths_of`), the same
        numbers. A beam meets a few hundred new images per set it expands, where one at a
        time each cost a loop over its members."""
        memo = self._lengths
        new = [m for m in dict.fromkeys(masks) if m not in memo]
        if len(new) < VECTOR_MIN:
            for m in new:
                self.part_lengths(m)
            return
        if self._columns is None:
            self._make_tables()
        inside = bit_rows(new, self.p.machine.n)
        big = np.zeros(len(new), dtype=np.int64)
        total = np.zeros(len(new), dtype=np.int64)
        for cols, chain in self._columns:
            sub = inside[:, cols]
            v = chain.lengths_of(sub)  # type: ignore[attr-defined]
            keep = (sub.sum(axis=1) >= 2) & np.isfinite(v)
            v = np.where(keep, v, 0.0).astype(np.int64)
            big = np.maximum(big, v)
            total += v
        for m, b, t in zip(new, big.tolist(), total.tolist(), strict=True):
            memo[m] = (b, t)

    def _make_tables(self) -> None:
        """The parts' tables of :meth:`part_lengths` and :meth:`part_lengths_of`."""
        chains = part_chains(self.p)
        self._parts = [(part, _byte_tables(local), chain) for part, local, chain in chains]
        self._columns = [
            (np.array(sorted(local, key=local.__getitem__), dtype=np.intp), chain)
            for _part, local, chain in chains
        ]

    def _known(self, mask: int, k: int) -> bool | None:
        """As :meth:`WorstCase._known`, refuting a set whose part bound exceeds ``k``
        before any search (A* itself has no budget of operations)."""
        if k > 0 and mask not in self.exact and not self.p.is_goal(mask):
            bound = self.part_bound(mask)
            if bound > k:
                self.lb[mask] = max(self.lb.get(mask, 1), bound)
                return False
        return super()._known(mask, k)

    def share_heuristic(self, other: QuietWorst) -> None:
        """Use ``other``'s tables of the parts' backchaining lengths (the same machine; a
        margin floor does not change them)."""
        if other._parts is None or other._columns is None:
            other._make_tables()
        self._parts, self._lengths = other._parts, other._lengths
        self._columns = other._columns

    def part_bound(self, mask: int) -> int:
        """:meth:`WorstCase.part_bound` from the memoised :meth:`part_lengths` (A*'s
        heuristic)."""
        return self.part_lengths(mask)[0]

    def bounds_ahead(self, masks: list[int]) -> None:
        """:meth:`part_lengths_of` (A* asks :meth:`part_bound` of each image of the set it
        expands)."""
        self.part_lengths_of(masks)


def _byte_tables(local: dict[int, int]) -> list[list[int]]:
    """For each byte of a machine's mask, the local mask of each of its 256 values (the
    states of ``local``, renumbered)."""
    tables = []
    for k in range((max(local, default=0) >> 3) + 1):
        table = [0] * 256
        for i, j in local.items():
            if i >> 3 == k:
                bit = 1 << (i & 7)
                for v in range(256):
                    if v & bit:
                        table[v] |= 1 << j
        tables.append(table)
    return tables


def _always(_mask: int) -> bool:
    return True


def beam_chain(
    worst: QuietWorst, mask: int, width: int, deadline: Deadline
) -> tuple[int | None, bool]:
    """The length of a sensorless plan of ``mask`` found by a beam over sets: level by level,
    the images of the level's sets not met before, of which the ``width`` nearest a goal by
    :meth:`QuietWorst.part_lengths` (the largest, then the sum, then the fewest states) make
    the next level, and whether some level was cut to the width (if not, the search was
    breadth-first and the length is the set's own); None when a level is empty first. The
    path's actions are recorded in ``worst``'s ``ub`` and ``choice`` where shorter than what
    they hold (each a plan of its set within the rest of the path). Polls ``deadline`` once
    per set expanded (Timeout).

    Only for sets no reading can shorten (:class:`QuietWorst`): the path's sets are images.
    """
    p = worst.p
    if p.is_goal(mask):
        return 0, False
    useful = p.min_margin == 0.0
    parent: dict[int, tuple[int, tuple[float, float, int]] | None] = {mask: None}
    level = [mask]
    found = None
    cut = False
    while level and found is None:
        scored: dict[int, tuple[int, int, int]] = {}
        for cur in level:
            deadline.check()
            cells = p.choices.cells(cur, useful)
            worst.part_lengths_of([c[2] for c in cells if c[2] not in parent])
            for cell in cells:
                img = cell[2]
                if img in parent:
                    continue
                parent[img] = (cur, cell)
                if p.is_goal(img):
                    found = img
                    break
                big, total = worst.part_lengths(img)
                scored[img] = (big, total, img.bit_count())
            if found is not None:
                break
        cut = cut or len(scored) > width
        level = sorted(scored, key=scored.__getitem__)[:width]
    if found is None:
        return None, cut
    k = 0
    step = found
    while (link := parent[step]) is not None:
        prev, cell = link
        k += 1
        # chain_plan follows ``choice``: each entry's image has an entry no longer than it
        # (or is a goal), so an entry is replaced only by a shorter one.
        if worst.choice.get(prev, (k + 1,))[0] > k:
            act = p.choices.act(prev, cell, exact=not useful)
            assert act is not None  # the image does not contain the set
            worst.ub[prev] = min(worst.ub.get(prev, k), k)
            worst.choice[prev] = (k, act)
        step = prev
    return k, cut


def widening_chains(worst: QuietWorst, roots, deadline: Deadline) -> int | None:
    """The longest over ``roots`` of the shortest :func:`beam_chain` lengths found by beams
    ``FIRST_WIDTH``, then ``WIDTH_FACTOR`` times as wide, and so on, until ``deadline``
    passes, each root meets its proven bound (``worst.lb``) or a beam kept every set; None
    when some root had no plan by then. The roots' plans are in ``worst.choice``.

    Both landings of the random 1000-point outline at 3 % on the ideal model (a root of 64
    states), traced in ``plan`` under a 60 s limit: widths 1 to 128 found 34, 33, 30, 31,
    29, 27, 27 and 26 operations after the first alignment in 17 s; 256 ran out (weighted A*,
    the heuristic doubled, found 33 in 2 s; the parts' chains in turn 38).
    """
    best: dict[int, int] = {}
    todo = [r for r in roots if not worst.p.is_goal(r)]
    width = FIRST_WIDTH
    with contextlib.suppress(Timeout):
        while todo:
            for r in list(todo):
                k, cut = beam_chain(worst, r, width, deadline)
                if k is not None and k < best.get(r, k + 1):
                    best[r] = k
                if not cut or (r in best and best[r] <= worst.lb.get(r, 1)):
                    todo.remove(r)  # searched breadth-first, or at its bound
            width *= WIDTH_FACTOR
    if any(not worst.p.is_goal(r) and r not in best for r in roots):
        return None
    return max(best.values(), default=0)


MARGIN_STEP_DEG = 0.01
"""The margin bisection of :func:`widest_chain` stops when its interval is this narrow."""


@dataclass(frozen=True)
class WidestChain:
    """What :func:`widest_chain` found: a search whose choices hold the chains (None: none
    found above the floor), their smallest margin (deg), and what cut the bisection short
    (a Timeout's reason; None when it ran to ``MARGIN_STEP_DEG``)."""

    search: QuietWorst | None
    margin: float
    cut_by: str | None


def widest_chain(
    worst: QuietWorst, roots, longest: int, floor: float, deadline: Deadline
) -> WidestChain:
    """Chains of every root within ``longest`` operations keeping the largest smallest margin
    above ``floor`` (deg) that the bisection finds under ``deadline``.

    The margin is the plan's tie-break after the length (docs/planning.md, "Which plan among
    the shortest"), decided as a feasibility question: "within ``longest`` with every
    margin at least ``m``?" is A* over sets of ``worst``'s problem with that margin floor
    (its heuristic, ``worst``'s tables, stays consistent: a floor only takes actions away),
    bisected between the largest margin found and one that failed (at first the roots'
    widest range: a chain starts with one of its root's), until the interval is
    ``MARGIN_STEP_DEG`` wide or ``deadline`` passes. A set's chain keeps the margin of its
    own ranges for the reading sets that follow it (a subset's range holding the same
    rotation is no narrower), and a reading that fits every state leaves the whole image, so
    no plan keeps more than the best chain.
    """
    problem = worst.p
    found: QuietWorst | None = None
    lo = kept = floor
    # A chain starts with one of its root's ranges: none keeps more than the widest of them.
    hi = min(
        (
            max(((c[1] - c[0]) / 2.0 for c in problem.choices.cells(r, False)), default=floor)
            for r in roots
            if not problem.is_goal(r)
        ),
        default=floor,
    )
    cut_by = None
    space = worst.arc_space() if problem.min_margin == 0.0 else None
    undecided = False  # a probe the search over sets left open within SET_PROBE_POLLS
    try:
        while hi - lo > MARGIN_STEP_DEG:
            mid = (lo + hi) / 2.0
            probe = deadline
            if space is not None:
                # The arc search with every range at least 2 * mid wide: where it finds no
                # chain none keeps mid; where its chains keep mid they answer; else (a
                # set's ranges are narrower than its arcs') the search over sets decides,
                # within SET_PROBE_POLLS (past them the probe counts as failed, unproven).
                search = QuietWorst(problem, deadline)
                margin = search.arc_chains(space, roots, longest, mid)
                if margin is None:
                    hi = mid
                    continue
                if margin >= mid:
                    if margin > kept:
                        found, kept = search, margin
                    lo = margin
                    continue
                probe = WorkBudget(deadline, SET_PROBE_POLLS)
            search = QuietWorst(problem.with_margin(mid), probe)
            search.share_heuristic(worst)
            try:
                fits = all(search.within(r, longest) for r in roots)
            except Timeout as exc:
                if probe is deadline or exc.reason != "work":
                    raise
                fits, undecided = False, True
            finally:
                if probe is not deadline:
                    deadline.polls += probe.polls  # the probe's work is the bisection's
            if fits:
                found, kept = search, _chain_margin(search, roots)
                lo = max(kept, mid)
            else:
                hi = mid
    except Timeout as exc:
        cut_by = exc.reason
    if cut_by is None and undecided:
        cut_by = "work"
    return WidestChain(found, kept, cut_by)


SET_PROBE_POLLS = 2_000
"""A margin probe the arc search leaves open (its chain keeps less than the probe) gets the
search over sets for at most this many polls (about a second); past them :func:`widest_chain`
takes the probe as failed and says the margin is not proven the largest."""


def _chain_margin(search: WorstCase, roots) -> float:
    """The smallest margin of the actions on the chains ``search`` chose from ``roots``."""
    out = math.inf
    seen: set[int] = set()
    todo = [r for r in roots if r in search.choice]
    while todo:
        mask = todo.pop()
        if mask in seen or search.p.is_goal(mask):
            continue
        seen.add(mask)
        act = search.choice[mask][1]
        out = min(out, act.action.margin)
        todo.append(act.action.image)
    return out


def chain_plan(
    problem: Problem, worst: WorstCase, roots, root_branches, deadline: Deadline
) -> Step:
    """The plan that follows ``worst``'s chosen actions from the roots, each reading branch
    of a step going on with the subplan of the step's whole image (one step per operation),
    built under ``deadline`` (Timeout).

    Every root and each image on the way must have a chosen action (``worst.choice``, as
    :func:`beam_chain` and :meth:`~feederkit.planning.andor.WorstCase.sensorless_length`
    leave them) or be a goal; a reading leaves a subset of the image, and a subset of a goal
    is a goal.
    """
    choice = worst.choice

    def expand(mask: int):
        if problem.is_goal(mask):
            return Leaf(mask)
        act = choice[mask][1]
        img = act.action.image
        return act.action, [
            (b, b.mask if problem.is_goal(b.mask) else img)
            for b in problem.readings.image_branches(img)
        ]

    def root_of(mask: int) -> int:
        if problem.is_goal(mask):
            return mask
        root = next((r for r in roots if mask & ~r == 0 and r in choice), None)
        if root is None:
            raise AssertionError("chain_plan: a root branch lies in no root with a chosen action")
        return root

    keys = {b.mask: root_of(b.mask) for b in root_branches}
    made = build_dag(list(dict.fromkeys(keys.values())), expand, deadline)
    return root_step(((b, made[keys[b.mask]]) for b in root_branches), deadline)
