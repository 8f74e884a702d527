"""Verify a plan on the kinematic model: every start, every reading, every rotation.

For every part, every stable state it can start in, the plan is followed exactly, by
interval arithmetic rather than by sampling:

- a rotation ``action ± margin`` (the step's overlap range, section 6) from a state reaches
  every state whose resting range meets the rotated interval of fence orientations, so the
  whole range is checked, not a few rotations in it;
- a state of diameter ``d`` can give every reading of its reading set (the sensor model,
  section 5): for a tolerance sensor the open interval, split at every branch endpoint inside
  it, each piece and each endpoint tried once; for an LED array every beam count. Each
  reading must be held by some branch, and every branch that holds one (on a shared endpoint
  both) must be right.

Every path must end in a result that lists the part's final state (its landing too, in a
plan over landings), and the longest must take exactly the plan's stated length. The plan's
listed stable states must be the ones its hulls and COMs give. A landing listed in a reject
leaf must never be listed in an accept leaf (design.md, "Landings": a rejected landing never
reaches an accept leaf). The stated expected length must be the expected number of
operations with the start uniform on the circle and each member weighted by its share
(:func:`expected_operations`). Paths that share a (node, state) share their future, so the
search is memoised and linear in the plan's distinct nodes times states, however many paths
shared subplans make.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Container, Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, TypeVar

import numpy as np

from feederkit.angles import angle_close, norm360
from feederkit.errors import CheckFailed
from feederkit.mechanics.push import PushFunction, StableState, push, rotation_after
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS, NEAR_SYMMETRIC_REL, pose_differences
from feederkit.plans.execute import Trace, TraceStep, finish, rounding_inset
from feederkit.plans.model import Leaf, Node, Plan, Step, member_label, push_function_of
from feederkit.plans.readplan import as_plan
from feederkit.sensors import Sensor
from feederkit.words import plural

ANGLE_EPS_DEG = 1e-7
"""An overlap range is taken this much inside its ends (deg): the planner's ranges end exactly
on resting-range boundaries, which rebuilding the push function reproduces to about 1e-12."""


@dataclass(frozen=True)
class PartCheck:
    """What was tried for one member: starts, complete paths, the most operations any run
    took; ``landing`` the member's landing (None: not a plan over landings),
    ``rejects`` the paths that end in a reject leaf and ``unrecognized`` those that end in an
    accept leaf naming several members (:attr:`~feederkit.plans.model.Leaf.unrecognized`)."""

    part: str
    starts: int
    paths: int
    worst_operations: int
    failed_starts: int
    landing: str | None = None
    rejects: int = 0
    unrecognized: int = 0

    @property
    def label(self) -> str:
        """The member in words: ``PART`` or ``PART (LANDING)``."""
        return member_label(self.part, self.landing)

    def to_dict(self) -> dict[str, Any]:
        """As JSON."""
        return {
            "part": self.part,
            "landing": self.landing,
            "starts": self.starts,
            "paths": self.paths,
            "rejects": self.rejects,
            "unrecognized": self.unrecognized,
            "worst_operations": self.worst_operations,
            "failed_starts": self.failed_starts,
        }


@dataclass(frozen=True)
class VerificationReport:
    """The verification of a plan: per part, the failing paths, and inconsistencies of the file."""

    parts: tuple[PartCheck, ...]
    failures: tuple[Trace, ...] = ()
    problems: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """Whether every run succeeded and the file is consistent."""
        return not self.failures and not self.problems

    @property
    def paths(self) -> int:
        """Number of complete paths tried."""
        return sum(p.paths for p in self.parts)

    @property
    def unrecognized(self) -> int:
        """Paths that end, rightly, in an accept result naming several members."""
        return sum(p.unrecognized for p in self.parts)

    def first_problem(self) -> str | None:
        """The first counterexample or inconsistency, in one line (None when the plan passed)."""
        if self.problems:
            return self.problems[0]
        return self.failures[0].message if self.failures else None

    def to_dict(self) -> dict[str, Any]:
        """As JSON; ``first_problem`` is what failed, whichever verifier found it (a strong
        plan's first failing path is a problem, with no counts per part)."""
        return {
            "ok": self.ok,
            "first_problem": self.first_problem(),
            "paths": self.paths,
            "unrecognized": self.unrecognized,
            "parts": [p.to_dict() for p in self.parts],
            "problems": list(self.problems),
            "failures": [t.to_dict() for t in self.failures],
        }


@dataclass(frozen=True)
class _Failure:
    """A failing continuation from a node: the reading and branch chosen there, then the rest."""

    reading: float | None
    branch: int | None
    interval: tuple[float, float] | None
    rest: tuple[TraceStep, ...]
    final: StableState
    leaf: Leaf | None


@dataclass(frozen=True)
class _Outcome:
    paths: int
    worst: int
    failure: _Failure | None
    rejects: int = 0
    unrecognized: int = 0


def _discrete(sensor: Sensor, diameter: float) -> bool:
    """Whether the sensor's readings of this state are a finite set (an LED array's counts)
    rather than a continuum (a tolerance's interval): a single reading then has a positive
    probability."""
    r = sensor.nominal_reading(diameter)
    return r is not None and sensor.reading_probability(diameter, r, r) > 0.0


def candidate_readings(sensor: Sensor, step: Step, diameter: float) -> list[float | None]:
    """Readings that together meet every branch a state of this diameter can follow.

    Which branches hold a reading changes only at branch endpoints, so the endpoints inside
    the state's reading interval and one reading between each two neighbours cover the whole
    interval however narrow a branch is.
    """
    if not sensor.informative:
        return [None]
    if _discrete(sensor, diameter):
        return sorted(set(sensor.probe_readings(diameter, 0.0)))
    interval = sensor.reading_interval(diameter)
    assert interval is not None
    lo, hi = interval
    # An end strictly inside (lo, hi) is one of a branch meeting [lo, hi].
    met = (step.branches[k].reading for k in step.meeting(lo, hi))
    inner = sorted({x for r in met if r is not None for x in r if lo < x < hi})
    points = [lo, *inner, hi]
    mids = [(a + b) / 2.0 for a, b in zip(points, points[1:], strict=False) if a < b]
    out = sorted({*inner, *mids})
    return [r for r in out if sensor.consistent(diameter, r)]


_TURNS = np.array([[-360.0], [0.0], [360.0]])
"""A turn back, none and a turn forward: the shifts an arc and a range are compared at."""


def resting_arcs(pf: PushFunction) -> tuple[np.ndarray, np.ndarray]:
    """Each state's resting range (start in [0, 360), end) shifted by each of ``_TURNS``:
    two arrays of shape (3, states), columns in the order of ``pf.states``, the table
    :func:`rotation_outcomes` meets an arc against."""
    lo = np.array([norm360(s.resting_range_deg[0]) for s in pf.states], dtype=float)
    width = np.array([s.resting_range_deg[1] - s.resting_range_deg[0] for s in pf.states])
    return lo + _TURNS, lo + width + _TURNS


def rotation_outcomes(
    pf: PushFunction,
    normal_deg: float,
    step: Step,
    arcs: tuple[np.ndarray, np.ndarray] | None = None,
) -> list[StableState]:
    """Every state a rotation in the step's overlap range leads the state of ``normal_deg`` to.

    The rotated fence orientations ``normal - (action ± margin)`` form one open arc; the
    part settles in every state whose open resting range meets it (section 3.1), the arc
    and the range compared once a turn apart each way. ``arcs``: :func:`resting_arcs` of
    ``pf``, when the caller keeps it.
    """
    assert step.action_deg is not None and step.margin_deg is not None
    nominal = push(pf, rotation_after(normal_deg, step.action_deg))
    width = 2.0 * (step.margin_deg - ANGLE_EPS_DEG)
    if width <= 0.0:
        return [nominal]
    lo, hi = resting_arcs(pf) if arcs is None else arcs
    t0 = norm360(normal_deg - step.action_deg - step.margin_deg + ANGLE_EPS_DEG)
    t1 = t0 + width
    hit = (np.maximum(t0, lo) < np.minimum(t1, hi)).any(axis=0)
    met = [pf.states[i] for i in hit.nonzero()[0].tolist()]
    return met if nominal in met else [nominal, *met]


class _PartSearch:
    """The memoised search over (node, state) for one part."""

    def __init__(self, plan: Plan, p: int) -> None:
        self.plan = plan
        self.pf: PushFunction = push_function_of(plan.parts[p])
        # Readings a hair inside an open end only (docs/conventions.md): two reading sets
        # that touch at a breakpoint tolerance may overlap by an ulp in floating point.
        self.sensor = plan.sensor.narrowed(rounding_inset(self.pf.part.size))
        self.name = plan.parts[p].name
        self.landing = plan.parts[p].landing
        # Readings are those of the rebuilt part's true diameters, not the file's listed
        # (snapped) values: every reading a state can really give must lie in a branch.
        self.diameter = {s.id: s.diameter for s in self.pf.states}
        self.arcs = resting_arcs(self.pf)
        self.memo: dict[tuple[int, int], _Outcome] = {}
        self.arrivals: set[tuple[int, int]] = set()  # (id of a leaf, a state that ends there)

    def after_push(self, node: Step, number: int, state: StableState) -> _Outcome:
        """Outcome of every continuation once operation ``number`` of ``node`` left ``state``
        (``worst``: the number of the last operation of the longest).

        Memoised per (node, state) with the operations below the node, not their numbers: a
        shared subplan may be reached after different numbers of operations.
        """
        key = (id(node), state.id)
        hit = self.memo.get(key)
        if hit is not None:
            return _Outcome(
                hit.paths, number + hit.worst, hit.failure, hit.rejects, hit.unrecognized
            )
        paths, worst, failure, rejects, unrecognized = 0, number, None, 0, 0
        explored: set[int] = set()
        for reading in candidate_readings(self.sensor, node, self.diameter[state.id]):
            held = node.held_by(reading)
            if not held and failure is None:
                failure = _Failure(reading, None, None, (), state, None)
            for b in held:
                if b in explored:
                    continue
                explored.add(b)
                branch = node.branches[b]
                nxt = branch.next
                if isinstance(nxt, Leaf):
                    paths += 1
                    rejects += nxt.reject
                    unrecognized += nxt.unrecognized
                    self.arrivals.add((id(nxt), state.id))
                    if not nxt.accepts(self.name, state.id, self.landing) and failure is None:
                        failure = _Failure(reading, b, branch.reading, (), state, nxt)
                    continue
                assert nxt.action_deg is not None
                for s2 in rotation_outcomes(self.pf, state.normal_deg, nxt, self.arcs):
                    sub = self.after_push(nxt, number + 1, s2)
                    paths += sub.paths
                    rejects += sub.rejects
                    unrecognized += sub.unrecognized
                    worst = max(worst, sub.worst)
                    if sub.failure is not None and failure is None:
                        f = sub.failure
                        theta = _theta_into(state.normal_deg, nxt, s2)
                        step = TraceStep(
                            number + 1,
                            nxt.action_deg,
                            theta,
                            s2.id,
                            s2.edge,
                            s2.diameter,
                            f.reading,
                            f.branch,
                            f.interval,
                            norm360(state.normal_deg - nxt.action_deg - theta + 180.0) - 180.0,
                        )
                        failure = _Failure(
                            reading, b, branch.reading, (step, *f.rest), f.final, f.leaf
                        )
        self.memo[key] = _Outcome(paths, worst - number, failure, rejects, unrecognized)
        return _Outcome(paths, worst, failure, rejects, unrecognized)

    def run(self) -> tuple[PartCheck, list[Trace]]:
        paths, worst, failed, rejects, unrecognized = 0, 0, [], 0, 0
        starts = self.pf.states
        for s0 in starts:
            o = self.after_push(self.plan.root, 1, s0)
            paths += o.paths
            rejects += o.rejects
            unrecognized += o.unrecognized
            worst = max(worst, o.worst)
            if o.failure is not None:
                f = o.failure
                theta = s0.normal_deg
                first = TraceStep(
                    1, None, theta, s0.id, s0.edge, s0.diameter, f.reading, f.branch, f.interval
                )
                # a path's k-th step is operation k, wherever a shared subplan was first met
                steps = [replace(t, number=k) for k, t in enumerate((first, *f.rest), 1)]
                failed.append(finish(self.name, theta, steps, f.final, f.leaf, self.landing))
        check = PartCheck(
            self.name, len(starts), paths, worst, len(failed), self.landing, rejects, unrecognized
        )
        return check, failed


def unlike_unreached(pf: PushFunction, listed: Iterable[int], arrived: set[int]) -> list[int]:
    """The states of ``listed`` (one member's entries of a result) that are not ``arrived``
    (the member's states that end there) and whose pose looks like that of none of them
    (within ``NEAR_SYMMETRIC_REL`` of the part's size,
    :func:`~feederkit.mechanics.symmetry.pose_difference`); every missing one when none of
    the member's states ends there.

    A controller may take any entry of a result as the answer (design.md), so such an entry
    would send the part to a wrong pose, or name a part or landing that never comes there.
    Entries that look like an arriving one are harmless (a symmetric pose, or a
    near-symmetric one listed with it)."""
    missing = [s for s in listed if s not in arrived]
    if not missing or not arrived:
        return missing
    tol = NEAR_SYMMETRIC_REL * pf.part.size
    near = pose_differences(pf, [(s, a) for s in missing for a in sorted(arrived)])
    width = len(arrived)
    return [s for k, s in enumerate(missing) if near[k * width : (k + 1) * width].min() > tol]


Listed = tuple[int, int]
"""A result entry as the verifiers judge it: (member index, state id)."""


def unsupported(
    pfs: Sequence[PushFunction], listed: Iterable[Listed], arrived: set[Listed]
) -> list[Listed]:
    """The entries of ``listed`` (one result's) that are not ``arrived`` (the pairs that
    end there, from every start, outcome and reading) and that look like none of their
    member's arrived states (:func:`unlike_unreached`: every entry of a member none of whose
    states ends there), in the order listed. A result nothing ends in is not judged: only
    readings beyond the plan's model lead there (a part's own widths beyond a contact hull
    simplified inside its arcs, ``machine.widths``), which the file does not hold."""
    if not arrived:
        return []
    by_member: dict[int, list[int]] = {}
    for p, s in listed:
        by_member.setdefault(p, []).append(s)
    bad: set[Listed] = set()
    for p, states in by_member.items():
        mine = {s for q, s in arrived if q == p}
        bad.update((p, s) for s in unlike_unreached(pfs[p], states, mine))
    return [x for x in listed if x in bad]


def unsupported_words(label: str, state: int, member_there: bool, pose: float | None = None) -> str:
    """A result entry :func:`unsupported` refuses, in words: ``member_there`` whether some
    state of its member (``label``) ends there."""
    shown = "" if pose is None else f" (pose {pose:.6g} deg)"
    head = f"a result lists {label} state {state}{shown}, but no start, outcome or reading of "
    # Results before 2026-12-06 listed such entries (a controller may take any entry): the
    # fix is a plan made again, which names only what ends there.
    again = " (a plan written by an earlier feederkit may list it: make the plan again)"
    if not member_there:
        return head + f"{label} ends there" + again
    return head + "it ends there, and it looks like none that does" + again


def _arrivals(plan: Plan, searches: Mapping[int, _PartSearch]) -> dict[int, set[Listed]]:
    """Per result (its id): the (member, state) pairs of the searched members that end
    there."""
    out: dict[int, set[Listed]] = {id(leaf): set() for leaf in plan.leaves()}
    for p, search in searches.items():
        for leaf, state in search.arrivals:
            out[leaf].add((p, state))
    return out


def _listed(
    index: Mapping[tuple[str, str | None], int], leaf: Leaf, searched: Container[int]
) -> list[Listed]:
    """A result's entries of the searched members as (member, state) pairs (``index``: each
    member's index by its key)."""
    return [(k, e.state) for e in leaf.results if (k := index[e.key]) in searched]


def _member_index(plan: Plan) -> dict[tuple[str, str | None], int]:
    """Each member's index by its key ``(name, landing)``."""
    return {part.key: p for p, part in enumerate(plan.parts)}


def entry_problems(
    plan: Plan, searches: Mapping[int, _PartSearch], arrived: Mapping[int, set[Listed]]
) -> list[str]:
    """Result entries of the searched members that nothing ends in there and that look like
    none that does (:func:`unsupported`), ``arrived`` per result (:func:`_arrivals`); with
    some members searched only, a result none of theirs ends in is not judged."""
    pfs = plan.push_functions()
    poses = {(p, s.id): s.pose_deg for p, part in enumerate(plan.parts) for s in part.states}
    index = _member_index(plan)
    out = []
    for leaf in plan.leaves():
        ends = arrived[id(leaf)]
        for p, s in unsupported(pfs, _listed(index, leaf, searches), ends):
            there = any(q == p for q, _s in ends)
            out.append(unsupported_words(plan.parts[p].label, s, there, poses[(p, s)]))
    return out


def file_results(data: Mapping[str, Any], plan: Plan) -> dict[int, list[dict[str, Any]]]:
    """Per result of ``plan`` (its id): the result objects of ``data``, the file's object
    ``plan`` was read from, that it stands for (the two walked side by side)."""
    shared = data.get("nodes") or {}
    out: dict[int, list[dict[str, Any]]] = {}
    seen: set[int] = set()
    stack: list[tuple[Any, Node]] = [(data["root"], plan.root)]
    while stack:
        raw, node = stack.pop()
        while "ref" in raw:
            raw = shared[raw["ref"]]
        if id(raw) in seen:
            continue
        seen.add(id(raw))
        if isinstance(node, Leaf):
            out.setdefault(id(node), []).append(raw)
        else:
            stack.extend(
                (b["next"], n.next) for b, n in zip(raw["branches"], node.branches, strict=True)
            )
    return out


def prune_results(data: Mapping[str, Any], plan: Plan, arrived: Mapping[int, set[Listed]]) -> None:
    """Each result object of ``data`` (the file's object of ``plan``, being made, every
    member searched) pruned in place to the entries that end there, ``arrived`` per result
    (:func:`_arrivals`): a controller may take any entry as the answer, so a result names
    only what ends there. A result nothing ends in keeps its entries (:func:`unsupported`)."""
    everyone = range(len(plan.parts))
    index = _member_index(plan)
    by_id = {id(leaf): leaf for leaf in plan.leaves()}
    for leaf, raws in file_results(data, plan).items():
        ends = arrived[leaf]
        if not ends:
            continue
        keep = [x in ends for x in _listed(index, by_id[leaf], everyone)]
        for raw in raws:
            raw["result"] = [e for e, k in zip(raw["result"], keep, strict=True) if k]


def _theta_into(normal_deg: float, step: Step, target: StableState) -> float:
    """A fence orientation inside the step's overlap range that settles in ``target``: the
    nominal one when it does, else the nearest point of the target's resting range."""
    assert step.action_deg is not None and step.margin_deg is not None
    nominal = rotation_after(normal_deg, step.action_deg)
    lo, hi = target.resting_range_deg
    mid = (lo + hi) / 2.0
    offset = norm360(nominal - mid + 180.0) - 180.0  # nominal relative to the range's middle
    half = (hi - lo) / 2.0
    if abs(offset) < half:
        return nominal
    inside = math.copysign(half - min(ANGLE_EPS_DEG, half / 2.0), offset)
    return norm360(mid + inside)


def _diameter_eps(plan: Plan) -> float:
    """How far a plan's diameters may lie from its hulls': they are as planned on, and the
    machine snaps those equal within ``DIAMETER_REL_EPS`` of the plan's largest part
    (``build_machine``), so a small part's may differ from its own hull's by that much."""
    return DIAMETER_REL_EPS * max(push_function_of(q).part.size for q in plan.parts) + 1e-12


def _state_problems(plan: Plan, p: int, eps_d: float) -> list[str]:
    """Differences between the plan's stable states and those its hull and COM give
    (diameters within ``eps_d``, :func:`_diameter_eps`)."""
    part = plan.parts[p]
    pf = push_function_of(part)
    listed = {s.id: s for s in part.states}
    if set(listed) != {s.id for s in pf.states}:
        return [
            f"part {part.label!r}: the plan lists stable states {sorted(listed)}, but its hull "
            f"and COM give {pf.n}"
        ]
    out = []
    for s in pf.states:
        f = listed[s.id]
        same = (
            f.edge == s.edge
            and angle_close(f.normal_deg, s.normal_deg, 1e-6)
            and angle_close(f.resting_range_deg[0], s.resting_range_deg[0], 1e-6)
            and angle_close(f.resting_range_deg[1], s.resting_range_deg[1], 1e-6)
            and abs(f.diameter - s.diameter) <= eps_d
            and angle_close(f.pose_deg, s.pose_deg, 1e-6)
        )
        if not same:
            out.append(
                f"part {part.label!r} state {s.id}: the plan says {_state_words(f)}, but its "
                f"hull and COM give {_state_words(s)}"
            )
    return out


def _state_words(s: StableState) -> str:
    """A stable state's listed figures, to the digits the comparison above tells apart."""
    lo, hi = s.resting_range_deg
    return (
        f"edge {s.edge}, normal {s.normal_deg:.9g} deg, resting range {lo:.9g}..{hi:.9g} deg, "
        f"diameter {s.diameter:.10g}, pose {s.pose_deg:.9g} deg"
    )


def _pose_problems(plan: Plan) -> list[str]:
    """Result entries whose pose is not the pose of the state they name."""
    poses = {(*p.key, s.id): s.pose_deg for p in plan.parts for s in p.states}
    out = []
    for leaf in plan.leaves():
        for e in leaf.results:
            want = poses[(e.part, e.landing, e.state)]
            if not angle_close(e.pose_deg, want, 1e-6):
                out.append(
                    f"a result gives {member_label(e.part, e.landing)} state {e.state} the "
                    f"pose {e.pose_deg:.6g} deg, but that state's pose is {want:.6g} deg"
                )
    return out


def reject_problems(plan: Plan) -> list[str]:
    """Members (part and landing) listed both in a reject leaf and in an accept leaf: a
    rejected landing must never reach an accept leaf, nor an accepted one be rejected
    (design.md, "Landings")."""
    rejected: dict[tuple[str, str | None], None] = {}
    accepted: set[tuple[str, str | None]] = set()
    for leaf in plan.leaves():
        for e in leaf.results:
            if leaf.reject:
                rejected.setdefault(e.key)
            else:
                accepted.add(e.key)
    return [
        f"{member_label(*key)} is listed in a reject result and in an accept result: a "
        "landing the next station cannot take must never reach an accept result"
        for key in rejected
        if key in accepted
    ]


EXPECTED_REL_TOL = 1e-6
"""The stated expected length must be the computed one within this fraction."""


def _branch_probabilities(sensor: Sensor, step: Step, diameter: float) -> list[tuple[int, float]]:
    """``(branch index, probability)`` of each branch of ``step`` a state of this diameter
    follows with a positive probability, in order: the controller takes the first branch
    holding the reading (design.md), so a reading on a shared endpoint (a positive
    probability only for an LED array's counts) counts once. Only the branches within the
    sensor's reach are looked at: a step may have thousands."""
    if not sensor.informative:
        return [(0, 1.0)]
    if _discrete(sensor, diameter):
        out: dict[int, float] = {}
        for r in sorted(set(sensor.probe_readings(diameter, 0.0))):
            k = step.follow(r)
            if k is not None:
                out[k] = out.get(k, 0.0) + sensor.reading_probability(diameter, r, r)
        return [(k, pr) for k, pr in sorted(out.items()) if pr > 0.0]
    reach = sensor.branch_reach(diameter)
    near = range(len(step.branches)) if reach is None else step.meeting(*reach)
    shares = []
    for k in near:
        b = step.branches[k]
        if b.reading is not None:
            pr = sensor.reading_probability(diameter, *b.reading)
            if pr > 0.0:
                shares.append((k, pr))
    return shares


Item = TypeVar("Item")
"""A (step, state) of an expected walk, in whatever form its caller keeps it."""


def expected_walk(
    start: Item,
    continuations: Callable[[Item], Iterable[tuple[float, Item]]],
    key: Callable[[Item], Hashable],
    memo: dict[Hashable, float],
) -> float:
    """The expected number of operations from ``start`` on (itself counted): one, plus each
    continuation's (probability, next step) expectation, over a plan's steps and states
    (acyclic: a DAG of shared subplans), memoised in ``memo`` by ``key``, without recursion.
    ``continuations`` lists only those that go on to another step (a result ends the run).

    >>> chain = {"a": [(0.5, "b")], "b": []}
    >>> expected_walk("a", chain.__getitem__, str, {})
    1.5
    """
    open_steps: dict[Hashable, list[tuple[float, Hashable]]] = {}
    stack = [start]
    while stack:
        item = stack[-1]
        k = key(item)
        if k in memo:
            stack.pop()
            continue
        # Back at a step, its continuations are done: those pushed above it were popped
        # only once memoised (the plan is acyclic).
        steps = open_steps.pop(k, None)
        if steps is None:
            steps, todo = [], []
            for pr, nxt in continuations(item):
                nk = key(nxt)
                steps.append((pr, nk))
                if nk not in memo:
                    todo.append(nxt)
            if todo:
                open_steps[k] = steps
                stack.extend(todo)
                continue
        memo[k] = 1.0 + math.fsum(pr * memo[nk] for pr, nk in steps)
        stack.pop()
    return memo[key(start)]


def expected_operations(plan: Plan) -> float:
    """The expected number of operations of a plan on the kinematic model (the first
    alignment counted): the start uniform on the circle (a state weighs its resting range
    over 360), each member weighted by its normalised share (:meth:`Plan.shares`), a
    rotation by the step's ``action_deg``, and each branch followed with the probability
    that the state's reading falls in it (the sensor model, section 5). Memoised per
    (node, state), without recursion (:func:`expected_walk`)."""
    total = 0.0
    for p, share in enumerate(plan.shares()):
        pf = push_function_of(plan.parts[p])
        listed = {s.id: s.diameter for s in plan.parts[p].states}
        continuations = _continuations(plan.sensor, pf, listed)
        memo: dict[Hashable, float] = {}
        for s0 in pf.states:
            e = expected_walk((plan.root, s0), continuations, _step_key, memo)
            lo, hi = s0.resting_range_deg
            total += share * (hi - lo) / 360.0 * e
    return total


def _continuations(
    sensor: Sensor, pf: PushFunction, listed: Mapping[int, float]
) -> Callable[[tuple[Step, StableState]], list[tuple[float, tuple[Step, StableState]]]]:
    """The continuations of a (step, state) of part ``pf`` that go on to another step: each
    branch's probability (the state read at its ``listed`` diameter) and the next step with
    the state its rotation leaves."""
    by_id = {s.id: s for s in pf.states}

    def continuations(at: tuple[Step, StableState]) -> list[tuple[float, tuple[Step, StableState]]]:
        node, state = at
        d = listed.get(state.id, state.diameter)
        out = []
        for k, pr in _branch_probabilities(sensor, node, d):
            nxt = node.branches[k].next
            if isinstance(nxt, Step):
                assert nxt.action_deg is not None
                turned = rotation_after(state.normal_deg, nxt.action_deg)
                out.append((pr, (nxt, by_id[push(pf, turned).id])))
        return out

    return continuations


def _step_key(at: tuple[Step, StableState]) -> tuple[int, int]:
    """A (step, state) of the expected walk, by the step's identity and the state's id."""
    return id(at[0]), at[1].id


def expected_problems(plan: Plan, expected: float) -> list[str]:
    """The stated expected length against ``expected``, the computed one."""
    stated = plan.stats.expected_length
    if abs(stated - expected) <= EXPECTED_REL_TOL * max(1.0, expected):
        return []
    weights = "each part's share" if plan.parts[0].share is not None else "equal part shares"
    return [
        f"the plan's expected length is {stated:.10g}, but with the start uniform and "
        f"{weights} it is {expected:.10g}"
    ]


def verify_plan(
    plan: Plan | Mapping[str, Any],
    part_indices: Sequence[int] | None = None,
    *,
    prune: bool = False,
) -> VerificationReport:
    """Follow the plan on the kinematic model: every start, reading and rotation (see the
    module).

    ``part_indices`` restricts the check to some of the plan's parts (default: all); the
    plan's stated length is checked against its tree when it is made (plan_from_dict), so
    it holds either way. ``prune`` (a plan being made, given as its file's object, every
    part checked): each result of the object is pruned to what ends there
    (:func:`prune_results`) before its entries are judged. Raises InputError when the plan
    is structurally broken.
    """
    data = plan if prune and part_indices is None and not isinstance(plan, Plan) else None
    plan = as_plan(plan)
    indices = range(len(plan.parts)) if part_indices is None else part_indices
    problems = _pose_problems(plan) + reject_problems(plan)
    checks, failures = [], []
    length = plan.stats.length
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old, 4 * length + 200))  # the search recurses once per operation
    eps_d = _diameter_eps(plan)
    searches: dict[int, _PartSearch] = {}
    try:
        for p in indices:
            problems += _state_problems(plan, p, eps_d)
            search = searches[p] = _PartSearch(plan, p)
            check, failed = search.run()
            if check.worst_operations > length:
                problems.append(
                    f"part {check.part!r}: a run takes "
                    f"{plural(check.worst_operations, 'operation')}, "
                    f"but the plan's length is {length}"
                )
            checks.append(check)
            failures += failed
    finally:
        sys.setrecursionlimit(old)
    if not failures and plan.uncertainty.is_ideal:
        # A strong plan's results name physical resting states, each with all its ideal
        # members, some of which no kinematic path reaches: its own verifier checks its
        # entries (plans/strong.py).
        arrived = _arrivals(plan, searches)
        if data is None:
            problems += entry_problems(plan, searches, arrived)
        else:
            # Pruned to exactly what ends there, the file's results hold no entry to refuse.
            prune_results(data, plan, arrived)
    longest = max(c.worst_operations for c in checks)
    if part_indices is None and not failures and longest < length:
        # every node is reachable (its states are images of every start), so some path is as
        # long as the tree: a shorter longest path means a branch no part can reach
        problems.append(f"the plan's length is {length}, but no path takes more than {longest}")
    if not failures and not problems and plan.uncertainty.is_ideal:
        # A strong plan's expected length is over its physical states (plans/strong.py checks
        # it); replayed here on the kinematic model it differs, and that is no error.
        problems += expected_problems(plan, expected_operations(plan))
    return VerificationReport(tuple(checks), tuple(failures), tuple(problems))


