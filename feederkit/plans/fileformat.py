"""The plan file, ``feederkit-plan`` version 2 (design.md; version 1 stays readable): the one
maker, reader, checker and writer of :class:`~feederkit.plans.model.Plan`.

A plan is a conditional sequence of push-align operations (sections 4, 6, 8.5): each node
rotates the part by ``action_deg`` (none at the root, the first alignment from an unknown
orientation), lets it align on the fence, reads its diameter and follows the branch whose
closed reading interval holds the reading; a leaf lists the poses the part is then in.
Version 2 declares the uncertainty the plan is strong for (``"uncertainty"``, right after
``"sensor"``) and its certificate (``stats.certificate``, last); a version-1 file without
``"uncertainty"`` is read as the paper's ideal model and marked so
(``Plan.uncertainty_declared``).

Made only here: :func:`plan_from_result` (a planner's result), :func:`plan_from_dict` (a
loaded file, checked: types, ranges, the stated length against the tree, a depth limit) and
:func:`read_plan` (a file, refused above a size limit before it is parsed). Written only
here: :func:`plan_to_dict`, :func:`plan_json`, :func:`write_plan` (atomic). Nothing recurses
over the tree, so a plan as deep as the limit loads, writes and reports. Reading a plan
needs no planner: the planner's types are imported only where a result is turned into a
plan.
"""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from feederkit.errors import InputError, PlanningError
from feederkit.jsonio import parse_json, write_text_atomic
from feederkit.mechanics.push import PushFunction, StableState
from feederkit.plans.model import (
    Branch,
    Certificate,
    Leaf,
    Node,
    Plan,
    PlanPart,
    PlanStats,
    ResultEntry,
    Step,
    push_function_of,
)
from feederkit.sensors import Grouping, Sensor, sensor_from_dict
from feederkit.uncertainty import IDEAL, Uncertainty, max_shape_tolerance

if TYPE_CHECKING:
    from feederkit.machine import PushAlignMachine
    from feederkit.planning.tree import Leaf as TreeLeaf
    from feederkit.planning.tree import PlanResult
    from feederkit.planning.tree import Step as TreeStep

FORMAT = "feederkit-plan"
VERSION = 2
READABLE_VERSIONS = (1, 2)
"""Version 1 files (no declared uncertainty) stay readable, as the ideal model."""

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


MAX_FILE_NODES = 100_000
"""A plan whose file would hold more nodes than this is refused: no controller wants it."""

MAX_PLAN_BYTES = 50_000_000
"""A plan file larger than this (bytes) is refused before it is parsed (``max_bytes`` raises
it): parsing costs about ten times the file's size in memory."""

MAX_PLAN_DEPTH = 1000
"""A plan more operations deep than this is refused (``max_depth`` raises it)."""

_JSON_LEVELS_PER_OPERATION = 3
"""A step costs three levels of JSON nesting: the node, its branch list, a branch."""


# ---------------------------------------------------------------- from a planner's result


def members(mask: int) -> list[int]:
    """The machine states in a set (a bit mask), in increasing order."""
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


def _plan_part(machine: PushAlignMachine, p: int, pf: PushFunction) -> PlanPart:
    """A part's name, revision, COM, hull and stable states (diameters as planned on)."""
    diameter = {(ms.part, ms.state): ms.diameter for ms in machine.states}
    states = tuple(
        StableState(
            id=s.id,
            edge=s.edge,
            normal_deg=s.normal_deg,
            resting_range_deg=tuple(s.resting_range_deg),
            diameter=diameter[(p, s.id)],
            pose_deg=s.pose_deg,
        )
        for s in pf.states
    )
    return PlanPart(
        name=pf.part.name,
        revision=pf.part.revision,
        com=tuple(pf.part.com),
        hull=tuple(tuple(v) for v in pf.part.hull),
        states=states,
    )


def _reading(machine: PushAlignMachine, branch: Any) -> tuple[float, float] | None:
    """A branch's closed reading interval; None only when the plan is sensorless.

    A planner may leave a branch without an interval where readings carry no information
    (every state of the set reads alike); with a sensor the file still gives the interval
    its states read in, so a controller can tell a foreign part or a sensor fault.
    """
    if branch.lo is not None:
        return (branch.lo, branch.hi)
    if not machine.sensor.informative:
        return None
    diameters = [machine.states[i].diameter for i in members(branch.mask)]
    split = machine.sensor.split(diameters, Grouping.COMPONENTS)
    return (min(b.lo for b in split), max(b.hi for b in split))


