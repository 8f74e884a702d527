"""Reading a plan file: what a ``feederkit-plan`` file (design.md, "Plan file", versions 1
and 2) must satisfy to be read, and the one reader of a file, its text or its loaded JSON
into a :class:`~feederkit.plans.model.Plan`.

Every file goes through :func:`plan_from_dict` (:func:`read_plan` refuses a file above a size
limit before it is parsed; :func:`plan_from_text` and :func:`parse_plan_text` read a text):
types, ranges, design.md's grammar, names and landings, the shared subplans, the hull exactly
as the conventions fix it, numbers no part of the hull can have, ``stats`` against the tree
and a depth limit. Every check gives one line naming where (the source, then the part,
stable state, node or field), an InputError (exit 2). Nothing recurses over the tree, and
the JSON parser is given the room a plan of the limit's depth needs, so a plan as deep as
the limit loads. Whether the plan is right for its parts is the verifier's question.

What feederkit writes is read back first (:mod:`feederkit.plans.writeplan`). The format's
constants and the text itself are :mod:`feederkit.plans.fileformat`'s.
"""

from __future__ import annotations

import functools
import math
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

from feederkit.errors import InputError
from feederkit.hull import Point
from feederkit.jsonio import parse_json
from feederkit.landing.model import LANDING_RE
from feederkit.mechanics.push import StableState
from feederkit.plans.fileformat import (
    AS_DRAWN,
    FORMAT,
    READABLE_VERSIONS,
    check_shares,
    shown,
)
from feederkit.plans.model import (
    Branch,
    Certificate,
    Leaf,
    Member,
    Node,
    Plan,
    PlanPart,
    PlanStats,
    ResultEntry,
    Step,
    member_label,
    push_function_of,
)
from feederkit.sensors import LedSensor, Sensor, sensor_from_dict
from feederkit.uncertainty import IDEAL, Uncertainty, max_shape_tolerance

MAX_PLAN_BYTES = 50_000_000
"""A plan file larger than this (bytes) is refused before it is parsed (``max_bytes`` raises
it): parsing costs about ten times the file's size in memory."""

MAX_PLAN_DEPTH = 1000
"""A plan more operations deep than this is refused (``max_depth`` raises it)."""

