"""The plans a time-limited search returns when the exact search runs out of its budget.

The best of Goldberg's backchaining plan (one part), each part's chain in turn, the pairs
told apart one at a time (the ideal model), the widening beams and the AND/OR search again,
with the lower bound the searches proved (the hardest subsets' among them), all within the
rest of the plan's budget (docs/planning.md, "Time and memory limits"). Where the readings
carry nothing, :func:`sensorless_plan` is also the exact search's shortest plan; with
several parts the beams and the search are over sets (:mod:`~feederkit.planning.quiet`).

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 6.1 (the AND/OR search).
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10
(backchaining).
"""

from __future__ import annotations

import gc
import time

import numpy as np

from feederkit.angles import norm360
from feederkit.machine import OverlapRange
from feederkit.planning.andor import WorstCase
from feederkit.planning.beam import beam_plan
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import OutOfBudget, PlanningOptions, out_of_budget
from feederkit.planning.pairwise import applies as pairwise_applies
from feederkit.planning.pairwise import pairwise_plan
from feederkit.planning.problem import Problem
from feederkit.planning.quiet import QuietWorst, chain_plan, widening_chains
from feederkit.planning.sensorless import Backchain, BackchainWorst, push_circle
from feederkit.planning.sequential import sequential_plan
from feederkit.planning.solvable import no_strong_plan, unsolvable_by_pairs
from feederkit.planning.stats import node_states, tree_length
from feederkit.planning.subsets import subset_lower_bound
from feederkit.planning.tree import TIES_NONE, Leaf, Step, build_dag, root_step
from feederkit.words import plural

FALLBACK_MAX_OPERATIONS = 100
"""The depth-first fallback looks for plans of at most this many operations: longer ones are
of no use on a feeder, and every consumer of a plan walks it level by level."""

BEAM_SHARE = 0.2
"""The share of the fallback's time (after the backchaining plan) the widening beams may take,
never into the tree's reserve; the hardest subsets' lower bound and the AND/OR search for a
plan at the bound get the rest."""

FAR_GAP = 3
"""A plan in hand more than this many operations above the proven bound is far from it: the
searches at the bound and one above it seldom succeed, and the beams, which improve a plan
one operation at a time from the one in hand, get ``FAR_BEAM_SHARE`` of the time instead of
``BEAM_SHARE``."""

FAR_BEAM_SHARE = 0.5
"""The beams' share with a plan in hand far from the bound (``FAR_GAP``); the searches at the
bound, whose failures raise it, keep the rest. The random 1000-point outline at 0.9 % on the
ideal model, 60 s (19 in hand against a bound of 6): 11 against a bound of 8 (13 against 7
at ``BEAM_SHARE``, in a run beside the 0.8 one; 11 against 7 at 0.8); the command on the
1000-point outline at 3 % on the ideal model (``bench_command_deadline.py``): 39 against 13
at 0.5 and 0.8, 39 against 15 at ``BEAM_SHARE``. One run each: the bound's searches lose
time to the beams."""

READ_SHARE = 0.5
"""With a time limit, the share of what is left after the backchaining plan that the plan
following the readings may take (a node per maximal reading set it meets: 2.4 CPU s on the
random 1000-point outline at 1 % on the ideal model, whose fallback gets about 7 s of a
10 s limit; a quarter of that ran out)."""

TREE_RESERVE = 0.15
"""The share of the time limit the fallback's last search leaves for building its tree."""

WALK_SHARE = 1.0
"""With the beams' plan in hand, the searches after it stop this many times its tree's
building time before the limit (when more than half the tree reserve): the result's
statistics and renumbering walk that tree once more after them (the 50-part mix at 3 %
under 1 degree: the answer 2.6-4.5 s past a 60 s limit without this; 1.5 left the 20-part
mix at 5 % under 10 s no time for the subsets' bound)."""

QUIET_SHARE = 0.8
"""With readings that carry nothing on several parts (:mod:`~feederkit.planning.quiet`), the
share of what is left that its widening beams over sets may take (the AND/OR beams are not
run: every reading set they would open needs as many operations as its image)."""

