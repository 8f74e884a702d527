"""The plan file, ``feederkit-plan`` version 2 (design.md; version 1 stays readable): the
format's constants, the one maker of a :class:`~feederkit.plans.model.Plan` from a planner's
result, and the writer of its JSON.

A plan is a conditional sequence of push-align operations (sections 4, 6, 8.5): each node
rotates the part by ``action_deg`` (none at the root, the first alignment from an unknown
orientation), lets it align on the fence, reads its diameter and follows the branch whose
closed reading interval holds the reading; a leaf lists the poses the part is then in.
Version 2 declares the uncertainty the plan is strong for (``"uncertainty"``, right after
``"sensor"``) and its certificate (``stats.certificate``, last); a version-1 file without
``"uncertainty"`` is read as the paper's ideal model and marked so
(``Plan.uncertainty_declared``). A plan over landings (design.md, "Landings") lists one part
entry per landing (``"landing"``, ``"share"``), names the landing in every result entry and
ends the landings the next station cannot take in ``"reject": true`` results. A subtree that
occurs more than once is written once, in the top-level ``"nodes"`` table, and referred to
as ``{"ref": ID}``: the reader makes it one shared object again, so the size of a file and
the cost of every walk is its number of distinct nodes.

Made here: :func:`plan_from_result` (a planner's result). Written here: :func:`plan_to_dict`
and :func:`plan_json` (the text). The members' shares obey one rule, :func:`check_shares`,
for the maker and the reader alike. Reading and checking a file are
:mod:`feederkit.plans.readplan`'s, and the checked write (``read_back``, ``plan_file_text``,
``write_plan``: the text checked as the reader will read it)
:mod:`feederkit.plans.writeplan`'s; both import this module, never the other way round.
Nothing recurses over the tree, so a plan as deep as the reader's limit writes. The planner's
types are imported only where a result is turned into a plan, so reading a
plan needs no planner.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from json.encoder import c_make_encoder, encode_basestring_ascii  # type: ignore[attr-defined]
from typing import TYPE_CHECKING, Any

from feederkit.errors import InputError, PlanningError
from feederkit.machine.model import members
from feederkit.mechanics.push import PushFunction, StableState
from feederkit.plans.model import (
    Branch,
    Leaf,
    Node,
    Plan,
    PlanMember,
    PlanPart,
    PlanStats,
    ResultEntry,
    Step,
    member_label,
)
from feederkit.sensors import Grouping, LedSensor, Sensor
from feederkit.uncertainty import IDEAL, Uncertainty
from feederkit.words import plural

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
    "entry is a correct answer. 'margin_deg': on the ideal model (no uncertainty declared) "
    "the half-width of the action's overlap range, so any rotation within it of 'action_deg' "
    "gives the same outcome; in a strong plan (a declared rotation error r > 0) the slack "
    "beyond r: any rotation within r + margin_deg of 'action_deg' gives an outcome the plan "
    "was made for."
)

LED_WINDOWS = (
    "With an LED array of pitch p a branch over beam counts a..b holds [(a - 1/4) p, "
    "(b + 1/4) p] (ends rounded, never below 0), so a reading computed as count times pitch "
    "in any arithmetic (float32, fixed point, decimal) lies in its count's branch, and the "
    "branches of different counts lie half a pitch apart: a reading half-way between the "
    "counts of two branches is in neither."
)
"""What an LED plan's ``conventions`` adds: the rule of ``sensors.LedSensor.window``."""


LANDINGS = (
    "Landings: a part entry with 'landing' is the part as it lands on the belt, 'up' as "
    "drawn, 'down' mirrored about the part frame's y axis (x to -x, the COM too), 'pose-K' a "
    "solid's resting pose K; its 'hull', 'com', states and poses are those of that landing, in "
    'its own frame, and every result entry names the landing. A result with "reject": true '
    "is a landing the next station cannot take: the part is to be diverted, not placed."
)
"""What a plan over landings adds to its ``conventions`` paragraph (design.md, "Landings"):
the mirror axis of ``down`` decides every face-down pose, and a reject leaf asks for an
action of its own."""


def conventions_for(sensor: Sensor, landings: bool = False) -> str:
    """The ``conventions`` paragraph of a plan with this sensor (design.md): CONVENTIONS,
    for an LED array the rule its reading windows follow (:data:`LED_WINDOWS`), and for a
    plan over ``landings`` what they are (:data:`LANDINGS`)."""
    text = f"{CONVENTIONS} {LED_WINDOWS}" if isinstance(sensor, LedSensor) else CONVENTIONS
    return f"{text} {LANDINGS}" if landings else text