_JSON_LEVELS_PER_OPERATION = 3
"""A step costs three levels of JSON nesting: the node, its branch list, a branch."""


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
            raise self.fail(f"{what} must be a finite number, got {shown(value)}")
        return value

    def int_(self, value: object, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(f"{what} must be an integer, got {shown(value)}")
        return value

    def str_(self, value: object, what: str) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(f"{what} must be a non-empty string, got {shown(value)}")
        return value

    def pair(self, value: object, what: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(f"{what} must be a pair [a, b], got {shown(value)}")
        return self.num(value[0], what), self.num(value[1], what)

    def key(self, d: dict[str, Any], name: str, where: str) -> Any:
        if name not in d:
            raise self.fail(f"{where} has no {name!r}")
        return d[name]

    def only(self, d: dict[str, Any], keys: tuple[str, ...], where: str, form: str) -> None:
        """Refuse a key of ``d`` that design.md's grammar does not give ``form``: a node
        that is both an operation and a result means two things to a controller."""
        if d.keys() <= _allowed(keys):
            return
        extra = next((k for k in d if k not in keys), None)
        if extra is not None:
            allowed = ", ".join(repr(k) for k in keys)
            raise self.fail(
                f"{where} has {extra!r}, but {form} has only {allowed} (design.md, Plan file)"
            )


@functools.cache
def _allowed(keys: tuple[str, ...]) -> frozenset[str]:
    """The keys a form allows, as a set (made once per form)."""
    return frozenset(keys)


SENSOR_PARAMETERS = {"none": (), "tolerance": ("tolerance_mm",), "led": ("pitch_mm", "noise_mm")}
"""Each sensor model's parameters (design.md, "Cell profile" and "Plan file"): a key of
another model (an LED array with a ``tolerance_mm``) would mean something to a reader."""


def _check_sensor(c: _Checker, raw: object) -> Sensor:
    d = c.obj(raw, "'sensor'")
    model = c.str_(c.key(d, "model", "'sensor'"), "sensor model")
    keys = SENSOR_PARAMETERS.get(model)
    if keys is not None:  # an unknown model is sensor_from_dict's to refuse
        c.only(d, ("model", *keys), "'sensor'", f"the {model!r} sensor")
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


def _check_landing(c: _Checker, value: object, where: str) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str) or not LANDING_RE.match(value):
        raise c.fail(f"{where} landing must be up, down or pose-K, got {shown(value)}")
    return value


def _check_hull(c: _Checker, raw: object, where: str) -> tuple[Point, ...]:
    """A part's ``hull`` exactly as design.md fixes it ("Conventions"): at least three
    vertices, counter-clockwise, strictly convex, vertex 0 the lowest-then-leftmost.

    A controller takes edge i to join vertex i to vertex i + 1 of the file; feederkit
    rebuilds the part from the same list, so the two agree only when the list is already
    that hull, vertex for vertex (:func:`_hull_problem`).
    """
    hull = tuple(c.pair(v, f"{where} hull vertex") for v in c.lst(raw, f"{where} hull"))
    if len(hull) < 3:
        raise c.fail(f"{where} hull has fewer than three vertices")
    twice_area = sum(
        a[0] * b[1] - b[0] * a[1] for a, b in zip(hull, hull[1:] + hull[:1], strict=True)
    )
    if not math.isfinite(twice_area):
        raise c.fail(f"{where} hull is too large to compute with")
    if not twice_area > 0.0:  # design.md: counter-clockwise, so edges and normals agree
        raise c.fail(f"{where} hull is not counter-clockwise (its signed area is not positive)")
    problem = _hull_problem(hull)
    if problem is not None:
        raise c.fail(f"{where} hull: {problem} (design.md, Conventions)")
    return hull


def _hull_problem(hull: Sequence[Point]) -> str | None:
    """Why a counter-clockwise ring is not a strictly convex hull numbered from its
    lowest-then-leftmost vertex, in words; None when it is one.

    Exact, with no length tolerance: a vertex a billionth of the part's size off its
    neighbours' line is a corner (at ``--hull-tolerance 0`` the writer keeps it, and such a
    plan is right). Closer than rounding (:data:`feederkit.hull.COLLINEAR_REL`) the writer
    drops it, so the rebuilt hull differs and :func:`_check_part` refuses the list: every
    plan feederkit writes passes.
    """
    n = len(hull)
    for i in range(n):
        if hull[i] == hull[(i + 1) % n]:
            return f"vertex {(i + 1) % n} {_point(hull[i])} repeats vertex {i}"
    for i in range(n):
        a, b, d = hull[i - 1], hull[i], hull[(i + 1) % n]
        cross = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0])
        if cross <= 0.0:
            chord = math.hypot(d[0] - a[0], d[1] - a[1])
            side = "on" if cross == 0.0 or chord == 0.0 else f"{-cross / chord:.3g} mm inside"
            return (
                f"vertex {i} {_point(b)} is no corner: it lies {side} the line of vertices "
                f"{(i - 1) % n} and {(i + 1) % n}"
            )
    low = min(range(n), key=lambda i: (hull[i][1], hull[i][0]))
    if low != 0:
        return (
            f"vertex 0 {_point(hull[0])} is not the lowest-then-leftmost vertex; vertex {low} "
            f"{_point(hull[low])} is, and edge i joins vertex i to vertex i + 1 counted from it"
        )
    return None


def _point(p: Point) -> str:
    return f"({p[0]:g}, {p[1]:g})"


