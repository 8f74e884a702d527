"""The plan file (design.md, ``feederkit-plan`` version 1) read into values the report draws.

Only what the report needs is checked; anything malformed is bad input (``InputError``).
Nodes are numbered in pre-order from 0 (the root), which is the order the report draws them.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feederkit.errors import InputError

Point = tuple[float, float]


@dataclass(frozen=True)
class StateEntry:
    """A stable state as the plan file lists it."""

    id: int
    edge: int
    normal_deg: float
    resting_range_deg: tuple[float, float]
    diameter: float
    pose_deg: float


@dataclass(frozen=True)
class PartEntry:
    """A part of the plan's mix: its hull and COM in the part frame, and its stable states."""

    name: str
    revision: str | None
    com: Point
    hull: tuple[Point, ...]
    states: tuple[StateEntry, ...]

    def state(self, sid: int) -> StateEntry:
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
    conventions: str | None

    def part(self, name: str) -> PartEntry:
        """The part called ``name``; an unknown name is bad input."""
        for p in self.parts:
            if p.name == name:
                return p
        raise InputError(f"plan: a result names the unknown part {name!r}")


def _num(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"plan: {what} must be a finite number, got {value!r}")
    return float(value)


def _int(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"plan: {what} must be an integer, got {value!r}")
    return value


def _point(value: object, what: str) -> Point:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise InputError(f"plan: {what} must be a pair [x, y], got {value!r}")
    return (_num(value[0], what), _num(value[1], what))


def _dict(value: object, what: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise InputError(f"plan: {what} must be a JSON object")
    return value


def _list(value: object, what: str) -> list[Any]:
    if not isinstance(value, list):
        raise InputError(f"plan: {what} must be a list")
    return value


def _state(raw: object, where: str) -> StateEntry:
    d = _dict(raw, where)
    try:
        rr = _point(d["resting_range_deg"], f"{where} resting_range_deg")
        return StateEntry(
            id=_int(d["id"], f"{where} id"),
            edge=_int(d["edge"], f"{where} edge"),
            normal_deg=_num(d["normal_deg"], f"{where} normal_deg"),
            resting_range_deg=rr,
            diameter=_num(d["diameter"], f"{where} diameter"),
            pose_deg=_num(d["pose_deg"], f"{where} pose_deg"),
        )
    except KeyError as exc:
        raise InputError(f"plan: {where} has no {exc.args[0]!r}") from None


def _part(raw: object, index: int) -> PartEntry:
    d = _dict(raw, f"part {index}")
    name = d.get("name")
    if not isinstance(name, str) or not name:
        raise InputError(f"plan: part {index} needs a non-empty 'name'")
    revision = d.get("revision")
    hull = tuple(_point(p, f"part {name!r} hull") for p in _list(d.get("hull"), f"{name!r} hull"))
    if len(hull) < 3:
        raise InputError(f"plan: part {name!r} has a hull of fewer than three vertices")
    raw_states = _list(d.get("stable_states"), f"part {name!r} stable_states")
    states = tuple(_state(s, f"part {name!r} state {i}") for i, s in enumerate(raw_states))
    if not states:
        raise InputError(f"plan: part {name!r} has no stable states")
    return PartEntry(
        name=name,
        revision=None if revision is None else str(revision),
        com=_point(d.get("com"), f"part {name!r} com"),
        hull=hull,
        states=states,
    )


def _node(raw: object, depth: int, counter: list[int]) -> Node:
    d = _dict(raw, "a plan node")
    node_id = counter[0]
    counter[0] += 1
    if "result" in d:
        entries = []
        for r in _list(d["result"], f"node {node_id} result"):
            e = _dict(r, f"node {node_id} result entry")
            if not isinstance(e.get("part"), str):
                raise InputError(f"plan: node {node_id} has a result entry without a part name")
            entries.append(
                ResultEntry(
                    part=e["part"],
                    state=_int(e.get("state"), f"node {node_id} result state"),
                    pose_deg=_num(e.get("pose_deg"), f"node {node_id} result pose_deg"),
                )
            )
        if not entries:
            raise InputError(f"plan: node {node_id} has an empty result")
        return ResultNode(node_id=node_id, depth=depth, results=tuple(entries))
    if "branches" not in d:
        raise InputError(f"plan: node {node_id} has neither 'branches' nor 'result'")
    action = d.get("action_deg")
    margin = d.get("margin_deg")
    branches = []
    for b in _list(d["branches"], f"node {node_id} branches"):
        bd = _dict(b, f"node {node_id} branch")
        reading = bd.get("reading")
        rd = None if reading is None else _point(reading, f"node {node_id} reading")
        if rd is not None and rd[0] > rd[1]:
            raise InputError(f"plan: node {node_id} has a reading range with lo > hi")
        if "next" not in bd:
            raise InputError(f"plan: node {node_id} has a branch without 'next'")
        branches.append(Branch(reading=rd, next=_node(bd["next"], depth + 1, counter)))
    if not branches:
        raise InputError(f"plan: node {node_id} has no branches")
    return OpNode(
        node_id=node_id,
        depth=depth,
        action_deg=None if action is None else _num(action, f"node {node_id} action_deg"),
        margin_deg=None if margin is None else _num(margin, f"node {node_id} margin_deg"),
        branches=tuple(branches),
    )


def plan_view(plan: object) -> PlanView:
    """Check a loaded plan file and return its values; a non-plan is bad input."""
    d = _dict(plan, "the plan file")
    if d.get("format") != "feederkit-plan":
        raise InputError("plan: not a feederkit plan (its 'format' is not \"feederkit-plan\")")
    if d.get("version") != 1:
        raise InputError(f"plan: unsupported plan version {d.get('version')!r} (expected 1)")
    parts = tuple(_part(p, i) for i, p in enumerate(_list(d.get("parts"), "'parts'")))
    if not parts:
        raise InputError("plan: the plan lists no parts")
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        raise InputError("plan: two parts share a name")
    if "root" not in d:
        raise InputError("plan: the plan has no 'root' node")
    root = _node(d["root"], 0, [0])
    view = PlanView(
        parts=parts,
        sensor=_dict(d.get("sensor", {"model": "none"}), "'sensor'"),
        root=root,
        stats=_dict(d.get("stats", {}), "'stats'"),
        conventions=d.get("conventions") if isinstance(d.get("conventions"), str) else None,
    )
    for leaf in leaves(root):
        for r in leaf.results:
            view.part(r.part).state(r.state)
    return view


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
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{p}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read the file ({exc})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    if not isinstance(data, dict) or data.get("format") != "feederkit-plan":
        raise InputError(f"{p}: not a feederkit plan file")
    return data
