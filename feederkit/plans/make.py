"""Make a verified plan file for one part or a mix: machine, planner, file, verification.

Every plan is verified before anyone writes or prints it; a plan that fails is a bug,
reported as CheckFailed with the first counterexample (docs/architecture.md). The planning
options arrive as one validated :class:`PlanningOptions` value, the declared uncertainty as
one :class:`~feederkit.uncertainty.Uncertainty` (design.md's default: rotation error 1
degree). On the ideal model the plan is verified on the kinematic model
(:func:`~feederkit.plans.verify.check_plan`); under uncertainty it is a strong plan, verified
for every outcome and reading (:func:`~feederkit.plans.strong.verify_strong`). Every plan
carries its certificate (:class:`~feederkit.planning.tree.Certificate`, made by
:mod:`~feederkit.plans.certify` within its share of the time limit,
:mod:`~feederkit.plans.timelimit`); its warnings, and the reasons when no plan meets the
request, are worded by :mod:`~feederkit.plans.advice`.

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

from feederkit.errors import InputError, PlanningError
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.machine.build import build_machine
from feederkit.machine.weights import normalised_shares, weigh_members
from feederkit.machine.widths import widen_widths
from feederkit.mechanics.modelerror import exact_push_function, largest_offset, part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.planning.api import plan as plan_machine
from feederkit.planning.budget import collector_paused
from feederkit.planning.lumping import lumped_words
from feederkit.planning.options import PlanningOptions
from feederkit.planning.solvable import NoStrongPlan
from feederkit.planning.tree import Leaf as TreeLeaf
from feederkit.planning.tree import PlanResult, PlanTree, leaf_masks
from feederkit.planning.tree import Step as TreeStep
from feederkit.plans.advice import (
    SMALLER_ERROR_S,
    blocking_members,
    drawing_distance_words,
    lump_shapes,
    short_chords_words,
    smaller_error_words,
    spread_words,
    thin_branch_words,
    ties_cut_words,
    unlike_twins_words,
)
from feederkit.plans.certify import certificate, ideal_length, largest_uncertainty
from feederkit.plans.fileformat import member_keys, plan_to_dict, result_nodes
from feederkit.plans.model import PlanMember, ideal_plan_words, low_margin_words, member_label
from feederkit.plans.readplan import as_plan
from feederkit.plans.strong import ideal_view, verify_strong
from feederkit.plans.timelimit import (
    OUTPUT_SHARE,
    output_seconds,
    planner_budget,
    seconds_left,
)
from feederkit.plans.verify import VerificationReport, check_plan
from feederkit.plans.verify import expected_operations as file_expected
from feederkit.sensors import Sensor, ToleranceSensor, sensor_warnings
from feederkit.uncertainty import IDEAL, Uncertainty, check_for_part

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
    tell apart (:func:`~feederkit.plans.advice.unlike_twins_words`): the words saying so (a
    command exits 1)."""
    holds_nothing: str | None = None
    """When the plan is the ideal model's and its certificate holds no rotation error at all
    on a feeder that vibrates (:func:`~feederkit.plans.model.ideal_plan_words`): a result to
    act on, in words (a command exits 1): such a plan fails on the belt with an exact robot
    (a drop near a hilltop goes either way)."""


