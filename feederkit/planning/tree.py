"""Conditional plans over the push-align machine: the planners' output.

A :class:`Step` is one push-align operation: rotate by ``action`` (none at the root, the
first alignment from an unknown orientation), align, read, follow the branch whose closed
reading interval holds the reading. A :class:`Leaf` is an oriented set of states (every pair
inseparable); all its states are correct answers.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from feederkit.machine import OverlapRange, PushAlignMachine, ReadingBranch

if TYPE_CHECKING:
    from feederkit.planning.budget import Deadline
    from feederkit.uncertainty import Uncertainty


@dataclass(frozen=True)
class Leaf:
    """An oriented set of machine states (a goal)."""

    mask: int


@dataclass(frozen=True, repr=False)
class Step:
    """One push-align operation and its branches on the reading.

    ``action`` is None at the root; ``branches`` pair each reading branch (its ``mask`` is
    the set of states consistent with the reading) with the subtree that follows. Equal
    subplans are often one object (a plan is a DAG in memory), so the repr names only the
    action and the number of branches: written out as a tree it can grow exponentially.
    """

    action: OverlapRange | None
    branches: tuple[tuple[ReadingBranch, Step | Leaf], ...]

    def __repr__(self) -> str:
        return f"Step(action={self.action!r}, branches=<{len(self.branches)}>)"


PlanTree = Step | Leaf


def leaf_masks(root: Step | Leaf) -> list[int]:
    """The masks of the distinct leaves of a plan tree (a DAG walked once per node)."""
    seen: set[int] = set()
    todo: list[Step | Leaf] = [root]
    out: list[int] = []
    while todo:
        node = todo.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, Step):
            todo.extend(child for _b, child in node.branches)
        else:
            out.append(node.mask)
    return out


def map_tree(
    root: Step | Leaf,
    leaf: Callable[[Leaf], Leaf],
    step: Callable[[Step, tuple[tuple[ReadingBranch, Step | Leaf], ...]], Step],
) -> Step | Leaf:
    """The plan with every leaf replaced by ``leaf(it)`` and every step by ``step(it, its
    branches with their subtrees mapped)``: each distinct node once, children first, without
    recursion (a plan's DAG can have far more paths than nodes, and more levels than Python's
    stack), so shared subplans stay shared.

    >>> t = Step(None, ((ReadingBranch(1.0, 2.0, 0b11), Leaf(0b11)),))
    >>> map_tree(t, lambda x: Leaf(x.mask & 1), lambda n, subs: Step(n.action, subs)).branches[0][1]
    Leaf(mask=1)
    """
    nodes: dict[int, Step | Leaf] = {}
    stack: list[tuple[Step | Leaf, bool]] = [(root, False)]
    while stack:
        n, ready = stack.pop()
        if id(n) in nodes:
            continue
        if isinstance(n, Leaf):
            nodes[id(n)] = leaf(n)
            continue
        if not ready:
            stack.append((n, True))
            stack.extend((sub, False) for _b, sub in n.branches if id(sub) not in nodes)
            continue
        nodes[id(n)] = step(n, tuple((b, nodes[id(sub)]) for b, sub in n.branches))
    return nodes[id(root)]


def branch_pairs(branches: Iterable[tuple[ReadingBranch, object]]) -> int:
    """The (node, state) pairs a step's branches add to a plan: the states of each branch,
    those that can reach the node below it (what verifying the plan walks, and what a
    planner commits to its deadline: :meth:`~feederkit.planning.budget.Deadline.commit`)."""
    return sum(b.mask.bit_count() for b, _c in branches)


def root_step(branches: Iterable[tuple[ReadingBranch, Step | Leaf]], deadline: Deadline) -> Step:
    """The plan's root (the first alignment, no rotation) over ``branches``, its pairs
    committed to ``deadline``."""
    node = Step(None, tuple(branches))
    deadline.commit(branch_pairs(node.branches))
    return node


def build_dag(
    keys: Iterable[Hashable],
    expand: Callable[[Hashable], Leaf | tuple[OverlapRange, list[tuple[ReadingBranch, Hashable]]]],
    deadline: Deadline,
) -> dict[Hashable, Step | Leaf]:
    """The plan nodes of ``keys`` and everything below, built on an explicit stack.

    ``expand(key)`` is a Leaf or a node's action with its (branch, child key) pairs; equal
    keys share one node (the tree is a DAG in memory). The keys must not lead back to
    themselves (each expansion gets closer to a goal), and no depth meets Python's
    recursion limit. Each step's (node, state) pairs are committed to ``deadline``
    (:meth:`~feederkit.planning.budget.Deadline.commit`): a plan too large to verify in the
    time left stops like one too slow to build.
    """
    made: dict[Hashable, Step | Leaf] = {}
    pending: dict[Hashable, tuple[OverlapRange, list[tuple[ReadingBranch, Hashable]]]] = {}
    stack: list[tuple[Hashable, bool]] = [(k, False) for k in keys]
    while stack:
        key, ready = stack.pop()
        if key in made:
            continue
        if ready:
            action, subs = pending.pop(key)
            made[key] = Step(action, tuple((b, made[c]) for b, c in subs))
            deadline.commit(branch_pairs(subs))
            continue
        if key in pending:
            continue
        deadline.check()
        node = expand(key)
        if isinstance(node, Leaf):
            made[key] = node
            continue
        pending[key] = node
        stack.append((key, True))
        stack.extend((c, False) for _b, c in node[1] if c not in made)
    return made


@dataclass(frozen=True)
class Certificate:
    """What a strong plan guarantees beyond its declared uncertainty (design.md, plan file
    ``stats.certificate``); the one value the planners' result and the plan model share.

    ``max_rotation_error_deg``: the largest rotation error (a supremum) under which the plan
    as written still reaches its results for every outcome; ``max_shape_tolerance_mm``: the
    largest shape tolerance likewise (to the bisection's resolution); ``ideal_length``: the
    minimum length on the ideal model (zero uncertainty; None when not computed), what
    robustness costs.
    """

    max_rotation_error_deg: float
    max_shape_tolerance_mm: float
    ideal_length: int | None

    def to_dict(self) -> dict[str, float | int | None]:
        """The plan file's ``stats.certificate`` object (design.md's key order)."""
        return {
            "max_rotation_error_deg": self.max_rotation_error_deg,
            "max_shape_tolerance_mm": self.max_shape_tolerance_mm,
            "ideal_length": self.ideal_length,
        }


TIES_EXACT = "exact"
"""``tie_breaks``: every tie-break of the objective was decided exactly."""
TIES_MARGIN = "margin"
"""``tie_breaks``: the largest margin is exact, the expected operations are not minimised."""
TIES_NONE = "none"
"""``tie_breaks``: no tie-break is proven (the margin is the best found in the budget)."""
TIES_CHAIN = "backchain"
"""``tie_breaks``: the sensorless chain of a set whose readings carry nothing (Goldberg's
backchaining with one part, its rotations the widest that shorten the set; with several, a
shortest path over sets keeping the largest margin found by bisection,
:func:`~feederkit.planning.quiet.widest_chain`): no expected-operations tie-break."""


@dataclass(frozen=True)
class PlanResult:
    """A plan and its statistics.

    ``length`` is the worst-case number of push-align operations, the first alignment
    counted (design.md). ``expected_length`` assumes a uniformly random initial orientation
    (each first state weighted by its resting range). ``min_margin`` is the smallest
    half-width of the plan's actions (inf when it has none). ``optimal`` says the length
    (or the expected length, for that objective) is proven minimal; ``lower_bound`` is a
    proven lower bound on the optimum. Under uncertainty the length is the worst case over
    every outcome nature can pick (a strong plan), ``min_margin`` the extra rotation error
    beyond the declared one that an action tolerates without changing its outcome sets, and
    ``certificate`` (set by :func:`feederkit.plans.make.make_plan`) what the plan guarantees.
    ``lumped_pairs``: pairs some result lists together that are not inseparable, because
    no strong plan tells them apart or merges them under the declared uncertainty
    (near-symmetric states, :mod:`feederkit.planning.lumping`). ``tie_breaks``: how far
    the choice among plans of the proven length went (docs/planning.md, "Which plan among
    the shortest"): ``"exact"`` every stage, ``"margin"`` the largest smallest margin but
    not the fewest expected operations, ``"none"`` the margin found when the tie-breaking
    budget ran out, ``"backchain"`` the sensorless chain where readings carry nothing (with
    several parts the largest margin among chains, :data:`TIES_CHAIN`). ``ties_cut_by``:
    what cut the choice short, ``"work"`` (the tie-breaking stages' budget, a multiple of
    the length proof's work: the same on any computer), ``"time"`` or ``"memory"`` (the
    run's limits); None when nothing did.
    """

    machine: PushAlignMachine
    root: Step
    length: int
    expected_length: float
    min_margin: float
    optimal: bool
    lower_bound: int
    objective: str = "worst"
    grouping: str = "exact"
    certificate: Certificate | None = None
    lumped_pairs: tuple[tuple[int, int], ...] = ()
    tie_breaks: str = "exact"
    ties_cut_by: str | None = None

    @property
    def uncertainty(self) -> Uncertainty:
        """The declared uncertainty the plan is strong for (the machine's)."""
        return self.machine.uncertainty
