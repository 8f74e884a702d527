"""The words that say why a result is as it is and what would change it.

On a made plan: warnings that it holds less than its margins say on a feeder that vibrates,
that the choice among shortest plans was cut short, that results lump poses (and whether a
smaller rotation error or tighter tolerances would tell them apart), that results list
unlike poses no plan can tell apart (the paper's indistinguishable poses) or spread over
shallow wells. When no strong plan exists: the members that leave a mix none (section 8.5)
and the short hull edges a shape tolerance tilts.
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
from feederkit.hull import contact_hull, hull_distance
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.machine.build import build_machine
from feederkit.machine.widths import Offsets, widen_widths
from feederkit.mechanics.modelerror import keeping_tolerance
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.symmetry import (
    NEAR_SYMMETRIC_REL,
    look_alike,
    poses_differences,
)
from feederkit.part import make_part
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.lumping import may_lump, unresolvable_pairs
from feederkit.planning.options import Lumping, PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.tree import Certificate, PlanResult, leaf_masks
from feederkit.plans.certify import decided_exists
from feederkit.plans.fileformat import distinct_nodes
from feederkit.plans.model import PlanMember
from feederkit.sensors import Sensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty
from feederkit.words import plural

THIN_BRANCH_SHARE = 0.01
"""A reading branch narrower than this share of a tolerance sensor's window (twice its
tolerance) tells states apart by diameters closer than the sensor can read."""


def thin_branch_words(
    plan: Mapping[str, Any], sensor: Sensor, uncertainty: Uncertainty
) -> str | None:
    """A warning when a plan made for parts exactly as drawn (shape tolerance 0) has reading
    branches narrower than :data:`THIN_BRANCH_SHARE` of the sensor's window, else None.

    Two states whose diameters differ by d leave a branch d wide at each end of the window
    they share (section 5's tolerance model): a reading there names one of them, which holds
    only while the parts are made to better than d. A 0.05 mm drawing difference between two
    parts gave a 0.0007 mm branch under a 0.1 mm sensor; with a declared shape tolerance the
    model covers the parts' own spread instead.

    >>> root = {"action_deg": None, "margin_deg": None, "branches": [
    ...     {"reading": [9.9, 10.1], "next": {"result": []}},
    ...     {"reading": [10.1, 10.1005], "next": {"result": []}}]}
    >>> thin_branch_words({"root": root}, ToleranceSensor(0.1), IDEAL)[:40]
    '1 reading branch is narrower than 1% of '
    """
    if not isinstance(sensor, ToleranceSensor) or uncertainty.shape_tolerance_mm > 0.0:
        return None
    least = THIN_BRANCH_SHARE * 2.0 * sensor.tolerance
    thin = [
        b["reading"]
        for node in distinct_nodes(plan)
        if len(node.get("branches") or ()) > 1
        for b in node["branches"]
        if b.get("reading") is not None and b["reading"][1] - b["reading"][0] < least
    ]
    if not thin:
        return None
    lo, hi = min(thin, key=lambda r: r[1] - r[0])
    return (
        f"{plural(len(thin), 'reading branch is', 'reading branches are')} narrower than "
        f"{THIN_BRANCH_SHARE:.0%} of the sensor's window of ±{sensor.tolerance:g} mm (the "
        f"narrowest {hi - lo:.2g} mm, reads {lo:.6g} .. {hi:.6g} mm): a reading there tells "
        "states apart by diameters closer than that, as drawn; a part made to a looser "
        "tolerance may read in another's branch: declare it with --shape-tolerance"
    )


def ties_cut_words(result: PlanResult, options: PlanningOptions) -> str | None:
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


CHORD_RUN = 3
"""Short hull edges (within twice the shortest) this many in a row look like an arc drawn as
chords; fewer are the part's own short edges (a small part's chamfer), and the hint does not
guess an arc (:func:`short_chords_words`)."""


def _chord_run(hull: Sequence[tuple[float, float]], shortest: float) -> int:
    """The most consecutive hull edges (around the closed hull) no longer than twice
    ``shortest``."""
    n = len(hull)
    short = [math.dist(hull[i], hull[(i + 1) % n]) <= 2.0 * shortest for i in range(n)]
    if all(short):
        return n
    start = short.index(False)  # count runs from an edge that is not short: none wraps
    best = run = 0
    for k in range(1, n + 1):
        run = run + 1 if short[(start + k) % n] else 0
        best = max(best, run)
    return best


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
    # An arc is guessed only where short edges come in a run (CHORD_RUN): a small part's
    # own short edge is no arc, and fewer arc points cannot lengthen it.
    arc = _chord_run(pf.part.hull, length) >= CHORD_RUN
    head = (
        f"; {name}'s contact hull has edges as short as {length:.3g} mm"
        f"{' (an arc drawn as many chords?)' if arc else ''}, which the shape tolerance may "
        f"tilt by {tilt:.3g} degrees, each then a possible resting edge near a corner: a "
        "smaller --shape-tolerance"
        + (
            ", or an outline with fewer arc points (a coarser tessellation in a mesh's CAD export)"
            if arc
            else ""
        )
    )
    coarser = coarser_kept_hull(pf, t)
    if coarser is not None:
        return (
            f"{head}, or the part imported with --hull-tolerance {coarser:.3g} (its resting "
            "states kept, no edge that short), may have a plan (docs/uncertainty.md)"
        )
    if not arc:  # one remedy: no comma before its verb
        return f"{head} may have a plan (docs/uncertainty.md)"
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
    Pairs the lumping listed together because its rule allowed poses that do not look alike
    (``lumped_pairs``, lumping ``any``) are left to its warning; a lumped pair the machine
    records as alike (``MachineState.alike``: no plan tells it apart even on the ideal model,
    :func:`~feederkit.machine.build.ideal_twins`) is named here, as on the ideal model, where it
    is inseparable and never lumped: the part is not oriented between them whatever the
    rotation error."""
    machine = result.machine
    lumped = set(result.lumped_pairs)
    listed: list[tuple[int, list[int]]] = []  # (part, its states a leaf lists together)
    for mask in leaf_masks(result.root):
        by_part: dict[int, list[int]] = {}
        for i in members(mask):
            if not machine.states[i].reject:  # a reject result needs no telling apart
                by_part.setdefault(machine.states[i].part, []).append(i)
        listed.extend((part, idx) for part, idx in by_part.items() if len(idx) > 1)
    # One comparison per part of the states its leaves list: look_alike decides pair by
    # pair, and a dense outline's boundary is then sampled once per pose, not once per leaf.
    alike: dict[int, set[tuple[int, int]]] = {}
    for part in {part for part, _idx in listed}:
        used = sorted({i for p, idx in listed if p == part for i in idx})
        near = look_alike(pfs[part], [machine.states[i].ideal_states for i in used])
        alike[part] = {(i, used[k]) for i, row in zip(used, near, strict=True) for k in row}
    found: dict[tuple[int, int], None] = {}
    for part, idx in listed:
        for a, i in enumerate(idx):
            for j in idx[a + 1 :]:
                if (i, j) in alike[part]:
                    continue
                if (i, j) not in lumped or machine.states[i].alike(machine.states[j]):
                    found[(i, j)] = None
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


