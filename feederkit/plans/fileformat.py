"""The plan file, ``feederkit-plan`` version 1 (design.md): made, read, checked, written.

A plan is a conditional sequence of push-align operations (sections 4, 6, 8.5): each node
rotates the part by ``action_deg`` (none at the root, the first alignment from an unknown
orientation), lets it align on the fence, reads its diameter and follows the branch whose
closed reading interval holds the reading; a leaf lists the poses the part is then in.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from feederkit.errors import InputError, PlanningError
from feederkit.jsonio import read_json, write_text_atomic
from feederkit.machine import Branch, PushAlignMachine, members
from feederkit.mechanics.push import PushFunction
from feederkit.planning.tree import Leaf, PlanResult, Step
from feederkit.plans.stats import plan_stats
from feederkit.sensors import NoSensor, sensor_from_dict, sensor_to_dict, split_by_reading

FORMAT = "feederkit-plan"
VERSION = 1

CONVENTIONS = (
    "Lengths in mm, angles in degrees. Part frame: the outline's own coordinates; the contact "
    "polygon ('hull') is the convex hull of the outline, counter-clockwise, vertex 0 the "
    "lowest-then-leftmost, edge i joining vertex i to vertex i+1; 'com' is the center of mass. "
    "theta is the direction, in the part frame, of the fence's contact normal pointing from the "
    "COM toward the fence; edge e rests on the fence when theta equals its outward normal "
    "('normal_deg'), and every theta strictly inside 'resting_range_deg' settles there. An "
    "action a rotates the part counter-clockwise, seen from above, before the next push: "
    "theta' = theta - a; rotations are given in [0, 360). World: the belt moves toward -y and "
    "the fence is below the part; the pose of a part resting on edge e is the "
    "counter-clockwise rotation of the part frame into the world, pose = -90 - normal(e) "
    "(mod 360). The reading is the part's diameter (width across the belt) in mm; an LED "
    "array reports its beam count times its pitch. A node is executed by rotating the part by "
    "'action_deg' (none at the root: the first alignment from an unknown orientation), "
    "letting it align, reading, and following the branch whose closed interval [lo, hi] holds "
    "the reading (null: sensorless, the only branch); on a shared endpoint either branch is "
    "right. A reading no branch holds means a foreign part or a sensor fault: stop. 'length' "
    "is the worst-case number of push-align operations, the first alignment counted as "
    "operation 1. A result with several entries lists poses no plan can tell apart; every "
    "entry is a correct answer."
)


def _parts_list(machine: PushAlignMachine, parts: Sequence[PushFunction]) -> list[dict[str, Any]]:
    """Each part's name, revision, COM, hull and stable states (diameters as planned on)."""
    diameter = {(ms.part, ms.state): ms.diameter for ms in machine.states}
    return [
        {
            "name": pf.part.name,
            "revision": pf.part.revision,
            "com": list(pf.part.com),
            "hull": [list(v) for v in pf.part.hull],
            "stable_states": [
                {
                    "id": s.id,
                    "edge": s.edge,
                    "normal_deg": s.normal_deg,
                    "resting_range_deg": list(s.resting_range_deg),
                    "diameter": diameter[(p, s.id)],
                    "pose_deg": s.pose_deg,
                }
                for s in pf.states
            ],
        }
        for p, pf in enumerate(parts)
    ]


def _reading(machine: PushAlignMachine, branch: Branch) -> list[float] | None:
    """A branch's closed reading interval; null only when the plan is sensorless.

    A planner may leave a branch without an interval where readings carry no information
    (every state of the set reads alike); with a sensor the file still gives the interval
    its states read in, so a controller can tell a foreign part or a sensor fault.
    """
    if branch.lo is not None:
        return [branch.lo, branch.hi]
    if isinstance(machine.sensor, NoSensor):
        return None
    diameters = [machine.states[i].diameter for i in members(branch.mask)]
    split = split_by_reading(machine.sensor, diameters, "components")
    return [min(b.lo for b in split), max(b.hi for b in split)]


