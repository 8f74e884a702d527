"""Verification and certificate of strong plans (design.md, "Uncertainty"; docs/planning.md).

A strong plan must reach its result for every outcome the declared uncertainty allows and
every reading the sensor can give. :func:`verify_strong` checks a plan file on mechanics
rebuilt from the file alone (each part's hull and COM, the declared ``uncertainty``), never
from the machine the planner used: every start physical state runs through the plan; at an
action every outcome of :func:`~feederkit.mechanics.outcomes.outcome_set` is followed; at a
node every branch whose closed reading interval the state's reading set meets is followed,
and a reading that no branch holds is a failure (interval arithmetic over the branches' ends,
:meth:`~feederkit.sensors.Sensor.uncovered_reading`, not sampling). Every path must end in a
leaf naming its state (all its ideal member states, for that part and landing); the worst
path must take exactly the stated length; no landing may be listed both in a reject leaf and
in an accept leaf; and the stated expected length must be the one of the uncertain model
(:func:`expected_operations`: a rotation's outcomes shared equally, the members weighted by
their shares). The plan's tree may be a DAG (shared subplans, ``"nodes"``): every check is
memoised per (node, state), so it costs the distinct nodes, not the paths.

:func:`certificate` computes what the plan guarantees beyond the declared uncertainty: per
action node the largest rotation error keeping every outcome of every state that reaches
the node within the states its subtree handles (``max_rotation_error``; the plan's value is
the minimum), and the largest shape tolerance under which the plan still verifies (a
bisection re-verifying the plan).

:func:`ideal_view` writes a strong plan over the parts' ideal stable states, so the plan
file names a physical state by its ideal members (docs/planning.md, "Results").
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Hashable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from feederkit.errors import CheckFailed, InputError
from feederkit.machine import PushAlignMachine, members
from feederkit.machine.build import snap_intervals
from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.certificates import max_rotation_error
from feederkit.mechanics.outcomes import outcome_set
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.planning.budget import Deadline
from feederkit.planning.reindex import map_masks
from feederkit.planning.tree import PlanResult, Step
from feederkit.plans.execute import rounding_inset
from feederkit.plans.fileformat import member_keys, result_nodes
from feederkit.plans.model import PlanPart, member_label, names_several, push_function_of
from feederkit.plans.verify import (
    PartCheck,
    VerificationReport,
    expected_walk,
    unsupported,
    unsupported_words,
)
from feederkit.sensors import Sensor, sensor_from_dict
from feederkit.uncertainty import IDEAL, Uncertainty
from feederkit.uncertainty import max_shape_tolerance as shape_tolerance_limit
from feederkit.words import plural

MAX_ROTATION_ERROR_DEG = 90.0
"""The certificate of a plan with no rotation: every error design.md allows (below 90)."""

MARGIN_TOL_DEG = 1e-6
"""A margin or certificate is checked this far inside what it claims (deg): the planner's
ranges end exactly on cell boundaries, which rebuilding the mechanics from the file
reproduces to about 1e-9."""


SHAPE_REL_TOL = 1e-3
"""The shape-tolerance certificate's bisection stops at this fraction of its bound."""

State = tuple[int, int]
"""A physical state of the plan: (part index, physical state id)."""

ReadBranch = tuple[Sequence[float], Mapping[str, Any]]
"""A branch of a plan node: its reading interval and its next node (a reference resolved)."""

Tally = tuple[int, int, int, int]
"""From a (node, state) on: the worst operations, the paths, those ending in a reject and
those ending in an unrecognized result."""


@dataclass(frozen=True)
class StrongModel:
    """The parts of a plan file with their mechanics under one uncertainty.

    ``diameters[p][s]``: physical state ``s``'s diameter interval, endpoints snapped outward across
    the parts as the machine snaps them (so exact ties survive rounding).
    """

    names: tuple[str, ...]
    mechanics: tuple[UncertainMechanics, ...]
    diameters: tuple[tuple[tuple[float, float], ...], ...]
    sensor: Sensor
    landings: tuple[str | None, ...] = ()

    @property
    def members(self) -> tuple[tuple[str, str | None], ...]:
        """Each part's ``(name, landing)``, as result entries name it."""
        landings = self.landings or (None,) * len(self.names)
        return tuple(zip(self.names, landings, strict=True))

    def label(self, p: int) -> str:
        """Part ``p`` in words: ``NAME`` or ``NAME (LANDING)``."""
        return member_label(*self.members[p])

    def states(self) -> Iterator[State]:
        """Every physical state of every part."""
        for p, mech in enumerate(self.mechanics):
            for s in mech.states:
                yield (p, s.id)


