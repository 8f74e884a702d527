"""Near-symmetric states under uncertainty: lump the pairs no strong plan can resolve.

Under a declared uncertainty (design.md, "Uncertainty") two states can be neither bisimilar
(so not inseparable, :mod:`feederkit.machine.inseparable`) nor resolvable: a part whose
centre of mass sits a hair off a symmetry axis has two poses whose outcome sets differ only
by an outcome nature may pick, and the rotation error keeps every strong plan from either
telling them apart by a reading or merging them. With the inseparable goal alone such a
part has no strong plan at all. This module widens the goal the way the ideal model treats
exact symmetry (section 3.3: a result lists the poses no plan can tell apart):

- a pair of states is *resolvable* when a strong plan takes the set of the two to a goal of
  the machine's inseparable pairs (``R``), i.e. separates them by readings or merges them
  for every outcome; :func:`~feederkit.machine.inseparable.kept_apart` proves many pairs
  unresolvable cheaply (a pair fixpoint like the bisimulation),
  :func:`~feederkit.planning.solvable.unsolvable_pairs` decides the
  rest from their pair sets at once (one pass over the sets they reach, shared; the pairs
  with a short plan set aside first where they reach many);
- the *lumped* relation is ``R`` together with the unresolvable pairs ``U``; a set is a
  goal when every pair in it is lumped (the same pairwise test as before, over more pairs).

One round is the fixpoint: solvability is monotone in the goal (a plan reaching ``R``-goals
reaches the larger ``R ∪ U``-goals), so a pair resolvable under ``R`` stays resolvable,
and a pair of ``U`` is a goal itself; no iteration adds pairs. The relation need not be
transitive (``a ~ b`` and ``b ~ c`` lumped, ``a`` and ``c`` resolvable): a set holding ``a``
and ``c`` is still not a goal, so a plan never reports two states together that some
strong plan tells apart. Every pair being resolvable or lumped does **not** make every set
solvable under nondeterminism (an action's outcome sets can grow a set again; three states
whose every pair some action merges while every action maps the three onto themselves are
the smallest case), so :func:`lumped_goal` also checks the roots and gives up (None, the
planner then keeps "no strong plan") when they stay unsolvable: conservative, never wrong.

Which unresolvable pairs may be lumped is the caller's rule (:class:`~feederkit.planning.
options.Lumping`): by default only pairs of one part whose poses look alike (the machine
build records them in ``MachineState.look_alike``; the planners read the record, never
geometry) and pairs of different parts; the others are left out of the goal (``unlike``),
and when the roots stay unsolvable without them there is no strong plan. Leaving pairs out
keeps the argument above: the goal only shrinks, a pair left out is simply not a goal.

On the ideal model a plan always exists (docs/planning.md, "The goal"), so lumping is only
for machines with outcome sets and only when the inseparable goal leaves no strong plan.
docs/planning.md ("Near-symmetric states under uncertainty") says more.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.errors import InputError
from feederkit.machine import Grouping, PushAlignMachine, members
from feederkit.planning.andor import Deadline, Timeout
from feederkit.planning.options import Lumping
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.solvable import (
    MAX_SETS,
    candidate_pairs,
    kept_pairs,
    solve,
    unsolvable_pairs,
)
from feederkit.planning.tree import PlanTree, leaf_masks
from feederkit.planning.wandering import is_twin_pair, wandering_words

Pair = tuple[int, int]

PAIR_SETS = 20_000
"""The most sets the exact pair check explores before it settles for
:func:`~feederkit.machine.inseparable.kept_apart`."""


@dataclass(frozen=True)
class LumpedGoal:
    """The goal widened by the pairs no strong plan resolves.

    ``insep[i]``: the states ``i`` is lumped with (inseparable or unresolvable), the masks a
    :class:`~feederkit.planning.problem.Problem` takes as its goal; ``pairs``: the lumped
    pairs ``(i, j)``, ``i < j``, sorted (not inseparable, yet no strong plan separates or
    merges them under the machine's declared uncertainty); ``exact``: they are all such
    pairs (False: those :func:`~feederkit.machine.inseparable.kept_apart` proves, when the
    exact check was too large).
    """

    insep: tuple[int, ...]
    pairs: tuple[Pair, ...]
    exact: bool = True

    def renumbered(self, old: Sequence[int]) -> LumpedGoal:
        """The same lumping over the original numbering (``old[new_index]``, as
        :func:`~feederkit.planning.reindex.by_diameter` returns it, or several new states to
        one old one, as :func:`~feederkit.planning.wandering.split_wandering` does)."""
        masks = [0] * (max(old, default=-1) + 1)
        for k, m in enumerate(self.insep):
            for j in members(m):
                masks[old[k]] |= 1 << old[j]
        # A twin and its wandering state (feederkit.planning.wandering) are one state again.
        pairs = sorted({(min(old[i], old[j]), max(old[i], old[j])) for i, j in self.pairs})
        return LumpedGoal(tuple(masks), tuple(p for p in pairs if p[0] != p[1]), self.exact)

    def in_leaves(self, root: PlanTree) -> tuple[Pair, ...]:
        """The lumped pairs that some leaf of the plan ``root`` reports together (the ones
        the output must name), sorted."""
        lumped = set(self.pairs)
        found: set[Pair] = set()
        for mask in leaf_masks(root):
            idx = members(mask)
            for a, i in enumerate(idx):
                found.update((i, j) for j in idx[a + 1 :] if (i, j) in lumped)
        return tuple(sorted(found))


def unresolvable_pairs(
    problem: Problem, deadline: Deadline | None = None, max_sets: int = PAIR_SETS
) -> tuple[Pair, ...] | None:
    """The candidate pairs from whose set no strong plan reaches a goal of ``problem`` (no
    margin floor), exactly; None when undecided (more than ``max_sets`` sets). Raises
    Timeout when ``deadline`` passes.

    The pairs :func:`~feederkit.machine.inseparable.kept_apart` finds are unresolvable at
    once, and so is every set that holds one (nature keeps that pair);
    :func:`~feederkit.planning.solvable.unsolvable_pairs` decides the rest from their pair
    sets together, those sets pruned.
    """
    pairs = candidate_pairs(problem)
    kept = kept_pairs(problem, deadline)
    rest = [p for p in pairs if p not in kept]
    found = set(kept)
    if rest:
        holds = lumped([0] * problem.n, sorted(kept))

        def hopeless(mask: int) -> bool:
            return any(holds[i] & mask for i in members(mask))

        roots = [(1 << i) | (1 << j) for i, j in rest]
        bad = unsolvable_pairs(problem.with_margin(0.0), roots, deadline, max_sets, hopeless)
        if bad is None:
            return None
        refused = set(bad)
        found.update(p for p, r in zip(rest, roots, strict=True) if r in refused)
    return tuple(sorted(found))


def lumped(insep: Sequence[int], pairs: Sequence[Pair]) -> tuple[int, ...]:
    """The masks ``insep`` with every pair of ``pairs`` added (both ways)."""
    masks = list(insep)
    for i, j in pairs:
        masks[i] |= 1 << j
        masks[j] |= 1 << i
    return tuple(masks)


def _rule(value: Lumping | str) -> Lumping:
    """``value`` as a :class:`Lumping` rule; anything else is bad input naming the choices."""
    try:
        return Lumping(value)
    except ValueError:
        choices = ", ".join(m.value for m in Lumping)
        raise InputError(f"the lumping must be one of {choices}, got {value!r}") from None


def may_lump(machine: PushAlignMachine, i: int, j: int, rule: Lumping | str) -> bool:
    """Whether ``rule`` lets a plan list states ``i`` and ``j`` together (:class:`Lumping`).

    ``near-symmetric``: states of different parts, or of one part when each names the other
    in ``look_alike`` (``MachineState.alike``: a state that records nothing, built by hand,
    allows any). Never an accepted state with a rejected one, whatever the rule.
    """
    rule = _rule(rule)
    if rule is Lumping.NONE or machine.states[i].reject != machine.states[j].reject:
        # A leaf accepts or rejects all it lists: an accepted state listed with a rejected
        # one would send a part the next station cannot take to it (design.md, "Landings").
        return False
    if rule is Lumping.ANY:
        return True
    return machine.states[i].alike(machine.states[j])


@dataclass(frozen=True)
class LumpingTry:
    """What lumping made of a machine with no strong plan to its inseparable goal.

    ``goal``: the lumped goal, when it gives every root reading set a strong plan (else
    None); ``unlike``: the unresolvable pairs the rule left out (poses that do not look
    alike), sorted; ``decided``: False when the search ran out of time or sets (``goal`` is
    then None, and no strong plan may yet exist); ``cut_by``: then what it ran out of (the
    Timeout's reason, ``"time"`` or ``"memory"``, or ``"sets"``), else None; ``undecided``:
    with ``"sets"``, the lumped goals whose roots had too many sets to decide, fewest pairs
    across parts first (their pairs are decided: a planner's search may still find a strong
    plan to one).
    """

    goal: LumpedGoal | None
    unlike: tuple[Pair, ...] = ()
    decided: bool = True
    cut_by: str | None = None
    undecided: tuple[LumpedGoal, ...] = ()


def try_lumping(
    machine: PushAlignMachine,
    grouping: Grouping | str = Grouping.EXACT,
    deadline: Deadline | None = None,
    max_sets: int = MAX_SETS,
    pair_sets: int = PAIR_SETS,
    rule: Lumping | str = Lumping.NEAR_SYMMETRIC,
    share: Deadline | None = None,
) -> LumpingTry:
    """The lumped goal of ``machine`` under ``rule`` (:func:`lumped_goal`), with the pairs the
    rule left out and whether it was decided.

    ``share``, a deadline before ``deadline`` (a stage of a plan's budget): past it what is
    not yet decided is left as past ``pair_sets`` and ``max_sets`` (the pairs from
    :func:`~feederkit.planning.solvable.kept_pairs`, the goals ``undecided`` for a search to
    try), so that deciding cannot take the time a search needs; only ``deadline`` itself
    ends in Timeout's reason.
    """
    rule = _rule(rule)
    if machine.deterministic or machine.n < 2 or rule is Lumping.NONE:
        return LumpingTry(None)
    problem = Problem(machine, grouping, 0.0)
    inner = deadline if share is None else share

    def cut(exc: Timeout) -> bool:
        """Whether the Timeout is the share's own, with ``deadline`` still running."""
        return (
            share is not None
            and exc.reason == "time"
            and not (deadline is not None and deadline.expired())
        )

    try:
        try:
            pairs = unresolvable_pairs(problem, inner, pair_sets)
        except Timeout as exc:
            if not cut(exc):
                raise
            pairs = None
        exact = pairs is not None
        if pairs is None:
            # Past the share, under the plan's own limit (its Timeout ends the decision).
            pairs = tuple(sorted(kept_pairs(problem, deadline)))
        unlike = tuple(p for p in pairs if not may_lump(machine, *p, rule))
        pairs = tuple(p for p in pairs if may_lump(machine, *p, rule))
        if not pairs:
            return LumpingTry(None, unlike)
        # Fewer pairs across parts first (within_first); every lumpable pair if those
        # leave a root without a strong plan (or that is undecided).
        try:
            fewer = within_first(problem, pairs, inner, pair_sets) if exact else None
        except Timeout as exc:
            if not cut(exc):
                raise
            fewer = None
        tries = [pairs] if fewer is None else [fewer, pairs]
        for k, lumps in enumerate(tries):
            goal = lumped(problem.insep, lumps)
            wide = Problem(machine, grouping, 0.0, goal)
            roots = sorted(maximal_sets(b.mask for b in wide.readings.branches(wide.full)))
            try:
                value = solve(wide, roots, inner, max_sets)
            except Timeout as exc:
                if not cut(exc):
                    raise
                value = None
            if value is not None and all(value[r] < math.inf for r in roots):
                return LumpingTry(LumpedGoal(goal, lumps, exact), unlike)
            if value is None:
                # Undecided: this goal and every wider one are for a search to try, in order
                # (fewer pairs across parts first, as when decided).
                left = tuple(LumpedGoal(lumped(problem.insep, x), x, exact) for x in tries[k:])
                return LumpingTry(None, unlike, False, "sets", left)
    except Timeout as exc:
        return LumpingTry(None, decided=False, cut_by=exc.reason)
    return LumpingTry(None, unlike)


def within_first(
    problem: Problem,
    pairs: Sequence[Pair],
    deadline: Deadline | None = None,
    pair_sets: int = PAIR_SETS,
) -> tuple[Pair, ...] | None:
    """The lumpable ``pairs`` left once one part's own are lumped: those pairs, and the
    pairs across parts no strong plan resolves even then; None when that leaves all of
    ``pairs`` (or is undecided).

    Listing two parts together gives up recognizing them (section 8), so it is the last
    resort: a pair across parts that is unresolvable only because one part's near-symmetric
    states had to be told apart is resolved once they are lumped (an L-bracket mesh's
    poses 3 and 4 were listed together in a 1-operation plan; with only each pose's own
    states lumped, a 3-operation plan tells them apart).
    """
    states = problem.machine.states
    own = [(i, j) for i, j in pairs if states[i].part == states[j].part]
    if not own or len(own) == len(pairs):
        return None
    wide = Problem(problem.machine, problem.grouping, 0.0, lumped(problem.insep, own))
    again = unresolvable_pairs(wide, deadline, pair_sets)
    if again is None:
        return None
    across = set(pairs) - set(own)
    kept = tuple(sorted(set(own) | (set(again) & across)))
    return None if len(kept) == len(pairs) else kept


def lumped_goal(
    machine: PushAlignMachine,
    grouping: Grouping | str = Grouping.EXACT,
    deadline: Deadline | None = None,
    max_sets: int = MAX_SETS,
    pair_sets: int = PAIR_SETS,
    rule: Lumping | str = Lumping.NEAR_SYMMETRIC,
) -> LumpedGoal | None:
    """The lumped goal of ``machine`` when it gives every root reading set a strong plan.

    The lumped pairs are the :func:`unresolvable_pairs` that ``rule`` allows
    (:func:`may_lump`); when deciding them all takes more than ``pair_sets`` sets, the
    allowed pairs :func:`~feederkit.machine.inseparable.kept_apart` finds (every one
    unresolvable, maybe not all;
    ``LumpedGoal.exact`` False). None when lumping does not help or cannot be decided: the
    machine is ideal (a plan always exists there), the rule is ``none``, no pair is lumped
    (the set-level failure of the module docstring, or only pairs the rule leaves out), the
    roots stay unsolvable under the lumped goal, there are more than ``max_sets`` sets from
    the roots, or ``deadline`` passes. The caller then keeps its "no strong plan".
    """
    return try_lumping(machine, grouping, deadline, max_sets, pair_sets, rule).goal


WORDS_PAIRS = 4
""":func:`lumped_words` names at most this many pairs, then counts the rest."""


def lumped_words(machine: PushAlignMachine, pairs: Sequence[Pair]) -> str:
    """One sentence naming the lumped pairs, for the plan's output (empty when none).

    A physical state is named by its ideal stable states (docs/planning.md, "Results").
    """
    if not pairs:
        return ""
    u = machine.uncertainty
    return (
        f"results list states together that no strong plan tells apart under "
        f"rotation error {u.rotation_error_deg:g} deg ({_listed(machine, pairs)})"
    )


def _listed(machine: PushAlignMachine, pairs: Sequence[Pair]) -> str:
    """The first :data:`WORDS_PAIRS` pairs by name, and a count of the rest."""

    def name(i: int) -> str:
        s = machine.states[i]
        ids = "/".join(str(k) for k in s.ideal_states)
        return f"{machine.part_names[s.part]} state {ids}"

    # A wandering state and its twin (planning.wandering) have one name: each pair once.
    named = list(dict.fromkeys(f"{name(i)} with {name(j)}" for i, j in pairs))
    listed = "; ".join(named[:WORDS_PAIRS])
    if len(named) > WORDS_PAIRS:
        listed += f"; and {len(named) - WORDS_PAIRS} more pairs"
    return listed


def unlike_words(machine: PushAlignMachine, pairs: Sequence[Pair]) -> str:
    """Clauses naming the unresolvable pairs that were not lumped, for a "no strong plan"
    message (empty when none): a state a part at rest wanders over unlike poses in, with its
    twin (:mod:`feederkit.planning.wandering`), an accepted state with a rejected one (no rule
    lumps those: accept both or neither), then poses that do not look alike (lumping ``any``
    might)."""
    states = machine.states
    twins = [p for p in pairs if is_twin_pair(machine, *p)]
    pairs = [p for p in pairs if not is_twin_pair(machine, *p)]
    mixed = [p for p in pairs if states[p[0]].reject != states[p[1]].reject]
    unlike = [p for p in pairs if states[p[0]].reject == states[p[1]].reject]
    out = [wandering_words(machine, twins)] if twins else []
    if mixed:
        out.append(
            "no strong plan tells accepted states from rejected ones "
            f"({_listed(machine, mixed)}): accept both landings of each pair or neither"
        )
    if unlike:
        out.append(
            f"no strong plan tells apart poses that do not look alike "
            f"({_listed(machine, unlike)}); a plan that lists them together, leaving the part "
            "unoriented between them, may exist with lumping 'any'"
        )
    return "; ".join(out)


__all__ = [
    "LumpedGoal",
    "LumpingTry",
    "lumped",
    "lumped_goal",
    "lumped_words",
    "may_lump",
    "try_lumping",
    "unlike_words",
    "unresolvable_pairs",
]