def _node_dict(machine: PushAlignMachine, parts: Sequence[PushFunction], node: Step | Leaf) -> dict:
    if isinstance(node, Leaf):
        result = []
        for i in members(node.mask):
            ms = machine.states[i]
            s = parts[ms.part].states[ms.state]
            result.append({"part": parts[ms.part].part.name, "state": s.id, "pose_deg": s.pose_deg})
        return {"result": result}
    return {
        "action_deg": None if node.action is None else node.action.representative,
        "margin_deg": None if node.action is None else node.action.margin,
        "branches": [
            {
                "reading": _reading(machine, b),
                "next": _node_dict(machine, parts, nxt),
            }
            for b, nxt in node.branches
        ],
    }


MAX_FILE_NODES = 100_000
"""A plan whose file would hold more nodes than this is refused: no controller wants it."""


def file_nodes(root: Step | Leaf) -> int:
    """How many nodes the plan file holds once shared subtrees are written out in full.

    Counted on the planner's shared structure (each distinct node once), so a plan whose
    written tree would be astronomically large is measured without being built.
    """
    memo: dict[int, int] = {}

    def count(node: Step | Leaf) -> int:
        key = id(node)
        if key not in memo:
            memo[key] = (
                1 if isinstance(node, Leaf) else 1 + sum(count(nxt) for _b, nxt in node.branches)
            )
        return memo[key]

    return count(root)


def plan_to_dict(result: PlanResult, parts: Sequence[PushFunction]) -> dict[str, Any]:
    """The plan file's JSON object for a planner's result on the machine of ``parts`` (in order).

    ``parts`` are the push functions the machine was built from (``build_machine``): the file
    records each part's hull and COM, so the plan can be checked on the geometry alone.
    Raises InputError when two parts share a name (results name their part) and
    PlanningError when the written tree would exceed MAX_FILE_NODES nodes (a plan found
    under a time limit for a part whose states nearly all read alike can share subtrees
    that would expand beyond any file).
    """
    machine = result.machine
    names = [pf.part.name for pf in parts]
    if tuple(names) != machine.part_names or sum(pf.n for pf in parts) != machine.n:
        raise ValueError("plan_to_dict: the parts are not the ones the machine was built from")
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError(f"two parts of the mix are both named {dup!r}: a plan names its parts")
    size = file_nodes(result.root)
    if size > MAX_FILE_NODES:
        found = f"the plan found ({result.length} operations"
        if not result.optimal:
            found += f", not proven optimal; a plan needs at least {result.lower_bound}"
        raise PlanningError(
            f"{found}) would write {size:.3g} nodes, more than {MAX_FILE_NODES:,}: give the "
            "planner more --time-limit, use a finer sensor, or set a --min-margin"
        )
    return {
        "format": FORMAT,
        "version": VERSION,
        "conventions": CONVENTIONS,
        "sensor": sensor_to_dict(machine.sensor),
        "parts": _parts_list(machine, parts),
        "root": _node_dict(machine, parts, result.root),
        "stats": plan_stats(result, parts),
    }


# ---------------------------------------------------------------- validation


