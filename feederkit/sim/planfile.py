"""Read a plan file (design.md, ``feederkit-plan`` version 1) into what the simulator executes.

Only the plan JSON is used: each part is rebuilt from its ``hull`` and ``com`` by
:func:`feederkit.plans.execute.rebuild_part` (as ``feederkit run`` does), and the plan's
stable-state ids are matched to the rebuilt part's push function by their normal direction,
so a plan whose states do not belong to its hull is refused. Bad plans raise InputError with
one line.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from feederkit.angles import norm360
from feederkit.errors import InputError
from feederkit.jsonio import read_json
from feederkit.mechanics.push import PushFunction, StableState
from feederkit.part import Part
from feederkit.plans.execute import rebuild_part
from feederkit.sensors import SensorModel, sensor_from_dict

NORMAL_MATCH_DEG = 1e-4
"""A plan state and a computed state are the same when their normals differ by less."""


@dataclass(frozen=True)
class ResultEntry:
    """One correct answer of a leaf: part ``part`` resting in its state ``state``."""

    part: str
    state: int
    pose_deg: float | None


@dataclass(frozen=True)
class Leaf:
    """The end of a plan: every listed (part, state) is a correct answer."""

    results: tuple[ResultEntry, ...]

    def accepts(self, part: str, state: int) -> bool:
        """Whether the part resting in ``state`` is one of the answers."""
        return any(r.part == part and r.state == state for r in self.results)


@dataclass(frozen=True)
class Branch:
    """Follow ``next`` when the reading lies in the closed interval ``reading`` (None: always)."""

    reading: tuple[float, float] | None
    next: Node


@dataclass(frozen=True)
class Step:
    """One push-align operation: rotate by ``action_deg`` (None at the root), align, read."""

    action_deg: float | None
    margin_deg: float | None
    branches: tuple[Branch, ...]

    def follow(self, reading: float | None) -> int | None:
        """Index of the first branch whose interval holds ``reading``; None when none does."""
        for i, b in enumerate(self.branches):
            if b.reading is None:
                return i
            if reading is not None:
                lo, hi = b.reading
                slack = 1e-9 * max(1.0, abs(lo), abs(hi))
                if lo - slack <= reading <= hi + slack:
                    return i
        return None


Node = Step | Leaf


@dataclass(frozen=True)
class PlanPart:
    """A part of the plan's mix, rebuilt from the plan, with its push function.

    ``state_of_edge`` maps a hull edge of the rebuilt part to the plan's state id.
    """

    name: str
    part: Part
    pf: PushFunction
    state_of_edge: dict[int, int]
    states: dict[int, StableState]  # plan id -> computed stable state


@dataclass(frozen=True)
class SimPlan:
    """What the simulator needs from a plan file."""

    parts: tuple[PlanPart, ...]
    root: Node
    sensor: SensorModel
    min_margin_deg: float | None
    length: int | None

    def part(self, name: str) -> PlanPart:
        """The plan part called ``name``."""
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(name)


def load_plan_json(path: str | os.PathLike[str]) -> dict:
    """Read a plan file's JSON object; unreadable or malformed files are bad input."""
    data = read_json(path, "file")
    if not isinstance(data, dict):
        raise InputError(f"{Path(path)}: a plan file holds a JSON object")
    return data


def _number(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"plan: {what} must be a finite number, got {value!r}")
    return float(value)


def _plan_part(entry: object, index: int) -> PlanPart:
    if not isinstance(entry, dict):
        raise InputError(f"plan: parts[{index}] must be an object")
    name = entry.get("name")
    if not isinstance(name, str) or not name:
        raise InputError(f"plan: parts[{index}] needs a name")
    hull, com, states = entry.get("hull"), entry.get("com"), entry.get("stable_states")
    if not isinstance(hull, list) or not isinstance(com, list) or not isinstance(states, list):
        raise InputError(f"plan: part {name!r} needs 'hull', 'com' and 'stable_states'")
    pf = rebuild_part(entry)
    state_of_edge: dict[int, int] = {}
    by_id: dict[int, StableState] = {}
    for s in states:
        if not isinstance(s, dict) or "id" not in s or "normal_deg" not in s:
            raise InputError(
                f"plan: part {name!r} has a stable state without 'id' and 'normal_deg'"
            )
        sid = s["id"]
        if isinstance(sid, bool) or not isinstance(sid, int):
            raise InputError(f"plan: part {name!r} has a state id that is not an integer")
        normal = norm360(_number(s["normal_deg"], f"part {name!r} state {sid} normal_deg"))
        match = [
            c
            for c in pf.states
            if min(norm360(c.normal_deg - normal), norm360(normal - c.normal_deg))
            < NORMAL_MATCH_DEG
        ]
        if not match:
            raise InputError(
                f"plan: part {name!r} state {sid} (normal {normal:g} deg) "
                "is not a stable edge of its hull"
            )
        if sid in by_id:
            raise InputError(f"plan: part {name!r} lists state {sid} twice")
        by_id[sid] = match[0]
        state_of_edge[match[0].edge] = sid
    if len(by_id) != pf.n:
        raise InputError(
            f"plan: part {name!r} lists {len(by_id)} stable states but its hull has {pf.n}"
        )
    return PlanPart(name=name, part=pf.part, pf=pf, state_of_edge=state_of_edge, states=by_id)


