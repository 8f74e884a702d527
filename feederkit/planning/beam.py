"""Anytime plans by beam search over sets: the AND/OR search restricted to a set's few best
actions, widened until the time runs out or the plan meets its proven lower bound.

When the exact search (section 6.1) cannot prove a length in time, some plan is still
wanted, and a short one. The same depth-first search of
:class:`~feederkit.planning.andor.WorstCase` is run with only the ``width`` actions of each
set whose reading branches are smallest (the largest branch, then their total): a plan
it finds is a plan, and the restricted space is small enough to search to depth 10 in
seconds where the full one is not. Until a first plan, its targets grow by steps (the bound,
then 1, 2, 4, ... more); then each target is one less than the best plan so far. Widths
double; each one looks only for a plan shorter than the best so far, so the answer improves
toward the bound (greedy best-first AND/OR search with a beam, as in heuristic search over
AND/OR graphs; Nilsson 1980, chapter 3).

A restricted failure proves nothing about the machine, so a search's own lower bounds stay
in that search; its plans (``ub`` and ``choice``) carry over to the next, wider one.

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 6.1 (AND/OR search).
Nilsson, N. J. (1980). Principles of Artificial Intelligence. Tioga, chapter 3 (AND/OR
graph search).
"""

from __future__ import annotations

import time
from collections.abc import Iterator

from feederkit.planning.andor import WorstCase
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.choices import children_key
from feederkit.planning.problem import Act, Problem

FIRST_WIDTH = 4
"""The first search tries this many actions per set; each next one twice as many."""

CHEAP_POLLS = 2_000
"""Until a first plan, a beam that fails at a target within this many polls of its deadline
(about half a second's work) is cheap to fail: the beam twice as wide is tried at the same
target before the target grows (:func:`beam_plan`)."""

SHALLOW_SHARE = 0.25
"""Until a first plan, a target below ``cap`` may take at most this share of the time left
for a first plan; past it the target grows as if the beam had failed there. A shallow target
that fails slowly must not take the time of the deeper one that succeeds (the 50-part mix at
5 % under 1 degree: width 4 failed at 8 operations after 11.6 s of the 19 s left, and the
search at 12 ran out of time)."""

SMALL_SET = 4
"""A set of at most this many states keeps every action in a beam. Its few actions all leave
branches about as small, so the beam's order (:func:`branch_key`) picks among them by the
image and the width alone, and can keep only actions that never resolve it: on the 50-part
mix at 5 % under 1 degree (lumped goal) three states with an exact length of 3 had no plan in
the width-4 beam within 27 operations, and no width-4 plan of the mix existed within 100;
with every action of the small sets, 10 operations at a target of 10."""

SMALL_DEPTH = 12
"""Under uncertainty, a set of at most ``SMALL_SET`` states that has no plan within this many
operations (and no proven bound above it) is taken, in a beam, to have none
(``BeamSearch.never``; the beam is then not exhaustive). A set reached by a
rotation can hold a pair no strong plan orients; a deep target asks it at every budget below
(the 100-part mix at 5 % under 1 degree: 5,400 sets, most of them failing at budgets of 80-99,
and no width-4 plan within 100 after 12 s)."""

PROBE_POLLS = 4_000
"""The beam twice as wide tried at the same target gets at most this many polls: past them
the target grows, with the beam that failed cheaply."""

DESCENT_SHARE = 0.5
"""A first plan found under a first plan's deadline is shortened by the same beam, one
operation at a time, until the beams' own deadline or within this share of the time then
left to the first plan's deadline, whichever is later; no wider beam is tried past the
beams' own deadline. With a plan in hand each shorter target costs little (the beam's memo
holds the sets the plan met): on the 50-part mix at 5 % under 1 degree, at a 600 s limit, a
first plan of 12 operations after its first alignment at a target of 12, then 11, 10 and 9
in 0.6, 0.7 and 1.5 s. At a 60 s limit the first plan came after the beams' deadline (the
command answered 14), or, once sets inside solved ones were taken as solved, 0.3 s before
it (the command answered 12; with the descent the targets 13, 12, 11 and 10 then took
1.6-1.9 s each)."""


def branch_key(act: Act) -> tuple[int, int]:
    """The beam's order of a set's actions: the smallest largest branch, then the fewest
    states over all branches (the most a reading can tell apart)."""
    return children_key(act.children)