def spread_words(result: PlanResult, pfs: Sequence[PushFunction]) -> str | None:
    """A warning naming the results that end in a physical state of several unlike stable
    states (shallow wells a breath of vibration crosses: a part resting anywhere over their
    poses, docs/uncertainty.md), with the angle their normals span; None when there are
    none. Congruent ones (a regular polygon's) orient the part and are not named."""
    machine = result.machine
    merged = {
        i: machine.states[i]
        for mask in leaf_masks(result.root)
        for i in members(mask)
        if len(machine.states[i].members) > 1
    }
    # Per part, one comparison of every member of its merged states (pair by pair alike).
    alike: dict[int, set[tuple[int, int]]] = {}
    for part in {s.part for s in merged.values()}:
        poses = sorted({m for s in merged.values() if s.part == part for m in s.members})
        near = look_alike(pfs[part], [(m,) for m in poses])
        alike[part] = {(m, poses[k]) for m, row in zip(poses, near, strict=True) for k in row}
    found: dict[int, float] = {}
    for i, s in merged.items():
        pairs = [(a, b) for k, a in enumerate(s.members) for b in s.members[k + 1 :]]
        if all((a, b) in alike[s.part] for a, b in pairs):
            continue
        pf = pfs[s.part]
        normals = [pf.states[m].normal_deg for m in s.members]
        found[i] = norm360(normals[-1] - normals[0])
    if not found:
        return None
    named = "; ".join(
        f"{machine.part_names[machine.states[i].part]} states "
        f"{', '.join(str(m) for m in machine.states[i].members)} over {spread:.3g} degrees"
        for i, spread in sorted(found.items(), key=lambda kv: -kv[1])
    )
    return resting_spread_words(named)