AS_DRAWN = "up"
"""The landing a result entry names in a plan not made over landings (design.md: every
result entry names its landing): the part as given, whose part entry has no ``landing``."""


def member_keys(members: Sequence[tuple[str, str | None]]) -> dict[tuple[str, str | None], int]:
    """Each member's index by the ``(part, landing)`` a result entry names: its own, and for
    a member without a landing also ``(part, AS_DRAWN)``, as the writer names it.

    >>> member_keys([("bar", None)])
    {('bar', None): 0, ('bar', 'up'): 0}
    """
    out: dict[tuple[str, str | None], int] = {}
    for p, (name, landing) in enumerate(members):
        out[(name, landing)] = p
        if landing is None:
            out.setdefault((name, AS_DRAWN), p)
    return out


MAX_FILE_NODES = 100_000
"""A plan whose file would hold more nodes than this is refused: no controller wants it.
Shared subplans count once (they are written once, in ``"nodes"``)."""


# ---------------------------------------------------------------- the shares rule


def shown(value: object) -> str:
    """A value in a message, clipped to one short line."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


SHARE_SUM_EPS = 1e-6
"""The members' shares may sum to at most this above 1 (rounding of the products)."""


def check_shares(shares: Sequence[float | None], fail: Any) -> None:
    """Every member's share or none, each in (0, 1], their sum at most 1: a share is a prior
    probability (part share times landing probability). ``fail`` makes the error."""
    given = [x for x in shares if x is not None]
    if not given:
        return
    if len(given) != len(shares):
        raise fail("either every part gives its 'share' or none does")
    for x in given:
        if isinstance(x, bool) or not isinstance(x, int | float) or not 0.0 < x <= 1.0:
            raise fail(f"a part's share must be a number in (0, 1], got {shown(x)}")
    if math.fsum(given) > 1.0 + SHARE_SUM_EPS:
        raise fail(f"the parts' shares sum to {math.fsum(given):.6g}, more than 1")


# ---------------------------------------------------------------- from a planner's result


state_members = members
"""The machine states in a set (a bit mask), in increasing order: the machine's
:func:`~feederkit.machine.model.members`, under the name this module has given it."""


def _plan_part(
    machine: PushAlignMachine, p: int, pf: PushFunction, member: PlanMember | None
) -> PlanPart:
    """A part's name (its member's, when given, with landing and share), revision, COM,
    hull and stable states (diameters as planned on)."""
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
        name=pf.part.name if member is None else member.name,
        revision=pf.part.revision,
        com=tuple(pf.part.com),
        hull=tuple(tuple(v) for v in pf.part.hull),
        states=states,
        landing=None if member is None else member.landing,
        share=None if member is None else member.share,
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
    diameters = [machine.states[i].diameter for i in state_members(branch.mask)]
    split = machine.sensor.split(diameters, Grouping.COMPONENTS)
    return (min(b.lo for b in split), max(b.hi for b in split))


def distinct_nodes(plan: Mapping[str, Any]) -> Iterator[Mapping[str, Any]]:
    """Every distinct NODE of a plan file's object (a shared subplan's once, its ``"ref"``
    resolved), in pre-order, without building the :class:`Plan` model: for a caller that
    only reads a plan it made (a large mix's plan has tens of thousands of nodes, and the
    model takes seconds to check). The object is trusted."""
    shared = plan.get("nodes") or {}
    seen: set[int] = set()
    stack = [plan["root"]]
    while stack:
        node = stack.pop()
        while "ref" in node:
            node = shared[node["ref"]]
        if id(node) in seen:
            continue
        seen.add(id(node))
        yield node
        if "result" not in node:
            stack.extend(b["next"] for b in reversed(node["branches"]))


def result_nodes(plan: Mapping[str, Any]) -> Iterator[Mapping[str, Any]]:
    """Every distinct result NODE of a plan file's object (:func:`distinct_nodes`)."""
    return (node for node in distinct_nodes(plan) if "result" in node)


def file_nodes(root: Node) -> int:
    """How many nodes the plan file of this tree holds: each distinct step once (a shared
    one in ``"nodes"``), and each leaf once per place (leaves are written in place).

    Counted on the distinct nodes, without recursion, so a plan whose tree has
    astronomically many paths is measured by what is written.
    """
    shape = _shape(root)
    return len(shape.steps) + sum(
        1 for c in shape.steps for k in shape.children[c] if k not in shape.steps
    )