def check_plan(plan: Plan | Mapping[str, Any], *, prune: bool = False) -> VerificationReport:
    """Verify a plan (``prune``: as :func:`verify_plan`); a failure raises CheckFailed with
    the first counterexample in one line."""
    report = verify_plan(plan, prune=prune)
    if not report.ok:
        raise CheckFailed(f"the plan failed verification: {report.first_problem()}")
    return report


def verify_declared(
    plan: Plan | Mapping[str, Any], part_indices: Sequence[int] | None = None
) -> VerificationReport:
    """Verify a plan at the uncertainty it declares: the one check every consumer calls.

    A plan declaring the ideal model (or a version-1 file declaring none) is followed on the
    kinematic model (:func:`verify_plan`); any other is a strong plan (design.md,
    "Uncertainty"), checked for every outcome the declared uncertainty allows and every
    reading (:func:`feederkit.plans.strong.verify_strong`), together with the file's own
    consistency (listed states and poses against the hulls and COMs), its margins (both
    verifiers: the ideal one follows the whole overlap range) and, for either, its
    certificate (:func:`~feederkit.plans.strong.certificate_problems`): a margin or
    certificate larger than the plan keeps is a false promise to the controller. A failure
    is in the report (``ok`` False, ``first_problem``), not raised; structural breakage is
    InputError.
    """
    plan = as_plan(plan)
    old = sys.getrecursionlimit()
    # The strong checks recurse a few frames per operation (``_Run.handles``, ``_Run.walk``).
    sys.setrecursionlimit(max(old, 8 * plan.stats.length + 200))
    try:
        return _verify_declared(plan, part_indices)
    finally:
        sys.setrecursionlimit(old)