def _check_state(c: _Checker, raw: object, sw: str, edges: int, across: float) -> StableState:
    """One listed stable state of a hull of ``edges`` edges: its fields, and numbers its part
    can have.

    Whether they are the states its hull and COM give is the verifier's question (a plan
    that disagrees with its own geometry fails verification, exit 1, and ``report`` draws
    it under a red banner). Refused here are numbers no part of this hull has, so that no
    consumer computes with them: angles outside [0, 360) (design.md: pose is taken mod
    360), a resting range not holding its normal, a diameter not positive or wider than the
    hull's bounding box is ``across`` (a diameter of 1e308 overflowed the LED beam counts).
    """
    sd = c.obj(raw, sw)
    sid = c.int_(c.key(sd, "id", sw), f"{sw} id")
    edge = c.int_(c.key(sd, "edge", sw), f"{sw} edge")
    if not 0 <= edge < edges:
        raise c.fail(f"{sw} names edge {edge}, but the hull has {edges} edges")
    normal = _angle(c, c.key(sd, "normal_deg", sw), f"{sw} normal_deg")
    lo, hi = c.pair(c.key(sd, "resting_range_deg", sw), f"{sw} resting_range_deg")
    if not lo < normal < hi or hi - lo >= 360.0:
        raise c.fail(f"{sw} resting range [{lo}, {hi}] does not hold its normal {normal}")
    diameter = c.num(c.key(sd, "diameter", sw), f"{sw} diameter")
    if not 0.0 < diameter <= across * (1.0 + 1e-9):
        raise c.fail(
            f"{sw} diameter {diameter:g} mm is not in (0, {across:.6g}]: no width of the part "
            "is more than its hull's bounding box is across"
        )
    pose = _angle(c, c.key(sd, "pose_deg", sw), f"{sw} pose_deg")
    return StableState(sid, edge, normal, (lo, hi), diameter, pose)


def _angle(c: _Checker, value: object, what: str) -> float:
    """A direction in degrees, in [0, 360) as the writer gives it (design.md: mod 360)."""
    a = c.num(value, what)
    if not 0.0 <= a < 360.0:
        raise c.fail(f"{what} {a:g} is not in [0, 360)")
    return a


def _check_part(c: _Checker, raw: object, index: int) -> PlanPart:
    d = c.obj(raw, f"part {index}")
    name = c.str_(c.key(d, "name", f"part {index}"), f"part {index} name")
    landing = _check_landing(c, d.get("landing"), f"part {name!r}")
    where = f"part {member_label(name, landing)!r}"
    share = d.get("share")
    if share is not None:
        share = c.num(share, f"{where} share")
        if not 0.0 < share <= 1.0:
            raise c.fail(f"{where} share {share:g} is not in (0, 1]")
    if "revision" not in d:  # design.md lists it in every part; older writers wrote it too
        raise c.fail(f"{where} has no 'revision' (null when the part has none)")
    rev = d["revision"]
    if rev is not None and (isinstance(rev, bool) or not isinstance(rev, str | int)):
        raise c.fail(f"{where} 'revision' must be a string, an integer or null")
    com = c.pair(c.key(d, "com", where), f"{where} com")
    hull = _check_hull(c, c.key(d, "hull", where), where)
    raw_states = c.lst(c.key(d, "stable_states", where), f"{where} stable_states")
    if not raw_states:
        raise c.fail(f"{where} has no stable states")
    across = math.hypot(*(max(v[k] for v in hull) - min(v[k] for v in hull) for k in (0, 1)))
    states: list[StableState] = []
    for k, s in enumerate(raw_states):
        state = _check_state(c, s, f"{where} stable state {k}", len(hull), across)
        if any(t.id == state.id for t in states):
            raise c.fail(f"{where} lists stable state {state.id} twice")
        states.append(state)
    part = PlanPart(name, rev, com, hull, tuple(states), landing, share)
    try:
        rebuilt = push_function_of(part).part.hull  # cached for later use
    except InputError as exc:
        raise c.fail(f"{where}: {exc}") from None
    if rebuilt != hull:  # the guarantee _check_hull's rules give, stated directly
        raise c.fail(f"{where} hull is not the convex hull of its vertices, numbered from 0")
    return part