def file_nodes(root: TreeStep | TreeLeaf) -> int:
    """How many nodes the plan file holds once shared subtrees are written out in full.

    Counted on the planner's shared structure (each distinct node once, without recursion),
    so a plan whose written tree would be astronomically large is measured without being
    built.
    """
    from feederkit.planning.tree import Leaf as TreeLeaf

    memo: dict[int, int] = {}
    stack: list[tuple[TreeStep | TreeLeaf, bool]] = [(root, False)]
    while stack:
        node, expanded = stack.pop()
        key = id(node)
        if key in memo:
            continue
        if isinstance(node, TreeLeaf):
            memo[key] = 1
        elif expanded:
            memo[key] = 1 + sum(memo[id(nxt)] for _b, nxt in node.branches)
        else:
            stack.append((node, True))
            stack.extend((nxt, False) for _b, nxt in node.branches if id(nxt) not in memo)
    return memo[id(root)]


def _tree(result: PlanResult, parts: Sequence[PushFunction]) -> Step:
    """The planner's tree as plan nodes; shared subtrees stay shared (built once)."""
    from feederkit.planning.tree import Leaf as TreeLeaf

    machine = result.machine
    built: dict[int, Node] = {}
    stack: list[tuple[TreeStep | TreeLeaf, bool]] = [(result.root, False)]
    while stack:
        node, expanded = stack.pop()
        key = id(node)
        if key in built:
            continue
        if isinstance(node, TreeLeaf):
            entries = []
            for i in members(node.mask):
                ms = machine.states[i]
                s = parts[ms.part].states[ms.state]
                entries.append(ResultEntry(parts[ms.part].part.name, s.id, s.pose_deg))
            built[key] = Leaf(tuple(entries))
        elif expanded:
            built[key] = Step(
                None if node.action is None else node.action.representative,
                None if node.action is None else node.action.margin,
                tuple(Branch(_reading(machine, b), built[id(nxt)]) for b, nxt in node.branches),
            )
        else:
            stack.append((node, True))
            stack.extend((nxt, False) for _b, nxt in node.branches if id(nxt) not in built)
    root = built[id(result.root)]
    assert isinstance(root, Step)
    return root


def plan_from_result(
    result: PlanResult,
    parts: Sequence[PushFunction],
    *,
    uncertainty: Uncertainty | None = None,
) -> Plan:
    """The plan of a planner's result on the machine of ``parts`` (in order).

    The plan declares ``uncertainty`` (default: the result's, its machine's) and carries the
    result's certificate when it has one. A strong plan written over the ideal states
    (``feederkit.plans.strong.ideal_view``) has the ideal machine, so its maker passes the
    declared uncertainty here.

    ``parts`` are the push functions the machine was built from (``build_machine``): the plan
    records each part's hull and COM, so it can be checked on the geometry alone. Raises
    InputError when two parts share a name (results name their part) and PlanningError when
    the written tree would exceed MAX_FILE_NODES nodes (a plan found under a time limit for a
    part whose states nearly all read alike can share subtrees that would expand beyond any
    file).
    """
    machine = result.machine
    names = [pf.part.name for pf in parts]
    if tuple(names) != machine.part_names or sum(pf.n for pf in parts) != machine.n:
        raise ValueError("plan_from_result: the parts are not the ones the machine was built from")
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
            "planner more time, use a finer sensor, or ask for a minimum margin"
        )
    from feederkit.plans.stats import plan_stats

    s = plan_stats(result, parts)
    stats = PlanStats(
        length=s["length"],
        expected_length=s["expected_length"],
        min_margin_deg=s["min_margin_deg"],
        optimal=s["optimal"],
        lower_bound=s["lower_bound"],
        objective=s["objective"],
        grouping=s["grouping"],
        polygon_class=s["class"],
        class_bound=s["class_bound"],
        meets_bound=s["meets_bound"],
        certificate=_certificate_of(result),
    )
    return Plan(
        sensor=machine.sensor,
        parts=tuple(_plan_part(machine, p, pf) for p, pf in enumerate(parts)),
        root=_tree(result, parts),
        stats=stats,
        conventions=CONVENTIONS,
        uncertainty=getattr(machine, "uncertainty", IDEAL) if uncertainty is None else uncertainty,
    )