def _parts(plan: Mapping[str, Any], deadline: Deadline | None = None) -> list[PushFunction]:
    out = []
    for part in plan["parts"]:
        if deadline is not None:
            deadline.check()
        pp = PlanPart(
            name=part["name"],
            revision=part.get("revision"),
            com=tuple(part["com"]),
            hull=tuple(tuple(v) for v in part["hull"]),
            states=(),
        )
        out.append(push_function_of(pp))
    return out


def declared_uncertainty(plan: Mapping[str, Any]) -> Uncertainty:
    """The plan file's declared uncertainty (the ideal model when the file has none: a plan
    written before uncertainty was declared)."""
    data = plan.get("uncertainty")
    return IDEAL if data is None else Uncertainty.from_dict(data)


def strong_model(
    plan: Mapping[str, Any],
    uncertainty: Uncertainty | None = None,
    *,
    vibration_mm: float | None = None,
    parts: Sequence[PushFunction] | None = None,
    vibrating: bool = False,
    deadline: Deadline | None = None,
) -> StrongModel:
    """The plan's parts rebuilt from its hulls and COMs, with their mechanics.

    ``uncertainty`` defaults to the declared one; ``vibration_mm`` to the mechanics' own
    rule, except that a plan declared on the ideal model keeps vibration off (the model it
    was verified on) unless ``vibrating``: the feeder's vibration whatever the declared
    uncertainty, as the planner's model has it under any rotation error (fragile states
    merged, a push band at each hilltop). A certificate speaks of that feeder.
    """
    declared = declared_uncertainty(plan)
    unc = declared if uncertainty is None else uncertainty
    if vibration_mm is None and declared.is_ideal and not vibrating:
        vibration_mm = 0.0
    pfs = list(parts) if parts is not None else _parts(plan, deadline)

    def vibration(pf: PushFunction) -> float | None:
        if vibration_mm is None and vibrating:
            return FRAGILE_BARRIER_REL * pf.part.size  # the mechanics' rule off the ideal
        return vibration_mm

    def mechanics(pf: PushFunction) -> UncertainMechanics:
        if deadline is not None:
            deadline.check()  # a mix's parts take a while: a certificate stops between them
        return uncertain_mechanics(pf.part, unc, vibration_mm=vibration(pf))

    mechs = tuple(mechanics(pf) for pf in pfs)
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in pfs)
    # The same outward-snapped intervals the machine's states read in (machine.build).
    ends = snap_intervals([s.diameter for m in mechs for s in m.states], eps)
    diam: list[tuple[tuple[float, float], ...]] = []
    k = 0
    for m in mechs:
        row = []
        for _ in m.states:
            row.append(ends[k])
            k += 1
        diam.append(tuple(row))
    return StrongModel(
        tuple(part["name"] for part in plan["parts"]),
        mechs,
        tuple(diam),
        sensor_from_dict(plan["sensor"]),
        tuple(part.get("landing") for part in plan["parts"]),
    )