class BeamSearch(WorstCase):
    """:class:`~feederkit.planning.andor.WorstCase` over the ``width`` best actions of each
    set (:func:`branch_key`; every action of a set of at most ``SMALL_SET`` states).
    ``within`` answers for that restricted space: True is a plan, False only that this beam
    has none."""

    SUBSET_REFUTES = False  # a beam's failure is no proof: it does not refute supersets

    def __init__(self, problem: Problem, width: int, deadline: Deadline | None = None) -> None:
        super().__init__(problem, deadline)
        self.width = width
        self.cut = False
        """Whether some set met had more actions than the beam keeps (a wider beam may then
        find more)."""
        self.gave_up = False
        """Whether some small set was taken to have no plan past ``SMALL_DEPTH``. With
        neither, the search was exhaustive and its failures are proofs."""
        self._beam: dict[int, tuple[Act, ...]] = {}

    def _known(self, mask: int, k: int) -> bool | None:
        # Under uncertainty a small set asked within a deep budget is asked within SMALL_DEPTH
        # first: past it, taken as having no plan at all (for this beam, which is then no
        # longer exhaustive: ``gave_up``).
        out = super()._known(mask, k)
        if (
            out is None
            and k > SMALL_DEPTH
            and not self.p.machine.deterministic
            and mask.bit_count() <= SMALL_SET
            and self.lb.get(mask, 1) <= SMALL_DEPTH
        ):
            # A set inside a set solved within ``k`` is solved (asked first: the give-up
            # below would hold for the rest of this beam).
            if self.inside_solved(mask, k) or self.within(mask, SMALL_DEPTH):
                return True
            self.never.add(mask)
            self.gave_up = True
            return False
        return out

    def actions_of(self, mask: int) -> Iterator[Act]:
        acts = self._beam.get(mask)
        if acts is None:
            choices = self.p.choices
            if mask.bit_count() <= SMALL_SET:
                # Every action of a small set: they are few, and the beam's order cannot tell
                # them apart (each leaves branches of two states at most, for a pair).
                acts = tuple(choices.search_actions(mask, self.deadline.limits))
            elif self.p.min_margin > 0.0:  # margins are not monotone: every branch counts
                every = choices.exact_actions(mask, self.deadline.limits)
                self.cut |= len(every) > self.width
                acts = tuple(sorted(every, key=branch_key)[: self.width])
            else:
                # Ranked from the cells and their branches; only the kept actions are made
                # (a set has about a hundred on a near-round part, and the beam keeps four).
                ranked = choices.useful_cells(mask, self.deadline.limits)  # branch_key order
                self.cut |= len(ranked) > self.width
                acts = tuple(choices.useful_act(cell) for cell in ranked[: self.width])
            self._beam[mask] = acts
        return iter(acts)


def beam_plan(
    problem: Problem,
    roots: list[int],
    seed: WorstCase | None,
    deadline: Deadline,
    cap: int,
    lower: int = 1,
    first: Deadline | None = None,
    in_hand: bool = False,
) -> tuple[BeamSearch, int] | None:
    """The shortest plan the widening beams found for every root within ``cap`` operations:
    a search whose ``choice`` table holds it, and its largest root length; None when none
    was found in time: before ``first`` passed (when given: the deadline for a first plan,
    later than ``deadline``), else ``deadline``; a shorter one before ``deadline`` or, when
    later, by the same beam within ``DESCENT_SHARE`` of what ``first`` had left when the
    first plan came (:func:`_descent`).

    ``seed``, when given, is an exact search of the same problem: its proven bounds and
    plans start every beam. ``in_hand``: a plan of ``cap + 1`` operations or more is in hand,
    so the first target is ``cap`` itself, then one less each time, not the bound and up: a
    plan just shorter is found along the beam's best actions at about the cost of its own
    sets, where a target near the bound may fail only after a long search (the random
    1000-point outline at 0.9 % on the ideal model, bound 6, 19 in hand: width 4 fails at 8
    exhaustively in 8.8 s and runs out at 10, where the targets 12, 15 and 18 each find a
    plan in 1-1.6 s). Stops early when a plan meets ``lower`` (a proven bound on the
    largest root length) or a beam kept every action. Every entry of a beam's ``choice`` is a
    plan of its set within its bound, so each wider beam starts from the last one's.
    """
    best: int | None = None
    target = cap
    beam = _beam(problem, FIRST_WIDTH, deadline if first is None else first, seed, None)
    # Until a plan is in hand, each beam deepens by growing steps: the bound, one more,
    # three more, seven more, ... (a short plan where one is near, a long one soon where
    # none is). Where a beam fails cheaply, the one twice as wide is probed at the same
    # target first (``_probe``): a narrow beam that fails at once near the bound may find a
    # long plan only slowly (the 50-part mix at 3 % under 1 degree: 7 operations in about
    # 2 s at width 4, where width 8 finds 5, the optimum, at the bound's target).
    start = max(lower, 1, *(beam.lb.get(r, 1) for r in roots))
    if in_hand:
        start = max(start, cap)
    aim, step = start, 1
    while target >= max(lower, 1):
        reach = target if best is not None else min(aim, target)
        whole = beam.deadline
        shallow = best is None and reach < target and whole.end is not None
        if shallow:  # a target below cap gets SHALLOW_SHARE of the time left for a first plan
            rest = whole.remaining() or 0.0
            beam.deadline = whole.ending(time.perf_counter() + SHALLOW_SHARE * rest)
        used = beam.deadline
        polls = used.polls
        try:
            lengths = _lengths(beam, roots, reach)
        except Timeout:
            if not shallow or whole.expired():
                break
            beam.deadline = whole  # out of its share: what it proved stays, the target grows
            aim, step = reach + step, 2 * step
            continue
        beam.deadline = whole
        cheap = used.polls - polls <= CHEAP_POLLS
        if lengths is None and best is None and beam.cut and cheap:
            try:
                probed = _probe(problem, beam, roots, reach, seed)
            except Timeout:
                break
            if probed is not None:
                beam, lengths = probed
        if lengths is not None:
            if best is None:
                beam.deadline = _descent(deadline, first)
            best = max(lengths)
            target = best - 1  # the same beam (its failures still hold), for a shorter plan
        elif reach < target:
            aim, step = reach + step, 2 * step
        elif beam.cut and (best is None or not deadline.expired()):
            # With a plan in hand a wider beam gets the beams' own deadline, not the descent's.
            wider = beam.deadline if best is None else deadline
            beam = _beam(problem, 2 * beam.width, wider, seed, beam)
            aim, step = start, 1
        else:
            # Every action kept: no plan within the target exists (unless small sets were
            # given up, ``gave_up``; a wider beam gives them up the same way).
            break
    return None if best is None else (beam, best)