def _certificate_of(result: PlanResult) -> Certificate | None:
    """The plan model's certificate of a planner's result (None when it has none)."""
    cert = getattr(result, "certificate", None)
    if cert is None:
        return None
    return Certificate(
        max_rotation_error_deg=cert.max_rotation_error_deg,
        max_shape_tolerance_mm=cert.max_shape_tolerance_mm,
        ideal_length=cert.ideal_length,
    )


# ---------------------------------------------------------------- to a dict and a file


def _part_dict(part: PlanPart) -> dict[str, Any]:
    return {
        "name": part.name,
        "revision": part.revision,
        "com": list(part.com),
        "hull": [list(v) for v in part.hull],
        "stable_states": [
            {
                "id": s.id,
                "edge": s.edge,
                "normal_deg": s.normal_deg,
                "resting_range_deg": list(s.resting_range_deg),
                "diameter": s.diameter,
                "pose_deg": s.pose_deg,
            }
            for s in part.states
        ],
    }


def _stats_dict(s: PlanStats) -> dict[str, Any]:
    out: dict[str, Any] = {
        "length": s.length,
        "expected_length": s.expected_length,
        "min_margin_deg": s.min_margin_deg,
        "optimal": s.optimal,
        "lower_bound": s.lower_bound,
        "objective": s.objective,
        "grouping": s.grouping,
        "class": s.polygon_class,
        "class_bound": s.class_bound,
        "meets_bound": s.meets_bound,
    }
    if s.certificate is not None:
        out["certificate"] = s.certificate.to_dict()
    return out


def _tree_dict(root: Node) -> dict[str, Any]:
    """The tree as the file's nested NODE objects, built without recursion."""

    def shell(node: Node) -> dict[str, Any]:
        if isinstance(node, Leaf):
            return {
                "result": [
                    {"part": e.part, "state": e.state, "pose_deg": e.pose_deg} for e in node.results
                ]
            }
        return {"action_deg": node.action_deg, "margin_deg": node.margin_deg, "branches": []}

    top = shell(root)
    stack: list[tuple[Node, dict[str, Any]]] = [(root, top)]
    while stack:
        node, out = stack.pop()
        if isinstance(node, Step):
            for b in node.branches:
                child = shell(b.next)
                reading = None if b.reading is None else list(b.reading)
                out["branches"].append({"reading": reading, "next": child})
                stack.append((b.next, child))
    return top


def plan_to_dict(
    plan: Plan | PlanResult, parts: Sequence[PushFunction] | None = None
) -> dict[str, Any]:
    """The plan file's JSON object of a :class:`Plan`.

    Also called as ``plan_to_dict(result, parts)`` for a planner's result (the form
    ``plans/make.py`` uses): that is ``plan_to_dict(plan_from_result(result, parts))``.
    """
    if not isinstance(plan, Plan):
        if parts is None:
            raise TypeError("plan_to_dict(result, parts): the push functions are needed")
        plan = plan_from_result(plan, parts)
    return {
        "format": FORMAT,
        "version": VERSION,
        "conventions": plan.conventions,
        "sensor": plan.sensor.to_dict(),
        "uncertainty": plan.uncertainty.to_dict(),
        "parts": [_part_dict(p) for p in plan.parts],
        "root": _tree_dict(plan.root),
        "stats": _stats_dict(plan.stats),
    }


def _one_line(value: object) -> str | None:
    """The text of a value written on one line, or None when it is spread over lines.

    Lists of plain values (points, intervals) and small flat objects (result entries, the
    sensor) stay on one line.
    """
    if isinstance(value, dict):
        plain = all(not isinstance(v, dict | list) for v in value.values())
        if (plain and len(value) <= 3) or not value:
            return json.dumps(value, allow_nan=False)
        return None
    if isinstance(value, list | tuple):
        if not value or all(not isinstance(v, dict | list | tuple) for v in value):
            return json.dumps(value, allow_nan=False)
        return None
    return json.dumps(value, allow_nan=False)