class _Run:
    """Every path of every start through one plan, memoised per (node, state).

    Each node's branches are indexed by their reading intervals once, their next nodes
    resolved, so a state's branches are found by bisection (a node of a large mix has
    hundreds of branches and a state reads into a few); a state's outcomes are memoised per
    rotation (nodes share rotations), its branches per (node, state), and the walk's tally
    (:meth:`walk`) per (node, state), so the length, the handled states, the expected length
    and the rotation certificate ask each once.
    """

    def __init__(
        self,
        plan: Mapping[str, Any],
        model: StrongModel,
        margins: bool = False,
        tighten: bool = False,
        deadline: Deadline | None = None,
    ) -> None:
        self.model = model
        self.deadline = deadline
        self.margins = margins
        self.tighten = tighten
        self.lowered = 0  # margins lowered to what their rotation keeps (``tighten``)
        self.shared = plan.get("nodes") or {}
        self.by_name = member_keys(model.members)
        # Per (node, state): (worst operations, paths, paths to a reject, paths to an
        # unrecognized result), from the node on.
        self.tally: dict[tuple[int, State], Tally] = {}
        self._handles: dict[tuple[int, State], bool] = {}
        self.arrivals: dict[int, set[tuple[int, int]]] = {}  # leaf id: (part, ideal state)
        self._outcomes: dict[tuple[float, State], list[State]] = {}
        self._follow: dict[tuple[int, State], list[Mapping[str, Any]] | float] = {}
        self._index: dict[int, _BranchIndex] = {}
        # The ideal verifier's rounding policy: touching open ends do not overlap.
        self._sensors = [
            model.sensor.narrowed(rounding_inset(m.part.size)) for m in model.mechanics
        ]

    def node(self, node: Mapping[str, Any]) -> Mapping[str, Any]:
        """A node with a shared-subplan reference resolved."""
        seen = 0
        while "ref" in node:
            ref = node["ref"]
            if ref not in self.shared or seen > len(self.shared):
                raise InputError(f"the plan refers to an unknown shared subplan {ref!r}")
            node = self.shared[ref]
            seen += 1
        return node

    def outcomes(self, node: Mapping[str, Any], x: State) -> list[State]:
        """Where state ``x`` can rest after the node's rotation (itself at the root)."""
        a = node.get("action_deg")
        if a is None:
            return [x]
        key = (a, x)  # the rotation's, not the node's: many nodes share a rotation
        hit = self._outcomes.get(key)
        if hit is None:
            p, s = x
            hit = [(p, t) for t in sorted(outcome_set(self.model.mechanics[p], s, float(a)))]
            self._outcomes[key] = hit
        return hit

    def _check_margin(self, node: Mapping[str, Any], x: State, base: frozenset[int]) -> None:
        """CheckFailed when the node's ``margin_deg`` overstates what its rotation keeps for
        state ``x``: a strong plan's margin is slack beyond the declared rotation error r
        (docs/plans.md), so every rotation within ``action ± margin`` gives the state the same
        outcome set and an error up to ``r + margin`` keeps its outcomes within ``base``, its
        set at r (checked ``MARGIN_TOL_DEG`` inside)."""
        m = node.get("margin_deg")
        if m is None:
            return
        p, s = x
        mech = self.model.mechanics[p]
        a, r = float(node["action_deg"]), mech.uncertainty.rotation_error_deg
        wide = outcome_set(mech, s, a, r + float(m) - MARGIN_TOL_DEG)
        if wide <= base:
            return
        keeps = max(max_rotation_error(mech, [s], a) - r, 0.0)
        if self.tighten:
            # A plan being made: its margin is what the rotation keeps for every state that
            # reaches the node (a lower margin only eases the states checked before).
            node["margin_deg"] = min(float(m), keeps)  # type: ignore[index]
            self.lowered += 1
            return
        raise CheckFailed(
            f"the margin ±{m:.6g}° of the rotation {a:.6g}° is more than it keeps "
            f"(±{keeps:.6g}° beyond the declared ±{r:g}°): with a rotation error of "
            f"±{r + m:.6g}° {self.model.label(p)} in physical state {s} can end in "
            f"{sorted(wide - base)} besides {sorted(base)}"
        )

    def branch_index(self, node: Mapping[str, Any]) -> _BranchIndex:
        """The node's branches indexed by reading, their next nodes resolved."""
        index = self._index.get(id(node))
        if index is None:
            index = self._index[id(node)] = _BranchIndex(node["branches"], self.node)
        return index

    def branches_of(
        self, node: Mapping[str, Any], x: State, sensor: Sensor | None = None
    ) -> list[ReadBranch] | None:
        """The node's branches a resting state ``x`` may read into under ``sensor`` (default:
        the verifier's, narrowed by rounding), in the node's order, as (reading interval,
        next node resolved): a superset, those whose interval comes within the sensor's
        reach of the state's reading set. None when the node has no readings (every branch
        is followed)."""
        index = self.branch_index(node)
        if index.blind or not self.model.sensor.informative:
            return None
        p, s = x
        sensor = self._sensors[p] if sensor is None else sensor
        reach = sensor.branch_reach(self.model.diameters[p][s])
        if reach is None:
            return index.with_reading
        return index.within(*reach)

    def follows(self, node: Mapping[str, Any], x: State) -> list[Mapping[str, Any]] | None:
        """:meth:`follow`, None where it fails."""
        hit = self._followed(node, x)
        return None if isinstance(hit, float) else hit

    def follow(self, node: Mapping[str, Any], x: State) -> list[Mapping[str, Any]]:
        """The branches resting state ``x`` can follow; CheckFailed when a reading it can
        give is in none."""
        hit = self._followed(node, x)
        if isinstance(hit, float):
            p, s = x
            diam = self.model.diameters[p][s]
            action = node.get("action_deg")
            after = "the first alignment" if action is None else f"rotation {action:.6g}°"
            raise CheckFailed(
                f"{self.model.label(p)}: physical state {s} (diameter {diam[0]:.6g} to "
                f"{diam[1]:.6g} mm) can read {hit:.6g} mm, which no branch after {after} holds"
            )
        return hit

    def _followed(self, node: Mapping[str, Any], x: State) -> list[Mapping[str, Any]] | float:
        """:meth:`follow` memoised per (node, state): the next nodes, or a reading no branch
        holds."""
        key = (id(node), x)
        hit = self._follow.get(key)
        if hit is None:
            hit = self._follow[key] = self._follow_uncached(node, x)
        return hit

    def _follow_uncached(
        self, node: Mapping[str, Any], x: State
    ) -> list[Mapping[str, Any]] | float:
        """:meth:`follow` computed: the next nodes, or a reading no branch holds."""
        near = self.branches_of(node, x)
        if near is None:
            return self.branch_index(node).nexts
        p, s = x
        diam = self.model.diameters[p][s]
        sensor = self._sensors[p]
        # Branches out of reach hold none of the state's readings: leaving them out changes
        # neither the uncovered reading found nor the branches followed.
        miss = sensor.uncovered_reading(diam, [r for r, _n in near])
        if miss is not None:
            return float(miss)
        return [n for r, n in near if sensor.reads_into(diam, *r)]

    def named(self, leaf: Mapping[str, Any], x: State) -> bool:
        """Whether a leaf names state ``x``: every ideal member of it, for its part and
        landing."""
        p, s = x
        listed = {
            e["state"]
            for e in leaf["result"]
            if self.by_name.get((e["part"], e.get("landing"))) == p
        }
        return set(self.model.mechanics[p].states[s].members) <= listed

    def walk(self, node: Mapping[str, Any], x: State) -> Tally:
        """(worst operations, paths, paths to a reject, paths to an unrecognized result)
        from ``node`` on for a part resting in ``x`` before it; CheckFailed on the first path
        that fails. The followed nodes come resolved (:meth:`follow`), and a memoised
        (node, state) is read without a call: most pairs are met on several paths."""
        node = self.node(node)
        key = (id(node), x)
        tally = self.tally
        hit = tally.get(key)
        if hit is not None:
            return hit
        if "result" in node:
            if not self.named(node, x):
                p, s = x
                ideal = list(self.model.mechanics[p].states[s].members)
                raise CheckFailed(
                    f"{self.model.label(p)}: a path ends in a result that does not name its "
                    f"physical state {s} (ideal states {ideal})"
                )
            reject = node.get("reject") is True
            members = ((e["part"], e.get("landing")) for e in node["result"])
            hit = (0, 1, 1 if reject else 0, 1 if names_several(members, reject) else 0)
            p, s = x
            self.arrivals.setdefault(id(node), set()).update(
                (p, m) for m in self.model.mechanics[p].states[s].members
            )
        else:
            if self.margins:
                # On the verified paths only: the expected walk also follows branches a
                # reading meets within rounding (probability ~1e-16), where no margin is
                # claimed.
                self._check_margin(node, x, frozenset(t for _p, t in self.outcomes(node, x)))
            longest, paths, rejected, unrecognized = 0, 0, 0, 0
            for y in self.outcomes(node, x):
                for nxt in self.follow(node, y):
                    sub = tally.get((id(nxt), y)) or self.walk(nxt, y)
                    if sub[0] > longest:
                        longest = sub[0]
                    paths += sub[1]
                    rejected += sub[2]
                    unrecognized += sub[3]
            hit = (1 + longest, paths, rejected, unrecognized)
        tally[key] = hit
        return hit

    def results(self, root: Mapping[str, Any]) -> list[Mapping[str, Any]]:
        """Every distinct result node, references resolved."""
        out, seen, stack = [], set(), [root]
        while stack:
            node = self.node(stack.pop())
            if id(node) in seen:
                continue
            seen.add(id(node))
            if "result" in node:
                out.append(node)
            else:
                stack.extend(b["next"] for b in node["branches"])
        return out

    def listed(self, node: Mapping[str, Any]) -> list[tuple[int, int]]:
        """A result's entries as (part, ideal state) pairs."""
        return [(self.by_name[(e["part"], e.get("landing"))], e["state"]) for e in node["result"]]

    def prune(self, root: Mapping[str, Any]) -> None:
        """Each result node pruned in place to the entries that end there (a plan being
        made: a controller may take any entry as the answer, so a result names only what
        ends there); a result nothing ends in keeps its entries
        (:func:`~feederkit.plans.verify.unsupported`)."""
        for node in self.results(root):
            ends = self.arrivals.get(id(node))
            if ends:
                keep = [x in ends for x in self.listed(node)]
                entries = node["result"]
                node["result"] = [e for e, k in zip(entries, keep, strict=True) if k]  # type: ignore[index]

    def unreached(self, root: Mapping[str, Any]) -> str | None:
        """The first result entry nothing supports there (None: none): a state that no
        start, outcome or reading ends in there and that looks like none of its member's
        that does, or of a part or landing none of whose states ends there
        (:func:`~feederkit.plans.verify.unsupported`)."""
        pfs = [m.push for m in self.model.mechanics]
        for node in self.results(root):
            ends = self.arrivals.get(id(node), set())
            bad = unsupported(pfs, self.listed(node), ends)
            if bad:
                p, s = bad[0]
                there = any(q == p for q, _s in ends)
                return unsupported_words(self.model.label(p), s, there)
        return None

    def handles(self, node: Mapping[str, Any], x: State) -> bool:
        """Whether every path of ``x`` from ``node`` on ends in a leaf naming its state."""
        node = self.node(node)
        key = (id(node), x)
        hit = self._handles.get(key)
        if hit is None:
            if self.deadline is not None:
                self.deadline.check()  # once per (node, state) pair: the walk's work
            if "result" in node:
                hit = self.named(node, x)
            else:
                hit = all(self.settles(node, y) for y in self.outcomes(node, x))
            self._handles[key] = hit
        return hit

    def settles(self, node: Mapping[str, Any], y: State) -> bool:
        """Whether a part resting in ``y`` after ``node``'s rotation is handled from there."""
        nexts = self.follows(node, y)
        return bool(nexts) and all(self.handles(n, y) for n in nexts)