class _Checker:
    """Structural checks of a loaded plan; each failure is one line naming where."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, message: str) -> InputError:
        return InputError(f"{self.source}: {message}")

    def obj(self, value: object, what: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(f"{what} must be a JSON object")
        return value

    def lst(self, value: object, what: str) -> list[Any]:
        if not isinstance(value, list):
            raise self.fail(f"{what} must be a list")
        return value

    def num(self, value: object, what: str) -> float:
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise self.fail(f"{what} must be a finite number, got {value!r}")
        return float(value)

    def int_(self, value: object, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(f"{what} must be an integer, got {value!r}")
        return value

    def pair(self, value: object, what: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(f"{what} must be a pair [a, b], got {value!r}")
        return self.num(value[0], what), self.num(value[1], what)

    def key(self, d: dict[str, Any], name: str, where: str) -> Any:
        if name not in d:
            raise self.fail(f"{where} has no {name!r}")
        return d[name]


def _check_part(c: _Checker, raw: object, index: int) -> tuple[str, set[int]]:
    d = c.obj(raw, f"part {index}")
    name = c.key(d, "name", f"part {index}")
    if not isinstance(name, str) or not name:
        raise c.fail(f"part {index} needs a non-empty string 'name'")
    where = f"part {name!r}"
    rev = d.get("revision")
    if rev is not None and not isinstance(rev, str | int):
        raise c.fail(f"{where} 'revision' must be a string or null")
    c.pair(c.key(d, "com", where), f"{where} com")
    hull = c.lst(c.key(d, "hull", where), f"{where} hull")
    if len(hull) < 3:
        raise c.fail(f"{where} hull has fewer than three vertices")
    for v in hull:
        c.pair(v, f"{where} hull vertex")
    states = c.lst(c.key(d, "stable_states", where), f"{where} stable_states")
    if not states:
        raise c.fail(f"{where} has no stable states")
    ids: set[int] = set()
    for k, s in enumerate(states):
        sw = f"{where} stable state {k}"
        sd = c.obj(s, sw)
        sid = c.int_(c.key(sd, "id", sw), f"{sw} id")
        if sid in ids:
            raise c.fail(f"{where} lists stable state {sid} twice")
        ids.add(sid)
        edge = c.int_(c.key(sd, "edge", sw), f"{sw} edge")
        if not 0 <= edge < len(hull):
            raise c.fail(f"{sw} names edge {edge}, but the hull has {len(hull)} edges")
        normal = c.num(c.key(sd, "normal_deg", sw), f"{sw} normal_deg")
        lo, hi = c.pair(c.key(sd, "resting_range_deg", sw), f"{sw} resting_range_deg")
        if not lo < normal < hi:
            raise c.fail(f"{sw} resting range [{lo}, {hi}] does not hold its normal {normal}")
        if c.num(c.key(sd, "diameter", sw), f"{sw} diameter") <= 0.0:
            raise c.fail(f"{sw} diameter must be positive")
        c.num(c.key(sd, "pose_deg", sw), f"{sw} pose_deg")
    return name, ids


def _walk(root: object) -> Iterator[tuple[object, int]]:
    """Every node with its depth (root 0), pre-order, without recursion."""
    stack = [(root, 0)]
    while stack:
        node, depth = stack.pop()
        yield node, depth
        if isinstance(node, dict) and isinstance(node.get("branches"), list):
            for b in reversed(node["branches"]):
                if isinstance(b, dict) and "next" in b:
                    stack.append((b["next"], depth + 1))


def _check_tree(c: _Checker, root: object, parts: Mapping[str, set[int]], sensorless: bool) -> None:
    for count, (raw, depth) in enumerate(_walk(root)):
        where = "the root" if depth == 0 else f"node {count} (depth {depth})"
        node = c.obj(raw, where)
        if "result" in node:
            if depth == 0:
                raise c.fail("the root must be an operation (the first alignment), not a result")
            entries = c.lst(node["result"], f"{where} result")
            if not entries:
                raise c.fail(f"{where} has an empty result")
            for e in entries:
                ed = c.obj(e, f"{where} result entry")
                part = c.key(ed, "part", f"{where} result entry")
                if part not in parts:
                    raise c.fail(f"{where} names the unknown part {part!r}")
                sid = c.int_(c.key(ed, "state", f"{where} result entry"), f"{where} result state")
                if sid not in parts[part]:
                    raise c.fail(f"{where} names state {sid}, which part {part!r} does not list")
                c.num(c.key(ed, "pose_deg", f"{where} result entry"), f"{where} result pose_deg")
            continue
        action = c.key(node, "action_deg", where)
        margin = c.key(node, "margin_deg", where)
        if depth == 0:
            if action is not None or margin is not None:
                raise c.fail(
                    "the root is the first alignment: its action_deg and margin_deg are null"
                )
        else:
            a = c.num(action, f"{where} action_deg")
            if not 0.0 <= a < 360.0:
                raise c.fail(f"{where} action_deg {a} is not in [0, 360)")
            m = c.num(margin, f"{where} margin_deg")
            if not 0.0 <= m <= 180.0:
                raise c.fail(f"{where} margin_deg {m} is not in [0, 180]")
        branches = c.lst(c.key(node, "branches", where), f"{where} branches")
        if not branches:
            raise c.fail(f"{where} has no branches")
        if sensorless and len(branches) != 1:
            raise c.fail(f"{where} branches on a reading, but the plan is sensorless")
        for b in branches:
            bd = c.obj(b, f"{where} branch")
            reading = c.key(bd, "reading", f"{where} branch")
            if sensorless and reading is not None:
                raise c.fail(f"{where} has a reading interval, but the plan is sensorless")
            if not sensorless:
                if reading is None:
                    raise c.fail(f"{where} has a branch without a reading interval")
                lo, hi = c.pair(reading, f"{where} reading")
                if lo > hi:
                    raise c.fail(f"{where} has a reading interval [{lo}, {hi}] with lo > hi")
            c.key(bd, "next", f"{where} branch")


def _check_stats(c: _Checker, raw: object) -> None:
    d = c.obj(raw, "'stats'")
    if c.int_(c.key(d, "length", "'stats'"), "stats length") < 1:
        raise c.fail("stats length must be at least 1 (the first alignment)")
    c.num(c.key(d, "expected_length", "'stats'"), "stats expected_length")
    m = c.key(d, "min_margin_deg", "'stats'")
    if m is not None:
        c.num(m, "stats min_margin_deg")
    if not isinstance(c.key(d, "optimal", "'stats'"), bool):
        raise c.fail("stats optimal must be true or false")
    c.int_(c.key(d, "lower_bound", "'stats'"), "stats lower_bound")


def validate_plan(data: object, source: str = "plan") -> dict[str, Any]:
    """Check a loaded plan file's structure (design.md, version 1) and return it.

    Raises InputError with one line naming ``source`` and the first problem found.
    """
    c = _Checker(source)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise c.fail('not a feederkit plan (its "format" is not "feederkit-plan")')
    if data.get("version") != VERSION:
        raise c.fail(f"unsupported plan version {data.get('version')!r} (this feederkit reads 1)")
    if not isinstance(data.get("conventions"), str):
        raise c.fail("the plan states no 'conventions'")
    try:
        sensor = sensor_from_dict(c.key(data, "sensor", "the plan"))
    except InputError as exc:
        raise c.fail(str(exc)) from None
    parts_raw = c.lst(c.key(data, "parts", "the plan"), "'parts'")
    if not parts_raw:
        raise c.fail("the plan lists no parts")
    parts: dict[str, set[int]] = {}
    for i, p in enumerate(parts_raw):
        name, ids = _check_part(c, p, i)
        if name in parts:
            raise c.fail(f"two parts are both named {name!r}")
        parts[name] = ids
    _check_tree(c, c.key(data, "root", "the plan"), parts, sensor.model == "none")
    _check_stats(c, c.key(data, "stats", "the plan"))
    return data


def _dump(value: object, indent: int) -> str:
    """Indented JSON; lists of plain values (points, intervals) and result entries on one line."""
    pad = "  " * (indent + 1)
    plain = isinstance(value, dict) and all(not isinstance(v, dict | list) for v in value.values())
    if plain and len(value) <= 3:
        return json.dumps(value, allow_nan=False)
    if isinstance(value, dict) and value:
        items = [f"{pad}{json.dumps(k)}: {_dump(v, indent + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * indent + "}"
    if isinstance(value, list | tuple) and value:
        if all(not isinstance(v, dict | list | tuple) for v in value):
            return json.dumps(value, allow_nan=False)
        items = [pad + _dump(v, indent + 1) for v in value]
        return "[\n" + ",\n".join(items) + "\n" + "  " * indent + "]"
    return json.dumps(value, allow_nan=False)


def plan_json(plan: Mapping[str, Any]) -> str:
    """The plan file's text: indented JSON (short lists on one line), no NaN or infinity."""
    return _dump(plan, 0) + "\n"


def read_plan(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Load and check a plan file; a missing, unreadable or malformed file is bad input."""
    return validate_plan(read_json(path, "plan file"), str(Path(path)))


def write_plan(path: str | os.PathLike[str], plan: Mapping[str, Any]) -> None:
    """Write a plan file atomically (a temporary file beside it, then a rename)."""
    write_text_atomic(path, plan_json(plan))
