"""Whether a strong plan exists: a least fixpoint over the sets a plan can meet.

With outcome sets (design.md, "Uncertainty") some sets have no strong plan: every action may
send two states that must be told apart into one reading, or merge them only sometimes. The
sets reachable from the roots (through the length view's actions and reading branches) are
finite; a set is solvable when it is a goal or some action has every branch solvable, and
its minimum worst-case length is the least fixpoint of ``1 + min over actions of max over
branches``. :func:`solve` finds both, level by level with a counter per action, in time
linear in the explored graph; the planners then read the lengths instead of searching.
Subsets of solvable sets are solvable (images and branches shrink with the set), so the
length view's pruning is sound here too.

When none exists the planners raise :class:`NoStrongPlan`, naming the declared uncertainty.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection

from feederkit.errors import PlanningError
from feederkit.machine import Grouping, PushAlignMachine, members, search_space
from feederkit.machine.inseparable import kept_apart
from feederkit.planning.andor import Deadline, Timeout, WorstCase
from feederkit.planning.problem import Problem

MAX_SETS = 200_000
"""The most sets the check explores before it gives up (None: undecided)."""


def solve(
    problem: Problem,
    roots: list[int],
    deadline: Deadline | None = None,
    max_sets: int = MAX_SETS,
    hopeless: Callable[[int], bool] | None = None,
) -> dict[int, float] | None:
    """The minimum worst-case number of operations of every set reachable from ``roots``
    (inf: no strong plan); None when more than ``max_sets`` sets are reachable.

    ``hopeless(mask)`` may name sets already known to have no strong plan (they are given
    inf and not expanded; :mod:`feederkit.planning.lumping` uses it to prune).

    Knuth's generalisation of Dijkstra to AND/OR graphs with unit costs: sets are settled
    level by level from the goals (0); an action is complete when all its branch sets are
    settled, and the first completed action of a set settles it one level above its last
    child (a level-by-level order makes that child the largest).
    """
    deadline = deadline or Deadline(None)
    acts: dict[int, list[tuple[int, ...]]] = {}
    value: dict[int, float] = {}
    stack = list(roots)
    while stack:
        m = stack.pop()
        if m in acts or m in value:
            continue
        deadline.check()
        if problem.is_goal(m):
            value[m] = 0
            continue
        if hopeless is not None and hopeless(m):
            value[m] = math.inf
            continue
        children = list(problem.choices.branch_sets(m, deadline.limits))
        acts[m] = children
        if len(acts) > max_sets:
            return None
        for ch in children:
            stack.extend(c for c in ch if c not in acts and c not in value)
    preds: dict[int, list[list]] = {}
    level = [m for m, v in value.items() if v == 0]
    for m, children in acts.items():
        for ch in children:
            edge = [m, len(ch)]
            for c in ch:
                preds.setdefault(c, []).append(edge)
    depth = 0
    while level:
        nxt: list[int] = []
        for c in level:
            for edge in preds.get(c, ()):
                edge[1] -= 1
                if edge[1] == 0 and edge[0] not in value:
                    value[edge[0]] = depth + 1
                    nxt.append(edge[0])
        level = nxt
        depth += 1
    for m in acts:
        value.setdefault(m, math.inf)
    return value


QUICK_SETS = 1_000
""":func:`decide` first explores the roots' own sets up to this many: a part whose actions
keep few sets (a near-round part, or no plan at all) is decided at once."""

PAIR_CHECK_SETS = 50_000
"""The most sets :func:`decide` lets the pairs' check explore (the 50-part mix at 3 mm
under 1 degree needs 16,520)."""


def decide(
    problem: Problem, roots: list[int], deadline: Deadline | None = None, max_sets: int = MAX_SETS
) -> tuple[list[int] | None, dict[int, float] | None]:
    """Roots no strong plan orients (empty: every root has one; None: undecided; when the
    pairs decide it, some of them) and, when the roots' own sets were all explored, every
    reachable set's length (:func:`solve`).

    Cheapest first: the roots' sets when they are few (``QUICK_SETS``); then their pairs
    (:func:`unsolvable_by_pairs`, within half the time left and ``PAIR_CHECK_SETS`` sets):
    a root holding a pair no strong plan orients has none; then the roots' sets in full.
    Each way wins somewhere: a random 1000-point outline at 3 % under 1 degree has 4 sets
    from its root and pairs reaching over 20,000; a 50-part mix the other way round.
    """
    deadline = deadline or Deadline(None)
    value = solve(problem, roots, deadline, QUICK_SETS)
    if value is None:
        rest = deadline.remaining()
        share = deadline if rest is None else deadline.ending(deadline.end - rest / 2.0)
        try:
            bad = unsolvable_by_pairs(problem, roots, share, PAIR_CHECK_SETS)
        except Timeout as exc:
            if exc.reason == "memory":
                raise
            bad = None
        if bad:
            return bad, None
        value = solve(problem, roots, deadline, max_sets)
    if value is None:
        return None, None
    return [r for r in roots if value[r] == math.inf], value


def unsolvable(
    problem: Problem, roots: list[int], deadline: Deadline | None = None, max_sets: int = MAX_SETS
) -> list[int] | None:
    """The roots no strong plan orients (empty: all solvable); None when undecided
    (:func:`decide`)."""
    return decide(problem, roots, deadline, max_sets)[0]


def candidate_pairs(problem: Problem) -> list[tuple[int, int]]:
    """The pairs a goal test can meet that are not inseparable.

    With exact reading branching every set a plan reaches holds states that can all give one
    reading, so only pairs that can read alike meet; the components rule can join states
    that cannot (through a third), so there every pair is a candidate.
    """
    machine = problem.machine
    sensor = machine.sensor
    sensed = [s.sensed for s in machine.states]
    exact = problem.grouping is Grouping.EXACT
    return [
        (i, j)
        for i in range(machine.n)
        for j in range(i + 1, machine.n)
        if not problem.insep[i] >> j & 1
        and (not exact or sensor.can_read_alike(sensed[i], sensed[j]))
    ]


def alike_pairs(problem: Problem) -> list[tuple[int, int]]:
    """The :func:`candidate_pairs` that can read alike, whatever the grouping: the pairs
    :func:`~feederkit.machine.inseparable.kept_apart` is sound over (nature answers each
    reading with one both states can give). Under the components rule a pair that never
    reads alike is a candidate, yet a reading separates it once no third state bridges the
    two: keeping it apart proves nothing."""
    if problem.grouping is Grouping.EXACT:
        return candidate_pairs(problem)
    sensor = problem.machine.sensor
    sensed = [s.sensed for s in problem.machine.states]
    return [
        (i, j) for i, j in candidate_pairs(problem) if sensor.can_read_alike(sensed[i], sensed[j])
    ]


def kept_pairs(problem: Problem, deadline: Deadline | None = None) -> frozenset[tuple[int, int]]:
    """:func:`~feederkit.machine.inseparable.kept_apart` over :func:`alike_pairs` of
    ``problem``, polled by ``deadline``, made once per machine, grouping and goal relation (a
    cut-short one is not kept): a plan asks it first (:func:`kept_roots`), its lumping again
    (:func:`~feederkit.planning.lumping.unresolvable_pairs`), and once that is cut short, for
    the pairs it still names (over a second on the 100-part mix at 5 % under 1 degree)."""
    space = search_space(problem.machine)
    key = (problem.grouping, tuple(problem.insep))
    hit = space.kept.get(key)
    if hit is None:
        check = None if deadline is None else deadline.check
        hit = frozenset(kept_apart(problem.machine, alike_pairs(problem), check))
        space.kept[key] = hit
    return hit


def holding_kept_pairs(roots: list[int], kept: Collection[tuple[int, int]]) -> list[int]:
    """The roots holding a pair of ``kept`` (pairs nature keeps apart,
    :func:`~feederkit.machine.inseparable.kept_apart`): no strong plan orients them."""
    if not kept:
        return []
    partner: dict[int, int] = {}
    for i, j in kept:
        partner[i] = partner.get(i, 0) | 1 << j
    return [r for r in roots if any(partner.get(i, 0) & r for i in members(r))]


def kept_roots(problem: Problem, roots: list[int], deadline: Deadline | None = None) -> list[int]:
    """The roots holding a pair nature keeps apart whatever the plan does
    (:func:`~feederkit.machine.inseparable.kept_apart` over :func:`alike_pairs`, one
    fixpoint over all pairs, polled by ``deadline``): no strong plan orients them.

    Sound, not complete (empty proves nothing), and cheap beside a search: the 50-part mix at
    5 % under 1 degree names 30 of its 96 roots in 0.2 s, where the length search ran 30 s
    before it gave up; 0.01-0.13 s on the mixes of 20-50 parts at 1-3 %, which have plans.
    """
    return holding_kept_pairs(roots, kept_pairs(problem, deadline))


def unsolvable_by_pairs(
    problem: Problem,
    roots: list[int],
    deadline: Deadline | None = None,
    max_sets: int = MAX_SETS,
    *,
    kept_known: bool = False,
) -> list[int] | None:
    """Roots holding a pair of states that no strong plan orients: a subset of a solvable
    set is solvable, so these roots are not (empty: every pair is; that proves nothing of the
    roots themselves); None when undecided (too many sets, or ``deadline``).

    Two states reach few sets (their images' reading branches), so :func:`solve` over every
    pair inside a root is quick where the roots' own reachable sets are too many to explore:
    on a 50-part mix at 3 mm under 1 degree 10,809 pairs and 16,520 sets in 6 s decide that
    30 of 96 roots hold one, where the roots' own sets did not finish in 120 s. The
    neighbours in diameter are asked first (``NEIGHBOUR_PAIRS``): when one of those pairs
    has no strong plan, the roots holding such a pair are the answer (some of the roots
    with none, not necessarily all). Both landings of a 20-part mix at 5 % under 1 degree:
    0.28 s instead of 3.2 s.

    Before any search, the pairs nature can keep apart whatever the plan does
    (:func:`~feederkit.machine.inseparable.kept_apart` over :func:`candidate_pairs`, one
    fixpoint over all pairs): the roots holding one are the answer. The 50-part mix at 5 %
    under 1 degree: the same 30 roots in 0.3 s, where the pairs' searches take 5.8 s.
    ``kept_known``: the caller found no such root already (:func:`kept_roots`, 2 s on a
    100-part mix at 5 %), and it is not asked again.
    """
    deadline = deadline or Deadline(None)
    held = [] if kept_known else kept_roots(problem, roots, deadline)
    if held:
        return held
    near = _pairs_within(problem, roots, NEIGHBOUR_PAIRS, deadline)
    bad = unsolvable_pairs(problem, near, deadline, max_sets)
    if bad is not None and not bad:
        every = _pairs_within(problem, roots, None, deadline)
        bad = unsolvable_pairs(problem, every, deadline, max_sets)
    if bad is None:
        return None
    return [r for r in roots if any(pair & r == pair for pair in bad)]


def _pairs_within(
    problem: Problem, roots: list[int], reach: int | None, deadline: Deadline
) -> list[int]:
    """The pairs of states inside a root that are not a goal: each state with the next
    ``reach`` of its root (None: every other state), as bit masks. Polls ``deadline`` per
    state: the largest root of a 200-part mix at 0.5 % holds 920 states, 422,796 pairs."""
    pairs: set[int] = set()
    for r in roots:
        idx = members(r)
        for k, a in enumerate(idx):
            deadline.check()
            for b in idx[k + 1 : None if reach is None else k + 1 + reach]:
                pair = (1 << a) | (1 << b)
                if not problem.is_goal(pair):
                    pairs.add(pair)
    return sorted(pairs)


def unsolvable_pairs(
    problem: Problem,
    pairs: list[int],
    deadline: Deadline | None = None,
    max_sets: int = MAX_SETS,
    hopeless: Callable[[int], bool] | None = None,
) -> list[int] | None:
    """The ``pairs`` (sets of two states) no strong plan orients, in their order; None when
    undecided (more than ``max_sets`` sets). ``hopeless`` as in :func:`solve`.

    :func:`solve` explores every set a pair reaches before it settles any, however short the
    pair's plan. Where the pairs reach more than ``SETS_PER_PAIR`` sets each, the pairs
    with a short plan are set aside first (:func:`_unsettled`) and only the rest explored.
    """
    value = solve(problem, pairs, deadline, min(max_sets, SETS_PER_PAIR * len(pairs)), hopeless)
    if value is None:
        left = _unsettled(problem, pairs, deadline, max_sets)
        if left is None:
            return None
        if not left:
            return []
        pairs = left
        value = solve(problem, pairs, deadline, max_sets, hopeless)
    if value is None:
        return None
    return [pair for pair in pairs if value[pair] == math.inf]


SETS_PER_PAIR = 4
""":func:`unsolvable_pairs` explores the pairs' sets at once up to this many per pair; past it the
pairs with a short plan are set aside first. The pairs of mixes of 20-50 parts at 1-3 %
reach 1.2-5 sets each, and one exploration is about as quick as a search per pair; those of
both landings of a random 200-point outline at 1 % reach thousands."""

SETTLE_DEPTH = 4
""":func:`_unsettled` searches each pair's length up to this many operations; a pair with a
plan that short has one and is not handed to :func:`solve`."""


def _unsettled(
    problem: Problem, pairs: list[int], deadline: Deadline | None, max_sets: int = MAX_SETS
) -> list[int] | None:
    """The ``pairs`` with no plan within ``SETTLE_DEPTH`` operations, by the length search
    (section 6.1; iterative deepening, one memo for every pair); None once the pairs and the
    sets the search opened below them are more than ``max_sets``.

    The depth-first search stops at a pair's first plan, where :func:`solve` explores every
    set the pair reaches. Both landings of a random 200-point outline at 1 % under 1 degree
    (38 states): 627 pairs, each with a plan of at most 4 operations, found in under half a
    second, where :func:`solve` of the 50 neighbour pairs alone had not finished after 300 s
    (about 5,700 sets from each pair).
    """
    search = WorstCase(problem, deadline, pair_bound=False)
    left = []
    for n, pair in enumerate(pairs, 1):
        if not any(search.within(pair, k) for k in range(1, SETTLE_DEPTH + 1)):
            left.append(pair)
        if n + search.opened > max_sets:  # the pairs count, as in solve
            return None
    return left


NEIGHBOUR_PAIRS = 1
""":func:`unsolvable_by_pairs` first asks only each state and the next this many of its root
(in the machine's order: by diameter in the planners), the pairs most alike; the sets they
reach are a few of all pairs' (the problem keeps their actions for the full check after)."""


class NoStrongPlan(PlanningError):
    """No strong plan exists under the machine's declared uncertainty (design.md).

    ``reason`` is the message without ``hint``, the clause (maybe empty) naming the
    unresolvable pairs the lumping rule would not list together (docs/planning.md,
    "Near-symmetric states under uncertainty"); callers that add to the message put the
    hint last.
    """

    def __init__(self, reason: str, hint: str = "") -> None:
        super().__init__(f"{reason}; {hint}" if hint else reason)
        self.reason = reason
        self.hint = hint


def _uncertainty_words(machine: PushAlignMachine) -> str:
    u = machine.uncertainty
    return (
        f"rotation error {u.rotation_error_deg:g} deg, shape tolerance "
        f"{u.shape_tolerance_mm:g} mm, COM tolerance {u.com_tolerance_mm:g} mm"
    )


def no_strong_plan(machine: PushAlignMachine, undecided: bool = False) -> NoStrongPlan:
    """The error naming the declared uncertainty: no strong plan exists, or (``undecided``)
    none was found within :func:`length_cap` operations."""
    what = _uncertainty_words(machine)
    if undecided:
        return NoStrongPlan(
            f"no strong plan found within {length_cap(machine)} operations ({what})"
        )
    return NoStrongPlan(
        f"no strong plan exists under the declared uncertainty ({what}): for every action "
        "some outcome leaves states that must be told apart reading alike"
    )


def length_cap(machine: PushAlignMachine) -> int:
    """A cap on a strong plan's length when solvability is undecided (sets too many)."""
    return 4 * machine.n + 4
