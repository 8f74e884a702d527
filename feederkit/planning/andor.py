"""Minimum worst-case plan length by AND/OR search over sets of states (section 6.1).

A node is a set of states; an OR choice is a representative action; its AND children are the
sets the reading can leave. ``length(mask)`` is the smallest number of further push-align
operations that orient every state of ``mask`` (0 for a goal). The search is depth-first
iterative deepening with memoised proven bounds per set (a set that failed with ``k`` steps
is never retried with ``k``), so repeated sets and repeated depths cost nothing; lengths being
monotone under subsets (no margin floor), a set holding a set refuted with ``k`` steps is
refuted with ``k`` unopened (:mod:`~feederkit.planning.refuted`), and a set inside a set
solved within ``k`` is solved within ``k`` the same way (:mod:`~feederkit.planning.solved`).

Where readings carry no information (every set reachable from a set reads alike:
:meth:`~feederkit.planning.readings.Readings.carries_no_information`) the AND/OR tree is a
path, and the set's length is a shortest path over sets (section 4: breadth-first, or A*
with each part's backchaining length as the bound, Goldberg 1993), which also proves every
set on the path found and a lower bound for every set it met.

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 6.1 (AND/OR search).
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator
from dataclasses import replace

from feederkit.angles import ActionRange
from feederkit.machine import PushAlignMachine, members
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.problem import Act, Problem
from feederkit.planning.refuted import RefutedSets
from feederkit.planning.solved import SolvedSets

__all__ = ["Deadline", "Timeout", "WorstCase"]

PAIR_BOUND_DEPTH = 4
"""The pair lower bound is used once a set whose length is searched (a root) has a hardest
pair of this many operations, or its search deepens to this budget: a shallower proof ends
before the pairs' own searches pay (a 98-state mix of length 4: 0.05 s without them, 0.12 s
with), a deeper one gains (a 98-state mix of length 6: 11,066 sets instead of 26,671, 3.3 s
instead of 7.4)."""
PAIR_BOUND_SETS = 2000
"""The pair lower bound is also used once the searches have opened this many sets: a
proof long in work, however shallow its budget."""
PAIR_BOUND_STATES = 1024
"""The pair lower bound is used on machines with at most this many states (a pair's length
is searched when a set holding it first asks; the table has n^2 entries)."""


class WorstCase:
    """Exact minimum worst-case lengths of sets, memoised.

    ``lb`` and ``ub`` are proven bounds per set; ``choice`` keeps, per set, the action that
    first proved the smallest bound (with that bound), so some plan can always be rebuilt.
    ``pair_bound=False``: no hardest-pair bound (:meth:`pair_bound` answers 0), for searches
    that are themselves about pairs.

    Without a margin floor lengths are monotone under subsets, so a set holding a set the
    search refuted at a depth is refuted there too (:mod:`~feederkit.planning.refuted`);
    ``SUBSET_REFUTES`` False turns that off for searches whose failures are not proofs. A set
    inside a set solved within a depth is solved within it, following the larger set's plan
    (:mod:`~feederkit.planning.solved`; its ``choice`` is the larger set's action, whose
    rotation sends it inside the larger set's image): a plan is a plan in any search.
    ``SUBSET_SOLVES`` False turns that off for searches whose plans follow each set's own
    action.
    """

    SUBSET_REFUTES = True
    SUBSET_SOLVES = True

    def __init__(
        self, problem: Problem, deadline: Deadline | None = None, pair_bound: bool = True
    ) -> None:
        self.p = problem
        self.lb: dict[int, int] = {}
        self.ub: dict[int, int] = {}
        self.choice: dict[int, tuple[int, Act]] = {}
        self.exact: dict[int, int] = {}
        self.never: set[int] = set()
        self.deadline = deadline or Deadline(None)
        self._quiet = getattr(problem, "carries_no_information", None)
        self._chains: list[tuple[int, dict[int, int], object]] | None = None
        self._chain_of: dict[int, tuple[int, dict[int, int], object]] = {}
        # None: not yet known whether the pair bound applies (``pair_bound``); False: never.
        self._pairs: _PairLengths | None | bool = None if pair_bound else False
        self._pair_memo: dict[int, int] = {}
        self._deep = False  # pair bounds pay: PAIR_BOUND_DEPTH or PAIR_BOUND_SETS reached
        self._opened = 0  # sets the searches have opened (frames pushed)
        machine = getattr(problem, "machine", None)
        # Lengths are monotone under subsets (no margin floor): both indexes are sound.
        monotone = getattr(problem, "min_margin", None) == 0.0
        monotone = monotone and isinstance(machine, PushAlignMachine)
        self._refuted = RefutedSets(machine.n) if monotone and self.SUBSET_REFUTES else None
        self._solved = SolvedSets(machine.n) if monotone and self.SUBSET_SOLVES else None

    @property
    def opened(self) -> int:
        """How many sets the searches have opened below the sets asked (frames pushed)."""
        return self._opened

    def holds_plan(self, mask: int, k: int) -> bool:
        """Whether the memo already holds a plan of ``mask`` within ``k`` operations, without
        a search: a plan the search found (``ub``, its action in ``choice``). An exact
        length alone is not one (another algorithm's, recorded without its action)."""
        return self.p.is_goal(mask) or (
            k > 0 and self.ub.get(mask, k + 1) <= k and mask in self.choice
        )

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
        if mask in self.never:
            return False
        if self._quiet is not None and self._quiet(mask):
            e = self.sensorless_length(mask, k)
            return e is not None and e <= k
        pb = self.pair_bound(mask)
        if pb > k:
            self.lb[mask] = max(self.lb.get(mask, 1), pb)
            return False
        return None

    def pair_bound(self, mask: int, force: bool = False) -> int:
        """A lower bound on the length of ``mask``: its hardest pair's length (a subset
        needs no more operations). Only on the ideal model with readings, no margin floor
        and at most ``PAIR_BOUND_STATES`` states, once the search is deep (a set whose
        length is searched has a pair bound or a budget of ``PAIR_BOUND_DEPTH``, or the
        searches have opened ``PAIR_BOUND_SETS`` sets) or when ``force``d (each pair's
        length by the same search on its reading branches, when a set holding it first
        asks); 0 otherwise."""
        if not (self._deep or force):
            return 0
        pairs = self._pairs
        if pairs is None:
            pairs = self._pairs = _PairLengths.of(self.p) or False
        if pairs is False or mask & (mask - 1) == 0:
            return 0
        v = self._pair_memo.get(mask)
        if v is None:
            v = 0
            table = pairs.table
            idx = members(mask)
            for a, i in enumerate(idx):
                row = table[i]
                for j in idx[a + 1 :]:
                    x = row[j]
                    if x < 0:
                        x = pairs.length(i, j, self.deadline)
                    if x > v:
                        v = x
            self._pair_memo[mask] = v
        return v

    def sensorless_length(self, mask: int, cap: int | None = None) -> int | None:
        """The length of a set no reading can split, by a shortest-path search over sets
        (None: no plan orients it); with ``cap``, ``cap + 1`` as soon as the length is known
        to exceed ``cap``.

        Every action then has one branch, its image, so the minimum worst-case length is a
        shortest path to a goal (section 4): A* with :meth:`part_bound` as the heuristic,
        breadth-first search where it is 0. Sets on the path found are proven with their
        actions (``choice``, so a plan can be rebuilt); a set met at depth ``d`` of a search
        of length ``L`` needs at least ``L - d``. Polls the deadline once per set expanded.
        When the deadline passes or the least f-value still open exceeds ``cap``, that
        value is recorded as the set's lower bound.
        """
        e = self.exact.get(mask)
        if e is not None:
            return e
        if self.p.is_goal(mask):
            return 0
        choices = self.p.choices
        # Without a margin floor a set's image containing it cannot help (lengths are
        # monotone under subsets); with one every range counts (Choices.search_actions).
        useful = self.p.min_margin == 0.0
        bound = self.part_bound
        parent: dict[int, tuple[int, tuple[float, float, int]] | None] = {mask: None}
        met = {mask: 0}
        # A* over sets (unit steps; the per-part bound is consistent: one operation lowers a
        # part's backchaining length by at most one), ties to the deeper set.
        heap = [(bound(mask), 0, mask)]
        done: set[int] = set()
        found = None
        depth = 0
        reached = 0  # the least f-value still open: a lower bound on the length
        while heap:
            f, neg, cur = heapq.heappop(heap)
            if cur in done:
                continue
            if self.p.is_goal(cur):
                found, depth = cur, -neg
                break
            done.add(cur)
            # The heuristic is consistent (a set no plan orients counts 0, but no shortest
            # path passes through one), so a set on a shortest path is open with its least
            # f-value, which is at most the length: what the search has proved.
            reached = max(reached, f)
            if cap is not None and reached > cap:
                self.lb[mask] = max(self.lb.get(mask, 1), reached)
                return cap + 1
            try:
                self.deadline.check()
            except Timeout:
                self.lb[mask] = max(self.lb.get(mask, 1), reached)
                raise
            g = 1 - neg
            cells = choices.cells(cur, useful)
            self.bounds_ahead([c[2] for c in cells])
            for cell in cells:
                img = cell[2]
                old = met.get(img)
                if old is not None and old <= g:
                    continue
                met[img] = g
                parent[img] = (cur, cell)
                heapq.heappush(heap, (g + bound(img), -g, img))
        if found is None:
            self.never.add(mask)
            return None
        # A set met at depth d needs at least depth - d (else ``mask`` would need fewer).
        for t, d in met.items():
            if depth - d > self.lb.get(t, 1) and t not in self.exact:
                self.lb[t] = depth - d
        step = found
        k = 0
        while True:
            link = parent[step]
            if link is None:
                break
            prev, cell = link
            k += 1
            act = choices.act(prev, cell, exact=not useful)
            assert act is not None  # its one branch, the image, does not contain the set
            self.exact[prev] = k
            self.ub[prev] = min(self.ub.get(prev, k), k)
            if prev not in self.choice or self.choice[prev][0] > k:
                self.choice[prev] = (k, act)
            step = prev
        return depth

    def bounds_ahead(self, masks: list[int]) -> None:
        """Make :meth:`part_bound` of many sets at once, ahead of their asking, where a
        subclass can do so more cheaply than one at a time (A* asks it of every image of
        the set it expands); here nothing."""

    def part_bound(self, mask: int) -> int:
        """A lower bound on the length of ``mask``: the largest, over the machine's parts,
        of the backchaining length of its states of that part (Goldberg 1993; a subset needs
        no more operations, and a part's states only reach states of that part). 0 for
        parts that are not push functions (outcome sets, or goals other than symmetry)."""
        if self._chains is None:
            self._chains = part_chains(self.p)
            self._chain_of = {i: c for c in self._chains for i in c[1]}
        chains = self._chains
        if mask.bit_count() < len(chains):
            # Fewer states than parts (a large mix): only the parts the set meets.
            chain_of = self._chain_of
            chains = list({id(c): c for i in members(mask) if (c := chain_of.get(i))}.values())
        best = 0
        for part, local, chain in chains:
            sub = mask & part
            if sub & (sub - 1):
                m = 0
                for i in members(sub):
                    m |= 1 << local[i]
                v = chain.length(m)  # type: ignore[attr-defined]
                if best < v < float("inf"):
                    best = int(v)
        return best

    def within(self, mask: int, k: int) -> bool:
        """Whether ``mask`` can be oriented in at most ``k`` operations.

        A depth-first AND/OR search kept on an explicit stack (a frame per open set: its
        budget, its action iterator, the action being tried and its next child), so a deep
        budget never meets Python's recursion limit. An action with a branch the memo
        already refutes fails at once; else its branches are searched smallest first (the
        cheapest to settle, to success or refutation: on the benchmark's hard sensor cases
        a half to a sixth of the sets the largest first visits).
        """
        known = self._known(mask, k)
        if known is None and self.holds_refuted(mask, k):
            known = False
        if known is None and self.inside_solved(mask, k):
            known = True
        if known is not None:
            return known
        self.deadline.check()
        # frame: [mask, k, actions, act or None, index of the next child]
        stack: list[list] = [[mask, k, self.actions_of(mask), None, 0]]
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
                    # A child the memo already refutes refutes the action without a search.
                    if any(self._known(c, fk - 1) is False for c in act.children):
                        act = None
                        continue
                # The smallest child first: the cheapest to search, to success or refutation.
                children = act.children[::-1]
                while ci < len(children):
                    c = children[ci]
                    known = self._known(c, fk - 1)
                    if known is None and self.holds_refuted(c, fk - 1):
                        known = False
                    if known is None and self.inside_solved(c, fk - 1):
                        known = True
                    if known is None:
                        f[3], f[4] = act, ci
                        self.deadline.check()
                        self._opened += 1
                        if self._opened >= PAIR_BOUND_SETS:
                            self._deep = True
                        stack.append([c, fk - 1, self.actions_of(c), None, 0])
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
                if self._solved is not None:
                    self._solved.add(fmask)
                result = True
            else:
                self.lb[fmask] = fk + 1
                if self._refuted is not None:
                    self._refuted.add(fmask, fk + 1)
                result = False
            if stack:
                parent = stack[-1]
                if result:
                    parent[4] += 1  # that child is within: the parent's next child
                else:
                    parent[3] = None  # the parent's action failed: its next action
        return result

    def inside_solved(self, mask: int, k: int) -> bool:
        """Whether ``mask`` lies inside a set the search solved within ``k`` (it is then
        solved too: its ``ub`` and ``choice`` become that set's), asked before the search
        opens it."""
        if self._solved is None:
            return False
        choice = self.choice

        def fits(s: int) -> bool:
            entry = choice.get(s)
            return entry is not None and entry[0] <= k

        s = self._solved.holder(mask, fits)
        if s is None:
            return False
        entry = choice[s]
        self.ub[mask] = min(self.ub.get(mask, entry[0]), entry[0])
        if mask not in choice or choice[mask][0] > entry[0]:
            choice[mask] = entry
        return True

    def holds_refuted(self, mask: int, k: int) -> bool:
        """Whether ``mask`` holds a set the search refuted within ``k`` (it is then
        refuted too, and its lower bound kept), asked before the search opens it."""
        if self._refuted is None:
            return False
        lb = self._refuted.bound(mask, k + 1)
        if lb is None:
            return False
        self.lb[mask] = max(self.lb.get(mask, 1), int(lb))
        return True

    def actions_of(self, mask: int) -> Iterator[Act]:
        """The actions :meth:`within` tries for a set, in order: every one the length search
        needs (``Choices.search_actions``); a restricted search overrides it."""
        return self.p.choices.search_actions(mask, self.deadline.limits)

    def length(self, mask: int, limit: int | None = None) -> int:
        """The minimum worst-case number of operations for ``mask`` (iterative deepening).

        Raises ValueError when ``limit`` is given and exceeded.
        """
        if self.p.is_goal(mask):
            return 0
        e = self.exact.get(mask)
        if e is not None:
            return e
        if self._quiet is not None and self._quiet(mask):
            e = self.sensorless_length(mask)
            if e is None:
                raise ValueError("no plan orients the set")
            if limit is not None and e > limit:
                raise ValueError(f"no plan within {limit} operations")
            return e
        # The set's own hardest pair (a root's, from longest_root) says whether the
        # search will be deep enough for every set's pair bound to pay.
        k = max(self.lb.get(mask, 1), self.pair_bound(mask, force=True))
        while True:
            if k >= PAIR_BOUND_DEPTH:
                self._deep = True
            if self.within(mask, k):
                break
            k += 1
            if limit is not None and k > limit:
                raise ValueError(f"no plan within {limit} operations")
        self.exact[mask] = k
        return k


def part_chains(problem: Problem) -> list[tuple[int, dict[int, int], object]]:
    """Per part whose states form a push function with the goal its symmetry: the mask of
    its states, their local numbers and the part's backchaining table."""
    from feederkit.planning.sensorless import Backchain, push_circle  # sensorless imports us

    machine = getattr(problem, "machine", None)
    if not isinstance(machine, PushAlignMachine) or not machine.deterministic:
        return []
    out = []
    for p in sorted({s.part for s in machine.states}):
        idx = [i for i, s in enumerate(machine.states) if s.part == p]
        local = {g: k for k, g in enumerate(idx)}
        part = sum(1 << i for i in idx)
        if any(t not in local for i in idx for t in machine.targets[i]):
            continue
        maps = tuple(
            tuple(
                ActionRange(r.lo, r.hi, local[t])
                for r, t in zip(machine.action_maps[i], machine.targets[i], strict=True)
            )
            for i in idx
        )
        states = tuple(replace(machine.states[i], part=0) for i in idx)
        sub = PushAlignMachine((machine.part_names[p],), states, maps, machine.sensor)
        insep = tuple(sum(1 << local[j] for j in members(problem.insep[i] & part)) for i in idx)
        circle = push_circle(sub, insep)
        if circle is not None:
            out.append((part, local, Backchain(circle)))
    return out


class _PairLengths:
    """Each pair's minimum worst-case length, searched when first asked (``table[i][j]``,
    -1 until then): the AND/OR search on the pair's reading branches, with its own memo and
    no pair bound inside. Most pairs are told apart or merged by the first action tried. A
    pair is bounded by its reading branches' lengths: a set the search meets has had its
    reading, and under the components rule a pair inside a larger component can still read
    apart alone."""

    def __init__(self, problem: Problem) -> None:
        self.p = problem
        n = problem.machine.n
        self.table = [[-1] * n for _ in range(n)]
        self.search = WorstCase(problem, None, pair_bound=False)

    @classmethod
    def of(cls, problem: Problem) -> _PairLengths | None:
        """The pair table of ``problem``, or None where the pair bound does not apply (see
        :meth:`WorstCase.pair_bound`)."""
        machine = getattr(problem, "machine", None)
        if (
            not isinstance(machine, PushAlignMachine)
            or not machine.deterministic
            or problem.min_margin != 0.0
            or getattr(problem, "sensorless", True)
            or not 2 <= machine.n <= PAIR_BOUND_STATES
        ):
            return None
        return cls(problem)

    def length(self, i: int, j: int, deadline: Deadline) -> int:
        """The pair's length, searched under ``deadline`` (the asking search's)."""
        search = self.search
        search.deadline = deadline
        v = max(search.length(c) for c in self.p.readings.children((1 << i) | (1 << j)))
        self.table[i][j] = self.table[j][i] = v
        return v