class _BranchIndex:
    """A node's branches with a reading, sorted by interval, for :meth:`_Run.branches_of`.

    Exact reading cells (and the components rule's intervals) come in reading order with
    both ends ascending; then the branches meeting ``[lo, hi]`` are one run found by
    bisection. Otherwise (a hand-written file) every branch is a candidate.
    """

    def __init__(
        self,
        branches: Sequence[Mapping[str, Any]],
        resolve: Callable[[Mapping[str, Any]], Mapping[str, Any]],
    ) -> None:
        self.nexts = [resolve(b["next"]) for b in branches]  # every branch's, in order
        with_reading = [
            (b["reading"], n)
            for b, n in zip(branches, self.nexts, strict=True)
            if b["reading"] is not None
        ]
        self.blind = not with_reading
        self.with_reading = with_reading
        ends = [(float(r[0]), float(r[1])) for r, _n in with_reading]
        self._los = [a for a, _b in ends]
        self._his = [b for _a, b in ends]
        self._sorted = all(
            a0 <= a1 and b0 <= b1 for (a0, b0), (a1, b1) in zip(ends, ends[1:], strict=False)
        )

    def within(self, lo: float, hi: float) -> list[ReadBranch]:
        """The branches whose interval meets ``[lo, hi]`` (all of them when unsorted)."""
        if not self._sorted:
            return self.with_reading
        first = bisect.bisect_left(self._his, lo)  # the first whose upper end reaches lo
        last = bisect.bisect_right(self._los, hi)  # past the last that starts by hi
        return self.with_reading[first:last]