def resting_spread_words(named: str) -> str:
    """The warning of :func:`spread_words` around ``named`` (``PART states 1, 2 over 28
    degrees; ...``): ``plan`` says it of the machine, the report of the plan file."""
    return (
        f"some results name a resting state made of several stable states, shallow wells a "
        f"breath of vibration crosses (docs/uncertainty.md): {named}; there the part rests "
        "anywhere over those poses, oriented only that far"
    )


SMALLER_ERROR_FACTOR = 1e-3
"""A rotation error this fraction of the declared one stands for "a smaller rotation error":
:func:`smaller_error_words` asks whether the lumped pairs are still unresolvable there."""

PRACTICAL_ROTATION_ERROR_DEG = 0.01
"""The finest rotation error a cell can keep (deg): a robot's wrist repeats to about ±0.01
degree at best, and the drop onto the belt adds more. A smaller rotation error that helps
only below it is named as out of reach, not as a remedy (:func:`smaller_error_words`)."""

SMALLER_ERROR_DIGITS = 2
"""Significant digits of the largest rotation error :func:`smaller_error_words` names: it
bisects (geometrically) over rotation errors of this many digits, a figure a user can pass
to ``--rotation-error`` as is, and stops when no such figure lies between what helps and
what does not (a step of 1-10 %)."""

SMALLER_ERROR_S = 5.0
"""The most seconds :func:`smaller_error_words` spends deciding (less when the time limit
leaves less); undecided, it says a smaller rotation error may or may not help."""


@dataclass(frozen=True)
class _Reach:
    """The largest rotation error found at which a strong plan tells the helped pairs apart
    (``deg``, checked there): ``decided`` when the search ended (no figure of
    :data:`SMALLER_ERROR_DIGITS` digits left between it and one that fails), ``practical``
    False when it is below :data:`PRACTICAL_ROTATION_ERROR_DEG` though the declared error
    is not (:data:`PRACTICAL_ROTATION_ERROR_DEG` itself fails)."""

    deg: float
    decided: bool = True
    practical: bool = True


def _between(lo: float, hi: float) -> float | None:
    """The rotation error of :data:`SMALLER_ERROR_DIGITS` significant digits nearest the
    geometric mean of ``lo`` and ``hi`` and strictly between them; None when there is none."""
    mean = math.sqrt(lo * hi)
    step = 10.0 ** (math.floor(math.log10(mean)) - SMALLER_ERROR_DIGITS + 1)
    down = math.floor(mean / step) * step
    for x in sorted((down, down + step), key=lambda x: abs(x - mean)):
        x = float(f"{x:.{SMALLER_ERROR_DIGITS}g}")
        if lo < x < hi:
            return x
    return None


def largest_helping_error(helps: Callable[[float], bool | None], good: float, bad: float) -> _Reach:
    """The largest rotation error at which ``helps`` (whether a strong plan tells the pairs
    apart there; None: undecided in time) holds, given that it holds at ``good`` and not at
    ``bad`` (the declared error). Bisection (telling apart at a rotation error tells apart
    at every smaller one: outcome sets shrink) over figures of
    :data:`SMALLER_ERROR_DIGITS` digits, after one look at
    :data:`PRACTICAL_ROTATION_ERROR_DEG` when it lies between: a user needs the largest a
    robot can keep, or to know that none it can keep would do."""
    floor = PRACTICAL_ROTATION_ERROR_DEG
    if good < floor < bad:
        at_floor = helps(floor)
        if at_floor is None:
            return _Reach(good, decided=False)
        if not at_floor:
            return _Reach(good, practical=False)
        good = floor
    while (mid := _between(good, bad)) is not None:
        found = helps(mid)
        if found is None:
            return _Reach(good, decided=False)
        good, bad = (mid, bad) if found else (good, mid)
    return _Reach(good)


def _reach_words(reach: _Reach, them: str) -> tuple[str, str]:
    """How far a smaller rotation error helps, in words: what follows "a smaller rotation
    error helps" ("" or " only below" the practical floor) and where it tells ``them`` (the
    pairs it helps) apart."""
    at = f"±{reach.deg:.{SMALLER_ERROR_DIGITS + 1}g} deg"
    if not reach.practical:
        limit = f" only below ±{PRACTICAL_ROTATION_ERROR_DEG:g} deg, finer than a robot turns"
        return limit, f"at {at} a strong plan tells {them} apart"
    if not reach.decided:
        return "", (
            f"at {at} a strong plan tells {them} apart (whether a larger rotation error does "
            "was not decided in time)"
        )
    return "", f"up to {at} a strong plan tells {them} apart"