def make_plan(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    certify: bool = True,
    members: Sequence[PlanMember] | None = None,
    weights: Sequence[float] | None = None,
    started: float | None = None,
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
    ``started`` is the :func:`time.monotonic` instant the options' time limit counts from
    (None: now): a command passes its own start, so that reading its parts counts too.
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
            started=started,
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
    started: float | None,
) -> MadePlan:
    """:func:`make_plan`'s work."""
    opts = PlanningOptions() if options is None else options
    if not isinstance(opts, PlanningOptions):
        raise InputError(f"the planning options must be PlanningOptions, got {opts!r}")
    unc = Uncertainty() if uncertainty is None else uncertainty
    if not isinstance(unc, Uncertainty):
        raise InputError(f"the uncertainty must be an Uncertainty, got {unc!r}")
    if started is None:
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
    budget = planner_budget(opts, started, certify, strong=not unc.is_ideal)
    try:
        result = plan_machine(machine, opts, budget=budget)
    except NoStrongPlan as exc:
        left = seconds_left(opts, started)
        blame = blocking_members(
            pfs, sensor, unc, opts, offsets, named, None if left is None else left / 2.0
        )
        largest = largest_uncertainty(
            pfs,
            sensor,
            unc,
            opts,
            seconds_left(opts, started),
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
        # Still "no strong plan exists" (its callers may add to it), with what it blames.
        raise NoStrongPlan(f"{exc.reason}{who}; {largest}", hint.removeprefix("; ")) from None
    # Planned on the parts' own widths, the plan's expected length is restated on the file's
    # model (its diameters), the one every reader computes.
    widened = machine is not unwidened
    if unc.is_ideal:
        data = with_uncertainty(_plan_dict(result, pfs, named, shares), unc)
        if widened:
            data["stats"]["expected_length"] = file_expected(as_plan(data))
        listed = _entries(data)
        walk = time.monotonic()
        report = check_plan(data, prune=True)
        if _entries(data) != listed and _time_left(opts, started, time.monotonic() - walk):
            report = check_plan(data)  # its counts (runs ending unrecognized) are the file's
    else:
        ideal = weigh_members(build_machine(pfs, sensor, IDEAL), shares, rejected)
        ideal = widen_widths(ideal, offsets)
        data = with_uncertainty(_plan_dict(ideal_view(result, ideal), pfs, named, shares), unc)
        # Its paths and its margins: a margin the rebuilt model finds more than some state at
        # the node keeps is lowered to what it keeps, so the file claims no more than holds.
        listed = _entries(data)
        walk = time.monotonic()
        report = verify_strong(data, tighten_margins=True, restate_expected=widened, prune=True)
        if _entries(data) != listed and _time_left(opts, started, time.monotonic() - walk):
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
    # What the caller needs to write and show the plan (measured idle: as loaded now); the
    # certificate and the advice below take only what is left besides.
    output_s = output_seconds(data) * budget.slowness() if certify else 0.0
    if certify:
        cert, cut = certificate(data, unc, opts, started, output_s)
        if not unc.is_ideal:
            cert = replace(cert, ideal_length=ideal_length(ideal, opts, started, output_s))
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
        left = seconds_left(opts, started, OUTPUT_SHARE if certify else 0.0, output_s)
        smaller = smaller_error_words(
            lambda u: widen_widths(weighed(u), offsets),
            unc,
            result.machine,
            result.lumped_pairs,
            SMALLER_ERROR_S if left is None else min(SMALLER_ERROR_S, max(left, 0.0)),
        )
        warnings.append(lumped + lump_shapes(result.machine, pfs, result.lumped_pairs) + smaller)
    spread = spread_words(result, pfs)
    if spread is not None:
        warnings.append(spread)
    thin = thin_branch_words(data, sensor, unc)
    if thin is not None:
        warnings.append(thin)
    drawn = drawing_distance_words(pfs, unc, result.certificate)
    if drawn is not None:
        warnings.append(drawn)
    unoriented = unlike_twins_words(result, pfs)
    cut = ties_cut_words(result, opts)
    if cut is not None:
        warnings.append(cut)
    margin = low_margin_words(result.min_margin, unc.rotation_error_deg)
    if margin is not None:
        warnings.append(
            f"{margin}; ask for a minimum margin or check the plan with feederkit simulate"
        )
    held = ideal_plan_words(unc, result.min_margin, result.certificate)
    nothing = None
    if held is not None:
        warnings.append(held)
        if result.certificate is not None and result.certificate.max_rotation_error_deg <= 0.0:
            nothing = HOLDS_NOTHING_WORDS
    return MadePlan(data, result, report, tuple(warnings + notes), unoriented, nothing)


HOLDS_NOTHING_WORDS = (
    "the plan is the ideal model's and holds no rotation error on a feeder that vibrates "
    "(see the warning): by the planner's model of such a feeder, a drop near a hilltop may go "
    "either way even with an exact robot; plan with --rotation-error DEG, or check this plan "
    "with feederkit simulate before it goes to the line"
)
"""The result line of a plan that :attr:`MadePlan.holds_nothing`."""


def _time_left(opts: PlanningOptions, started: float, walk_s: float) -> bool:
    """Whether the time limit (if any) leaves time for one more walk of the plan, which
    takes about as long as the last one (``walk_s``), besides the output's share: the plan
    in hand's verification may have taken the certificate's reserve."""
    left = seconds_left(opts, started, OUTPUT_SHARE)
    return left is None or left > walk_s


def _entries(data: Mapping[str, Any]) -> int:
    """How many entries the results of the plan file's object ``data`` list."""
    return sum(len(node["result"]) for node in result_nodes(data))


def listed_tree(result: PlanResult, data: dict[str, Any]) -> PlanTree:
    """The planner's tree with each leaf's mask cut to the states its result in the plan
    file's object ``data`` (written from that tree, then pruned) still lists: a state stays
    when one of its ideal members is listed there.

    The tree is rebuilt along the file: a leaf the planner shares between places whose
    results were pruned apart (a chain's last reading set, also a root branch's) becomes one
    leaf per place; a subplan the planner shares and the file writes once (its ``nodes``
    table, pruned in place for all its places) stays one object, and one whose leaves keep
    their masks is the planner's own.
    """
    machine = result.machine
    index = member_keys([(part["name"], part.get("landing")) for part in data["parts"]])
    shared = data.get("nodes") or {}

    def resolve(raw: Any) -> Any:
        while "ref" in raw:
            raw = shared[raw["ref"]]
        return raw

    def cut(leaf: TreeLeaf, raw: Any) -> TreeLeaf:
        names = {(index[(e["part"], e.get("landing"))], e["state"]) for e in raw["result"]}
        mask = 0
        for i in members(leaf.mask):
            ms = machine.states[i]
            if any((ms.part, m) in names for m in ms.ideal_states):
                mask |= 1 << i
        return leaf if mask == leaf.mask else TreeLeaf(mask)

    made: dict[tuple[int, int], PlanTree] = {}  # (tree node id, file node id): rebuilt
    top = (result.root, resolve(data["root"]))
    stack: list[tuple[PlanTree, Any, bool]] = [(*top, False)]
    while stack:  # children before their parent, on an explicit stack (plans can be long)
        node, raw, ready = stack.pop()
        key = (id(node), id(raw))
        if key in made:
            continue
        if isinstance(node, TreeLeaf):
            made[key] = cut(node, raw)
            continue
        pairs = [
            (child, resolve(b["next"]))
            for (_b, child), b in zip(node.branches, raw["branches"], strict=True)
        ]
        if not ready:
            stack.append((node, raw, True))
            stack.extend((c, r, False) for c, r in pairs if (id(c), id(r)) not in made)
            continue
        subs = tuple(
            (b, made[(id(c), id(r))])
            for (b, _old), (c, r) in zip(node.branches, pairs, strict=True)
        )
        same = all(new is old for (_b, new), (_c, old) in zip(subs, node.branches, strict=True))
        made[key] = node if same else TreeStep(node.action, subs)
    return made[(id(top[0]), id(top[1]))]


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