def verify_strong(
    plan: Mapping[str, Any],
    uncertainty: Uncertainty | None = None,
    *,
    vibration_mm: float | None = None,
    parts: Sequence[PushFunction] | None = None,
    tighten_margins: bool = False,
    restate_expected: bool = False,
    prune: bool = False,
) -> VerificationReport:
    """Execute every start, outcome and reading branch of ``plan`` on rebuilt mechanics.

    ``uncertainty`` defaults to the plan's declared one (another value re-verifies the plan
    under it). At the declared uncertainty every action's margin is checked as well, per
    (node, state) as the paths are followed (``_Run._check_margin``). Returns the report (per
    part: starts, paths, the worst operations); raises CheckFailed with the first failing
    path or margin, or when the worst path's length differs from the stated one.
    ``tighten_margins`` (a plan being made, not yet written): a margin larger than what its
    rotation keeps for some state that reaches the node is lowered to that, in ``plan``
    itself, with ``stats.min_margin_deg``: a safety net, since the planner's margin is over
    the states its own model puts at the node. Margins are checked on the verified paths
    only; the expected-length walk also follows branches a reading meets within rounding (a
    touching end at a critical tolerance, probability ~1e-16), where nothing is claimed.
    ``restate_expected`` (a plan made on wider reading sets than its file's model, the parts'
    own widths: ``machine.widths``): ``stats.expected_length`` is set to the file model's
    figure rather than checked against it. ``prune`` (a plan being made): each result is
    pruned in place to what ends there (:meth:`_Run.prune`) before its entries are judged.
    """
    model = strong_model(plan, uncertainty, vibration_mm=vibration_mm, parts=parts)
    # The margins are claims at the declared uncertainty (the ideal verifier follows them).
    margins = uncertainty is None and not declared_uncertainty(plan).is_ideal
    run = _Run(plan, model, margins, tighten=tighten_margins)
    root = plan["root"]
    checks = []
    overall = 0
    for p, (name, landing) in enumerate(model.members):
        worst, paths, rejected, unrecognized = 0, 0, 0, 0
        states = [x for x in model.states() if x[0] == p]
        for x in states:
            w, n, r, u = run.walk(root, x)
            worst = max(worst, w)
            paths += n
            rejected += r
            unrecognized += u
        overall = max(overall, worst)
        checks.append(
            PartCheck(name, len(states), paths, worst, 0, landing, rejected, unrecognized)
        )
    if prune:
        run.prune(root)
    spurious = run.unreached(root) if uncertainty is None else None
    if spurious is not None:
        raise CheckFailed(spurious)
    stated = plan["stats"]["length"]
    if overall != stated:
        raise CheckFailed(
            f"the plan's length is {stated}, but its worst path under the declared uncertainty "
            f"takes {plural(overall, 'operation')}"
        )
    if run.lowered:
        plan["stats"]["min_margin_deg"] = min(  # type: ignore[index]
            float(n["margin_deg"]) for n in action_nodes(plan)
        )
    clash = reject_clash(plan)
    if clash is not None:
        raise CheckFailed(
            f"{member_label(*clash)} is listed in a reject result and in an accept result: a "
            "landing the next station cannot take must never reach an accept result"
        )
    if uncertainty is None:
        pfs = list(parts) if parts is not None else _parts(plan)
        expected = expected_operations(plan, model, pfs, run)
        if restate_expected:
            plan["stats"]["expected_length"] = expected  # type: ignore[index]
        given = plan["stats"]["expected_length"]
        if abs(given - expected) > EXPECTED_REL_TOL * max(1.0, expected):
            raise CheckFailed(
                f"the plan's expected length is {given:.10g}, but under the declared "
                f"uncertainty (outcomes shared equally, the parts weighted by their shares) "
                f"it is {expected:.10g}"
            )
    return VerificationReport(tuple(checks))