class _Members:
    """The plan's members as a leaf check asks them, made once per plan: the part names and
    each member's state ids (a large mix's plan has tens of thousands of result entries)."""

    def __init__(self, parts: Mapping[Member, PlanPart]) -> None:
        self.parts = parts
        self.names = {name for name, _ in parts}
        self.ids = {key: {s.id for s in p.states} for key, p in parts.items()}


_ENTRY_KEYS = frozenset(("part", "landing", "state", "pose_deg"))


def _check_leaf(c: _Checker, node: dict[str, Any], where: str, known: _Members) -> Leaf:
    c.only(node, ("result", "reject"), where, "a result")
    entries = c.lst(node["result"], f"{where} result")
    if not entries:
        raise c.fail(f"{where} has an empty result")
    reject = node.get("reject", False)
    if not isinstance(reject, bool):
        raise c.fail(f"{where} 'reject' must be true or false, got {shown(reject)}")
    parts, names, ids = known.parts, known.names, known.ids
    out = []
    for e in entries:
        if type(e) is dict and e.keys() <= _ENTRY_KEYS:
            # A well-formed entry, as the writer writes it, without the messages' texts.
            part, landing, sid, pose = (
                e.get("part"),
                e.get("landing"),
                e.get("state"),
                e.get("pose_deg"),
            )
            if landing == AS_DRAWN and type(part) is str and (part, None) in ids:
                landing = None  # a plan not made over landings: its parts name none
            listed = (
                ids.get((part, landing))
                if type(part) is str and (landing is None or type(landing) is str)
                else None
            )
            if (
                listed is not None
                and type(sid) is int
                and sid in listed
                and type(pose) is float
                and 0.0 <= pose < 360.0
            ):
                out.append(ResultEntry(part, sid, pose, landing))
                continue
        ed = c.obj(e, f"{where} result entry")
        c.only(ed, ("part", "landing", "state", "pose_deg"), f"{where} result entry", "an entry")
        part = c.key(ed, "part", f"{where} result entry")
        if not isinstance(part, str):
            raise c.fail(f"{where} result part must be a part's name, got {shown(part)}")
        if part not in names:
            raise c.fail(f"{where} names the unknown part {part!r}")
        landing = _check_landing(c, ed.get("landing"), f"{where} result")
        if landing == AS_DRAWN and (part, None) in parts:
            landing = None  # a plan not made over landings: its parts name none
        member = parts.get((part, landing))
        if member is None:
            listed = ", ".join(str(k[1]) for k in parts if k[0] == part)
            said = "no landing" if landing is None else f"landing {landing!r}"
            raise c.fail(
                f"{where} names part {part!r} with {said}, but the plan lists it with "
                f"landing {listed}"
            )
        sid = c.int_(c.key(ed, "state", f"{where} result entry"), f"{where} result state")
        if sid not in known.ids[(part, landing)]:
            raise c.fail(f"{where} names state {sid}, which part {member.label!r} does not list")
        pose = _angle(c, c.key(ed, "pose_deg", f"{where} result entry"), f"{where} result pose_deg")
        out.append(ResultEntry(part, sid, pose, landing))
    return Leaf(tuple(out), reject)