def plan_json(plan: Plan | Mapping[str, Any]) -> str:
    """The plan file's text: indented JSON (short lists on one line), no NaN or infinity.

    Written with an explicit stack, so any depth the reader accepts can be written.
    """
    value = plan_to_dict(plan) if isinstance(plan, Plan) else plan
    out: list[str] = []
    stack: list[str | tuple[object, int]] = [(value, 0)]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            out.append(item)
            continue
        v, indent = item
        line = _one_line(v)
        if line is not None:
            out.append(line)
            continue
        pad = "  " * (indent + 1)
        work: list[str | tuple[object, int]] = []
        if isinstance(v, dict):
            work.append("{\n")
            for k, (key, child) in enumerate(v.items()):
                work += [",\n"] if k else []
                work += [f"{pad}{json.dumps(key)}: ", (child, indent + 1)]
            work.append("\n" + "  " * indent + "}")
        else:
            assert isinstance(v, list | tuple)
            work.append("[\n")
            for k, child in enumerate(v):
                work += [",\n"] if k else []
                work += [pad, (child, indent + 1)]
            work.append("\n" + "  " * indent + "]")
        stack.extend(reversed(work))
    return "".join(out) + "\n"


def write_plan(
    plan: Plan | str | os.PathLike[str], path: str | os.PathLike[str] | Plan | Mapping[str, Any]
) -> None:
    """Write a plan file atomically (a temporary file beside it, then a rename).

    ``write_plan(plan, path)``; the older order ``write_plan(path, plan_dict)`` is accepted
    while callers move to the :class:`Plan`.
    """
    if isinstance(plan, Plan | Mapping):
        target, value = path, plan
    else:
        target, value = plan, path
    assert isinstance(target, str | os.PathLike)
    write_text_atomic(target, plan_json(value), what="plan file")  # type: ignore[arg-type]