_VIBRATION = (
    "the feeder's vibration, which any declared uncertainty switches on (push bands and "
    "merged fragile states: docs/uncertainty.md)"
)


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
    smaller rotation error helps", up to the largest rotation error that does
    (:func:`largest_helping_error`, with the time left: a figure a robot must keep, or
    "only below" :data:`PRACTICAL_ROTATION_ERROR_DEG` when none it can keep would do); else,
    told apart without the tolerances: a smaller --shape-tolerance / --com-tolerance helps;
    else the vibration keeps them together, or not even the ideal model tells them apart.
    The command line names a flag only where the words say it helps (``with_flags``).
    """
    r = uncertainty.rotation_error_deg
    tiny = replace(uncertainty, rotation_error_deg=r * SMALLER_ERROR_FACTOR)
    loose = uncertainty.shape_tolerance_mm > 0.0 or uncertainty.com_tolerance_mm > 0.0
    exact = replace(tiny, shape_tolerance_mm=0.0, com_tolerance_mm=0.0)
    if exact.is_ideal:  # nothing declared but the rotation error, and that is 0
        exact = replace(exact, rotation_error_deg=SMALLER_ERROR_FACTOR)
    stop = time.monotonic() + max(seconds, 0.0)
    built: dict[Uncertainty, PushAlignMachine] = {}

    def left_at(u: Uncertainty, among: Sequence[tuple[int, int]]) -> list[tuple[int, int]] | None:
        """The pairs of ``among`` still unresolvable at ``u`` (None: undecided in time)."""
        rest = stop - time.monotonic()
        if rest <= 0.0:
            return None
        try:
            at = built[u] = machine_at(u)
            found = unresolvable_pairs(Problem(at, "exact", 0.0), Deadline(rest))
        except Timeout:
            return None
        if found is None:
            return None
        kept = set(found)
        return [
            (i, j)
            for i, j in among
            if any(
                (min(x, y), max(x, y)) in kept
                for x in _alike(machine, i, at)
                for y in _alike(machine, j, at)
            )
        ]

    def reach(helped: Sequence[tuple[int, int]]) -> _Reach:
        """The largest rotation error telling the ``helped`` pairs apart with a strong plan
        for the whole machine (each pair told apart alone is not enough: a set of them may
        have none), in the time left."""
        options = PlanningOptions(lumping=_lumping_rule(machine, pairs))

        def helps(deg: float) -> bool | None:
            u = replace(uncertainty, rotation_error_deg=deg)
            still = left_at(u, helped)
            if still is None or still:
                return None if still is None else False
            rest = stop - time.monotonic()
            return decided_exists(built[u], options, rest) if rest > 0.0 else None

        return largest_helping_error(helps, tiny.rotation_error_deg, r)

    left = left_at(tiny, pairs) if r > 0.0 else list(pairs)
    at = f"±{tiny.rotation_error_deg:.3g} deg"
    if left is None:
        return (
            "; whether a smaller rotation error or tighter tolerances help was not decided: "
            f"they may or may not, since {_VIBRATION} may keep them together whatever they are"
        )
    if not left:
        limit, where = _reach_words(reach(pairs), "each pair")
        return f"; a smaller rotation error helps{limit}: {where}"
    helped = [p for p in pairs if p not in left]
    rest = _rest_words(machine_at, machine, pairs, left, exact if loose else None, left_at)
    if helped:
        # the rest is decided first: the search for the largest helping error takes the time left
        limit, where = _reach_words(reach(helped), "them")
        head = (
            f"; a smaller rotation error helps{limit}{',' * bool(limit)} "
            f"{plural(len(helped), 'pair')} only ({where}): at {at} {len(left)} of the "
            f"{len(pairs)} are still not told apart"
        )
    elif r > 0.0:
        head = f"; no smaller rotation error helps: at {at} they are still not told apart"
    else:
        head = ""
    return f"{head}{': ' if head else '; '}{rest}"


def _lumping_rule(machine: PushAlignMachine, pairs: Sequence[tuple[int, int]]) -> Lumping:
    """The strictest lumping rule that lists the lumped ``pairs`` together: ``any`` only when
    some pair's poses do not look alike (the plan's own rule is not passed here; a stricter
    one can only find a smaller helping rotation error, so the words stay true)."""
    strict = Lumping.NEAR_SYMMETRIC
    return strict if all(may_lump(machine, i, j, strict) for i, j in pairs) else Lumping.ANY


def _rest_words(
    machine_at: Callable[[Uncertainty], PushAlignMachine],
    machine: PushAlignMachine,
    pairs: Sequence[tuple[int, int]],
    left: list[tuple[int, int]],
    exact: Uncertainty | None,
    left_at: Callable[[Uncertainty, Sequence[tuple[int, int]]], list[tuple[int, int]] | None],
) -> str:
    """What keeps the ``left`` pairs (of ``pairs``, not told apart at the smallest rotation
    error) together, in words: the declared tolerances (``exact``, the uncertainty without
    them, when any is declared), the feeder's vibration, or not even the ideal model tells
    them apart (:func:`smaller_error_words`)."""
    if exact is not None:
        still = left_at(exact, left)
        if still is not None and len(still) < len(left):
            fixed = len(left) - len(still)
            which = "them" if not still else plural(fixed, "pair")
            return (
                f"the declared shape and COM tolerances keep {which} together: with none a "
                f"strong plan tells {which} apart (a smaller shape tolerance or COM "
                "tolerance helps)"
            )
        if still is None:
            return (
                f"the declared shape and COM tolerances or {_VIBRATION} keep them together "
                "(not decided which)"
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
            f"no rotation error helps, not even 0: the ideal model does not tell {which} "
            "apart either (the mix's pairs say why)"
        )
    return (
        f"{_VIBRATION} keeps them together, whatever else is declared; the ideal model (no "
        "uncertainty declared) plans with no margin for that vibration"
    )


def _alike(machine: PushAlignMachine, i: int, table: PushAlignMachine) -> list[int]:
    """The states of ``table`` that hold some ideal state of ``machine``'s state ``i``."""
    s = machine.states[i]
    ideal = set(s.ideal_states)
    return [
        k for k, t in enumerate(table.states) if t.part == s.part and ideal & set(t.ideal_states)
    ]


