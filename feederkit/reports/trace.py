"""The plan as the report draws it: its distinct nodes numbered, the states possible at each.

A plan may share subplans (a DAG, design.md's ``"nodes"``): the report numbers each distinct
node once, in the pre-order of :meth:`Plan.walk` (root 0; for a plan without shared nodes
every node of the tree), so a plan with astronomically many paths costs its distinct nodes.
States are keyed by member (a plan over landings has one member per landing, design.md
"Landings") and state id. The states possible at a node are the union over its parents of the
states each parent's branch lets through; the path shown to a node is the first one in
pre-order. A state's push is the state whose resting range holds the new fence orientation
``normal - action`` (design.md conventions, read off the plan's listed states); a state follows
a branch when its reading set meets the branch's closed range (:meth:`Sensor.reads_into`).
Everything here iterates: a plan as deep as the reader accepts is drawn without recursion.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from itertools import combinations

from feederkit.angles import norm360
from feederkit.mechanics.push import StableState, rotation_after
from feederkit.plans.model import Leaf, Node, Plan, PlanPart, Step

StateKey = tuple[int, int]
"""A state of the mix: (member index in ``plan.parts``, state id)."""


@dataclass(frozen=True)
class Place:
    """A distinct node of the plan: its number (pre-order of distinct nodes), its depth (the
    operations before it on its first path), the node, the numbers of the nodes its branches
    lead to (in branch order) and how many branches lead to it (more than one: shared)."""

    node_id: int
    depth: int
    node: Node
    children: tuple[int, ...]
    uses: int = 1

    @property
    def shared(self) -> bool:
        """Whether several branches lead here (the report draws it once, refers to it)."""
        return self.uses > 1


def places(plan: Plan) -> list[Place]:
    """Every distinct node of the plan once, numbered in :meth:`Plan.walk` order (root 0)."""
    walked = list(plan.walk())
    number = {id(node): k for k, (node, _) in enumerate(walked)}
    uses = [0] * len(walked)
    for node, _ in walked:
        if isinstance(node, Step):
            for b in node.branches:
                uses[number[id(b.next)]] += 1
    out = []
    for k, (node, op) in enumerate(walked):
        kids = tuple(number[id(b.next)] for b in node.branches) if isinstance(node, Step) else ()
        depth = op - 1 if isinstance(node, Step) else op
        out.append(Place(k, depth, node, kids, max(uses[k], 1)))
    return out


@dataclass(frozen=True)
class TraceStep:
    """One push-align operation on the way to a node: rotation (None: first alignment), reading."""

    action_deg: float | None
    reading: tuple[float, float] | None


@dataclass(frozen=True)
class Trace:
    """Possible states at each node (before its operation; the union over its parents) and
    one path of operations that leads there (the first in pre-order)."""

    states: Mapping[int, tuple[StateKey, ...]]
    paths: Mapping[int, tuple[TraceStep, ...]]


@dataclass(frozen=True)
class Confusion:
    """Two members a leaf of the plan leaves together: the plan cannot tell them apart."""

    part_a: str
    part_b: str
    states_a: tuple[int, ...]
    states_b: tuple[int, ...]
    node_id: int
    path: tuple[TraceStep, ...]


def pushed(part: PlanPart, state: StableState, action_deg: float) -> StableState:
    """The state ``state`` settles into after a counter-clockwise rotation by ``action_deg``:
    the push function (section 3.1) read off the plan's resting ranges."""
    theta = rotation_after(state.normal_deg, action_deg)
    for s in part.states:
        lo, hi = s.resting_range_deg
        if norm360(theta - lo) < hi - lo:
            return s
    return min(part.states, key=lambda s: abs(norm360(s.normal_deg - theta + 180.0) - 180.0))


def _topological(numbered: list[Place]) -> list[int]:
    """The node numbers, every parent before its children (Kahn's algorithm)."""
    waiting = [0] * len(numbered)
    for place in numbered:
        for k in place.children:
            waiting[k] += 1
    ready = [p.node_id for p in numbered if waiting[p.node_id] == 0]
    order: list[int] = []
    while ready:
        k = ready.pop()
        order.append(k)
        for child in reversed(numbered[k].children):
            waiting[child] -= 1
            if waiting[child] == 0:
                ready.append(child)
    return order


def trace_plan(plan: Plan, numbered: list[Place]) -> Trace:
    """Follow every state of every member through the plan from the root, each distinct node
    once, parents before children (no recursion)."""
    reached: dict[int, dict[StateKey, None]] = {
        0: {(m, s.id): None for m, p in enumerate(plan.parts) for s in p.states}
    }
    paths: dict[int, tuple[TraceStep, ...]] = {0: ()}
    for number in _topological(numbered):
        place = numbered[number]
        node = place.node
        if not isinstance(node, Step):
            continue
        here = reached.get(number, {})
        image: dict[StateKey, None] = {}
        for m, sid in here:
            part = plan.parts[m]
            s = part.state(sid)
            after = s if node.action_deg is None else pushed(part, s, node.action_deg)
            image[(m, after.id)] = None
        for b, child in zip(node.branches, place.children, strict=True):
            into = reached.setdefault(child, {})
            for m, sid in image:
                diameter = plan.parts[m].state(sid).diameter
                if b.reading is None or plan.sensor.reads_into(diameter, *b.reading):
                    into[(m, sid)] = None
    for place in numbered:  # pre-order: a node's first parent comes before it
        node = place.node
        if isinstance(node, Step):
            for b, child in zip(node.branches, place.children, strict=True):
                if child not in paths:
                    paths[child] = (*paths[place.node_id], TraceStep(node.action_deg, b.reading))
    states = {p.node_id: tuple(sorted(reached.get(p.node_id, {}))) for p in numbered}
    return Trace(states=states, paths={p.node_id: paths.get(p.node_id, ()) for p in numbered})


def leaf_members(plan: Plan, leaf: Leaf) -> dict[int, list[int]]:
    """A leaf's results grouped by member index (in result order): member -> state ids."""
    out: dict[int, list[int]] = {}
    for r in leaf.results:
        out.setdefault(plan.part_index(r.part, r.landing), []).append(r.state)
    return out


def confusions(plan: Plan, numbered: list[Place], trace: Trace) -> list[Confusion]:
    """Pairs of members that end in the same (accepting) leaf: the plan says no plan can tell
    them apart. A reject leaf needs no telling apart: every member there is recirculated."""
    out: list[Confusion] = []
    for place in numbered:
        leaf = place.node
        if not isinstance(leaf, Leaf) or leaf.reject:
            continue
        by_member = leaf_members(plan, leaf)
        for a, b in combinations(by_member, 2):
            out.append(
                Confusion(
                    part_a=plan.parts[a].label,
                    part_b=plan.parts[b].label,
                    states_a=tuple(by_member[a]),
                    states_b=tuple(by_member[b]),
                    node_id=place.node_id,
                    path=trace.paths[place.node_id],
                )
            )
    return out