def _tree(
    result: PlanResult,
    parts: Sequence[PushFunction],
    members: Sequence[PlanMember] | None,
) -> Step:
    """The planner's tree as plan nodes; shared subtrees stay shared (built once).

    A leaf whose every state belongs to a member the next station does not accept is a
    reject leaf (design.md, "Landings").
    """
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
            rejected = True
            for i in state_members(node.mask):
                ms = machine.states[i]
                s = parts[ms.part].states[ms.state]
                if members is None:
                    entries.append(ResultEntry(parts[ms.part].part.name, s.id, s.pose_deg))
                    rejected = False
                    continue
                m = members[ms.part]
                entries.append(ResultEntry(m.name, s.id, s.pose_deg, m.landing))
                rejected = rejected and not m.accept
            built[key] = Leaf(tuple(entries), reject=rejected and bool(entries))
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
    members: Sequence[PlanMember] | None = None,
) -> Plan:
    """The plan of a planner's result on the machine of ``parts`` (in order).

    The plan declares ``uncertainty`` (default: the result's, its machine's) and carries the
    result's certificate when it has one. A strong plan written over the ideal states
    (``feederkit.plans.strong.ideal_view``) has the ideal machine, so its maker passes the
    declared uncertainty here.

    ``parts`` are the push functions the machine was built from (``build_machine``): the plan
    records each part's hull and COM, so it can be checked on the geometry alone.
    ``members`` (one per part, in order) name the plan's members when they are not the
    parts' own names: a plan over landings gives each landing's part its part name, landing
    and share, and ends sets of states of members it does not accept in reject leaves
    (design.md, "Landings"). Raises InputError when two members share a name and landing
    (results name their member) and PlanningError when the file would hold more than
    MAX_FILE_NODES distinct nodes (shared subplans count once).
    """
    machine = result.machine
    names = [pf.part.name for pf in parts]
    if tuple(names) != machine.part_names or sum(pf.n for pf in parts) != machine.n:
        raise ValueError("plan_from_result: the parts are not the ones the machine was built from")
    if members is not None:
        members = tuple(members)
        if len(members) != len(parts):
            raise ValueError("plan_from_result: one member per part is needed")
        check_shares([m.share for m in members], InputError)
    keys = [(n, None) for n in names] if members is None else [(m.name, m.landing) for m in members]
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        which = f"named {dup[0]!r}" if dup[1] is None else repr(member_label(*dup))
        raise InputError(f"two parts of the mix are both {which}: a plan names its parts")
    root = _tree(result, parts, members)
    size = file_nodes(root)
    if size > MAX_FILE_NODES:
        found = f"the plan found ({plural(result.length, 'operation')}"
        if not result.optimal:
            found += f", not proven optimal; a plan needs at least {result.lower_bound}"
        raise PlanningError(
            f"{found}) would write {size:,} nodes, more than {MAX_FILE_NODES:,}: give the "
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
        certificate=getattr(result, "certificate", None),
    )
    return Plan(
        sensor=machine.sensor,
        parts=tuple(
            _plan_part(machine, p, pf, None if members is None else members[p])
            for p, pf in enumerate(parts)
        ),
        root=root,
        stats=stats,
        conventions=conventions_for(
            machine.sensor, members is not None and any(m.landing for m in members)
        ),
        uncertainty=getattr(machine, "uncertainty", IDEAL) if uncertainty is None else uncertainty,
    )


# ---------------------------------------------------------------- to a dict and a file


