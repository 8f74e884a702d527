"""The plan file (design.md, ``feederkit-plan`` version 1) read into values the report draws.

The plan is checked by :func:`feederkit.plans.fileformat.validate_plan` (anything malformed is
bad input, ``InputError``); its stable states are :class:`~feederkit.mechanics.push.StableState`
values as the file lists them. Nodes are numbered in pre-order from 0 (the root), which is the
order the report draws them.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feederkit.errors import InputError
from feederkit.jsonio import read_json
from feederkit.mechanics.push import StableState
from feederkit.plans.fileformat import validate_plan

Point = tuple[float, float]


@dataclass(frozen=True)
class PartEntry:
    """A part of the plan's mix: its hull and COM in the part frame, and its stable states."""

    name: str
    revision: str | None
    com: Point
    hull: tuple[Point, ...]
    states: tuple[StableState, ...]

    def state(self, sid: int) -> StableState:
        """The state with id ``sid``; an unknown id is bad input."""
        for s in self.states:
            if s.id == sid:
                return s
        raise InputError(f"plan: part {self.name!r} has no stable state {sid}")


@dataclass(frozen=True)
class ResultEntry:
    """One final pose a leaf of the plan names."""

    part: str
    state: int
    pose_deg: float


@dataclass(frozen=True)
class Branch:
    """An edge of the plan: the closed reading range ``[lo, hi]`` (None when sensorless)."""

    reading: tuple[float, float] | None
    next: Node


@dataclass(frozen=True)
class OpNode:
    """An operation: rotate by ``action_deg`` (None at the root), align, read, branch."""

    node_id: int
    depth: int
    action_deg: float | None
    margin_deg: float | None
    branches: tuple[Branch, ...]


@dataclass(frozen=True)
class ResultNode:
    """A leaf: the poses the part may be in; several entries are poses no plan tells apart."""

    node_id: int
    depth: int
    results: tuple[ResultEntry, ...]


Node = OpNode | ResultNode


@dataclass(frozen=True)
class PlanView:
    """The parts, sensor, tree, statistics and conventions of a plan file."""

    parts: tuple[PartEntry, ...]
    sensor: dict[str, Any]
    root: Node
    stats: dict[str, Any]
    conventions: str

    def part(self, name: str) -> PartEntry:
        """The part called ``name``; an unknown name is bad input."""
        for p in self.parts:
            if p.name == name:
                return p
        raise InputError(f"plan: a result names the unknown part {name!r}")


def _point(value: list[Any]) -> Point:
    return (float(value[0]), float(value[1]))


def _state(d: dict[str, Any]) -> StableState:
    return StableState(
        id=d["id"],
        edge=d["edge"],
        normal_deg=float(d["normal_deg"]),
        resting_range_deg=_point(d["resting_range_deg"]),
        diameter=float(d["diameter"]),
        pose_deg=float(d["pose_deg"]),
    )


def _part(d: dict[str, Any]) -> PartEntry:
    revision = d.get("revision")
    return PartEntry(
        name=d["name"],
        revision=None if revision is None else str(revision),
        com=_point(d["com"]),
        hull=tuple(_point(p) for p in d["hull"]),
        states=tuple(_state(s) for s in d["stable_states"]),
    )


def _node(d: dict[str, Any], depth: int, counter: list[int]) -> Node:
    node_id = counter[0]
    counter[0] += 1
    if "result" in d:
        results = tuple(
            ResultEntry(part=e["part"], state=e["state"], pose_deg=float(e["pose_deg"]))
            for e in d["result"]
        )
        return ResultNode(node_id=node_id, depth=depth, results=results)
    branches = tuple(
        Branch(
            reading=None if b["reading"] is None else _point(b["reading"]),
            next=_node(b["next"], depth + 1, counter),
        )
        for b in d["branches"]
    )
    action, margin = d["action_deg"], d["margin_deg"]
    return OpNode(
        node_id=node_id,
        depth=depth,
        action_deg=None if action is None else float(action),
        margin_deg=None if margin is None else float(margin),
        branches=branches,
    )


def plan_view(plan: object) -> PlanView:
    """Check a loaded plan file (``validate_plan``) and return its values; a non-plan is bad
    input."""
    d = validate_plan(plan, "plan")
    return PlanView(
        parts=tuple(_part(p) for p in d["parts"]),
        sensor=d["sensor"],
        root=_node(d["root"], 0, [0]),
        stats=d["stats"],
        conventions=d["conventions"],
    )


def nodes(root: Node) -> list[Node]:
    """All nodes in pre-order (the order of their ids)."""
    out: list[Node] = [root]
    if isinstance(root, OpNode):
        for b in root.branches:
            out.extend(nodes(b.next))
    return out


def leaves(root: Node) -> list[ResultNode]:
    """The result nodes in pre-order."""
    return [n for n in nodes(root) if isinstance(n, ResultNode)]


def read_plan_file(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Load a plan file as a dict; an unreadable file, bad JSON or a non-plan is bad input."""
    data = read_json(path, "file")
    if not isinstance(data, dict) or data.get("format") != "feederkit-plan":
        raise InputError(f"{Path(path)}: not a feederkit plan file")
    return data