PAIRWISE_SHARE = 0.7
"""With a time limit and no plan in hand, the share of what is left that the plan telling
the states apart one pair at a time may take (the ideal model only)."""

FIRST_PLAN_RESERVE = 2.0
"""With no plan in hand, the widening beams look for a first one until this many tree
reserves (``TREE_RESERVE``) before the limit, past their ``BEAM_SHARE``; shorter ones only
within it."""

FIRST_PLAN_GRACE_S = 1.5
"""With no plan in hand, the first this many seconds of the first plan's verification,
besides the caller's reserve (``Deadline.reserve_s``: the certificate's time, which the
plan's verification takes instead), are not committed to the budget
(:meth:`~feederkit.planning.budget.Deadline.with_grace`): a plan a little late beats none
(the command then answers at most this much past its limit); one later still is dropped
like one too slow to find. The plan in hand's verification may take the reserve as well
(``_Held``)."""


class NoFallback(OutOfBudget):
    """The exact search ran out of its share of a limit and the options turn the fallback
    off (``PlanningOptions.fallback``): no plan, as none is proven shortest. ``reason``: the
    Timeout's (``"time"`` or ``"memory"``)."""

    def __init__(self, options: PlanningOptions, reason: str) -> None:
        super().__init__(
            f"no plan proven shortest within {out_of_budget(options, reason)} "
            "(the fallback is off)",
            reason,
        )