# ---------------------------------------------------------------- from a dict: the validator


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
            raise self.fail(f"{what} must be a finite number, got {_shown(value)}")
        return value

    def int_(self, value: object, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(f"{what} must be an integer, got {_shown(value)}")
        return value

    def str_(self, value: object, what: str) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(f"{what} must be a non-empty string, got {_shown(value)}")
        return value

    def pair(self, value: object, what: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(f"{what} must be a pair [a, b], got {_shown(value)}")
        return self.num(value[0], what), self.num(value[1], what)

    def key(self, d: dict[str, Any], name: str, where: str) -> Any:
        if name not in d:
            raise self.fail(f"{where} has no {name!r}")
        return d[name]


def _shown(value: object) -> str:
    """A value in a message, clipped to one short line."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _check_sensor(c: _Checker, raw: object) -> Sensor:
    d = c.obj(raw, "'sensor'")
    model = c.str_(c.key(d, "model", "'sensor'"), "sensor model")
    for name, value in d.items():
        if name != "model" and c.num(value, f"sensor {name}") < 0.0:
            raise c.fail(f"sensor {name} must not be negative, got {value!r}")
    for name in ("tolerance_mm", "pitch_mm"):
        if name in d and d[name] <= 0.0:
            raise c.fail(f"sensor {name} must be positive, got {d[name]!r}")
    try:
        return sensor_from_dict(d)
    except InputError as exc:
        raise c.fail(f"{exc} ({model})") from None


UNCERTAINTY_KEYS = ("rotation_error_deg", "shape_tolerance_mm", "com_tolerance_mm")
CERTIFICATE_KEYS = ("max_rotation_error_deg", "max_shape_tolerance_mm", "ideal_length")


def _check_uncertainty(c: _Checker, raw: object) -> Uncertainty:
    """The declared uncertainty: three finite numbers, rotation error in [0, 90) degrees,
    tolerances nonnegative (design.md, "Uncertainty")."""
    d = c.obj(raw, "'uncertainty'")
    extra = sorted(set(d) - set(UNCERTAINTY_KEYS))
    if extra:
        raise c.fail(f"'uncertainty' has the unknown key {extra[0]!r}")
    r, t, com = (c.num(c.key(d, k, "'uncertainty'"), f"uncertainty {k}") for k in UNCERTAINTY_KEYS)
    if not 0.0 <= r < 90.0:
        raise c.fail(f"uncertainty rotation_error_deg {r} is not in [0, 90)")
    for name, v in (("shape_tolerance_mm", t), ("com_tolerance_mm", com)):
        if v < 0.0:
            raise c.fail(f"uncertainty {name} {v} must not be negative")
    return Uncertainty(r, t, com)


def _check_certificate(c: _Checker, raw: object, unc: Uncertainty) -> Certificate:
    """``stats.certificate``: it guarantees at least the declared uncertainty (a plan
    certified below what it declares contradicts itself)."""
    d = c.obj(raw, "stats certificate")
    extra = sorted(set(d) - set(CERTIFICATE_KEYS))
    if extra:
        raise c.fail(f"stats certificate has the unknown key {extra[0]!r}")
    r = c.num(c.key(d, "max_rotation_error_deg", "stats certificate"), "certificate rotation")
    t = c.num(c.key(d, "max_shape_tolerance_mm", "stats certificate"), "certificate shape")
    if not 0.0 <= r <= 90.0:
        raise c.fail(f"certificate max_rotation_error_deg {r} is not in [0, 90]")
    if r < unc.rotation_error_deg - 1e-9:
        raise c.fail(
            f"certificate max_rotation_error_deg {r:g} is below the declared rotation error "
            f"{unc.rotation_error_deg:g}"
        )
    if t < unc.shape_tolerance_mm - 1e-9:
        raise c.fail(
            f"certificate max_shape_tolerance_mm {t:g} is below the declared shape tolerance "
            f"{unc.shape_tolerance_mm:g}"
        )
    ideal = c.key(d, "ideal_length", "stats certificate")
    if ideal is not None and c.int_(ideal, "certificate ideal_length") < 1:
        raise c.fail(f"certificate ideal_length {ideal} must be at least 1")
    return Certificate(r, t, ideal)


def _check_part(c: _Checker, raw: object, index: int) -> PlanPart:
    d = c.obj(raw, f"part {index}")
    name = c.str_(c.key(d, "name", f"part {index}"), f"part {index} name")
    where = f"part {name!r}"
    rev = d.get("revision")
    if rev is not None and (isinstance(rev, bool) or not isinstance(rev, str | int)):
        raise c.fail(f"{where} 'revision' must be a string, an integer or null")
    com = c.pair(c.key(d, "com", where), f"{where} com")
    hull = tuple(c.pair(v, f"{where} hull vertex") for v in c.lst(c.key(d, "hull", where), where))
    if len(hull) < 3:
        raise c.fail(f"{where} hull has fewer than three vertices")
    raw_states = c.lst(c.key(d, "stable_states", where), f"{where} stable_states")
    if not raw_states:
        raise c.fail(f"{where} has no stable states")
    states: list[StableState] = []
    for k, s in enumerate(raw_states):
        sw = f"{where} stable state {k}"
        sd = c.obj(s, sw)
        sid = c.int_(c.key(sd, "id", sw), f"{sw} id")
        if any(t.id == sid for t in states):
            raise c.fail(f"{where} lists stable state {sid} twice")
        edge = c.int_(c.key(sd, "edge", sw), f"{sw} edge")
        if not 0 <= edge < len(hull):
            raise c.fail(f"{sw} names edge {edge}, but the hull has {len(hull)} edges")
        normal = c.num(c.key(sd, "normal_deg", sw), f"{sw} normal_deg")
        lo, hi = c.pair(c.key(sd, "resting_range_deg", sw), f"{sw} resting_range_deg")
        if not lo < normal < hi or hi - lo >= 360.0:
            raise c.fail(f"{sw} resting range [{lo}, {hi}] does not hold its normal {normal}")
        diameter = c.num(c.key(sd, "diameter", sw), f"{sw} diameter")
        if diameter <= 0.0:
            raise c.fail(f"{sw} diameter must be positive")
        pose = c.num(c.key(sd, "pose_deg", sw), f"{sw} pose_deg")
        states.append(StableState(sid, edge, normal, (lo, hi), diameter, pose))
    part = PlanPart(name, rev, com, hull, tuple(states))
    try:
        push_function_of(part)  # the hull and COM must make a part (cached for later use)
    except InputError as exc:
        raise c.fail(f"{where}: {exc}") from None
    return part


def _walk(root: object) -> Iterator[tuple[object, int]]:
    """Every raw node with its depth (root 0), pre-order, without recursion."""
    stack = [(root, 0)]
    while stack:
        node, depth = stack.pop()
        yield node, depth
        if isinstance(node, dict) and isinstance(node.get("branches"), list):
            for b in reversed(node["branches"]):
                if isinstance(b, dict) and "next" in b:
                    stack.append((b["next"], depth + 1))


def _check_leaf(
    c: _Checker, node: dict[str, Any], where: str, parts: Mapping[str, PlanPart]
) -> Leaf:
    entries = c.lst(node["result"], f"{where} result")
    if not entries:
        raise c.fail(f"{where} has an empty result")
    out = []
    for e in entries:
        ed = c.obj(e, f"{where} result entry")
        part = c.key(ed, "part", f"{where} result entry")
        if not isinstance(part, str):
            raise c.fail(f"{where} result part must be a part's name, got {_shown(part)}")
        if part not in parts:
            raise c.fail(f"{where} names the unknown part {part!r}")
        sid = c.int_(c.key(ed, "state", f"{where} result entry"), f"{where} result state")
        if all(s.id != sid for s in parts[part].states):
            raise c.fail(f"{where} names state {sid}, which part {part!r} does not list")
        pose = c.num(c.key(ed, "pose_deg", f"{where} result entry"), f"{where} result pose_deg")
        out.append(ResultEntry(part, sid, pose))
    return Leaf(tuple(out))


def _check_step_fields(
    c: _Checker, node: dict[str, Any], where: str, depth: int, sensorless: bool
) -> tuple[float | None, float | None, list[tuple[tuple[float, float] | None, object]]]:
    action = c.key(node, "action_deg", where)
    margin = c.key(node, "margin_deg", where)
    if depth == 0:
        if action is not None or margin is not None:
            raise c.fail("the root is the first alignment: its action_deg and margin_deg are null")
    else:
        a = c.num(action, f"{where} action_deg")
        if not 0.0 <= a < 360.0:
            raise c.fail(f"{where} action_deg {a} is not in [0, 360)")
        m = c.num(margin, f"{where} margin_deg")
        if not 0.0 <= m < 180.0:
            raise c.fail(f"{where} margin_deg {m} is not in [0, 180)")
    branches = c.lst(c.key(node, "branches", where), f"{where} branches")
    if not branches:
        raise c.fail(f"{where} has no branches")
    if sensorless and len(branches) != 1:
        raise c.fail(f"{where} branches on a reading, but the plan is sensorless")
    out: list[tuple[tuple[float, float] | None, object]] = []
    for b in branches:
        bd = c.obj(b, f"{where} branch")
        reading = c.key(bd, "reading", f"{where} branch")
        interval = None
        if sensorless and reading is not None:
            raise c.fail(f"{where} has a reading interval, but the plan is sensorless")
        if not sensorless:
            if reading is None:
                raise c.fail(f"{where} has a branch without a reading interval")
            interval = c.pair(reading, f"{where} reading")
            if interval[0] > interval[1]:
                raise c.fail(
                    f"{where} has a reading interval [{interval[0]}, {interval[1]}] with lo > hi"
                )
        out.append((interval, c.key(bd, "next", f"{where} branch")))
    return action, margin, out


def _check_tree(
    c: _Checker, root: object, parts: Mapping[str, PlanPart], sensorless: bool, max_depth: int
) -> Step:
    """Check every node (pre-order, no recursion) and build the tree bottom-up."""
    order: list[tuple[object, int, str]] = []
    for count, (raw, depth) in enumerate(_walk(root)):
        if depth > max_depth:
            raise InputError(_too_deep(c.source, max_depth))
        order.append((raw, depth, "the root" if depth == 0 else f"node {count} (depth {depth})"))
    built: dict[int, Node] = {}
    for raw, depth, where in reversed(order):
        node = c.obj(raw, where)
        if "result" in node:
            if depth == 0:
                raise c.fail("the root must be an operation (the first alignment), not a result")
            built[id(raw)] = _check_leaf(c, node, where, parts)
            continue
        action, margin, branches = _check_step_fields(c, node, where, depth, sensorless)
        built[id(raw)] = Step(
            action, margin, tuple(Branch(r, built[id(nxt)]) for r, nxt in branches)
        )
    top = built[id(root)]
    assert isinstance(top, Step)
    return top


def _check_stats(c: _Checker, raw: object, plan: Plan) -> PlanStats:
    """The ``stats`` object, checked against the tree it describes."""
    d = c.obj(raw, "'stats'")
    length = c.int_(c.key(d, "length", "'stats'"), "stats length")
    depth = plan.depth()
    if length != depth:
        raise c.fail(f"stats length is {length}, but the plan's tree is {depth} operations deep")
    expected = c.num(c.key(d, "expected_length", "'stats'"), "stats expected_length")
    if not 1.0 - 1e-9 <= expected <= length + 1e-9:
        raise c.fail(f"stats expected_length {expected} is not between 1 and the length {length}")
    margin = c.key(d, "min_margin_deg", "'stats'")
    smallest = plan.smallest_margin()
    if margin is None:
        if smallest is not None:
            raise c.fail(f"stats min_margin_deg is null, but the plan rotates (±{smallest:.6g}°)")
    else:
        margin = c.num(margin, "stats min_margin_deg")
        if smallest is None or abs(margin - smallest) > 1e-9 * max(1.0, smallest):
            tree = "makes no rotation" if smallest is None else f"has ±{smallest:.6g}°"
            raise c.fail(f"stats min_margin_deg is {margin:.6g}, but the plan's smallest {tree}")
    optimal = c.key(d, "optimal", "'stats'")
    if not isinstance(optimal, bool):
        raise c.fail("stats optimal must be true or false")
    bound = c.int_(c.key(d, "lower_bound", "'stats'"), "stats lower_bound")
    if not 1 <= bound <= length:
        raise c.fail(f"stats lower_bound {bound} is not between 1 and the length {length}")
    extra: dict[str, Any] = {}
    for name, kind in (
        ("objective", str),
        ("grouping", str),
        ("class", int),
        ("class_bound", int),
        ("meets_bound", bool),
    ):
        value = d.get(name)
        wrong = isinstance(value, bool) and kind is not bool
        if value is not None and (wrong or not isinstance(value, kind)):
            raise c.fail(f"stats {name} must be {kind.__name__} or null, got {_shown(value)}")
        extra[name] = value
    cert = d.get("certificate")
    certificate = None if cert is None else _check_certificate(c, cert, plan.uncertainty)
    return PlanStats(
        length=length,
        expected_length=expected,
        min_margin_deg=margin,
        optimal=optimal,
        lower_bound=bound,
        objective=extra["objective"],
        grouping=extra["grouping"],
        polygon_class=extra["class"],
        class_bound=extra["class_bound"],
        meets_bound=extra["meets_bound"],
        certificate=certificate,
    )


def plan_from_dict(data: object, source: str = "plan", max_depth: int = MAX_PLAN_DEPTH) -> Plan:
    """The :class:`Plan` of a loaded plan file, checked (design.md, versions 1 and 2).

    Types (a version is the integer 1 or 2, a result's part a name), the declared
    uncertainty (required from version 2; a version-1 file without it is the ideal model)
    and the certificate (at least the declared uncertainty), ranges (actions in
    [0, 360), margins in [0, 180), reading intervals lo <= hi), names (results name listed
    parts and states), the tree at most ``max_depth`` operations deep, and ``stats`` against
    the tree (its length is the tree's depth, its smallest margin the tree's). Raises
    InputError with one line naming ``source`` and the first problem found. Whether the plan
    is right for its parts is :func:`feederkit.plans.verify.verify_plan`'s question.
    """
    c = _Checker(source)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise c.fail('not a feederkit plan (its "format" is not "feederkit-plan")')
    version = data.get("version")
    if (
        isinstance(version, bool)
        or not isinstance(version, int)
        or version not in READABLE_VERSIONS
    ):
        raise c.fail(f"unsupported plan version {_shown(version)} (this feederkit reads 1 and 2)")
    conventions = data.get("conventions")
    if not isinstance(conventions, str):
        raise c.fail("the plan states no 'conventions'")
    sensor = _check_sensor(c, c.key(data, "sensor", "the plan"))
    declared = "uncertainty" in data or version >= 2
    unc = _check_uncertainty(c, c.key(data, "uncertainty", "the plan")) if declared else IDEAL
    parts_raw = c.lst(c.key(data, "parts", "the plan"), "'parts'")
    if not parts_raw:
        raise c.fail("the plan lists no parts")
    parts: dict[str, PlanPart] = {}
    for i, p in enumerate(parts_raw):
        part = _check_part(c, p, i)
        if part.name in parts:
            raise c.fail(f"two parts are both named {part.name!r}")
        parts[part.name] = part
        limit = max_shape_tolerance(push_function_of(part).part)
        if unc.shape_tolerance_mm >= limit:
            raise c.fail(
                f"the shape tolerance {unc.shape_tolerance_mm:g} mm is not below half part "
                f"{part.name!r}'s smallest hull edge ({limit:.4g} mm)"
            )
    root = _check_tree(c, c.key(data, "root", "the plan"), parts, not sensor.informative, max_depth)
    draft = Plan(
        sensor,
        tuple(parts.values()),
        root,
        PlanStats(1, 1.0, None, False, 1),
        conventions,
        uncertainty=unc,
        uncertainty_declared=declared,
    )
    stats = _check_stats(c, c.key(data, "stats", "the plan"), draft)
    return replace(draft, stats=stats)


def validate_plan(data: object, source: str = "plan") -> dict[str, Any]:
    """Check a loaded plan file (:func:`plan_from_dict`) and return it as it was."""
    plan_from_dict(data, source)
    assert isinstance(data, dict)
    return data


def as_plan(plan: Plan | Mapping[str, Any], source: str = "plan") -> Plan:
    """A :class:`Plan` given one or a plan file's JSON object (checked)."""
    return plan if isinstance(plan, Plan) else plan_from_dict(plan, source)


@contextmanager
def _recursion_room(levels: int) -> Iterator[None]:
    """Let the JSON parser nest ``levels`` deep (it recurses once per level)."""
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old, levels + 200))
    try:
        yield
    finally:
        sys.setrecursionlimit(old)


def read_plan(
    path: str | os.PathLike[str],
    *,
    max_bytes: int = MAX_PLAN_BYTES,
    max_depth: int = MAX_PLAN_DEPTH,
) -> Plan:
    """Load and check a plan file (:func:`plan_from_dict`).

    A missing, unreadable or malformed file is bad input, and so is one larger than
    ``max_bytes`` (refused before it is read) or deeper than ``max_depth`` operations.
    """
    p = Path(path)
    try:
        size = p.stat().st_size
    except FileNotFoundError:
        raise InputError(f"{p}: no such plan file") from None
    except OSError as exc:
        raise InputError(f"{p}: cannot read the plan file ({exc.strerror})") from None
    if p.is_dir():
        raise InputError(f"{p}: a folder, not a plan file")
    if size > max_bytes:
        raise InputError(
            f"{p}: the plan file is {size / 1e6:.1f} MB, more than the limit of "
            f"{max_bytes / 1e6:.1f} MB"
        )
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = "not UTF-8 text" if isinstance(exc, UnicodeDecodeError) else exc.strerror
        raise InputError(f"{p}: cannot read the plan file ({reason})") from None
    levels = _JSON_LEVELS_PER_OPERATION * max_depth + 8
    try:
        with _recursion_room(levels):
            data = parse_json(text, str(p), max_depth=levels)
    except InputError as exc:
        if "nested deeper" not in str(exc):
            raise
        raise InputError(_too_deep(str(p), max_depth)) from None
    return plan_from_dict(data, str(p), max_depth)


def _too_deep(source: str, max_depth: int) -> str:
    return f"{source}: the plan is more than {max_depth} operations deep (the limit)"