def action_nodes(plan: Mapping[str, Any]) -> list[Mapping[str, Any]]:
    """A plan file's distinct rotation nodes (shared subplans once), as objects of ``plan``
    (editing one edits the plan).

    >>> plan = {"root": {"action_deg": None, "margin_deg": None, "branches": [
    ...     {"reading": None, "next": {"ref": "n1"}}]},
    ...     "nodes": {"n1": {"action_deg": 90.0, "margin_deg": 5.0, "branches": [
    ...         {"reading": None, "next": {"result": []}}]}}}
    >>> [n["action_deg"] for n in action_nodes(plan)]
    [90.0]
    """
    shared = plan.get("nodes") or {}
    out, seen, todo = [], set(), [plan["root"]]
    while todo:
        node = todo.pop()
        while "ref" in node:
            node = shared[node["ref"]]
        if id(node) in seen or "result" in node:
            continue
        seen.add(id(node))
        if node.get("action_deg") is not None:
            out.append(node)
        todo.extend(b["next"] for b in node["branches"])
    return out


def reject_clash(plan: Mapping[str, Any]) -> tuple[str, str | None] | None:
    """A member (part, landing) listed both in a reject leaf and in an accept leaf (None:
    there is none); each distinct result node of the file once (:func:`result_nodes`)."""
    rejected: set[tuple[str, str | None]] = set()
    accepted: set[tuple[str, str | None]] = set()
    for node in result_nodes(plan):
        into = rejected if node.get("reject") is True else accepted
        into.update((e["part"], e.get("landing")) for e in node["result"])
    both = [m for m in rejected if m in accepted]
    return min(both, key=str) if both else None


EXPECTED_REL_TOL = 1e-6
"""The stated expected length must be the computed one within this fraction."""


def member_shares(plan: Mapping[str, Any]) -> list[float]:
    """Each part's prior share, normalised (equal when the file gives none)."""
    given = [part.get("share") for part in plan["parts"]]
    if any(x is None for x in given):
        return [1.0 / len(given)] * len(given)
    total = math.fsum(given)
    return [x / total for x in given]


def expected_operations(
    plan: Mapping[str, Any],
    model: StrongModel,
    parts: Sequence[PushFunction],
    run: _Run | None = None,
) -> float:
    """The expected number of operations of a strong plan on the uncertain model, as the
    planner defines it (docs/planning.md): a part starts in each physical state with the
    resting ranges of the ideal states a first alignment can end there (each shared equally
    among its destinations) times its member's share; a rotation by ``action_deg`` shares a
    state's mass equally among its outcome set; a branch keeps the probability that the
    state's reading falls in it. Memoised per (node, state), without recursion
    (:func:`~feederkit.plans.verify.expected_walk`); ``run``, a walk of the same plan and
    model (the verification's), lends its indexes and memos."""
    run = _Run(plan, model) if run is None else run
    sensor = model.sensor
    memo: dict[Hashable, float] = {}

    def continuations(
        at: tuple[Mapping[str, Any], State],
    ) -> list[tuple[float, tuple[Mapping[str, Any], State]]]:
        """(probability, (next step, state)) of every continuation of a state at a step
        that goes on to another step."""
        node, x = at
        outs = run.outcomes(node, x)
        out = []
        for y in outs:
            near = run.branches_of(node, y, sensor)
            if near is None:
                out.append((1.0 / len(outs), run.branch_index(node).nexts[0], y))
                continue
            diam = model.diameters[y[0]][y[1]]
            # A branch out of the state's reach has probability 0: leaving it out changes no
            # term of the (exactly rounded) sum.
            for reading, nxt in near:
                pr = sensor.reading_probability(diam, *reading)
                if pr > 0.0:
                    out.append((pr / len(outs), nxt, y))
        return [(pr, (n, y)) for pr, n, y in out if "result" not in n]

    def key(at: tuple[Mapping[str, Any], State]) -> tuple[int, State]:
        return id(at[0]), at[1]

    expected = 0.0
    shares = member_shares(plan)
    root = run.node(plan["root"])
    for p, (mech, pf) in enumerate(zip(model.mechanics, parts, strict=True)):
        widths = resting_widths(pf)
        weight = [0.0] * mech.n
        for i, dest in enumerate(mech.destinations):
            for t in dest:
                weight[t] += widths[i] / 360.0 / len(dest)
        for s in range(mech.n):
            e = expected_walk((root, (p, s)), continuations, key, memo)
            expected += shares[p] * weight[s] * e
    return expected