def _verify_declared(plan: Plan, part_indices: Sequence[int] | None) -> VerificationReport:
    """:func:`verify_declared` with room to recurse."""
    from feederkit.plans.fileformat import plan_to_dict
    from feederkit.plans.strong import certificate_problems, verify_strong

    if plan.uncertainty.is_ideal:
        report = verify_plan(plan, part_indices)
        if not report.ok or plan.stats.certificate is None:
            return report
        claims = tuple(certificate_problems(plan_to_dict(plan)))
        return replace(report, problems=report.problems + claims)
    data = plan_to_dict(plan)
    indices = range(len(plan.parts)) if part_indices is None else part_indices
    problems = _pose_problems(plan) + reject_problems(plan)
    eps_d = _diameter_eps(plan)
    for p in indices:
        problems += _state_problems(plan, p, eps_d)
    names = {plan.parts[p].key for p in indices}
    try:
        strong = verify_strong(data)
    except CheckFailed as exc:
        unc = plan.uncertainty_words()
        problems.append(f"at the declared uncertainty ({unc}): {exc}")
        # The strong check stops at the first failing path: no per-part counts to report.
        return VerificationReport((), (), tuple(problems))
    if not problems:
        # The claim beyond the paths and margins (verify_strong checks those): the certificate.
        problems += certificate_problems(data)
    checks = tuple(c for c in strong.parts if (c.part, c.landing) in names)
    return VerificationReport(checks, (), tuple(problems))


def check_declared(plan: Plan | Mapping[str, Any]) -> VerificationReport:
    """:func:`verify_declared`; a failure raises CheckFailed with the first problem."""
    report = verify_declared(plan)
    if not report.ok:
        raise CheckFailed(f"the plan failed verification: {report.first_problem()}")
    return report