def _descent(deadline: Deadline, first: Deadline | None) -> Deadline:
    """The deadline for plans shorter than the first one, found now: ``deadline`` (the
    beams' own), or, when the first plan came under ``first`` and ``DESCENT_SHARE`` of what
    ``first`` has left ends later, that (the loop of :func:`beam_plan` tries no wider beam
    past ``deadline``)."""
    if first is None or first.end is None:
        return deadline
    rest = first.remaining() or 0.0
    late = time.perf_counter() + DESCENT_SHARE * rest
    if deadline.end is not None and late <= deadline.end:
        return deadline
    return first.ending(late)


def _probe(
    problem: Problem, narrow: BeamSearch, roots: list[int], reach: int, seed: WorstCase | None
) -> tuple[BeamSearch, list[int]] | None:
    """The beam twice as wide as ``narrow`` (which failed cheaply at ``reach``) at the same
    target, within ``PROBE_POLLS`` of ``narrow``'s deadline: that beam and its lengths when
    it finds a plan, else None (the target then grows with ``narrow``). Timeout when the
    deadline itself passes.

    One doubling only: a set's work grows with the beam's width, so a poll of a much wider
    beam costs far more than one of ``narrow``'s, and at a target below the optimum every
    width fails."""
    allowance = WorkBudget(narrow.deadline, PROBE_POLLS)
    wide = _beam(problem, 2 * narrow.width, allowance, seed, narrow)
    try:
        lengths = _lengths(wide, roots, reach)
    except Timeout as exc:
        if exc.reason != "work":
            raise
        return None
    if lengths is None:
        return None
    wide.deadline = narrow.deadline
    return wide, lengths


def _beam(
    problem: Problem,
    width: int,
    deadline: Deadline,
    seed: WorstCase | None,
    last: BeamSearch | None,
) -> BeamSearch:
    """A beam of ``width`` starting from the exact search's bounds and the last beam's plans."""
    beam = BeamSearch(problem, width, deadline)
    if seed is not None:
        beam.lb.update(seed.lb)
        beam.never.update(seed.never)
    for known in (seed, last):
        if known is not None:
            beam.ub.update(known.ub)
            beam.choice.update(known.choice)
    return beam


def _lengths(beam: BeamSearch, roots: list[int], target: int) -> list[int] | None:
    """Each root's length in a plan the beam finds within ``target`` (hardest roots first);
    None as soon as one has none.

    Depth-first at the target itself, not by iterative deepening: a plan well inside a
    generous target is found along the beam's best actions at about the cost of its own
    sets, where deepening pays for every failed shallower depth first (a random 200-point
    outline over both landings under 1 degree: 15 operations within a target of 20 in about
    6 s and 11 soon after, where deepening found none in 21 s). The plan found need not be
    the beam's shortest: its length (:func:`_depth`) is the next target's bound.
    """
    out = []
    for r in sorted(roots, key=lambda m: -beam.lb.get(m, 1)):
        if beam.p.is_goal(r):
            out.append(0)
            continue
        if not beam.within(r, target):
            return None
        # A fresh memo per root: the next root's search may give a set met here a
        # shorter plan (a smaller budget) where it meets it deeper down.
        out.append(_depth(beam, r, {}))
    return out


def _depth(search: WorstCase, mask: int, memo: dict[int, int]) -> int:
    """The length of the plan a search's ``choice`` table holds for ``mask``: its chosen
    action, then each branch's own plan (a set proven by a bound alone counts its bound).

    A set's choice is a plan within the budget it was proven under and its branches' within
    one less (a later, smaller budget replaces it), so the walk goes no deeper than that
    budget: the search's target. A set holding a larger set's action
    (:meth:`~feederkit.planning.andor.WorstCase.inside_solved`) counts that set's plan,
    which its own node in the plan follows, no deeper.
    """
    if search.p.is_goal(mask):
        return 0
    hit = memo.get(mask)
    if hit is not None:
        return hit
    entry = search.choice.get(mask)
    if entry is None:
        known = search.exact.get(mask)
        out = search.ub[mask] if known is None else known
    else:
        out = 1 + max(_depth(search, c, memo) for c in entry[1].children)
    memo[mask] = out
    return out