def _node(data: object, parts: dict[str, PlanPart], where: str, root: bool) -> Node:
    if not isinstance(data, dict):
        raise InputError(f"plan: {where} must be an object")
    if "result" in data:
        raw = data["result"]
        if not isinstance(raw, list) or not raw:
            raise InputError(f"plan: {where}.result must be a non-empty list")
        out = []
        for r in raw:
            if not isinstance(r, dict) or r.get("part") not in parts or "state" not in r:
                raise InputError(f"plan: {where}.result names a part or state the plan lacks")
            if r["state"] not in parts[r["part"]].states:
                raise InputError(
                    f"plan: {where}.result names state {r['state']!r} of {r['part']!r}"
                )
            pose = r.get("pose_deg")
            out.append(ResultEntry(r["part"], r["state"], None if pose is None else float(pose)))
        return Leaf(tuple(out))
    action = data.get("action_deg")
    if action is None and not root:
        raise InputError(f"plan: {where} has no action_deg (only the root may lack one)")
    action_deg = None if action is None else _number(action, f"{where}.action_deg")
    margin = data.get("margin_deg")
    margin_deg = None if margin is None else _number(margin, f"{where}.margin_deg")
    raw_branches = data.get("branches")
    if not isinstance(raw_branches, list) or not raw_branches:
        raise InputError(f"plan: {where} needs a result or a non-empty list of branches")
    branches = []
    for i, b in enumerate(raw_branches):
        if not isinstance(b, dict) or "next" not in b:
            raise InputError(f"plan: {where}.branches[{i}] needs 'reading' and 'next'")
        reading = b.get("reading")
        interval = None
        if reading is not None:
            if not isinstance(reading, list) or len(reading) != 2:
                raise InputError(
                    f"plan: {where}.branches[{i}].reading must be a pair lo, hi or null"
                )
            lo = _number(reading[0], f"{where}.branches[{i}].reading")
            hi = _number(reading[1], f"{where}.branches[{i}].reading")
            if lo > hi:
                raise InputError(f"plan: {where}.branches[{i}].reading has lo > hi")
            interval = (lo, hi)
        branches.append(
            Branch(interval, _node(b["next"], parts, f"{where}.branches[{i}].next", False))
        )
    return Step(action_deg, margin_deg, tuple(branches))


def read_plan(data: object) -> SimPlan:
    """Validate a plan file's JSON object and rebuild its parts."""
    if not isinstance(data, dict):
        raise InputError("plan: a plan file holds a JSON object")
    if data.get("format") != "feederkit-plan":
        raise InputError("plan: not a feederkit plan (its 'format' is not \"feederkit-plan\")")
    if data.get("version") != 1:
        raise InputError(f"plan: unsupported plan version {data.get('version')!r} (this reads 1)")
    raw_parts = data.get("parts")
    if not isinstance(raw_parts, list) or not raw_parts:
        raise InputError("plan: 'parts' must be a non-empty list")
    parts: dict[str, PlanPart] = {}
    for i, entry in enumerate(raw_parts):
        pp = _plan_part(entry, i)
        if pp.name in parts:
            raise InputError(f"plan: part {pp.name!r} appears twice")
        parts[pp.name] = pp
    sensor = sensor_from_dict(data.get("sensor", {"model": "none"}))
    root = _node(data.get("root"), parts, "root", True)
    stats = data.get("stats") if isinstance(data.get("stats"), dict) else {}
    margin = stats.get("min_margin_deg")
    length = stats.get("length")
    return SimPlan(
        parts=tuple(parts.values()),
        root=root,
        sensor=sensor,
        min_margin_deg=float(margin)
        if isinstance(margin, int | float) and math.isfinite(margin)
        else None,
        length=int(length) if isinstance(length, int) and not isinstance(length, bool) else None,
    )
