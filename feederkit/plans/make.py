"""Make a verified plan file for one part or a mix: machine, planner, file, verification.

Every plan is verified before anyone writes or prints it; a plan that fails is a bug,
reported as CheckFailed with the first counterexample (docs/architecture.md). The planning
options arrive as one validated :class:`PlanningOptions` value, the declared uncertainty as
one :class:`~feederkit.uncertainty.Uncertainty` (design.md's default: rotation error 1
degree). On the ideal model the plan is verified on the kinematic model
(:func:`~feederkit.plans.verify.check_plan`); under uncertainty it is a strong plan, verified
for every outcome and reading (:func:`~feederkit.plans.strong.verify_strong`). Every plan
carries its certificate (:class:`~feederkit.planning.tree.Certificate`).

A plan over landings (design.md "Landings", plan file version 2) names its members with
:class:`~feederkit.plans.model.PlanMember`: each landing of each part is one member of the
mix (section 8), with its prior share (the landing's probability times the part's share) and
whether the next station takes it. The shares weight the expected length; a set of states of
rejected members only is the planners' goal too
(:attr:`feederkit.machine.space.SearchSpace.inseparable`), so it ends in a reject leaf as
soon as the plan knows the part will be rejected.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import shapely

from feederkit.angles import norm360
from feederkit.errors import InputError, PlanningError
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.machine.build import build_machine
from feederkit.machine.weights import normalised_shares, weigh_members
from feederkit.machine.widths import Offsets, widen_widths
from feederkit.mechanics.modelerror import (
    exact_push_function,
    keeping_tolerance,
    largest_offset,
    part_offsets,
)
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.symmetry import NEAR_SYMMETRIC_REL, poses_difference, unlike_pairs
from feederkit.mechanics.uncertain import PUSH_BAND_DEG
from feederkit.part import make_part
from feederkit.planning.api import NoStrongPlan, shortest_length, strong_plan_exists
from feederkit.planning.api import plan as plan_machine
from feederkit.planning.budget import Deadline, Timeout, collector_paused
from feederkit.planning.lumping import lumped_words, unresolvable_pairs
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.tree import Certificate, PlanResult, PlanTree, leaf_masks, map_tree
from feederkit.planning.tree import Leaf as TreeLeaf
from feederkit.planning.tree import Step as TreeStep
from feederkit.plans.fileformat import plan_to_dict, result_nodes
from feederkit.plans.model import PlanMember, low_margin_words, member_label
from feederkit.plans.readplan import as_plan
from feederkit.plans.strong import (
    ideal_view,
    max_rotation_error_deg,
    max_shape_tolerance_mm,
    verify_strong,
)
from feederkit.plans.verify import VerificationReport, check_plan
from feederkit.plans.verify import expected_operations as file_expected
from feederkit.sensors import Sensor, ToleranceSensor, sensor_warnings
from feederkit.uncertainty import IDEAL, Uncertainty, check_for_part
from feederkit.words import at_most, plural

DIAMETER_DIGITS = 9
"""Diameters (mm) equal to this many decimals are one diameter: a regular polygon's states
differ only by rounding, and reading alike is then no fault of the sensor."""


@dataclass(frozen=True)
class MadePlan:
    """A plan file's object, the planner's result it came from, and its verification."""

    plan: dict[str, Any]
    result: PlanResult
    report: VerificationReport
    warnings: tuple[str, ...] = ()
    unoriented: str | None = None
    """When some result lists poses of one part that do not look alike and that no plan can
    tell apart (:func:`unlike_twins_words`): the words saying so (a command exits 1)."""


BISECT_STEPS = 12
"""Bisection steps for the largest uncertainty at which a strong plan exists (to 1/4096)."""


def make_plan(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    certify: bool = True,
    members: Sequence[PlanMember] | None = None,
    weights: Sequence[float] | None = None,
) -> MadePlan:
    """Plan for ``push_functions`` (one part, or a mix: section 8.5) and verify the plan file.

    ``members`` (one per push function, in order) name the plan's parts as the file writes
    them, with their landings, prior shares (normalised to sum to 1) and accept/reject
    (:class:`~feederkit.plans.model.PlanMember`); None: the push functions' parts, equal
    shares, every one accepted, written exactly as before. ``weights`` are the members'
    prior shares alone (one per push function, e.g. a product mix's part shares), for
    members that do not carry their own.

    ``options`` default to ``PlanningOptions()``. ``uncertainty``
    defaults to ``Uncertainty()`` (rotation error 1 degree); ``IDEAL`` is the paper's model.
    ``certify=False`` skips the certificate (the plan file then has none; for callers that
    re-plan many times, such as property tests). The result's ``warnings`` flag a plan that
    holds rotation errors below ``LOW_MARGIN_DEG`` (its declared rotation error plus its
    smallest margin, :func:`~feederkit.plans.model.low_margin_words`) and a sensor that reads
    every state alike. Raises InputError
    for bad options or a shape tolerance too large for a part, PlanningError when no plan
    meets the request (under uncertainty: naming the largest uncertainty with a strong
    plan; or an accepted and a rejected member no plan can tell apart), and CheckFailed when
    the plan fails verification.
    """
    # Planning, verification and certificate build tables of many small objects without
    # cycles: the cyclic collector would only rescan them (collector_paused).
    with collector_paused():
        return _make_plan(
            push_functions,
            sensor,
            options,
            uncertainty=uncertainty,
            certify=certify,
            members=members,
            weights=weights,
        )


def _make_plan(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    options: PlanningOptions | None,
    *,
    uncertainty: Uncertainty | None,
    certify: bool,
    members: Sequence[PlanMember] | None,
    weights: Sequence[float] | None,
) -> MadePlan:
    """:func:`make_plan`'s work."""
    opts = PlanningOptions() if options is None else options
    if not isinstance(opts, PlanningOptions):
        raise InputError(f"the planning options must be PlanningOptions, got {opts!r}")
    unc = Uncertainty() if uncertainty is None else uncertainty
    if not isinstance(unc, Uncertainty):
        raise InputError(f"the uncertainty must be an Uncertainty, got {unc!r}")
    started = time.monotonic()
    pfs = list(push_functions)
    for pf in pfs:
        check_for_part(unc, pf.part)
    _check_resolution(sensor, pfs)
    named = check_plan_members(_weighted_members(members, weights, pfs), pfs)
    shares, rejected = _member_weights(named)
    # The part itself may read a little off its simplified hull's diameters: the machine
    # reads each state over them too (machine.widths), so no branch parts what the part
    # itself cannot be told apart by.
    offsets = part_offsets(pfs)

    def weighed(u: Uncertainty) -> PushAlignMachine:
        """The mix's machine at ``u``: members' shares, rejected landings marked."""
        return weigh_members(build_machine(pfs, sensor, u), shares, rejected)

    unwidened = weighed(unc)
    machine = widen_widths(unwidened, offsets)
    if rejected:
        _check_rejects_separable(machine, named, lambda: _finest_machine(pfs, unc))
    try:
        result = plan_machine(machine, opts, budget=_planner_budget(opts, started, certify))
    except NoStrongPlan as exc:
        left = _left(opts, started)
        blame = blocking_members(
            pfs, sensor, unc, opts, offsets, named, None if left is None else left / 2.0
        )
        largest = largest_uncertainty(
            pfs,
            sensor,
            unc,
            opts,
            _left(opts, started),
            lambda u: widen_widths(weighed(u), offsets),
        )
        hint = f"; {exc.hint}" if exc.hint else ""
        culprits = [pfs[k] for k in blame.members] or pfs
        simplified = [pf.part.name for pf in culprits if exact_push_function(pf) is not None]
        chords = short_chords_words(culprits, unc.shape_tolerance_mm)
        if chords:
            hint += chords  # short chords: a coarser hull helps, a finer one does not
        elif simplified:
            hint += (
                f"; {simplified[0]}'s contact hull simplifies its outline (stable states of the "
                "simplification only, widths it cuts): a smaller --hull-tolerance may help"
            )
        who = f"; {blame.words}" if blame.words else ""
        raise PlanningError(f"{exc.reason}{who}; {largest}{hint}") from None
    # Planned on the parts' own widths, the plan's expected length is restated on the file's
    # model (its diameters), the one every reader computes.
    widened = machine is not unwidened
    if unc.is_ideal:
        data = with_uncertainty(_plan_dict(result, pfs, named, shares), unc)
        if widened:
            data["stats"]["expected_length"] = file_expected(as_plan(data))
        listed = _entries(data)
        report = check_plan(data, prune=True)
        if _entries(data) != listed and _time_left(opts, started):
            report = check_plan(data)  # its counts (runs ending unrecognized) are the file's
    else:
        ideal = weigh_members(build_machine(pfs, sensor, IDEAL), shares, rejected)
        ideal = widen_widths(ideal, offsets)
        data = with_uncertainty(_plan_dict(ideal_view(result, ideal), pfs, named, shares), unc)
        # Its paths and its margins: a margin the rebuilt model finds more than some state at
        # the node keeps is lowered to what it keeps, so the file claims no more than holds.
        listed = _entries(data)
        report = verify_strong(data, tighten_margins=True, restate_expected=widened, prune=True)
        if _entries(data) != listed and _time_left(opts, started):
            report = verify_strong(data, restate_expected=widened)  # the file's counts
        written = data["stats"]["min_margin_deg"]
        if written is not None and written < result.min_margin:
            result = replace(result, min_margin=written)
    # The file's results were pruned to what ends there: the warnings below read the same.
    root = listed_tree(result, data)
    result = replace(result, root=root, lumped_pairs=listed_together(result.lumped_pairs, root))
    if widened:
        result = replace(result, expected_length=data["stats"]["expected_length"])
    notes: list[str] = []
    widest = max((largest_offset(off)[0] for off in offsets), default=0.0)
    if widest > 0.0 and sensor.informative:
        notes.append(
            f"each state read over up to {widest:.3g} mm more of widths, those of the parts "
            "themselves (their contact hulls simplify the outlines' arcs; a smaller "
            "--hull-tolerance narrows it)"
        )
    floor = opts.min_margin_deg
    if floor > 0.0 and math.isfinite(result.min_margin) and result.min_margin < floor - 1e-9:
        notes.append(
            f"a rotation keeps ±{result.min_margin:.4g}° for a state that a reading at the end "
            f"of its interval lets reach it, less than --min-margin {floor:g}: the file says "
            "what holds"
        )
    if certify:
        output_s = _output_s(data)
        cert, cut = _certificate(data, unc, opts, started, output_s)
        if not unc.is_ideal:
            cert = replace(cert, ideal_length=_ideal_length(ideal, opts, started, output_s))
        else:
            cert = replace(cert, ideal_length=result.length)
        data["stats"]["certificate"] = cert.to_dict()
        result = replace(result, certificate=cert)
        if cut:
            what = f"{' and '.join(cut)} bound" + (
                "s are the declared values" if len(cut) > 1 else " is the declared value"
            )
            notes.append(
                f"the time limit of {opts.time_limit_s:g} s left no time for the whole "
                f"certificate: its {what}, which the verification proved, not the largest "
                "the plan holds (allow more time with --time-limit S)"
            )
    diameters = sorted({round(s.diameter, DIAMETER_DIGITS) for pf in pfs for s in pf.states})
    warnings = sensor_warnings(sensor, diameters)
    lumped = lumped_words(result.machine, result.lumped_pairs)
    if lumped:
        left = _left(opts, started)
        smaller = smaller_error_words(
            lambda u: widen_widths(weighed(u), offsets),
            unc,
            result.machine,
            result.lumped_pairs,
            SMALLER_ERROR_S if left is None else min(SMALLER_ERROR_S, max(left, 0.0)),
        )
        warnings.append(lumped + _lump_shapes(result.machine, pfs, result.lumped_pairs) + smaller)
    spread = _spread_words(result, pfs)
    if spread is not None:
        warnings.append(spread)
    unoriented = unlike_twins_words(result, pfs)
    cut = _ties_cut_words(result, opts)
    if cut is not None:
        warnings.append(cut)
    margin = low_margin_words(result.min_margin, unc.rotation_error_deg)
    if margin is not None:
        warnings.append(
            f"{margin}; ask for a minimum margin or check the plan with feederkit simulate"
        )
    held = ideal_plan_words(unc, result.min_margin, result.certificate)
    if held is not None:
        warnings.append(held)
    return MadePlan(data, result, report, tuple(warnings + notes), unoriented)


def _time_left(opts: PlanningOptions, started: float) -> bool:
    """Whether the time limit (if any) leaves time for one more walk of the plan."""
    left = _left(opts, started)
    return left is None or left > 0.0


def _entries(data: Mapping[str, Any]) -> int:
    """How many entries the results of the plan file's object ``data`` list."""
    return sum(len(node["result"]) for node in result_nodes(data))


def listed_tree(result: PlanResult, data: dict[str, Any]) -> PlanTree:
    """The planner's tree with each leaf's mask cut to the states its results in the plan
    file's object ``data`` (written from that tree, then pruned) still list: a state stays
    when one of its ideal members is listed at one of the leaf's places."""
    machine = result.machine
    parts = [(part["name"], part.get("landing")) for part in data["parts"]]
    shared = data.get("nodes") or {}
    listed: dict[int, set[tuple[int, int]]] = {}  # tree leaf id: (part, ideal state) listed
    index = {key: p for p, key in enumerate(parts)}
    seen: set[tuple[int, int]] = set()
    stack: list[tuple[PlanTree, Any]] = [(result.root, data["root"])]
    while stack:
        node, raw = stack.pop()
        while "ref" in raw:
            raw = shared[raw["ref"]]
        if (id(node), id(raw)) in seen:
            continue
        seen.add((id(node), id(raw)))
        if isinstance(node, TreeLeaf):
            names = listed.setdefault(id(node), set())
            names.update((index[(e["part"], e.get("landing"))], e["state"]) for e in raw["result"])
            continue
        pairs = zip(node.branches, raw["branches"], strict=True)
        stack.extend((child, b["next"]) for (_b, child), b in pairs)

    def cut(leaf: TreeLeaf) -> TreeLeaf:
        names = listed[id(leaf)]
        mask = 0
        for i in members(leaf.mask):
            ms = machine.states[i]
            if any((ms.part, m) in names for m in ms.ideal_states):
                mask |= 1 << i
        return leaf if mask == leaf.mask else TreeLeaf(mask)

    return _map_leaves(result.root, cut)


def listed_together(
    pairs: Sequence[tuple[int, int]], root: PlanTree
) -> tuple[tuple[int, int], ...]:
    """The ``pairs`` of states some leaf of ``root`` lists together (the lumped pairs a
    warning may name once results are pruned to what ends there).

    >>> from feederkit.planning.tree import Leaf, Step
    >>> listed_together([(0, 2), (1, 3)], Step(0.0, ((None, Leaf(0b0101)),)))
    ((0, 2),)
    """
    masks = leaf_masks(root)
    return tuple((i, j) for i, j in pairs if any(m >> i & 1 and m >> j & 1 for m in masks))


def _map_leaves(root: PlanTree, leaf: Callable[[TreeLeaf], TreeLeaf]) -> PlanTree:
    """The tree with every leaf replaced by ``leaf`` of it (shared subplans kept shared; a
    step none of whose leaves changes is kept, :func:`~feederkit.planning.tree.map_tree`)."""

    def step(n: TreeStep, subs: tuple) -> TreeStep:
        same = all(new is old for (_b, new), (_c, old) in zip(subs, n.branches, strict=True))
        return n if same else TreeStep(n.action, subs)

    return map_tree(root, leaf, step)


def ideal_plan_words(
    unc: Uncertainty, min_margin: float, certificate: Certificate | None
) -> str | None:
    """One line when a plan made on the ideal model holds less on a feeder that vibrates
    than its margins say: the certificate is computed with the vibration the planner's
    model has under any rotation error (fragile states merged, a push band at each hilltop,
    ``strong.strong_model``), where an ideal plan may hold no rotation error at all.

    >>> print(ideal_plan_words(IDEAL, 5.0, Certificate(3.0, 0.0, 2)))
    the plan is the ideal model's: on a feeder that vibrates it holds rotation errors up to ±3° ...
    """
    if not unc.is_ideal or certificate is None or not math.isfinite(min_margin):
        return None
    held = certificate.max_rotation_error_deg
    if held >= min_margin - 1e-9:
        return None
    what = "no rotation error at all" if held <= 0.0 else f"rotation errors up to ±{held:.4g}°"
    return (
        f"the plan is the ideal model's: on a feeder that vibrates it holds {what} (its "
        f"margins say ±{min_margin:.4g}°: drops near a hilltop may go either way, fragile "
        "states merge); plan with --rotation-error DEG for one that holds it"
    )


POST_SHARE = 0.15
"""With a time limit, the share of it a certified plan keeps after the planner: the plan file
and its verification (always made) and the certificate (its largest rotation error and shape
tolerance, then the ideal length, each only while time is left). The limit is the command's,
so the planner gets the rest; ``certify=False`` callers (a design's many plans, under their
own clock) give the planner the whole limit."""


POST_MIN_S = 1.5
"""With a time limit, at least this many seconds (up to ``POST_MAX_SHARE`` of the limit) are
kept after the planner, however short the limit: what the work after it costs whatever the
plan's size (the plan's own verification and file are committed by the planner as it builds
the plan, ``POST_S_PER_PAIR``)."""

POST_MAX_SHARE = 0.25
"""The most of a short time limit ``POST_MIN_S`` may take from the planner."""

OUTPUT_SHARE = 0.05
"""With a time limit, the share of it the certificate (whose ideal length may take all the
time left) leaves to the caller for writing and showing the plan, besides
``OUTPUT_S_PER_NODE`` per node of the plan file."""

POST_S_PER_PAIR = 4e-5
"""Seconds per (node, state) pair of a plan (a state that can reach a node) of the work after
the planner: the file, its verification and the command's output. The planner's deadline
comes this much earlier per pair of the nodes it makes (``Deadline.per_pair_s``), so a large
plan leaves time for its own verification and file. Measured about 3.2e-5 s on two plans
(``python benchmarks/bench_command_deadline.py``): a 100-part mix's under 1 degree, 164,000
pairs in 5.3 s, and a 1000-point outline's over both landings on the ideal model, 265,000
pairs in 8.5 s."""

OUTPUT_S_PER_NODE = 7e-5
"""Seconds per node of the plan file (each shared step once, each result in place) of what
comes after the certificate: writing the file, reading it back and drawing it (2.5 s for the
44,000 nodes of the 100-part mix's plan above)."""


def _planner_budget(options: PlanningOptions, started: float, certify: bool) -> Deadline:
    """The planner's budget: the options' time limit from ``started`` less, when certifying,
    ``POST_SHARE`` of it or ``POST_MIN_S`` (at most ``POST_MAX_SHARE`` of it), whichever is
    more (at least a tenth of the limit is left to plan), and their memory limit; the
    deadline comes ``POST_S_PER_PAIR`` earlier per pair of the plan made, whose
    verification follows whether certified or not."""
    limit = options.time_limit_s
    if limit is None:
        return Deadline(None, options.memory_limit_mb)
    left = _left(options, started) or 0.0
    keep = max(POST_SHARE * limit, min(POST_MIN_S, POST_MAX_SHARE * limit)) if certify else 0.0
    # A design's plan of 11,559 nodes took 7.6 s to verify past a 5 s limit uncommitted.
    return Deadline(
        max(left - keep, 0.1 * limit), options.memory_limit_mb, per_pair_s=POST_S_PER_PAIR
    )


def _certificate(
    data: dict[str, Any],
    declared: Uncertainty,
    options: PlanningOptions,
    started: float,
    output_s: float = 0.0,
) -> tuple[Certificate, list[str]]:
    """The plan's largest rotation error and shape tolerance (the certificate without its
    ideal length), each within what is left of the time limit less ``output_s`` seconds (for
    writing and showing the plan); one that runs out states the declared value, which the
    verification proved. Also the names of those cut short."""
    cut: list[str] = []
    figures: list[float] = []
    for name, figure, given in (
        ("rotation", max_rotation_error_deg, declared.rotation_error_deg),
        ("shape", max_shape_tolerance_mm, declared.shape_tolerance_mm),
    ):
        left = _left(options, started, OUTPUT_SHARE, output_s)
        try:
            figures.append(
                figure(data, deadline=None if left is None else Deadline(max(left, 0.0)))
            )
        except Timeout:
            figures.append(given)
            cut.append(name)
    rotation, shape = figures
    return Certificate(rotation, shape, None), cut


def _ties_cut_words(result: PlanResult, options: PlanningOptions) -> str | None:
    """One line when a plan of proven length stopped choosing among the shortest plans
    (``PlanResult.tie_breaks``; the time limit or the tie-breaking budget ended it): the
    largest smallest margin, or the fewest expected operations, was not found."""
    if not result.optimal or options.objective.value != "worst":
        return None
    words = f"a plan of {plural(result.length, 'operation')}"
    more = _MORE.get(result.ties_cut_by or "", _MORE["time"])
    if result.tie_breaks == "margin":
        return (
            f"the choice among shortest plans stopped at {words} with the largest margin, "
            f"not the fewest expected operations ({more})"
        )
    if result.tie_breaks == "none" and math.isfinite(result.min_margin):
        return (
            f"the choice among shortest plans stopped at {words} whose smallest margin, "
            f"±{result.min_margin:.4g}° of slack beyond the declared uncertainty, is not "
            f"proven the largest; another may keep more slack ({more})"
        )
    return None


_MORE = {
    "time": "allow more time with --time-limit S",
    "memory": "allow more memory with --memory-limit MB",
    "work": "the tie-breaking budget, a multiple of the length proof's work, ran out; "
    "more time does not change it",
}
"""What a user can do when the choice among shortest plans was cut short, by its cause
(``PlanResult.ties_cut_by``)."""


SHORT_CHORD_TILT_DEG = 5.0
"""A hull edge the shape tolerance may tilt by at least this much (``asin(2 t / length)``) is
named when no strong plan exists: finely drawn arcs make them."""

COARSE_HULL_PROBE_REL = 0.01
"""The coarsest hull tolerance, as a share of the part's size, :func:`coarser_kept_hull` tries
(then its halves, as import does)."""


def _chord_tilt(hull: Sequence[tuple[float, float]], t: float) -> tuple[float, float]:
    """The shortest edge of ``hull`` (mm) and how far the shape tolerance ``t`` may tilt it
    (degrees)."""
    shortest = min(math.dist(hull[i], hull[(i + 1) % len(hull)]) for i in range(len(hull)))
    return shortest, math.degrees(math.asin(min(1.0, 2.0 * t / shortest)))


def _hull_gap(exact: Sequence[tuple[float, float]], hull: Sequence[tuple[float, float]]) -> float:
    """How far the outline's exact hull strays outside a contact hull simplified inside it."""
    ring = shapely.LinearRing(hull)
    return float(np.max(shapely.distance(ring, shapely.points(np.asarray(exact, dtype=float)))))


def coarser_kept_hull(pf: PushFunction, t: float) -> float | None:
    """A hull tolerance coarser than the one ``pf``'s contact hull was simplified at that an
    import keeps (the simplified hull rests where the outline does: ``keeping_tolerance``,
    which lowers any coarser request, on a mesh or a drawing alike) and at which no hull edge
    is short enough for the shape tolerance ``t`` to tilt it by :data:`SHORT_CHORD_TILT_DEG`;
    None when there is none, and a coarser ``--hull-tolerance`` cannot help."""
    part = pf.part
    exact = make_part(part.outline, part.com, name=part.name)
    own = _hull_gap(exact.hull, part.hull)
    kept = keeping_tolerance(exact, COARSE_HULL_PROBE_REL * part.size)
    if kept.tolerance <= 1.01 * own + 1e-9:
        return None
    coarser = make_part(part.outline, part.com, hull_tolerance=kept.tolerance, name=part.name)
    if _chord_tilt(coarser.hull, t)[1] >= SHORT_CHORD_TILT_DEG:
        return None
    return kept.tolerance


def short_chords_words(pfs: Sequence[PushFunction], t: float) -> str:
    """ "; ..." naming the part whose contact hull has the shortest edge the shape tolerance
    ``t`` may tilt by ``SHORT_CHORD_TILT_DEG`` or more (an arc drawn as many short chords,
    each a possible resting edge near a corner under the vertex model, docs/uncertainty.md),
    and what may help: a coarser ``--hull-tolerance`` only when import would keep one that
    lengthens those edges (:func:`coarser_kept_hull`; a mesh's or a near-round part's is
    lowered back to what keeps its resting states); "" when none has such an edge."""
    if t <= 0.0:
        return ""
    (length, tilt), pf = min(((_chord_tilt(pf.part.hull, t), pf) for pf in pfs), key=_first)
    if tilt < SHORT_CHORD_TILT_DEG:
        return ""
    name = pf.part.name
    head = (
        f"; {name}'s contact hull has edges as short as {length:.3g} mm (an arc drawn as many "
        f"chords?), which the shape tolerance may tilt by {tilt:.3g} degrees, each then a "
        "possible resting edge near a corner: a smaller --shape-tolerance, or an outline with "
        "fewer arc points (a coarser tessellation in a mesh's CAD export)"
    )
    coarser = coarser_kept_hull(pf, t)
    if coarser is not None:
        return (
            f"{head}, or the part imported with --hull-tolerance {coarser:.3g} (its resting "
            "states kept, no edge that short), may have a plan (docs/uncertainty.md)"
        )
    return (
        f"{head}, may have a plan; a coarser --hull-tolerance cannot help: import lowers it "
        f"to what keeps {name}'s resting states (chords across its arcs would hold the part "
        "where it rolls) (docs/uncertainty.md)"
    )


def _first(item: tuple[tuple[float, float], PushFunction]) -> float:
    return item[0][0]


def unlike_twins_words(result: PlanResult, pfs: Sequence[PushFunction]) -> str | None:
    """Words naming the poses of one part that some result lists together though they do not
    look alike (holes, slots or notches placed differently: ``look_alike`` compares the
    outline) while no plan tells them apart (the contact hull, all the fence and the sensor
    feel, is symmetric: the paper's indistinguishable poses); None when there are none.
    Pairs the lumping already named (``lumped_pairs``) are left to its warning."""
    machine = result.machine
    lumped = set(result.lumped_pairs)
    found: dict[tuple[int, int], None] = {}
    for mask in leaf_masks(result.root):
        by_part: dict[int, list[int]] = {}
        for i in members(mask):
            if not machine.states[i].reject:  # a reject result needs no telling apart
                by_part.setdefault(machine.states[i].part, []).append(i)
        for part, idx in by_part.items():
            if len(idx) < 2:
                continue
            groups = [machine.states[i].ideal_states for i in idx]
            for a, b in unlike_pairs(pfs[part], groups):
                if (idx[a], idx[b]) not in lumped:
                    found[(idx[a], idx[b])] = None
    if not found:
        return None
    named = []
    for i, j in found:
        a, b = machine.states[i], machine.states[j]
        pf = pfs[a.part]
        poses = [norm360(-90.0 - pf.states[x.state].normal_deg) for x in (a, b)]
        named.append(
            f"{machine.part_names[a.part]} states {a.state} and {b.state} (poses "
            f"{poses[0]:.4g} and {poses[1]:.4g} degrees)"
        )
    return (
        "no plan can tell apart poses that do not look alike: "
        + "; ".join(named)
        + ": pushing and reading cannot tell them apart (the paper's indistinguishable poses: "
        "a symmetric contact hull with holes, slots or notches placed otherwise, or a push "
        "function that repeats), so a result lists them and the part is not oriented between "
        "them: check its pose by other means, or take it either way"
    )


def _spread_words(result: PlanResult, pfs: Sequence[PushFunction]) -> str | None:
    """A warning naming the results that end in a physical state of several unlike stable
    states (shallow wells a breath of vibration crosses: a part resting anywhere over their
    poses, docs/uncertainty.md), with the angle their normals span; None when there are
    none. Congruent ones (a regular polygon's) orient the part and are not named."""
    machine = result.machine
    found: dict[int, float] = {}
    for mask in leaf_masks(result.root):
        for i in members(mask):
            s = machine.states[i]
            if len(s.members) < 2 or i in found:
                continue
            pf = pfs[s.part]
            if not unlike_pairs(pf, [(m,) for m in s.members]):
                continue
            normals = [pf.states[m].normal_deg for m in s.members]
            found[i] = norm360(normals[-1] - normals[0])
    if not found:
        return None
    named = "; ".join(
        f"{machine.part_names[machine.states[i].part]} states "
        f"{', '.join(str(m) for m in machine.states[i].members)} over {spread:.3g} degrees"
        for i, spread in sorted(found.items(), key=lambda kv: -kv[1])
    )
    return (
        f"some results name a resting state made of several stable states, shallow wells a "
        f"breath of vibration crosses (docs/uncertainty.md): {named}; there the part rests "
        "anywhere over those poses, oriented only that far"
    )


SMALLER_ERROR_FACTOR = 1e-3
"""A rotation error this fraction of the declared one stands for "a smaller rotation error":
:func:`smaller_error_words` asks whether the lumped pairs are still unresolvable there."""

SMALLER_ERROR_S = 5.0
"""The most seconds :func:`smaller_error_words` spends deciding (less when the time limit
leaves less); undecided, it says a smaller rotation error may or may not help."""


def smaller_error_words(
    machine_at: Callable[[Uncertainty], PushAlignMachine],
    uncertainty: Uncertainty,
    machine: PushAlignMachine,
    pairs: Sequence[tuple[int, int]],
    seconds: float,
) -> str:
    """What keeps the lumped ``pairs`` (states of ``machine``) together, in words, decided
    exactly where it is affordable (within ``seconds``): the pairs still unresolvable
    (:func:`~feederkit.planning.lumping.unresolvable_pairs`) on the machines ``machine_at``
    builds at :data:`SMALLER_ERROR_FACTOR` of the declared rotation error, then with the
    declared shape and COM tolerances at 0 too, the feeder's vibration on in both (any
    declared uncertainty switches it on). Told apart at the smaller rotation error: "a
    smaller rotation error helps"; else, told apart without the tolerances: a smaller
    --shape-tolerance / --com-tolerance helps; else the vibration keeps them together, or
    not even the ideal model tells them apart. The command line names a flag only where the
    words say it helps (``with_flags``).
    """
    r = uncertainty.rotation_error_deg
    tiny = replace(uncertainty, rotation_error_deg=r * SMALLER_ERROR_FACTOR)
    loose = uncertainty.shape_tolerance_mm > 0.0 or uncertainty.com_tolerance_mm > 0.0
    exact = replace(tiny, shape_tolerance_mm=0.0, com_tolerance_mm=0.0)
    if exact.is_ideal:  # nothing declared but the rotation error, and that is 0
        exact = replace(exact, rotation_error_deg=SMALLER_ERROR_FACTOR)
    vibration = (
        "the feeder's vibration, which any declared uncertainty switches on (push bands and "
        "merged fragile states: docs/uncertainty.md)"
    )
    stop = time.monotonic() + max(seconds, 0.0)

    def left_at(u: Uncertainty) -> list[tuple[int, int]] | None:
        """The pairs still unresolvable at ``u`` (None: undecided in time)."""
        rest = stop - time.monotonic()
        if rest <= 0.0:
            return None
        try:
            at = machine_at(u)
            found = unresolvable_pairs(Problem(at, "exact", 0.0), Deadline(rest))
        except Timeout:
            return None
        if found is None:
            return None
        kept = set(found)
        return [
            (i, j)
            for i, j in pairs
            if any(
                (min(x, y), max(x, y)) in kept
                for x in _alike(machine, i, at)
                for y in _alike(machine, j, at)
            )
        ]

    left = left_at(tiny) if r > 0.0 else list(pairs)
    at = f"±{tiny.rotation_error_deg:.3g} deg"
    if left is None:
        return (
            "; whether a smaller rotation error or tighter tolerances help was not decided: "
            f"they may or may not, since {vibration} may keep them together whatever they are"
        )
    if not left:
        return f"; a smaller rotation error helps: at {at} a strong plan tells each pair apart"
    helped = len(pairs) - len(left)
    head = (
        f"; a smaller rotation error helps {plural(helped, 'pair')} only: at {at} "
        f"{len(left)} of the {len(pairs)} are still not told apart"
        if helped
        else (
            f"; no smaller rotation error helps: at {at} they are still not told apart"
            if r > 0.0
            else ""
        )
    )
    if loose:
        still = left_at(exact)
        if still is not None and len(still) < len(left):
            fixed = len(left) - len(still)
            which = "them" if not still else plural(fixed, "pair")
            return (
                f"{head}{': ' if head else '; '}the declared shape and COM tolerances keep "
                f"{which} together: with none a strong plan tells {which} apart (a smaller "
                "shape tolerance or COM tolerance helps)"
            )
        if still is None:
            return (
                f"{head}{': ' if head else '; '}the declared shape and COM tolerances or "
                f"{vibration} keep them together (not decided which)"
            )
        left = still
    ideal = machine_at(IDEAL)
    insep = search_space(ideal).inseparable
    if all(
        any(insep[x] >> y & 1 for x in _alike(machine, i, ideal) for y in _alike(machine, j, ideal))
        for i, j in left
    ):
        # the ideal model does not tell them apart either: no uncertainty is the cause
        which = "them" if len(left) == len(pairs) else "those left"
        return (
            f"{head}{': ' if head else '; '}no rotation error helps, not even 0: the ideal "
            f"model does not tell {which} apart either (the mix's pairs say why)"
        )
    cause = (
        f"{vibration} keeps them together, whatever else is declared; the ideal model (no "
        "uncertainty declared) plans with no margin for that vibration"
    )
    return f"{head}{': ' if head else '; '}{cause}"


def _alike(machine: PushAlignMachine, i: int, table: PushAlignMachine) -> list[int]:
    """The states of ``table`` that hold some ideal state of ``machine``'s state ``i``."""
    s = machine.states[i]
    ideal = set(s.ideal_states)
    return [
        k for k, t in enumerate(table.states) if t.part == s.part and ideal & set(t.ideal_states)
    ]


def _lump_shapes(
    machine: PushAlignMachine, pfs: Sequence[PushFunction], pairs: Sequence[tuple[int, int]]
) -> str:
    """How alike the lumped poses of one part look (:func:`poses_difference`, the measure
    the default lumping rule bounds by ``NEAR_SYMMETRIC_REL``), in words: near symmetry the
    user can accept, or (lumping ``any``) a warning that the plan leaves them unoriented."""
    worst, size = 0.0, 1.0
    for i, j in pairs:
        a, b = machine.states[i], machine.states[j]
        if a.part != b.part:
            continue  # parts that behave alike: reported as pairs of the mix
        pf = pfs[a.part]
        d = poses_difference(pf, a.ideal_states, b.ideal_states)
        if d / pf.part.size >= worst / size:
            worst, size = d, pf.part.size
    if worst == 0.0:
        return ""
    share = 100.0 * worst / size
    # Pairs of different members (parts, landings, mesh poses) are the mix's pairs, named
    # apart: the figure speaks of the states of one member only.
    across = any(machine.states[i].part != machine.states[j].part for i, j in pairs)
    whose = "the states of one part among them" if across else "their outlines"
    words = f"; {whose} differ by at most {worst:.3g} mm ({share:.2g} % of the part)"
    if worst > NEAR_SYMMETRIC_REL * size:
        words += (
            ": not near-symmetric, so the plan does not orient them apart (the default "
            "lumping says which rotation error, if any, has a plan that does)"
        )
    return words


def _left(
    options: PlanningOptions, started: float, keep: float = 0.0, keep_s: float = 0.0
) -> float | None:
    """Seconds left of the options' time limit since ``started``, less ``keep`` of the limit
    and ``keep_s`` seconds (None: no limit)."""
    if options.time_limit_s is None:
        return None
    return (1.0 - keep) * options.time_limit_s - keep_s - (time.monotonic() - started)


def _output_s(data: dict[str, Any]) -> float:
    """Seconds the caller needs to write and show the plan file's object ``data``:
    ``OUTPUT_S_PER_NODE`` per node (each shared step once, each result in place)."""
    return OUTPUT_S_PER_NODE * (len(data.get("nodes") or {}) + sum(1 for _ in result_nodes(data)))


def _ideal_length(
    ideal: PushAlignMachine, options: PlanningOptions, started: float, output_s: float = 0.0
) -> int | None:
    """The optimal length on the ideal model (the certificate's ``ideal_length``: the length
    search alone, ``shortest_length``), within what is left of the time limit less
    ``OUTPUT_SHARE`` of it and ``output_s`` seconds; None when no time is left or the length
    is not proven in it, or when the ideal model cannot meet the options (e.g. a margin
    floor it cannot keep)."""
    left = _left(options, started, OUTPUT_SHARE, output_s)
    if left is not None and left <= 0.0:
        return None
    opts = options if left is None else replace(options, time_limit_s=left)
    return shortest_length(ideal, opts)


def _weighted_members(
    members_: Sequence[PlanMember] | None,
    weights: Sequence[float] | None,
    push_functions: Sequence[PushFunction],
) -> Sequence[PlanMember] | None:
    """``members_`` with the shares ``weights`` (None: as given); without members, one per
    push function named as its part."""
    if weights is None:
        return members_
    shares = normalised_shares(weights, len(push_functions))
    if members_ is None:
        return tuple(
            PlanMember(pf.part.name, share=w) for pf, w in zip(push_functions, shares, strict=True)
        )
    named = tuple(members_)
    if len(named) != len(shares) or any(
        not isinstance(m, PlanMember) or m.share is not None for m in named
    ):
        raise InputError("give the shares either with the plan members or as weights, not both")
    return tuple(replace(m, share=w) for m, w in zip(named, shares, strict=True))


def check_plan_members(
    members_: Sequence[PlanMember] | None, push_functions: Sequence[PushFunction]
) -> tuple[PlanMember, ...] | None:
    """The members as given, checked; None when they change nothing (plain parts)."""
    if members_ is None:
        return None
    named = tuple(members_)
    if len(named) != len(push_functions):
        raise InputError(
            f"{len(named)} plan members for {len(push_functions)} parts: give one per part"
        )
    for m in named:
        if not isinstance(m, PlanMember):
            raise InputError(f"a plan member must be a PlanMember, got {m!r}")
    labels = [(m.name, m.landing) for m in named]
    for key in labels:
        if labels.count(key) > 1:
            twice = member_label(*key)
            raise InputError(f"{twice} is a member twice: a plan names each member once")
    given = [m.share is not None for m in named]
    if any(given) and not all(given):
        raise InputError("give every plan member a share, or none (equal shares)")
    plain = all(
        m.landing is None and m.name == pf.part.name
        for m, pf in zip(named, push_functions, strict=True)
    )
    if plain and not any(given) and all(m.accept for m in named):
        return None
    if not any(m.accept for m in named):
        raise InputError("every member is rejected: accept at least one landing")
    return named


def _member_weights(
    named: tuple[PlanMember, ...] | None,
) -> tuple[tuple[float, ...] | None, frozenset[int]]:
    """The members' normalised shares (None: equal) and the indices of the rejected ones."""
    if named is None:
        return None, frozenset()
    shares = None
    if named and named[0].share is not None:
        shares = normalised_shares([float(m.share or 0.0) for m in named], len(named))
    return shares, frozenset(k for k, m in enumerate(named) if not m.accept)


FINEST_REL = 1e-6
"""The sensor that stands for "any finer sensor": a tolerance of this fraction of the mix's
largest part (as exact as readings get; closer diameters are one value to the machine)."""


def _finest_machine(pfs: Sequence[PushFunction], unc: Uncertainty) -> PushAlignMachine:
    """The mix's machine with the finest sensor (:data:`FINEST_REL`)."""
    size = max(pf.part.size for pf in pfs)
    return build_machine(pfs, ToleranceSensor(FINEST_REL * size), unc)


def _check_rejects_separable(
    machine: PushAlignMachine,
    named: Sequence[PlanMember],
    finest: Callable[[], PushAlignMachine],
) -> None:
    """PlanningError when an accepted and a rejected member have states no plan can tell
    apart (section 8.4): no plan can then accept the one and reject the other. The advice
    names a finer sensor only when the pair comes apart with the finest one (``finest()``:
    the same parts and uncertainty with :data:`FINEST_REL`'s sensor); otherwise no sensor
    helps (the same push-diameter function, Lemma 8, or the same under the uncertainty)."""
    space = search_space(machine)
    bisimilar, rejected = space.bisimilar, space.rejected
    for i, s in enumerate(machine.states):
        if s.reject or not bisimilar[i] & rejected:
            continue
        other = machine.states[members(bisimilar[i] & rejected)[0]]
        a, b = named[s.part], named[other.part]
        fine = finest()
        index = {(x.part, x.state): k for k, x in enumerate(fine.states)}
        apart = (
            not search_space(fine).bisimilar[index[(s.part, s.state)]]
            >> index[(other.part, other.state)]
            & 1
        )
        sensor = "a sensor" if not machine.sensor.informative else "a finer sensor"
        advice = (
            f"accept both or neither, or use {sensor}"
            if apart
            else "accept both or neither: no sensor tells them apart"
        )
        raise PlanningError(
            f"{member_label(a.name, a.landing)} is accepted and "
            f"{member_label(b.name, b.landing)} rejected, but no plan can tell them apart "
            f"(their readings and push behaviour stay alike): {advice}"
        )


def _plan_dict(
    result: PlanResult,
    push_functions: Sequence[PushFunction],
    named: tuple[PlanMember, ...] | None,
    shares: tuple[float, ...] | None,
) -> dict[str, Any]:
    """The plan file's object of a planner's result, its parts named by ``named`` (with the
    normalised ``shares``; design.md plan file v2)."""
    if named is None:
        return plan_to_dict(result, push_functions)
    if shares is not None:
        named = tuple(replace(m, share=x) for m, x in zip(named, shares, strict=True))
    return plan_to_dict(result, push_functions, members=named)


RESOLUTION_REL = 1e-9
"""A sensor whose reading reach is below this fraction of the largest part's size cannot be
told from the rounding of the diameters (``DIAMETER_REL_EPS`` snaps them at this scale)."""


def _check_resolution(sensor: Sensor, push_functions: Sequence[PushFunction]) -> None:
    """Bad input: a sensor finer than the diameters themselves are known (a tolerance of
    1e-300 mm would make every reading interval empty in floating point)."""
    reach = sensor.reading_reach()
    if not math.isfinite(reach) or not push_functions:
        return
    floor = RESOLUTION_REL * max(pf.part.size for pf in push_functions)
    if reach / 2.0 < floor:
        raise InputError(
            f"the sensor's resolution ({reach / 2.0:.3g} mm) is finer than the parts' "
            f"diameters are known ({floor:.3g} mm, a billionth of the part's size): "
            "give a larger sensor tolerance or pitch"
        )


def with_uncertainty(data: dict[str, Any], uncertainty: Uncertainty) -> dict[str, Any]:
    """The plan file's object with ``"uncertainty"`` right after ``"sensor"`` (design.md)."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key == "uncertainty":
            continue
        out[key] = value
        if key == "sensor":
            out["uncertainty"] = uncertainty.to_dict()
    return out


VIBRATION_OBSTACLE = (
    "a strong plan exists only on the ideal model (rotation error 0): what leaves none is not "
    "the rotation error but the feeder's vibration, which any declared uncertainty switches "
    f"on (a push starting within {PUSH_BAND_DEG:g}° of a hilltop may end on either side, the "
    "push bands, and fragile states merge: docs/uncertainty.md), so no smaller rotation error "
    "helps; --rotation-error 0 plans on the ideal model, with no margin for that vibration"
)
"""The largest rotation error with a strong plan, in words, when it is 0 and nothing else is
declared: every positive rotation error switches the vibration on (push bands, merged fragile
states), and that is what no plan survives, however small the rotation error."""


def largest_uncertainty(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    uncertainty: Uncertainty,
    options: PlanningOptions,
    seconds: float | None = None,
    build: Callable[[Uncertainty], PushAlignMachine] | None = None,
) -> str:
    """In words: the largest rotation error (and shape tolerance) with a strong plan.

    ``build`` makes the machine at an uncertainty (by default the parts' plain machine; a
    plan's own caller passes the one it planned on: members' shares and rejected landings,
    the parts' own widths), so the figure is the plan's.

    Bisection over machine builds (a strong plan existing at an uncertainty exists at every
    smaller one: outcome sets and reading intervals shrink), ``BISECT_STEPS`` steps, or
    fewer when ``seconds`` run out (the bound found so far is then a lower one). When
    neither bisection finds a plan, the shape and COM tolerances leave none even with no
    rotation error: :func:`_tolerance_words` says which to loosen.
    """
    u = uncertainty
    stop = None if seconds is None else time.monotonic() + max(seconds, 0.0)

    def exists(unc: Uncertainty) -> bool | None:
        """Whether a strong plan exists at ``unc``; None when not decided in time."""
        left = None if stop is None else max(stop - time.monotonic(), 0.0)
        machine = build_machine(push_functions, sensor, unc) if build is None else build(unc)
        return _decided_exists(machine, options, left)

    at_zero_is_ideal = Uncertainty(0.0, u.shape_tolerance_mm, u.com_tolerance_mm).is_ideal
    words = []
    r = _largest(
        exists,
        lambda x: Uncertainty(x, u.shape_tolerance_mm, u.com_tolerance_mm),
        u.rotation_error_deg,
    )
    if r.value is None and not r.done:
        return "the largest uncertainty with a strong plan was not found within the time limit"
    if r.value is not None:
        words.append(r.said("rotation error", "deg", vibration=at_zero_is_ideal))
    if u.shape_tolerance_mm > 0.0:
        t = _largest(
            exists,
            lambda x: Uncertainty(u.rotation_error_deg, x, u.com_tolerance_mm),
            u.shape_tolerance_mm,
        )
        if t.value is not None:
            words.append(t.said("shape tolerance", "mm"))
    if not words:
        return _tolerance_words(u, exists)
    return " and ".join(words)


def _decided_exists(
    machine: PushAlignMachine, options: PlanningOptions, seconds: float | None
) -> bool | None:
    """Whether a strong plan exists for ``machine`` (:func:`strong_plan_exists`); None when
    not decided within ``seconds`` (None: no limit)."""
    budget = Deadline(seconds)
    found = strong_plan_exists(machine, options, budget)
    if budget.end is not None and time.perf_counter() > budget.end:
        return None
    return found


@dataclass(frozen=True)
class _Largest:
    """A bisection's answer: ``value`` the largest value with a plan (None: none, or
    undecided at 0), ``done`` whether it finished, ``width`` its final bracket's width."""

    value: float | None
    done: bool
    width: float

    def said(self, what: str, unit: str, *, vibration: bool = False) -> str:
        """In words; ``vibration``: 0 is the ideal model, so a plan only at 0 means the
        vibration any positive value switches on leaves none (:data:`VIBRATION_OBSTACLE`)."""
        value = self.value or 0.0
        if self.done and value == 0.0 and vibration:
            return VIBRATION_OBSTACLE
        if self.done and value > 0.0:
            # A bisection: a plan at ``value`` (printed rounded down), none a bracket above.
            return (
                f"the largest {what} with a strong plan is at least {at_most(value, 4)} {unit} "
                f"(bisected to {self.width:.2g} {unit})"
            )
        if self.done:
            return f"a strong plan exists only with no {what} at all (0 {unit})"
        return (
            f"a strong plan exists at {what} {at_most(value, 4)} {unit} (larger values were not "
            "decided within the time limit)"
        )


def _largest(
    exists: Callable[[Uncertainty], bool | None],
    make: Callable[[float], Uncertainty],
    top: float,
) -> _Largest:
    """The largest value in [0, ``top``] at which ``make(value)`` has a strong plan, bisected
    ``BISECT_STEPS`` times (``exists`` None: out of time, the bound so far is a lower one)."""
    at_zero = exists(make(0.0))
    if not at_zero:
        return _Largest(None, at_zero is not None, top)
    lo, hi = 0.0, top
    for _ in range(BISECT_STEPS):
        mid = (lo + hi) / 2.0
        found = exists(make(mid))
        if found is None:
            return _Largest(lo, False, hi - lo)
        lo, hi = (mid, hi) if found else (lo, mid)
    return _Largest(lo, True, hi - lo)


def _tolerance_words(u: Uncertainty, exists: Callable[[Uncertainty], bool | None]) -> str:
    """In words, when no rotation error, however small, has a strong plan under the declared
    shape and COM tolerances (nor any shape tolerance under the declared rotation error):
    the tolerances are what is left to loosen. Names the COM tolerance when it alone leaves
    none, and the largest rotation error with a plan once both are 0. Only when that is 0 is
    the feeder's vibration, which any positive rotation error switches on, the cause
    (tried first, at the bisection's smallest step: the one machine build it then takes)."""
    declared = [
        f"{what} {value:g} mm"
        for what, value in (
            ("shape tolerance", u.shape_tolerance_mm),
            ("COM tolerance", u.com_tolerance_mm),
        )
        if value > 0.0
    ]
    lead = (
        f"even with rotation error 0 the {' and '.join(declared)} "
        f"{'leave' if len(declared) > 1 else 'leaves'} no strong plan"
    )
    if u.rotation_error_deg > 0.0:
        least = u.rotation_error_deg / 2.0**BISECT_STEPS
        if exists(Uncertainty(least)) is False:
            return (
                f"{lead}, nor does any rotation error without "
                f"{'them' if len(declared) > 1 else 'it'}: {VIBRATION_ONLY}"
            )
    flags = "a smaller --shape-tolerance or --com-tolerance"
    if u.shape_tolerance_mm == 0.0:
        flags = "a smaller --com-tolerance"
    elif u.com_tolerance_mm == 0.0:
        flags = "a smaller --shape-tolerance"
    elif exists(Uncertainty(0.0, 0.0, u.com_tolerance_mm)) is False:
        flags = (
            f"a smaller --com-tolerance: the COM tolerance {u.com_tolerance_mm:g} mm alone "
            "leaves none"
        )
    words = f"{lead}: what is left to loosen is the tolerance{'s' * (len(declared) > 1)}, {flags}"
    if u.rotation_error_deg == 0.0:
        return (
            f"{words}; with neither, on the ideal model, a plan exists, with no margin for "
            "the feeder's vibration"
        )
    them = "them" if len(declared) > 1 else "it"
    if exists(Uncertainty(u.rotation_error_deg)):
        return (
            f"{words}; without {them} the declared rotation error {u.rotation_error_deg:g} deg "
            "has a strong plan"
        )
    bare = _largest(exists, lambda x: Uncertainty(x), u.rotation_error_deg)
    return f"{words}; without {them} {bare.said('rotation error', 'deg')}"


VIBRATION_ONLY = (
    "what leaves none is the feeder's vibration, which any declared uncertainty switches on (a "
    f"push starting within {PUSH_BAND_DEG:g}° of a hilltop may end on either side, the push "
    "bands, and fragile states merge: docs/uncertainty.md); only the ideal model (rotation "
    "error 0, no shape or COM tolerance) has a plan, with no margin for that vibration"
)
""":func:`_tolerance_words`' cause when no rotation error above 0 has a strong plan even
without the declared tolerances (:data:`VIBRATION_OBSTACLE`'s case, the tolerances too)."""


NAMED_MEMBERS = 6
""":func:`blocking_members` names at most this many members, then counts the rest."""


@dataclass(frozen=True)
class Blame:
    """Why a mix has no strong plan, member by member (:func:`blocking_members`): ``words``
    for the message ("" when there is nothing to say) and ``members``, the indices of the
    members blamed (none: the pairs between members, or nothing decided)."""

    words: str = ""
    members: tuple[int, ...] = ()


def blocking_members(
    pfs: Sequence[PushFunction],
    sensor: Sensor,
    unc: Uncertainty,
    options: PlanningOptions,
    offsets: Offsets,
    named: Sequence[PlanMember] | None,
    seconds: float | None = None,
) -> Blame:
    """The members of a mix with no strong plan that leave it none (section 8.5: the mix's
    plan orients every member, so one no strong plan orients alone leaves the mix none,
    whatever the others): the accepted members no strong plan orients even alone, then
    the landings of one part that each have a plan alone but none together, both accepted
    (only planning one side helps there: an accepted and a rejected landing no plan tells
    apart leave no plan either, docs/changeovers.md). Each check is a machine of one or two
    members, each read over its ``offsets`` as the mix's is; they stop when ``seconds`` run
    out (an undecided member is not blamed). With everything decided and none to blame, the words
    say that the pairs between members leave no plan."""
    if len(pfs) < 2:
        return Blame()
    stop = None if seconds is None else time.monotonic() + max(seconds, 0.0)
    rejected = set() if named is None else {k for k, m in enumerate(named) if not m.accept}

    def exists(ks: tuple[int, ...]) -> bool | None:
        left = None if stop is None else stop - time.monotonic()
        if left is not None and left <= 0.0:
            return None
        machine = build_machine([pfs[k] for k in ks], sensor, unc)
        machine = widen_widths(machine, [offsets[k] for k in ks])
        return _decided_exists(machine, options, left)

    verdicts = {k: exists((k,)) for k in range(len(pfs)) if k not in rejected}
    alone = [k for k, found in verdicts.items() if found is False]
    pairs = [p for p in _landing_pairs(named) if not set(p) & set(alone)]
    together = {p: exists(p) for p in pairs}
    sides = [p for p, found in together.items() if found is False]
    decided = None not in verdicts.values() and None not in together.values()
    words = []
    if alone:
        # A failing landing whose part has another landing in the mix: plan that one.
        others = named is not None and any(
            named[k].landing is not None and any(b in verdicts and b not in alone for b in p)
            for k in alone
            for p in _landing_pairs(named)
            if k in p
        )
        words.append(_alone_words([pfs[k].part.name for k in alone], others))
    if sides:
        words.append(_sides_words(pfs, named, sides))
    if not words and decided:
        words.append(
            "every member has a strong plan alone: what leaves none is states of different "
            "members that must be told apart (the pairs between members)"
        )
    blamed = dict.fromkeys([*alone, *(k for p in sides for k in p)])
    return Blame("; ".join(words), tuple(blamed))


def _landing_pairs(named: Sequence[PlanMember] | None) -> list[tuple[int, int]]:
    """The pairs of accepted members that are two landings of one part (a rejected landing
    is checked with the mix, not alone or in a pair)."""
    if named is None:
        return []
    return [
        (a, b)
        for a, m in enumerate(named)
        for b in range(a + 1, len(named))
        if m.landing is not None
        and named[b].landing is not None
        and named[b].name == m.name
        and m.accept
        and named[b].accept
    ]


def _alone_words(names: Sequence[str], landings: bool) -> str:
    """The members no strong plan orients even alone, and what to do, in words
    (``landings``: some is a landing whose part has another that may be planned)."""
    shown = list(names[:NAMED_MEMBERS])
    if len(names) > NAMED_MEMBERS:
        shown.append(f"{len(names) - NAMED_MEMBERS} more")
    one = len(names) == 1
    listed = shown[0] if len(shown) == 1 else f"{', '.join(shown[:-1])} and {shown[-1]}"
    out = "leave it out of the mix" if one else "leave them out of the mix"
    if landings:
        out += " (a landing: plan the others, --landings)"
    return (
        f"{listed} {'has' if one else 'have'} no strong plan even alone at the declared "
        f"uncertainty: {out}, or loosen the declared uncertainty"
    )


def _sides_words(
    pfs: Sequence[PushFunction],
    named: Sequence[PlanMember] | None,
    sides: Sequence[tuple[int, int]],
) -> str:
    """The landings of one part that each have a strong plan alone but none together, and
    the one remedy: plan only one side (``--landings``)."""
    assert named is not None
    listed = "; ".join(f"{pfs[a].part.name} and {pfs[b].part.name}" for a, b in sides)
    side = named[sides[0][0]].landing
    return (
        f"two landings of one part each have a strong plan alone but none together "
        f"({listed}): plan only one side (--landings {side})"
    )