def strong_holds(
    plan: Mapping[str, Any],
    uncertainty: Uncertainty,
    *,
    vibration_mm: float | None = None,
    parts: Sequence[PushFunction] | None = None,
    vibrating: bool = False,
    deadline: Deadline | None = None,
) -> bool:
    """Whether every path of ``plan`` under ``uncertainty`` ends in a leaf naming its state
    (``vibrating``: as :func:`strong_model`). Timeout when ``deadline`` passes first (polled
    per part rebuilt and per (node, state) pair walked)."""
    try:
        model = strong_model(
            plan,
            uncertainty,
            vibration_mm=vibration_mm,
            parts=parts,
            vibrating=vibrating,
            deadline=deadline,
        )
    except InputError:
        return False
    run = _Run(plan, model, deadline=deadline)
    return all(run.handles(plan["root"], x) for x in model.states())


def max_rotation_error_deg(
    plan: Mapping[str, Any],
    *,
    parts: Sequence[PushFunction] | None = None,
    deadline: Deadline | None = None,
) -> float:
    """The largest rotation error (deg, a supremum) under which ``plan`` as written still
    succeeds: per action node, ``max_rotation_error`` over the states that reach it, allowed
    to end in the states its subtree handles; the minimum over the nodes.

    Each (node, state) pair is taken once, however many paths lead there: the states
    reaching a node are propagated down the plan's DAG, each node handling only the states
    new to it. Timeout when ``deadline`` passes first (a minimum over some nodes is no
    bound)."""
    deadline = deadline or Deadline()
    model = strong_model(plan, parts=parts, vibrating=True, deadline=deadline)
    run = _Run(plan, model, deadline=deadline)
    best = MAX_ROTATION_ERROR_DEG
    # Per (node, part): the part's states the node's subtree handles after its rotation.
    handled: dict[tuple[int, int], frozenset[int]] = {}
    for node, new in _reaching(plan, run, deadline):
        a = node.get("action_deg")
        if a is None:
            continue
        by_part: dict[int, list[int]] = {}
        for p, s in new:
            by_part.setdefault(p, []).append(s)
        for p, here in sorted(by_part.items()):
            mech = model.mechanics[p]
            allowed = handled.get((id(node), p))
            if allowed is None:
                allowed = frozenset(st.id for st in mech.states if run.settles(node, (p, st.id)))
                handled[(id(node), p)] = allowed
            here.sort()
            r = max_rotation_error(mech, here, float(a), dict.fromkeys(here, allowed))
            best = min(best, r)
    return best


def _reaching(
    plan: Mapping[str, Any], run: _Run, deadline: Deadline
) -> Iterator[tuple[Mapping[str, Any], set[State]]]:
    """Each operation node (not a result) with states that reach it before its rotation, each
    (node, state) pair once however many paths lead there: the states are propagated down
    the plan's DAG, a node handling only the states new to it (a node may come more than
    once, each time with new states). Polls ``deadline`` once per node taken."""
    root = run.node(plan["root"])
    nodes: dict[int, Mapping[str, Any]] = {id(root): root}
    reached: dict[int, set[State]] = {}
    pending: dict[int, set[State]] = {id(root): set(run.model.states())}
    work = [id(root)]
    while work:
        deadline.check()
        key = work.pop()
        new = pending.pop(key)
        node = nodes[key]
        if "result" in node:
            continue
        reached.setdefault(key, set()).update(new)
        yield node, new
        for y in {y for x in new for y in run.outcomes(node, x)}:
            for nxt in run.follows(node, y) or ():
                n = run.node(nxt)
                k = id(n)
                if y in reached.get(k, ()):
                    continue
                bucket = pending.get(k)
                if bucket is None:
                    nodes[k] = n
                    bucket = pending[k] = set()
                    work.append(k)
                bucket.add(y)