def fallback(
    problem: Problem,
    worst: WorstCase,
    roots: list[int],
    root_branches,
    budget: Deadline,
    options: PlanningOptions,
    stop: str,
    apart: bool = False,
    kept_known: bool = False,
):
    """Some plan when the exact search ran out of its budget (``stop``: the Timeout's reason),
    with the lower bound proven; ``apart``: the goal tells every pair of states apart and a
    lumped one may follow, so with no plan found the bound is stated for this goal only;
    ``kept_known``: :func:`~feederkit.planning.solvable.kept_roots` found no root holding a
    pair nature keeps apart (it is not asked again).

    Everything here runs under the rest of the plan's ``budget``: the backchaining plan (one
    part, no margin floor: one chain of the whole set; the plan that follows the readings
    within ``READ_SHARE`` of what is left, when it is shorter); else, on the ideal model, the
    parts' chains in turn (:func:`~feederkit.planning.sequential.sequential_plan`, when the
    readings after them leave goals), else the plan that tells the states apart one pair at
    a time (within ``PAIRWISE_SHARE``); where the readings carry nothing on several parts
    (:class:`~feederkit.planning.quiet.QuietWorst`), the widening beams over sets instead
    (:func:`~feederkit.planning.quiet.widening_chains`, within ``QUIET_SHARE``, their plan
    a chain) and A* at the bound below; else the
    widening beams (:func:`~feederkit.planning.beam.beam_plan`, within ``BEAM_SHARE``, or
    ``FAR_BEAM_SHARE`` with a plan in hand more than ``FAR_GAP`` above the bound) for something
    shorter; with a plan in hand, the hardest subsets' bound
    (:func:`~feederkit.planning.subsets.subset_lower_bound`; not where the readings carry
    nothing, whose A* at the bound proves more); then a depth-first search (the
    greedy action order of ``Choices.lazy_actions``, on an explicit stack) for something
    shorter still. A tree follows the actions that proved it; a reading set the searches
    never met lies inside one they did (its "witness"), and follows the witness's
    rotations, in a node of its own where its image there is not the witness's
    (:func:`_choice_plan`). :class:`~feederkit.planning.options.OutOfBudget` when none finds
    a plan in time.

    No Timeout is kept past its ``except`` block: its traceback holds the frames of the
    search, and a frame holding it would make the searches' tables cyclic garbage that only
    the collector (paused while planning) could free.

    With the fallback off (``options.fallback`` False) it raises :class:`NoFallback` at once.
    """
    if not options.fallback:
        raise NoFallback(options, stop)
    lower = 1 + max((_proven(worst, r) for r in roots), default=0)
    # Readings that carry nothing on several parts (feederkit.planning.quiet): every search
    # below is over images, and its plans are chains (chain_plan); the AND/OR searches over
    # reading sets are not run (their choices are reading sets', which a chain cannot follow).
    quiet = isinstance(worst, QuietWorst)
    if stop == "memory":
        # Let the exact search's tables go: the fallback starts from a fresh problem.
        problem = Problem(problem.machine, problem.grouping, problem.min_margin, problem.insep)
        del worst
        gc.collect()
        if quiet:
            worst = QuietWorst(problem, budget)
    # Each plan below is built under a copy of the budget (its nodes' verification
    # committed there while it is built) and held, once made, by ``held`` on the budget.
    try:  # the backchaining plan itself first: one chain, one step per operation
        blind = sensorless_plan(problem, root_branches, budget.ending(None), by_image=True)
    except Timeout:
        blind = None
    rest = budget.remaining()
    share = budget.ending(None)
    if rest is not None and not problem.sensorless:
        # With readings its tree can be large: keep the rest for the searches.
        share = budget.ending(budget.end - rest * (1.0 - READ_SHARE))
    if blind is not None:
        try:  # the readings may shorten it
            read = sensorless_plan(problem, root_branches, share)
        except Timeout:
            read = None
        if read is not None and tree_length(read) < tree_length(blind):
            blind = read
    if blind is None:
        try:  # several parts on the ideal model: each part's backchaining chain in turn
            blind = sequential_plan(problem, root_branches, budget.ending(None))
        except Timeout:
            blind = None
        if blind is not None and tree_length(blind) > FALLBACK_MAX_OPERATIONS:
            blind = None
    held = _Held(budget)  # the plan in hand's verification comes out of the time left
    held.hold(blind)
    unbuilt: int | None = None  # the length of the shortest plan found but never built
    if quiet and (blind is None or tree_length(blind) > lower):
        # Weighted A* over the parts' arc hulls where it applies, else the widening beams
        # over sets, within QUIET_SHARE of what is left.
        rest = budget.remaining()
        share = budget if rest is None else budget.ending(budget.end - rest * (1 - QUIET_SHARE))
        longest = worst.weighted_chains(roots, share) if isinstance(worst, QuietWorst) else None
        if longest is None:
            longest = widening_chains(worst, roots, share)
        if longest is not None and (blind is None or longest + 1 < tree_length(blind)):
            try:
                blind = chain_plan(
                    problem, worst, roots, root_branches, held.building(budget, blind)
                )
                held.hold(blind)
            except Timeout:  # the plan in hand, if any, stays
                unbuilt = longest + 1
    # The exact search proved every root's length and only the tree ran out (the tie-breaks
    # or the tree of the margin probes): the proof's choices are a plan of the proven length,
    # which the beams below follow at once (a 200-part mix at 1 % on the ideal model, its
    # length proven at 9 s of 60: the pairwise plan took 4.3 s first, then the beams 0.04 s).
    proof = (
        stop != "memory"  # its tables are let go
        and type(worst) is WorstCase
        and all(worst.holds_plan(r, lower - 1) for r in roots)
    )
    if blind is None and not proof and pairwise_applies(problem):
        # On the ideal model a plan always exists: the pairs told apart one at a time
        # (feederkit.planning.pairwise), within PAIRWISE_SHARE of what is left; the searches
        # below then look for something shorter.
        rest = budget.remaining()
        share = budget
        if rest is not None:
            share = _graced(budget.ending(budget.end - rest * (1 - PAIRWISE_SHARE)))
        try:
            told = pairwise_plan(problem, root_branches, share)
        except Timeout:
            told = None
        if told is not None and tree_length(told) <= FALLBACK_MAX_OPERATIONS:
            blind = told
            held.hold(blind)
    anytime = QuietWorst(problem, budget) if quiet else WorstCase(problem, budget)
    if stop != "memory" and type(worst) in (WorstCase, QuietWorst):
        # What the exact search proved stays true (its exact lengths are left out: they
        # may come without the action that proves them).
        anytime.lb.update(worst.lb)
        anytime.ub.update(worst.ub)
        anytime.choice.update(worst.choice)
    cap = min(2 * problem.n + 1, FALLBACK_MAX_OPERATIONS)
    if blind is not None:
        cap = tree_length(blind) - 2  # look only for something shorter
    # A plan in hand needs time for its tree and statistics: the searches below stop a
    # reserve of the limit before it.
    reserve = 0.0 if budget.end is None else TREE_RESERVE * (budget.end - budget.start)
    gap = reserve / 2.0  # the tree of a plan found must be built by this long before the end
    rest = budget.remaining()
    # The widening beams (feederkit.planning.beam): a plan first, then shorter ones, within
    # BEAM_SHARE of what is left (FAR_BEAM_SHARE with a plan in hand far above the bound);
    # what they find is where the search below starts.
    far = blind is not None and tree_length(blind) - lower > FAR_GAP
    beam_share = FAR_BEAM_SHARE if far else BEAM_SHARE
    beam_end = None if rest is None else budget.end - max(rest * (1.0 - beam_share), reserve)
    seed = worst if stop != "memory" and type(worst) is WorstCase else None
    # With no plan in hand a first one may take until FIRST_PLAN_RESERVE before the limit
    # (what is left then builds its tree).
    first = None
    if blind is None and budget.end is not None:
        first = budget.ending(max(beam_end, budget.end - FIRST_PLAN_RESERVE * reserve))
    beamed = (
        None
        if quiet
        else beam_plan(
            problem,
            roots,
            seed,
            budget.ending(beam_end),
            cap,
            lower - 1,
            first,
            in_hand=blind is not None,
        )
    )
    if beamed is not None:
        search, best = beamed
        # Its tree now, under the whole budget: a plan in hand (shorter than blind) beats none,
        # though its statistics may then run past the limit by one walk of the tree.
        built = time.perf_counter()
        try:  # the plan in hand stays held until this one replaces it
            blind = _choice_plan(
                problem, search.choice, roots, root_branches, held.building(budget, blind)
            )
            # Its statistics and renumbering after the searches below cost up to about as
            # much as building it: they stop WALK_SHARE of that before the limit, when more
            # than the reserve's half.
            gap = max(gap, WALK_SHARE * (time.perf_counter() - built))
        except Timeout:  # the plan in hand, if any, stays
            unbuilt = best + 1  # the first alignment besides the root's rotations
        held.hold(blind)
        anytime.ub.update(search.ub)
        anytime.choice.update(search.choice)
        cap = best - 1  # the search below looks only for something shorter
    if blind is None and unbuilt is None and not problem.machine.deterministic:
        # No plan in hand under uncertainty: perhaps none exists (not so when a search found
        # one it could not build in time). A root holding a pair no strong plan orients has
        # none (solvable.unsolvable_by_pairs: quick where the roots' own sets are too many);
        # half of what is left decides it, when it can.
        rest = budget.remaining()
        share = budget if rest is None else budget.ending(budget.end - rest / 2.0)
        try:
            bad = unsolvable_by_pairs(problem.with_margin(0.0), roots, share, kept_known=kept_known)
        except Timeout:
            bad = None
        if bad:
            raise no_strong_plan(problem.machine)
    # Where a tree must be built by once a plan is in hand; read after the plan in hand's
    # pairs are committed (``held``), which brought the budget's end forward.
    tree_budget = budget if budget.end is None else budget.ending(budget.end - gap)
    if blind is not None and budget.end is not None and not quiet:
        # The bound, from the hardest subsets of the roots (feederkit.planning.subsets), up to
        # half the reserve (no tree to build, only the statistics of the plan in hand): a
        # closer bound tells how good that plan is, and ends the search below when met.
        # Where the readings carry nothing its AND/OR search over reading sets is no match
        # for the A* at the bound below, which gets the time (both landings of the random
        # 1000-point outline at a 6 s limit: 2.7 s of subsets for no bound).
        goal = tree_length(blind) - 1
        lower = 1 + subset_lower_bound(problem, roots, lower - 1, tree_budget, goal)
    # With a deadline, lengths at the proven bound and one above it first (each with a third
    # of the time left), then the generous cap: a plan within one operation of the bound
    # when the search finds one, some plan else.
    near = (lower - 1, lower) if budget.end is not None else ()
    caps = sorted({k for k in near if k < cap}) + [cap]
    found = None
    last = stop  # the reason the last search stopped
    # The last search keeps a reserve of the limit for the tree of what it finds: a plan
    # found at the deadline with no time left to write it down is no answer. With a plan in
    # hand every search keeps the whole reserve, and a shorter plan's tree half of it.
    if blind is None:
        tree_budget = budget
    for k in caps if cap >= max(lower - 1, 1) else ():
        rest = budget.remaining()
        if rest is None:
            end = None
        elif blind is not None:
            end = min(
                tree_budget.end, budget.end - max(reserve, rest * 2.0 / 3.0 if k < cap else 0.0)
            )
        elif k == cap:
            end = budget.end - min(reserve, rest / 2.0)
        else:
            end = budget.end - rest * 2.0 / 3.0
        anytime.deadline = budget.ending(end)
        try:
            if all(anytime.within(r, k) for r in roots):
                found = k
                break
        except Timeout as exc:
            last = exc.reason
            if last == "memory":
                break
    if quiet:  # A* at the bound records the least f-value it reached: a bound too
        lower = max(lower, 1 + max((_proven(anytime, r) for r in roots), default=0))
    root = None
    if found is not None:
        # The shorter plan replaces the one in hand, which stays held until it does.
        if budget.end is not None and blind is not None:
            tree_budget = budget.ending(budget.end - gap)
        anytime.deadline = tree_budget
        try:
            building = held.building(tree_budget, blind)
            if quiet:  # its choices are images' (one chain), not reading sets'
                root = chain_plan(problem, anytime, roots, root_branches, building)
            else:
                root = _choice_plan(problem, anytime.choice, roots, root_branches, building)
            held.hold(root)
        except Timeout as exc:
            last = exc.reason
            unbuilt = found + 1  # shorter than the beams' plan: the search looks below it
    if root is None:
        if blind is not None:
            return blind, False, None, lower, TIES_NONE, None
        reason = last if last == "memory" else stop
        which = "one whose results list no states together" if apart else "a plan"
        # A plan the searches found whose tree or its verification did not fit: more time
        # would give it.
        seen = (
            ""
            if unbuilt is None
            else f"; one of {plural(unbuilt, 'operation')} was found, but not built and verified "
            "in time"
        )
        raise OutOfBudget(
            f"no plan found within {out_of_budget(options, reason)} "
            f"({which} needs at least {plural(lower, 'operation')}{seen})",
            reason,
            lower if not apart else None,
        )
    return root, False, None, lower, TIES_NONE, None