def lump_shapes(
    machine: PushAlignMachine, pfs: Sequence[PushFunction], pairs: Sequence[tuple[int, int]]
) -> str:
    """How alike the lumped poses of one part look (:func:`poses_difference`, the measure
    the default lumping rule bounds by ``NEAR_SYMMETRIC_REL``), in words: near symmetry the
    user can accept, or (lumping ``any``) a warning that the plan leaves them unoriented."""
    worst, size = 0.0, 1.0
    by_part: dict[int, list[tuple[tuple[int, ...], tuple[int, ...]]]] = {}
    for i, j in pairs:
        a, b = machine.states[i], machine.states[j]
        if a.part == b.part:  # parts that behave alike: reported as pairs of the mix
            by_part.setdefault(a.part, []).append((a.ideal_states, b.ideal_states))
    for part, sets in by_part.items():
        pf = pfs[part]
        d = float(np.max(poses_differences(pf, sets)))
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
        return decided_exists(machine, options, left)

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


def drawing_distance_words(
    pfs: Sequence[PushFunction], unc: Uncertainty, certificate: Certificate | None
) -> str | None:
    """One line when a part's drawing lies farther from the plan's hull (the import's
    simplification, ``--hull-tolerance``) than the plan's certified shape tolerance allows
    beyond the declared one: the certificate and the declared shape tolerance are measured
    from the plan's hulls, so a part made within the declared tolerance of its *drawing* is
    then not covered (a fillet plate imported at 0.05 mm lay 0.037 mm from its hull while its
    plan declared 0.01 mm). None when every drawing is covered, or with no certificate."""
    if certificate is None:
        return None
    held = certificate.max_shape_tolerance_mm
    t = unc.shape_tolerance_mm
    far = []
    for pf in pfs:
        part = pf.part
        d = hull_distance(contact_hull(part.outline.vertices), part.hull)
        if d > 1e-6 * part.size and held < d + t - 1e-9:
            far.append(f"{part.name}'s lies {d:.4g} mm from its hull")
    if not far:
        return None
    return (
        "the plan's hulls simplify the drawings (the import's hull tolerance): "
        + "; ".join(far)
        + f"; the plan holds a shape tolerance of {held:.4g} mm from its hulls, less than that "
        f"plus the declared {t:g} mm, so a part made within the declared tolerance of its "
        "drawing is not covered by the certificate: import with a smaller --hull-tolerance, "
        "or check the plan on the drawing with feederkit simulate --part"
    )