def certificate_problems(
    plan: Mapping[str, Any],
    *,
    parts: Sequence[PushFunction] | None = None,
    deadline: Deadline | None = None,
) -> list[str]:
    """What a plan's ``stats.certificate`` overstates, in words (empty when it holds or the
    plan has none): its rotation error against :func:`max_rotation_error_deg` of the tree,
    its shape tolerance by re-verifying the plan there (with the feeder's vibration, as the
    certificate is computed). Its ideal length speaks of another plan and is not checked."""
    cert = (plan.get("stats") or {}).get("certificate")
    if not cert:
        return []
    deadline = deadline or Deadline()
    pfs = list(parts) if parts is not None else _parts(plan, deadline)
    out = []
    rot = cert.get("max_rotation_error_deg")
    if rot is not None:
        held = max_rotation_error_deg(plan, parts=pfs, deadline=deadline)
        if rot > held + MARGIN_TOL_DEG:
            out.append(
                f"the certificate's rotation error ±{rot:.6g}° is more than the plan holds "
                f"(±{held:.6g}°)"
            )
    shape = cert.get("max_shape_tolerance_mm")
    declared = declared_uncertainty(plan)
    if shape is not None and shape > declared.shape_tolerance_mm:
        unc = Uncertainty(declared.rotation_error_deg, shape, declared.com_tolerance_mm)
        if not strong_holds(plan, unc, parts=pfs, vibrating=True, deadline=deadline):
            out.append(
                f"the certificate's shape tolerance {shape:.6g} mm is more than the plan "
                "holds: some path fails there"
            )
    return out


def max_shape_tolerance_mm(
    plan: Mapping[str, Any],
    *,
    parts: Sequence[PushFunction] | None = None,
    rel_tol: float = SHAPE_REL_TOL,
    deadline: Deadline | None = None,
) -> float:
    """The largest shape tolerance (mm) under which ``plan`` still verifies at its declared
    rotation error and COM tolerance: a bisection re-verifying the plan (outcome sets and
    reading intervals grow with the tolerance) to ``rel_tol`` of the bound, half the parts'
    smallest hull edge. Returns the lower end of the final bracket, where the plan holds.
    A plan that fails at the smallest midpoint the bisection could try ends it at once (the
    declared tolerance). Timeout when ``deadline`` passes first (polled inside each
    re-verification, per part rebuilt and per (node, state) pair: :func:`strong_holds`)."""
    deadline = deadline or Deadline()
    declared = declared_uncertainty(plan)
    pfs = list(parts) if parts is not None else _parts(plan, deadline)
    limit = min(shape_tolerance_limit(pf.part) for pf in pfs)

    def holds(t: float) -> bool:
        # With the feeder's vibration, as every certificate (strong_model's ``vibrating``).
        unc = Uncertainty(declared.rotation_error_deg, t, declared.com_tolerance_mm)
        return strong_holds(plan, unc, parts=pfs, vibrating=True, deadline=deadline)

    lo = declared.shape_tolerance_mm
    hi = limit * (1.0 - 1e-9)
    if holds(hi):
        return hi
    # Holding is monotone in the tolerance (the bisection's premise): failing at the last
    # midpoint a bisection that never holds would try, every midpoint fails and the bracket
    # closes on ``lo``, so one re-verification answers where there would be a dozen.
    last, top = lo, hi
    while top - lo > rel_tol * limit:
        last = top = (lo + top) / 2.0
    if last > lo and not holds(last):
        return lo
    while hi - lo > rel_tol * limit:
        mid = (lo + hi) / 2.0
        lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    return lo


def ideal_view(result: PlanResult, ideal: PushAlignMachine) -> PlanResult:
    """``result`` over the parts' ideal stable states (the machine ``ideal``, built from the
    same push functions at zero uncertainty): each physical state becomes its ideal members
    in every mask, so a leaf names a physical state by all its ideal stable states."""
    machine = result.machine
    index = {(s.part, s.state): k for k, s in enumerate(ideal.states)}
    expand = []
    for s in machine.states:
        m = 0
        for i in s.ideal_states:
            m |= 1 << index[(s.part, i)]
        expand.append(m)
    masks: dict[int, int] = {}

    def mask(m: int) -> int:
        out = masks.get(m)
        if out is None:
            out = 0
            for k in members(m):
                out |= expand[k]
            masks[m] = out
        return out

    root = map_masks(result.root, mask)
    assert isinstance(root, Step)
    return PlanResult(
        machine=ideal,
        root=root,
        length=result.length,
        expected_length=result.expected_length,
        min_margin=result.min_margin,
        optimal=result.optimal,
        lower_bound=result.lower_bound,
        objective=result.objective,
        grouping=result.grouping,
        certificate=result.certificate,
    )


def finite_or_none(x: float) -> float | None:
    """A JSON-safe number: None for infinities."""
    return x if math.isfinite(x) else None


__all__ = [
    "MARGIN_TOL_DEG",
    "MAX_ROTATION_ERROR_DEG",
    "StrongModel",
    "action_nodes",
    "certificate_problems",
    "declared_uncertainty",
    "finite_or_none",
    "ideal_view",
    "max_rotation_error_deg",
    "max_shape_tolerance_mm",
    "strong_holds",
    "strong_model",
    "verify_strong",
]