def _part_dict(part: PlanPart) -> dict[str, Any]:
    head: dict[str, Any] = {"name": part.name}
    if part.landing is not None:
        head["landing"] = part.landing
    if part.share is not None:
        head["share"] = part.share
    return {
        **head,
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


@dataclass(frozen=True)
class _Shape:
    """The distinct structures of a tree (canonical structural equality, section-free):
    ``rep[c]`` a node of structure ``c``, ``children[c]`` its branches' structures,
    ``steps`` the structures that are steps, ``uses[c]`` how many branches of distinct steps
    lead to ``c``, ``root`` the root's structure."""

    rep: tuple[Node, ...]
    children: tuple[tuple[int, ...], ...]
    steps: frozenset[int]
    uses: tuple[int, ...]
    root: int


def _leaf_key(leaf: Leaf) -> tuple[Any, ...]:
    return (
        "leaf",
        leaf.reject,
        tuple((e.part, e.landing, e.state, e.pose_deg) for e in leaf.results),
    )


def _shape(root: Node) -> _Shape:
    """Intern every subtree by its structure, bottom-up without recursion: two subtrees are
    one when their written JSON is the same (so shared objects and equal copies alike)."""
    of: dict[int, int] = {}
    index: dict[tuple[Any, ...], int] = {}
    rep: list[Node] = []
    children: list[tuple[int, ...]] = []
    stack: list[tuple[Node, bool]] = [(root, False)]
    while stack:
        node, expanded = stack.pop()
        if id(node) in of:
            continue
        if isinstance(node, Step) and not expanded:
            stack.append((node, True))
            stack.extend((b.next, False) for b in node.branches if id(b.next) not in of)
            continue
        if isinstance(node, Leaf):
            key, kids = _leaf_key(node), ()
        else:
            kids = tuple(of[id(b.next)] for b in node.branches)
            readings = tuple(b.reading for b in node.branches)
            key = ("step", node.action_deg, node.margin_deg, readings, kids)
        c = index.setdefault(key, len(rep))
        if c == len(rep):
            rep.append(node)
            children.append(kids)
        of[id(node)] = c
    steps = frozenset(c for c, n in enumerate(rep) if isinstance(n, Step))
    uses = [0] * len(rep)
    for c in steps:
        for k in children[c]:
            uses[k] += 1
    return _Shape(tuple(rep), tuple(children), steps, tuple(uses), of[id(root)])


def _leaf_dict(leaf: Leaf) -> dict[str, Any]:
    entries = []
    for e in leaf.results:
        entry: dict[str, Any] = {"part": e.part, "landing": e.landing or AS_DRAWN}
        entry.update(state=e.state, pose_deg=e.pose_deg)
        entries.append(entry)
    out: dict[str, Any] = {"result": entries}
    if leaf.reject:
        out["reject"] = True
    return out


def _tree_dicts(root: Node) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """The tree as the file's NODE objects and its ``"nodes"`` table, without recursion.

    Every step structure used by more than one branch is written once in the table (ids
    ``n1``, ``n2``, ... in the order the file first refers to them) and as ``{"ref": ID}`` in
    its places; a leaf is always written in place (it is no larger than a reference and
    its table entry). The result depends on the structure only, so a file read back and
    written again gives the same bytes.
    """
    shape = _shape(root)
    shared = {c for c in shape.steps if shape.uses[c] > 1}
    ids: dict[int, str] = {}
    pending: list[int] = []

    def emit(top: int) -> dict[str, Any]:
        holder: list[dict[str, Any]] = []
        stack: list[tuple[int, list[dict[str, Any]], bool, tuple[float, float] | None]] = [
            (top, holder, True, None)
        ]
        while stack:
            c, out, first, reading = stack.pop()
            node = shape.rep[c]
            if c in shared and not first:
                if c not in ids:
                    ids[c] = f"n{len(ids) + 1}"
                    pending.append(c)
                d: dict[str, Any] = {"ref": ids[c]}
            elif isinstance(node, Leaf):
                d = _leaf_dict(node)
            else:
                d = {"action_deg": node.action_deg, "margin_deg": node.margin_deg, "branches": []}
                for b, k in reversed(list(zip(node.branches, shape.children[c], strict=True))):
                    stack.append((k, d["branches"], False, b.reading))
            if out is holder:
                holder.append(d)
            else:
                out.append({"reading": None if reading is None else list(reading), "next": d})
        return holder[0]

    tree = emit(shape.root)
    table: dict[str, dict[str, Any]] = {}
    k = 0
    while k < len(pending):
        c = pending[k]
        table[ids[c]] = emit(c)
        k += 1
    return tree, table


def plan_to_dict(
    plan: Plan | PlanResult,
    parts: Sequence[PushFunction] | None = None,
    *,
    members: Sequence[PlanMember] | None = None,
) -> dict[str, Any]:
    """The plan file's JSON object of a :class:`Plan` (``"nodes"`` only when some subtree
    is shared, right after ``"root"``).

    Also called as ``plan_to_dict(result, parts, members=None)`` for a planner's result (the
    form ``plans/make.py`` uses): that is ``plan_to_dict(plan_from_result(result, parts,
    members=members))``.
    """
    if not isinstance(plan, Plan):
        if parts is None:
            raise TypeError("plan_to_dict(result, parts): the push functions are needed")
        plan = plan_from_result(plan, parts, members=members)
    root, table = _tree_dicts(plan.root)
    out: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "conventions": plan.conventions,
        "sensor": plan.sensor.to_dict(),
        "uncertainty": plan.uncertainty.to_dict(),
        "parts": [_part_dict(p) for p in plan.parts],
        "root": root,
    }
    if table:
        out["nodes"] = table
    out["stats"] = _stats_dict(plan.stats)
    return out


