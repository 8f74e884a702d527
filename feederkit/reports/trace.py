"""The plan as the report draws it: numbered nodes, the states possible at each, witnesses.

Nodes are numbered in pre-order from 0 (the root), each place in the written tree once (a
subplan the planner shares is drawn wherever it is used). A state's push is the state whose
resting range holds the new fence orientation ``normal - action`` (design.md conventions,
read off the plan's listed states); a state follows a branch when its reading set meets the
branch's closed range (:meth:`Sensor.reads_into`). Everything here iterates: a plan as deep as
the reader accepts is drawn without recursion.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from itertools import combinations

from feederkit.angles import norm360
from feederkit.mechanics.push import StableState, rotation_after
from feederkit.plans.model import Leaf, Node, Plan, PlanPart, Step

StateKey = tuple[str, int]
"""A state of the mix: (part name, state id)."""


@dataclass(frozen=True)
class Place:
    """A node where the report draws it: its number (pre-order), the operations before it,
    the node, and the numbers of the nodes its branches lead to (in branch order)."""

    node_id: int
    depth: int
    node: Node
    children: tuple[int, ...]


def places(plan: Plan) -> list[Place]:
    """Every node of the written tree, numbered in pre-order (root 0), without recursion."""
    out: list[Place] = []
    pending: list[tuple[Node, int, int | None]] = [(plan.root, 0, None)]  # node, depth, parent
    kids: dict[int, list[int]] = {}
    order: list[tuple[Node, int]] = []
    while pending:
        node, depth, parent = pending.pop()
        number = len(order)
        order.append((node, depth))
        if parent is not None:
            kids[parent].append(number)
        kids[number] = []
        if isinstance(node, Step):
            for b in reversed(node.branches):
                pending.append((b.next, depth + 1, number))
    for number, (node, depth) in enumerate(order):
        out.append(Place(number, depth, node, tuple(kids[number])))
    return out


@dataclass(frozen=True)
class TraceStep:
    """One push-align operation on the way to a node: rotation (None: first alignment), reading."""

    action_deg: float | None
    reading: tuple[float, float] | None


@dataclass(frozen=True)
class Trace:
    """Possible states at each node (before its operation) and the operations that lead there."""

    states: Mapping[int, tuple[StateKey, ...]]
    paths: Mapping[int, tuple[TraceStep, ...]]


@dataclass(frozen=True)
class Confusion:
    """Two parts a leaf of the plan leaves together: the plan cannot tell them apart."""

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


def trace_plan(plan: Plan, numbered: list[Place]) -> Trace:
    """Follow every state of the mix through the plan from the root (pre-order, no recursion)."""
    states: dict[int, tuple[StateKey, ...]] = {
        0: tuple((p.name, s.id) for p in plan.parts for s in p.states)
    }
    paths: dict[int, tuple[TraceStep, ...]] = {0: ()}
    for place in numbered:
        node = place.node
        if not isinstance(node, Step):
            continue
        here, path = states[place.node_id], paths[place.node_id]
        image: list[StateKey] = []
        for name, sid in here:
            part = plan.part(name)
            s = part.state(sid)
            after = s if node.action_deg is None else pushed(part, s, node.action_deg)
            if (name, after.id) not in image:
                image.append((name, after.id))
        for b, child in zip(node.branches, place.children, strict=True):
            states[child] = tuple(
                k
                for k in image
                if b.reading is None
                or plan.sensor.reads_into(plan.part(k[0]).state(k[1]).diameter, *b.reading)
            )
            paths[child] = (*path, TraceStep(node.action_deg, b.reading))
    return Trace(states=states, paths=paths)


def confusions(numbered: list[Place], trace: Trace) -> list[Confusion]:
    """Pairs of parts that end in the same leaf: the plan says no plan can tell them apart."""
    out: list[Confusion] = []
    for place in numbered:
        leaf = place.node
        if not isinstance(leaf, Leaf):
            continue
        by_part: dict[str, list[int]] = {}
        for r in leaf.results:
            by_part.setdefault(r.part, []).append(r.state)
        for a, b in combinations(by_part, 2):
            out.append(
                Confusion(
                    part_a=a,
                    part_b=b,
                    states_a=tuple(by_part[a]),
                    states_b=tuple(by_part[b]),
                    node_id=place.node_id,
                    path=trace.paths[place.node_id],
                )
            )
    return out