def _graced(budget: Deadline) -> Deadline:
    """A copy of ``budget`` to build a first plan under (none in hand): the first
    ``FIRST_PLAN_GRACE_S`` and the reserve of its verification free (a plan a little late
    beats none)."""
    return budget.with_grace(FIRST_PLAN_GRACE_S + budget.reserve_s)


class _Held:
    """The plan in hand's verification, held as seconds of the fallback's budget
    (:meth:`~feederkit.planning.budget.Deadline.seconds_for` its (node, state) pairs): its
    verification and file come out of the time left, less the caller's reserve it may take
    (``Deadline.reserve_s``, a certificate's time), and a plan that replaces it gives exactly
    those seconds back, however the machine's load changed meanwhile."""

    def __init__(self, budget: Deadline) -> None:
        self.budget = budget
        self.held_s = 0.0  # seconds the plan in hand took from the budget's end

    def hold(self, root: Step | None) -> None:
        """``root`` is the plan in hand now (None: none): the budget's end moves by the
        difference of what the two plans take."""
        cost = 0.0 if root is None else self.budget.seconds_for(node_states(root))
        held = cost - min(self.budget.reserve_s, cost)
        self.budget.credit(self.held_s - held)  # the plan is made: keep it, never raise
        self.held_s = held

    def building(self, budget: Deadline, in_hand: Step | None) -> Deadline:
        """A copy of ``budget`` (a share of the held one) to build a plan under that would
        replace ``in_hand``: the seconds the plan in hand holds are free to it, and kept
        for the plan in hand should the build run out (a failed replacement must not take
        its verification's time); with none in hand, :func:`_graced`'s."""
        if in_hand is None:
            return _graced(budget)
        return budget.with_grace(self.held_s)