_ONE_LINE = json.JSONEncoder(allow_nan=False)
"""The encoder of one-line values, made once: ``json.dumps`` with an option makes a new one
per call, which dominated writing a plan of tens of thousands of results."""


def _one_line_encoder() -> Callable[[object], str]:
    """``_ONE_LINE.encode``, or the C encoder it makes per call made once (the same text and
    errors, a circular reference included: half the cost of writing a plan of a million
    values, each a call)."""
    if c_make_encoder is None:  # a Python without the json accelerator
        return _ONE_LINE.encode
    markers: dict[int, object] = {}  # the values being written, as the circular check keeps
    chunks = c_make_encoder(
        markers, _ONE_LINE.default, encode_basestring_ascii, None, ": ", ", ", False, False, False
    )

    def encode(value: object) -> str:
        try:
            return "".join(chunks(value, 0))
        except BaseException:
            markers.clear()  # an error leaves its values marked
            raise

    return encode


_ENCODE = _one_line_encoder()


def _one_line(value: object) -> str | None:
    """The text of a value written on one line, or None when it is spread over lines.

    Lists of plain values (points, intervals) and small flat objects (result entries, the
    sensor, references) stay on one line. Floats and strings, most of a plan's values, are
    written as ``json`` writes them without its per-call set-up; a NaN or an infinity is a
    ValueError, as ``allow_nan=False`` makes it.
    """
    kind = type(value)
    if kind is float:
        if not math.isfinite(value):  # type: ignore[arg-type]
            return _ONE_LINE.encode(value)  # json's own ValueError
        return float.__repr__(value)  # type: ignore[arg-type]
    if kind is str:
        return encode_basestring_ascii(value)
    if kind is dict:
        items = value.values()  # type: ignore[attr-defined]
        if not items or (len(items) <= 4 and not any(isinstance(v, dict | list) for v in items)):
            return _ENCODE(value)
        return None
    if kind is list or kind is tuple:
        if any(isinstance(v, dict | list | tuple) for v in value):  # type: ignore[attr-defined]
            return None
        return _ENCODE(value)
    if isinstance(value, dict | list | tuple):  # a subclass: as its base class
        return _one_line(dict(value) if isinstance(value, dict) else list(value))
    return _ENCODE(value)


def plan_json(plan: Plan | Mapping[str, Any]) -> str:
    """The plan file's text: indented JSON (short lists on one line), no NaN or infinity.

    Written with an explicit stack, so any depth the reader accepts can be written; each
    value's one-line text is tried once, by its parent, in order. Of several values that
    cannot be written, the error is about the first of an object's own values, before any
    inside the objects it holds.
    """
    value = plan_to_dict(plan) if isinstance(plan, Plan) else plan
    line = _one_line(value)
    if line is not None:
        return line + "\n"
    out: list[str] = []
    keys: dict[str, str] = {}  # each key's text once: a plan repeats a few keys
    # Pieces of text, and (value, indent) for a value spread over lines.
    stack: list[str | tuple[Any, int]] = [(value, 0)]
    push = stack.append
    while stack:
        item = stack.pop()
        if type(item) is str:
            out.append(item)
            continue
        v, indent = item  # type: ignore[misc]
        pad = "  " * (indent + 1)
        # The closing line first: the stack pops the pieces in reverse.
        if isinstance(v, dict):
            push("\n" + "  " * indent + "}")
            sep = ""
            lines = [_one_line(child) for child in v.values()]
            for (key, child), line in zip(reversed(v.items()), reversed(lines), strict=True):
                text = keys.get(key)
                if text is None:
                    text = keys[key] = f"{json.dumps(key)}: "
                if line is None:
                    push(sep)
                    push((child, indent + 1))
                    push(pad + text)
                else:
                    push(pad + text + line + sep)
                sep = ",\n"
            push("{\n")
        else:
            assert isinstance(v, list | tuple)
            push("\n" + "  " * indent + "]")
            sep = ""
            lines = [_one_line(child) for child in v]
            for child, line in zip(reversed(v), reversed(lines), strict=True):
                if line is None:
                    push(sep)
                    push((child, indent + 1))
                    push(pad)
                else:
                    push(pad + line + sep)
                sep = ",\n"
            push("[\n")
    return "".join(out) + "\n"