def _check_table(c: _Checker, data: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """The ``"nodes"`` table of shared subplans: a non-empty object of NODE objects, none of
    them itself a reference (absent: no shared subplans)."""
    if "nodes" not in data:
        return {}
    table = data["nodes"]
    if not isinstance(table, dict) or not table:
        raise c.fail("'nodes' must be a non-empty object of shared subplans {ID: NODE}")
    for key, node in table.items():
        if not isinstance(node, dict):
            raise c.fail(f"shared node {key!r} must be a JSON object")
        if "ref" in node:
            raise c.fail(f"shared node {key!r} is itself a reference: give the node")
    return table


class _Graph:
    """The file's nodes with references resolved: each raw node object (a table entry once)
    is one node of the plan."""

    def __init__(self, c: _Checker, table: dict[str, dict[str, Any]]) -> None:
        self.c = c
        self.table = table
        self.used: set[str] = set()

    def resolve(self, raw: object, where: str) -> tuple[object, str]:
        """The node ``raw`` stands for (a reference's table entry) and where it is."""
        if not isinstance(raw, dict) or "ref" not in raw:
            return raw, where
        ref = raw["ref"]
        if len(raw) != 1:
            raise self.c.fail(f"{where} is a reference with other keys than 'ref'")
        if not isinstance(ref, str):
            raise self.c.fail(f"{where} refers to {shown(ref)}: a reference names a shared node")
        if ref not in self.table:
            raise self.c.fail(f"{where} refers to the unknown shared node {ref!r}")
        self.used.add(ref)
        return self.table[ref], f"shared node {ref!r}"


def _check_tree(
    c: _Checker,
    root: object,
    table: dict[str, dict[str, Any]],
    parts: Mapping[Member, PlanPart],
    sensorless: bool,
    max_depth: int,
) -> Step:
    """Check every distinct node once and build the plan bottom-up, without recursion.

    A depth-first search over the nodes with references resolved: a reference back to a
    node on the current path is a cycle; the plan's depth (the longest path, memoised per
    node) must be at most ``max_depth``; every table entry must be used.
    """
    graph = _Graph(c, table)
    known = _Members(parts)
    if isinstance(root, dict) and "ref" in root:
        raise c.fail("the root is written in place, not as a reference")
    on_path: set[int] = set()
    built: dict[int, Node] = {}
    below: dict[int, int] = {}
    fields: dict[int, tuple[float | None, float | None, list[Any], list[object], str]] = {}
    count = 0
    # (raw node, where, depth of its first place, entering: False once its children are done)
    stack: list[tuple[object, str, int, bool]] = [(root, "the root", 0, True)]
    while stack:
        raw, where, depth, entering = stack.pop()
        key = id(raw)
        if entering:
            if key in built:
                continue
            if key in on_path:
                raise c.fail(f"{where} refers back to itself: the shared subplans form a cycle")
            node = c.obj(raw, where)
            if "result" in node:
                if depth == 0:
                    raise c.fail(
                        "the root must be an operation (the first alignment), not a result"
                    )
                built[key], below[key] = _check_leaf(c, node, where, known), 0
                continue
            action, margin, branches = _check_step_fields(c, node, where, depth, sensorless)
            resolved = []
            for _reading, nxt in branches:
                count += 1
                resolved.append(graph.resolve(nxt, f"node {count} (depth {depth + 1})"))
            fields[key] = (action, margin, branches, [t for t, _ in resolved], where)
            on_path.add(key)
            stack.append((raw, where, depth, False))
            stack.extend((t, there, depth + 1, True) for t, there in reversed(resolved))
            continue
        on_path.discard(key)
        action, margin, branches, kids, where = fields.pop(key)
        below[key] = 1 + max(below[id(t)] for t in kids)
        if below[key] > max_depth:
            raise InputError(_too_deep(c.source, max_depth))
        built[key] = Step(
            action,
            margin,
            tuple(Branch(r, built[id(t)]) for (r, _n), t in zip(branches, kids, strict=True)),
        )
    unused = sorted(set(table) - graph.used)
    if unused:
        raise c.fail(f"shared node {unused[0]!r} of 'nodes' is never used")
    top = built[id(root)]
    assert isinstance(top, Step)
    return top


def _check_step_fields(
    c: _Checker, node: dict[str, Any], where: str, depth: int, sensorless: bool
) -> tuple[float | None, float | None, list[tuple[tuple[float, float] | None, object]]]:
    c.only(node, ("action_deg", "margin_deg", "branches"), where, "an operation")
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
    for k, b in enumerate(branches):
        if type(b) is dict and len(b) == 2 and "reading" in b and "next" in b:
            # A well-formed branch, as the writer writes it, without the messages' texts.
            reading = b["reading"]
            if sensorless:
                if reading is None:
                    out.append((None, b["next"]))
                    continue
            elif type(reading) is list and len(reading) == 2:
                lo, hi = reading
                if (
                    type(lo) is float
                    and type(hi) is float
                    and lo <= hi
                    and math.isfinite(lo)
                    and math.isfinite(hi)
                ):
                    out.append(((lo, hi), b["next"]))
                    continue
        bd = c.obj(b, f"{where} branch")
        c.only(bd, ("reading", "next"), f"{where} branch {k}", "a branch")
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


MAX_BEAMS = 2**53
"""An LED array's reading is a whole number of beams; a float counts them exactly below
this, and a width this many pitches wide is no reading (x / pitch may even overflow)."""


def _check_beams(c: _Checker, plan: Plan) -> None:
    """With an LED array, every width the consumers turn into beam counts is a countable
    number of pitches: the noise, each state's diameter plus the noise, each reading bound.
    A hand-edited 1e308 (or a pitch of 5e-324) made them crash with an overflow."""
    sensor = plan.sensor
    if not isinstance(sensor, LedSensor):
        return
    if not sensor.noise / sensor.pitch < MAX_BEAMS:
        raise c.fail(
            f"sensor noise_mm {sensor.noise:g} is more than 2**53 beams of its pitch_mm "
            f"{sensor.pitch:g}"
        )
    for part in plan.parts:
        for k, s in enumerate(part.states):
            if not (s.diameter + sensor.noise) / sensor.pitch < MAX_BEAMS:
                raise c.fail(
                    f"part {part.label!r} stable state {k} diameter {s.diameter:g} mm is more "
                    f"than 2**53 beams of the LED array's pitch {sensor.pitch:g} mm"
                )
    for node, number in plan.walk():
        for b in node.branches if isinstance(node, Step) else ():
            if b.reading is not None and not max(map(abs, b.reading)) / sensor.pitch < MAX_BEAMS:
                raise c.fail(
                    f"a reading of operation {number}, [{b.reading[0]:g}, {b.reading[1]:g}], "
                    f"is more than 2**53 beams of the LED array's pitch {sensor.pitch:g} mm"
                )


OBJECTIVES = ("worst", "expected", "time", "worst-time")
"""The planner's objectives, as design.md's ``plan --objective`` names them."""

POLYGON_CLASSES = range(1, 9)
"""The polygon classes of Fig. 14 of the paper, 1-8 (design.md, ``part analyze``)."""


def _check_class_and_objective(
    c: _Checker, polygon_class: int | None, objective: str | None
) -> None:
    """``stats.class`` and ``stats.objective``, when given, within design.md's ranges (both
    are feederkit's own fields, null or absent in a plan of a mix or a hand-made file)."""
    if polygon_class is not None and polygon_class not in POLYGON_CLASSES:
        raise c.fail(f"stats class {polygon_class} is not a polygon class 1-8 (Fig. 14)")
    if objective is not None and objective not in OBJECTIVES:
        raise c.fail(f"stats objective {objective!r} is not one of {', '.join(OBJECTIVES)}")


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
            raise c.fail(f"stats {name} must be {kind.__name__} or null, got {shown(value)}")
        extra[name] = value
    _check_class_and_objective(c, extra["class"], extra["objective"])
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

    Types (a version is the integer 1 or 2, a result's part a name, a landing ``up``,
    ``down`` or ``pose-K``, ``reject`` a boolean, shares in (0, 1] summing to at most 1, for
    every part or none), results naming listed members (part and landing), the shared
    subplans (``"nodes"``: every reference known, no cycle, every entry used), the declared
    uncertainty (required from version 2; a version-1 file without it is the ideal model)
    and the certificate (at least the declared uncertainty), ranges (actions in
    [0, 360), margins in [0, 180), reading intervals lo <= hi), names (results name listed
    parts and states), the tree at most ``max_depth`` operations deep, and ``stats`` against
    the tree (its length is the tree's depth, its smallest margin the tree's). Also the
    contract with a controller: each hull exactly design.md's (:func:`_check_hull`), no
    number a part of it cannot have (:func:`_check_state`, :func:`_check_beams`), and
    design.md's grammar (node forms, each sensor model's keys, a part's ``revision``,
    ``stats`` class 1-8 and objective). Raises InputError with one line naming ``source``
    and the first problem found. Whether the plan is right for its parts is
    :func:`feederkit.plans.verify.verify_plan`'s question.
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
        raise c.fail(f"unsupported plan version {shown(version)} (this feederkit reads 1 and 2)")
    conventions = data.get("conventions")
    if not isinstance(conventions, str):
        raise c.fail("the plan states no 'conventions'")
    sensor = _check_sensor(c, c.key(data, "sensor", "the plan"))
    declared = "uncertainty" in data or version >= 2
    unc = _check_uncertainty(c, c.key(data, "uncertainty", "the plan")) if declared else IDEAL
    parts_raw = c.lst(c.key(data, "parts", "the plan"), "'parts'")
    if not parts_raw:
        raise c.fail("the plan lists no parts")
    parts: dict[Member, PlanPart] = {}
    for i, p in enumerate(parts_raw):
        part = _check_part(c, p, i)
        if part.key in parts:
            if part.landing is None:
                raise c.fail(f"two parts are both named {part.name!r}")
            raise c.fail(f"two parts are both {part.label!r}")
        parts[part.key] = part
        limit = max_shape_tolerance(push_function_of(part).part)
        if unc.shape_tolerance_mm >= limit:
            raise c.fail(
                f"the shape tolerance {unc.shape_tolerance_mm:g} mm is not below half part "
                f"{part.name!r}'s smallest hull edge ({limit:.4g} mm)"
            )
    check_shares([p.share for p in parts.values()], c.fail)
    table = _check_table(c, data)
    root = _check_tree(
        c, c.key(data, "root", "the plan"), table, parts, not sensor.informative, max_depth
    )
    draft = Plan(
        sensor,
        tuple(parts.values()),
        root,
        PlanStats(1, 1.0, None, False, 1),
        conventions,
        uncertainty=unc,
        uncertainty_declared=declared,
    )
    _check_beams(c, draft)
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
            f"{p}: the plan file is {size / 1e6:.3g} MB, more than the limit of "
            f"{max_bytes / 1e6:.3g} MB"
        )
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = "not UTF-8 text" if isinstance(exc, UnicodeDecodeError) else exc.strerror
        raise InputError(f"{p}: cannot read the plan file ({reason})") from None
    return plan_from_text(text, str(p), max_depth)


def parse_plan_text(text: str, source: str = "plan", max_depth: int = MAX_PLAN_DEPTH) -> object:
    """A plan file's JSON value, nested as deep as a plan of ``max_depth`` operations may be
    (not checked: :func:`plan_from_dict`); InputError naming ``source`` otherwise."""
    levels = _JSON_LEVELS_PER_OPERATION * max_depth + 8
    try:
        with _recursion_room(levels):
            return parse_json(text, source, max_depth=levels)
    except InputError as exc:
        if "nested deeper" not in str(exc):
            raise
        raise InputError(_too_deep(source, max_depth)) from None


def plan_from_text(text: str, source: str = "plan", max_depth: int = MAX_PLAN_DEPTH) -> Plan:
    """A plan file's text parsed and checked (:func:`plan_from_dict`), as :func:`read_plan`
    reads a file: InputError naming ``source`` for anything the file format refuses."""
    return plan_from_dict(parse_plan_text(text, source, max_depth), source, max_depth)


# ---------------------------------------------------------------- the checked write


def _too_deep(source: str, max_depth: int) -> str:
    return f"{source}: the plan is more than {max_depth} operations deep (the limit)"