def _choice_plan(problem: Problem, choice, roots, root_branches, deadline: Deadline) -> Step:
    """The plan that follows a search's ``choice`` table (the action that proved each set).

    A reading set the search did not choose for lies inside one it did (its witness: a
    searched superset, or the set itself, whichever has the shorter plan) and follows the
    witness's subplan itself: the witness's rotation sends the set inside the witness's
    image, each reading then leaves a subset of one of the image's branches, and a subset
    of a goal is a goal. So the plan has one node per witness, not one per reading set met
    (the 50-part mix at 3 % under 1 degree: about a tenth of the nodes), and every consumer
    (verification, certificate, file, drawing) walks that much less.

    A set may hold a larger set's action (``WorstCase.inside_solved``: solved inside it).
    Where its image under that rotation is not the larger set's, its node is its own: its
    overlap range around the rotation, its own image's reading branches, each a leaf where
    the reading orients the part, else going on with the maximal branch of its own image
    that holds it, following the plan of the larger set's branch around it. A node is keyed
    by its set and the set whose plan it follows (as ``Refiner.follow``), so every node is
    reached by all of its states and no branch is one that no state takes.
    """
    readings = problem.readings

    def witness_of(mask: int, supersets) -> int:
        # The set itself or a searched set containing it, whichever has the shorter plan: a
        # set's own entry may be a longer plan than the one its parent's bound counted on.
        if problem.is_goal(mask):
            return mask
        own = choice.get(mask)
        best = mask
        bound = own[0] if own is not None else None
        for c in supersets:
            if mask & c == mask and c in choice and (bound is None or choice[c][0] < bound):
                best, bound = c, choice[c][0]
        return best

    cells: dict[tuple[int, int], tuple[float, float, int] | None] = {}

    def own_cell(mask: int, lender: int) -> tuple[float, float, int] | None:
        # The set's own range around the lender's chosen rotation (a bisection per member),
        # None where its image there is the lender's: it then follows the lender's node,
        # every branch of which its states take. (The rotation lies strictly inside one of
        # the set's cells: a subset's cell boundaries are among the larger set's.)
        key = (mask, lender)
        if key not in cells:
            sa = choice[lender][1].action
            cell = problem.choices.cell_at(mask, norm360((sa.lo + sa.hi) / 2.0))
            cells[key] = None if cell is None or cell[2] == sa.image else cell
        return cells[key]

    def key_of(mask: int, lender: int) -> tuple[int, int]:
        # A plan node's key: the set arriving and the set whose plan it follows.
        if problem.is_goal(mask):
            return (mask, mask)
        if mask == lender or own_cell(mask, lender) is None:
            return (lender, lender)
        return (mask, lender)

    def expand(key: tuple[int, int]):
        mask, lender = key
        if problem.is_goal(mask):
            return Leaf(mask)
        act = choice[lender][1]
        cell = own_cell(mask, lender)
        if cell is None:  # the chosen action moves the set as it moves the lender
            subs = []
            for b in readings.image_branches(act.action.image):
                w = witness_of(b.mask, act.children)
                subs.append((b, key_of(w, w)))
            return act.action, subs
        maximal = readings.children(cell[2])
        subs = []
        for b in readings.image_branches(cell[2]):
            if problem.is_goal(b.mask):  # oriented by the reading
                subs.append((b, (b.mask, b.mask)))
                continue
            own = next(m for m in maximal if b.mask & m == b.mask)
            subs.append((b, key_of(own, witness_of(own, act.children))))
        return OverlapRange(*cell), subs

    top = [(b, key_of(w, w)) for b in root_branches for w in (witness_of(b.mask, roots),)]
    made = build_dag([k for _b, k in top], expand, deadline)
    return root_step(((b, made[k]) for b, k in top), deadline)


