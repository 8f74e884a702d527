"""Which states are possible at each node of a plan, and how a leaf is reached (its witness).

Uses only the plan file: a state's push is the state whose resting range holds the new fence
orientation ``normal - action`` (design.md conventions); a state follows a branch when its
possible readings (``feederkit.sensors``) meet the branch's closed reading range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from itertools import combinations

from feederkit.angles import norm360
from feederkit.mechanics.push import StableState, rotation_after
from feederkit.reports.planview import (
    Node,
    OpNode,
    PartEntry,
    PlanView,
    ResultNode,
    leaves,
)
from feederkit.sensors import NoSensor, SensorModel, ToleranceSensor, led_counts, sensor_from_dict

StateKey = tuple[str, int]
"""A state of the mix: (part name, state id)."""

READING_EPS = 1e-9
"""Slack, in beam pitches, when an LED reading range's end meets a beam count."""


@dataclass(frozen=True)
class Step:
    """One push-align operation on the way to a node: rotation (None: first alignment), reading."""

    action_deg: float | None
    reading: tuple[float, float] | None


@dataclass(frozen=True)
class Trace:
    """Possible states at each node (before its operation) and the operations that lead there."""

    states: Mapping[int, tuple[StateKey, ...]]
    paths: Mapping[int, tuple[Step, ...]]


@dataclass(frozen=True)
class Confusion:
    """Two parts a leaf of the plan leaves together: the plan cannot tell them apart."""

    part_a: str
    part_b: str
    states_a: tuple[int, ...]
    states_b: tuple[int, ...]
    node_id: int
    path: tuple[Step, ...]


def pushed(part: PartEntry, state: StableState, action_deg: float) -> StableState:
    """The state ``state`` settles into after a counter-clockwise rotation by ``action_deg``:
    the push function (section 3.1) read off the plan's resting ranges."""
    theta = rotation_after(state.normal_deg, action_deg)
    for s in part.states:
        lo, hi = s.resting_range_deg
        if norm360(theta - lo) < hi - lo:
            return s
    return min(part.states, key=lambda s: abs(norm360(s.normal_deg - theta + 180.0) - 180.0))


def reads_into(sensor: SensorModel, diameter: float, reading: tuple[float, float] | None) -> bool:
    """Whether a state of this diameter can give a reading in the closed range ``reading``."""
    if reading is None or isinstance(sensor, NoSensor):
        return True
    lo, hi = reading
    if isinstance(sensor, ToleranceSensor):
        return diameter - sensor.tolerance < hi and diameter + sensor.tolerance > lo
    c0, c1 = led_counts(sensor, diameter)
    first = math.ceil(lo / sensor.pitch - READING_EPS)
    last = math.floor(hi / sensor.pitch + READING_EPS)
    return max(c0, first) <= min(c1, last)


def trace_plan(view: PlanView) -> Trace:
    """Follow every state of the mix through the plan from the root."""
    sensor = sensor_from_dict(view.sensor)
    states: dict[int, tuple[StateKey, ...]] = {}
    paths: dict[int, tuple[Step, ...]] = {}
    all_states = tuple((p.name, s.id) for p in view.parts for s in p.states)

    def visit(node: Node, here: tuple[StateKey, ...], path: tuple[Step, ...]) -> None:
        states[node.node_id] = here
        paths[node.node_id] = path
        if isinstance(node, ResultNode):
            return
        image: list[StateKey] = []
        for name, sid in here:
            part = view.part(name)
            s = part.state(sid)
            after = s if node.action_deg is None else pushed(part, s, node.action_deg)
            key = (name, after.id)
            if key not in image:
                image.append(key)
        for b in node.branches:
            child = tuple(
                k
                for k in image
                if reads_into(sensor, view.part(k[0]).state(k[1]).diameter, b.reading)
            )
            visit(b.next, child, (*path, Step(node.action_deg, b.reading)))

    visit(view.root, all_states, ())
    return Trace(states=states, paths=paths)


def confusions(view: PlanView, trace: Trace) -> list[Confusion]:
    """Pairs of parts that end in the same leaf: the plan says no plan can tell them apart."""
    out: list[Confusion] = []
    for leaf in leaves(view.root):
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
                    node_id=leaf.node_id,
                    path=trace.paths[leaf.node_id],
                )
            )
    return out


def plan_depth(node: Node) -> int:
    """The worst-case number of operations below and including ``node``."""
    if isinstance(node, OpNode):
        return 1 + max(plan_depth(b.next) for b in node.branches)
    return 0