def sensorless_plan(
    problem: Problem, root_branches, deadline: Deadline, by_image: bool = False
) -> Step | None:
    """A plan that takes the readings but chooses rotations by backchaining, or None.

    For one part's push machine (no margin floor), Goldberg's table says how many
    operations collapse any set with no sensor; each step takes the rotation whose reading
    sets need the fewest (the largest, then their sum), which is fewer than the set needs,
    since a rotation that lowers the whole image's number exists and a reading only leaves
    a subset. Never longer than the sensorless plan; on the random 1000-point outline at
    1 % on the ideal model 21 operations, where the first rotation that lowers the image's
    number gave 22. Its size grows with the distinct reading sets, so it is built
    under ``deadline`` (Timeout). ``by_image``: the backchaining plan of the whole set
    itself, readings followed but not used, for when the other runs out: every root branch
    and every reading branch of a step goes on with the subplan of the step's whole image
    (a reading only leaves a subset of it, and a subset of a goal set is a goal), so the
    plan is one chain, one step per operation.
    """
    if problem.min_margin > 0.0:
        return None
    circle = push_circle(problem.machine, problem.insep)
    if circle is None:
        return None
    chain = Backchain(circle)

    def expand(mask: int):
        if problem.is_goal(mask):
            return Leaf(mask)
        cells = problem.choices.cells(mask, False)
        if by_image:
            k = chain.length(mask)
            lo, hi, img = next(c for c in cells if chain.length(c[2]) < k)
            return OverlapRange(lo, hi, img), [
                (b, img) for b in problem.readings.image_branches(img)
            ]
        # The rotation whose readings leave the shortest sets (the first such in the
        # problem's order): never worse than the first that shortens the whole image, and
        # better where the readings split it. A reading set goes on as the largest reading
        # set holding it (its witness: a plan of a set orients its subsets), so the plan
        # has a node per maximal set, not one per reading set (on the 1000-point outline
        # above 136 s became about 2).
        kids = [problem.readings.children(c[2]) for c in cells]
        best = _fewest_after(chain, kids)
        lo, hi, img = cells[best]
        wider = kids[best]

        def witness(m: int) -> int:
            return m if problem.is_goal(m) else next((c for c in wider if m & ~c == 0), m)

        return OverlapRange(lo, hi, img), [
            (b, witness(b.mask)) for b in problem.readings.image_branches(img)
        ]

    if by_image:
        # One chain for every reading: the whole set's rotations send each branch (a
        # subset) inside the same images, so the plan has one step per operation.
        keys = {b.mask: b.mask if problem.is_goal(b.mask) else problem.full for b in root_branches}
    else:
        keys = {b.mask: b.mask for b in root_branches}
    made = build_dag(list(keys.values()), expand, deadline)
    return root_step(((b, made[keys[b.mask]]) for b in root_branches), deadline)


def _fewest_after(chain: Backchain, kids: list[tuple[int, ...]]) -> int:
    """The first rotation whose reading sets (``kids``, per rotation) need the fewest
    sensorless operations: the largest, then their sum; all the sets' lengths at once
    (:meth:`~feederkit.planning.sensorless.Backchain.lengths_of_sets`).

    >>> from feederkit.planning.sensorless import PushCircle
    >>> chain = Backchain(PushCircle(360.0, (0, 1, 2, 3), (0.0, 60.0, 180.0, 200.0),
    ...                              (30.0, 20.0, 50.0, 40.0), (30.0, 20.0, 50.0, 40.0)))
    >>> [chain.length(m) for m in (0b1111, 0b0011, 0b1100, 0b0110, 0b0100)]
    [inf, 1, 1, inf, 0]
    >>> _fewest_after(chain, [(0b1111,), (0b0011, 0b1100), (0b0011, 0b0100, 0b1000)])
    2
    """
    if not all(kids):
        raise ValueError("a rotation with no reading sets")  # an image is never empty
    lengths = chain.lengths_of_sets([b for ks in kids for b in ks])
    starts = np.cumsum([0, *(len(ks) for ks in kids[:-1])])
    largest = np.maximum.reduceat(lengths, starts)
    total = np.add.reduceat(lengths, starts)
    tied = np.flatnonzero(largest == largest.min())
    return int(tied[np.argmin(total[tied])])


def _proven(worst: WorstCase, mask: int) -> int:
    """A proven lower bound on the set's operations (exact for backchaining)."""
    if worst.p.is_goal(mask):
        return 0
    if isinstance(worst, BackchainWorst):
        return worst.length(mask)
    return worst.exact.get(mask, worst.lb.get(mask, 1))
