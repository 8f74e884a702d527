"""``design sensor``: which sensor a mix needs, and what plan it then gets (docs/design.md).

For a tolerance sensor: every pair's exact critical tolerance and the mix's (the largest
tolerance at which it is recognizable, section 8.5 and Theorem 9), and the optimal plan
length as a step function of the tolerance up to it. For an LED array: the same, pitch by
pitch. Every figure is for strong plans at the declared uncertainty (design.md,
"Uncertainty"; :mod:`feederkit.design.strong`); with all three bounds zero it is the ideal
model, decided by :mod:`feederkit.design.critical` and :mod:`feederkit.design.steps`.

The members may be landings, some of them rejected (design.md, "Landings"; ``changeover
compile --accept``): the design is then of the plans that tell the accepted landings apart
from each other and from the rejected ones, and end the rejected ones in reject results, as
:func:`feederkit.plans.make.make_plan` plans them (:func:`landing_design_members`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from feederkit.design.critical import (
    MixCritical,
    PairCritical,
    mix_critical_tolerance,
    rejected_of,
)
from feederkit.design.limit import DesignClock, DesignTimeout, Progress
from feederkit.design.pitches import PitchRow, pitch_rows
from feederkit.design.steps import BREAKPOINT_REL_EPS, LengthStep, length_steps
from feederkit.design.strong import (
    StrongMix,
    strong_length_steps,
    strong_mix_critical,
    uncertainty_words,
)
from feederkit.errors import InputError
from feederkit.landing.model import Landing
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import landing_members, member_name, rejected_members
from feederkit.planning.budget import Timeout
from feederkit.planning.options import PlanningOptions
from feederkit.plans.advice import blocking_members
from feederkit.plans.make import check_plan_members
from feederkit.plans.model import Plan, PlanMember
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty
from feederkit.words import shown_tolerance

MODEL_NOTE = "ideal model: plans assume no rotation error"
"""The model note of the ideal model (all three bounds zero)."""


def model_note(uncertainty: Uncertainty) -> str:
    """Which model the figures are for, in words."""
    if uncertainty.is_ideal:
        return MODEL_NOTE
    return f"strong plans at the declared uncertainty ({uncertainty_words(uncertainty)})"


def uncertainty_dict(uncertainty: Uncertainty) -> dict[str, object]:
    """The output's ``uncertainty``: design.md's three bounds, applied to every figure."""
    return {**uncertainty.to_dict(), "applied": True}


def _check_mix(pfs: Sequence[PushFunction]) -> None:
    if len(pfs) < 2:
        raise InputError(
            "design sensor compares the parts of a mix: give at least two parts "
            "(one part alone is recognized with any sensor)"
        )


def landing_design_members(
    landings: Sequence[Landing], accept: Collection[str] | None = None
) -> tuple[PlanMember, ...]:
    """The members of a design over ``landings``: ``changeover compile``'s
    (:func:`feederkit.mix.changeover.landing_members`: the same names, accept/reject and
    validation of ``accept``, the landing names the next station takes; None: every
    landing), weighed alike (no shares: the design's expected figures weigh its members
    alike, docs/design.md)."""
    return tuple(replace(m, share=None) for m in landing_members(landings, accept))


def plan_members(
    plan: Mapping[str, Any], view: Plan | None = None
) -> tuple[PlanMember, ...] | None:
    """The members of a plan file (a stored changeover's) for its design: each part entry's
    name and landing, accepted unless the plan's reject results name it
    (:func:`feederkit.mix.changeover.rejected_members`), weighed alike; None for a plan of
    parts (no landings, nothing rejected), designed as its parts. ``view``: the plan already
    read (``as_plan``), not read again (a 16 MB plan takes 1.5 s)."""
    parts = list(plan.get("parts", []))
    out = rejected_members(plan if view is None else view)
    if not out and all(p.get("landing") is None for p in parts):
        return None
    return tuple(
        PlanMember(
            p["name"], p.get("landing"), None, member_name(p["name"], p.get("landing")) not in out
        )
        for p in parts
    )


def _checked_members(
    members: Sequence[PlanMember] | None, pfs: Sequence[PushFunction]
) -> tuple[PlanMember, ...] | None:
    """``members`` as given, checked as :func:`~feederkit.plans.make.make_plan` checks them
    (one per push function, each once, at least one accepted), so a design refuses what the
    plans it describes would refuse, with the same words."""
    if members is None:
        return None
    named = tuple(members)
    check_plan_members(named, pfs)
    return named


LISTED_REJECTS = 6
"""Rejected members the one-line answer names (the JSON's ``landings`` lists them all)."""


def _rejected_words(parts: Sequence[str], members: Sequence[PlanMember] | None) -> str:
    """``; the plan rejects A, B, C`` naming the rejected members (empty: none)."""
    out = [parts[k] for k in sorted(rejected_of(members))]
    if not out:
        return ""
    shown = ", ".join(out[:LISTED_REJECTS])
    more = len(out) - LISTED_REJECTS
    return f"; the plan rejects {shown}" + (f" and {more} more" if more > 0 else "")


def member_landing_rows(members: Sequence[PlanMember] | None) -> list[dict[str, Any]]:
    """The JSON's ``landings``: ``part``, ``landing`` and ``accept`` of each member that is a
    landing, in member order (none for a design of parts), as ``changeover compile --json``
    lists them."""
    return [
        {"part": m.name, "landing": m.landing, "accept": m.accept}
        for m in members or ()
        if m.landing is not None
    ]


def _model_words(
    parts: Sequence[str], members: Sequence[PlanMember] | None, u: Uncertainty, said: str
) -> str:
    """An answer's end: the members the plans reject, then the model they are for, unless
    ``said`` (the answer so far) names the uncertainty already (a pair's reason does)."""
    named = uncertainty_words(u)
    words = "" if u.is_ideal or named in said else f" (strong plans, {named})"
    return _rejected_words(parts, members) + words


def _pairs_words(pairs: Sequence[PairCritical], limit: int = 5) -> str:
    words = [f"{p.a} and {p.b}" for p in pairs[:limit]]
    more = len(pairs) - limit
    text = ", ".join(words) + (f" and {more} more pairs" if more > 0 else "")
    reasons = {p.witness.reason for p in pairs if p.witness is not None}
    if len(reasons) == 1:
        text += f" ({reasons.pop()})"
    return text


@dataclass(frozen=True)
class ToleranceDesign:
    """The critical tolerances of a mix and its plan length's steps up to the mix's, at the
    declared ``uncertainty``."""

    parts: tuple[str, ...]
    critical: MixCritical
    steps: tuple[LengthStep, ...]
    uncertainty: Uncertainty = IDEAL
    stopped: str | None = None
    """A partial design (``design_tolerance(..., partial=True)`` at its limit): why the
    length table is missing, every pair being decided; None for a whole design."""
    members: tuple[PlanMember, ...] | None = None
    """The members as planned (landings, accept/reject; None: the parts, each accepted)."""
    blame: str = ""
    """Where no strong plan exists at any tolerance the pairs allow: which members leave the
    mix none (one no strong plan orients even alone: :func:`~feederkit.plans.advice.
    blocking_members`), as ``changeover compile`` says; "" when not asked or not decided."""

    @property
    def rejected(self) -> tuple[str, ...]:
        """The members (named as ``parts``) the plans reject: they end in reject results."""
        return tuple(self.parts[k] for k in sorted(rejected_of(self.members)))

    @property
    def complete(self) -> bool:
        """Whether the length table was built (the design is not partial)."""
        return self.stopped is None

    @property
    def plan_limit(self) -> LengthStep | None:
        """The first step below the pairs' critical tolerance where the plan does not
        recognize the mix (no strong plan there, or one that lists two parts together):
        the mix is recognizable only up to its start. None when there is no such step."""
        x = self.critical.critical_tolerance
        if x is None:
            return None
        top = x * (1.0 - BREAKPOINT_REL_EPS)
        return next((s for s in self.steps if s.lo < top and not s.recognizable), None)

    @property
    def critical_tolerance(self) -> float | None:
        """The largest tolerance (mm) up to which the mix is recognizable; None: none.

        The pairs' (every pair distinguishable, section 8.5), lowered to the start of
        :attr:`plan_limit` when strong plans fail below it (docs/design.md).
        """
        x = self.critical.critical_tolerance
        if self.stopped is not None and not self.uncertainty.is_ideal:
            # Strong plans may fail below the pairs' tolerance: undecided without the table.
            return None
        limit = self.plan_limit
        if x is None or limit is None:
            return x
        return limit.lo if limit.lo > 0.0 else None

    @property
    def recognizable(self) -> bool:
        """Whether some tolerance makes the mix recognizable."""
        return self.critical_tolerance is not None

    def step_at(self, tolerance: float) -> LengthStep | None:
        """The step holding ``tolerance`` (None beyond the table)."""
        slack = BREAKPOINT_REL_EPS * abs(tolerance)
        for s in self.steps:
            if s.lo < tolerance - slack and (s.hi is None or tolerance <= s.hi + slack):
                return s
        return None

    def _model_words(self, said: str = "") -> str:
        """The answer's end (:func:`_model_words`)."""
        return _model_words(self.parts, self.members, self.uncertainty, said)

    def answer(self) -> str:
        """The design in one line, naming the members it rejects and the uncertainty it is
        for."""
        x = self.critical_tolerance
        pairs_x = self.critical.critical_tolerance
        if self.stopped is not None and pairs_x is not None:
            if x is not None:  # the ideal model: the pairs' tolerance is the mix's
                text = f"this mix is recognizable with a tolerance up to {shown_tolerance(x)} mm"
            else:
                text = (
                    f"every pair of this mix is told apart up to {shown_tolerance(pairs_x)} mm, "
                    "so no larger tolerance recognizes it; whether one strong plan does up to it "
                    "was not decided"
                )
            return f"{text}{self._model_words()}; {self.stopped}"
        if x is None:
            limit = self.plan_limit
            if self.critical.inseparable or limit is None:
                text = "no tolerance makes this mix recognizable: no sensor separates "
                text += _pairs_words(self.critical.inseparable)
                return text + self._model_words(text)
            where = "at any tolerance" if limit.hi is None else f"up to {limit.hi:.6g} mm"
            why = f" ({self.blame})" if self.blame else ""
            return (
                f"no tolerance makes this mix recognizable: {_limit_words(limit)} {where}{why}"
                + self._model_words()
            )
        step = self.step_at(x)
        text = f"this mix is recognizable with a tolerance up to {shown_tolerance(x)} mm"
        if step is not None and step.length is not None and step.expected is not None:
            text += (
                f"; with it the plan takes {step.length} operations (expected {step.expected:.4g})"
            )
        elif self.steps and self.steps[-1].hi is not None:
            text += f" (plan lengths tabulated up to {self.steps[-1].hi:.6g} mm only)"
        if self.plan_limit is not None:
            text += "; above it " + _limit_words(self.plan_limit)
        return text + self._model_words()

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``design sensor --json`` for a tolerance sensor (docs/design.md)."""
        return {
            "sensor_model": "tolerance",
            "parts": list(self.parts),
            "landings": member_landing_rows(self.members),
            "critical_tolerance_mm": self.critical_tolerance,
            "pairs": [p.to_dict() for p in self.critical.pairs],
            "lengths": [s.to_dict() for s in self.steps],
            "complete": self.complete,
            "stopped": self.stopped,
            "uncertainty": uncertainty_dict(self.uncertainty),
            "model": model_note(self.uncertainty),
            "answer": self.answer(),
        }


def _uncertainty(uncertainty: Uncertainty | None) -> Uncertainty:
    if uncertainty is None:
        return IDEAL
    if not isinstance(uncertainty, Uncertainty):
        raise InputError(f"the uncertainty must be an Uncertainty, got {uncertainty!r}")
    return uncertainty


def design_tolerance(
    pfs: Sequence[PushFunction],
    *,
    max_tolerance: float | None = None,
    uncertainty: Uncertainty | None = None,
    time_limit_s: float | None = None,
    progress: Progress | None = None,
    memory_limit_mb: float | None = None,
    partial: bool = False,
    members: Sequence[PlanMember] | None = None,
) -> ToleranceDesign:
    """Critical tolerances and length steps at ``uncertainty`` (default the ideal model);
    the steps reach the mix's critical tolerance, or ``max_tolerance`` (mm) when given
    (beyond the critical one the mix is not recognized, its plans end in results that name
    several parts). InputError for a shape tolerance too large for a part.

    ``time_limit_s``: seconds (None: no limit), ``memory_limit_mb``: the process's size
    (None: no limit); past either DesignTimeout, a PlanningError naming the limit and what
    was decided (:mod:`feederkit.design.limit`). With ``partial``, a limit passed after
    every pair is decided gives the design without its length table instead
    (:attr:`ToleranceDesign.stopped` says why; under uncertainty its critical tolerance is
    then undecided, the pairs' bounding it from above). ``progress(what, done, total)`` is
    told of each pair, goal probe and run of the table.

    ``members`` (one per push function, as :func:`~feederkit.plans.make.make_plan` takes
    them and checks them, InputError alike; None: the parts, each accepted): the design is
    then of the plans for those members, as ``changeover compile --accept`` makes them
    (:func:`landing_design_members`): two rejected members need not be told apart, an
    accepted one must be told from every other member, and a set of rejected members'
    states only ends in a reject result.
    """
    _check_mix(pfs)
    if max_tolerance is not None and not max_tolerance > 0.0:
        raise InputError(f"--max-tolerance must be a positive number of mm, got {max_tolerance}")
    unc = _uncertainty(uncertainty)
    named = _checked_members(members, pfs)
    clock = DesignClock(time_limit_s, progress, memory_limit_mb)
    try:
        return _design_tolerance(pfs, max_tolerance, unc, clock, partial, named)
    except Timeout as exc:
        raise clock.timeout(exc.reason) from None


def _design_tolerance(
    pfs: Sequence[PushFunction],
    max_tolerance: float | None,
    unc: Uncertainty,
    clock: DesignClock,
    partial: bool = False,
    members: tuple[PlanMember, ...] | None = None,
) -> ToleranceDesign:
    names = tuple(pf.part.name for pf in pfs)
    if unc.is_ideal:
        offsets = part_offsets(pfs)  # the parts' own widths, as the plans read them
        critical = mix_critical_tolerance(pfs, clock, rejected_of(members), offsets)
        up_to = max_tolerance if max_tolerance is not None else critical.critical_tolerance

        def table() -> tuple[LengthStep, ...]:
            return length_steps(
                pfs, up_to, critical=critical, clock=clock, members=members, offsets=offsets
            )
    else:
        mix = StrongMix(pfs, unc, members)
        critical = strong_mix_critical(mix, clock)
        up_to = max_tolerance if max_tolerance is not None else critical.critical_tolerance

        def table() -> tuple[LengthStep, ...]:
            return strong_length_steps(mix, up_to, critical, clock=clock)

    if up_to is None:
        return ToleranceDesign(names, critical, (), unc, members=members)
    try:
        return _blamed(pfs, ToleranceDesign(names, critical, table(), unc, members=members), clock)
    except Timeout as exc:
        if not partial:
            raise
        stopped = str(clock.timeout(exc.reason, partial=True))
        return ToleranceDesign(names, critical, (), unc, stopped, members)


BLAME_SHARE = 0.5
"""The share of the design's time left that saying which members leave no strong plan may take."""


def _blamed(
    pfs: Sequence[PushFunction], design: ToleranceDesign, clock: DesignClock
) -> ToleranceDesign:
    """``design`` with its :attr:`~ToleranceDesign.blame` where no strong plan exists from
    the finest tolerance on: the members no strong plan orients even alone (or two landings
    of one part together), checked with a sensor inside that first step, within
    ``BLAME_SHARE`` of the time left."""
    limit = design.plan_limit
    if design.uncertainty.is_ideal or limit is None or limit.length is not None or limit.lo > 0.0:
        return design
    top = limit.hi if limit.hi is not None else design.critical.critical_tolerance
    if top is None:
        return design
    left = clock.deadline.remaining()
    blame = blocking_members(
        pfs,
        ToleranceSensor(top / 2.0),
        design.uncertainty,
        PlanningOptions(),
        part_offsets(pfs),
        design.members,
        None if left is None else BLAME_SHARE * left,
    )
    return replace(design, blame=blame.words) if blame.members else design


@dataclass(frozen=True)
class PitchDesign:
    """LED pitches decided one by one, and the pairs no sensor at all can separate."""

    parts: tuple[str, ...]
    noise: float
    rows: tuple[PitchRow, ...]
    critical: MixCritical
    uncertainty: Uncertainty = IDEAL
    members: tuple[PlanMember, ...] | None = None
    """The members as planned (landings, accept/reject; None: the parts, each accepted)."""

    @property
    def rejected(self) -> tuple[str, ...]:
        """The members (named as ``parts``) the plans reject: they end in reject results."""
        return tuple(self.parts[k] for k in sorted(rejected_of(self.members)))

    @property
    def critical_pitch(self) -> float | None:
        """The largest pitch of the list that makes the mix recognizable (None: none does)."""
        ok = [r.pitch for r in self.rows if r.recognizable]
        return max(ok) if ok else None

    @property
    def recognizable(self) -> bool:
        """Whether some pitch of the list makes the mix recognizable."""
        return self.critical_pitch is not None

    def _model_words(self, said: str = "") -> str:
        """The answer's end (:func:`_model_words`)."""
        return _model_words(self.parts, self.members, self.uncertainty, said)

    def answer(self) -> str:
        """The design in one line, naming the members it rejects and the uncertainty it is
        for."""
        y = self.critical_pitch
        if y is None:
            text = "no LED pitch in the list makes this mix recognizable"
            worst = sorted({p for r in self.rows for p in r.unrecognizable})
            if self.critical.inseparable:
                text += ": no sensor separates " + _pairs_words(self.critical.inseparable)
            elif worst:
                text += ": it cannot tell apart " + ", ".join(f"{a} and {b}" for a, b in worst[:5])
                text += "; try finer pitches"
            else:
                text += ": no strong plan exists with any of them"
            return text + self._model_words(text)
        row = next(r for r in self.rows if r.pitch == y)
        return (
            f"this mix is recognizable with an LED pitch of {y:.6g} mm "
            f"(noise {self.noise:.6g} mm); with it the plan takes {row.length} operations "
            f"(expected {row.expected:.4g})" + self._model_words()
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``design sensor --json`` for an LED array (docs/design.md)."""
        return {
            "sensor_model": "led",
            "parts": list(self.parts),
            "landings": member_landing_rows(self.members),
            "noise_mm": self.noise,
            "critical_pitch_mm": self.critical_pitch,
            "pitches": [r.to_dict() for r in self.rows],
            "critical_tolerance_mm": self.critical.critical_tolerance,
            "pairs": [p.to_dict() for p in self.critical.pairs],
            "uncertainty": uncertainty_dict(self.uncertainty),
            "model": model_note(self.uncertainty),
            "answer": self.answer(),
        }


def design_pitches(
    pfs: Sequence[PushFunction],
    pitches: Sequence[float],
    *,
    noise: float = 0.0,
    uncertainty: Uncertainty | None = None,
    time_limit_s: float | None = None,
    progress: Progress | None = None,
    memory_limit_mb: float | None = None,
    members: Sequence[PlanMember] | None = None,
) -> PitchDesign:
    """Each pitch decided on its own at ``uncertainty`` (default the ideal model;
    :mod:`feederkit.design.pitches`), and the pairs' exact critical tolerances, which name
    the pairs no sensor can separate. ``time_limit_s``, ``memory_limit_mb``, ``progress``
    and ``members`` as for :func:`design_tolerance`."""
    _check_mix(pfs)
    if not pitches:
        raise InputError("--pitches is empty: give pitches in mm, e.g. 0.1,0.2,0.5")
    if noise < 0.0:
        raise InputError(f"--noise must be zero or a positive number of mm, got {noise}")
    unc = _uncertainty(uncertainty)
    named = _checked_members(members, pfs)
    clock = DesignClock(time_limit_s, progress, memory_limit_mb)
    names = tuple(pf.part.name for pf in pfs)
    try:
        if unc.is_ideal:
            offsets = part_offsets(pfs)
            rows = pitch_rows(pfs, pitches, noise, clock=clock, members=named, offsets=offsets)
            critical = mix_critical_tolerance(pfs, clock, rejected_of(named), offsets)
            return PitchDesign(names, noise, rows, critical, unc, named)
        mix = StrongMix(pfs, unc, named)
        rows = pitch_rows(pfs, pitches, noise, mix=mix, clock=clock)
        return PitchDesign(names, noise, rows, strong_mix_critical(mix, clock), unc, named)
    except Timeout as exc:
        raise clock.timeout(exc.reason) from None


REPORT_DESIGN_LIMIT_S = 60.0
"""Seconds a changeover report gives its sensor design (``feederkit design sensor`` has its
own ``--time-limit``): a report must come out even for a mix whose design takes minutes."""


def report_design(
    pfs: Sequence[PushFunction],
    uncertainty: Uncertainty | float | None = None,
    time_limit_s: float | None = REPORT_DESIGN_LIMIT_S,
    members: Sequence[PlanMember] | None = None,
) -> dict[str, Any] | None:
    """The sensor design a changeover report shows (``ToleranceDesign.to_dict``) at the
    changeover's ``uncertainty`` (its plan file's; a number is a rotation error in degrees
    with exact shapes; None the ideal model), or None for a single part (nothing to tell
    apart). ``members``: the changeover's (:func:`plan_members` of its plan file), so the
    design is of plans that reject what it rejects. DesignTimeout past ``time_limit_s``
    (:func:`report_design_or_warning`)."""
    if len(pfs) < 2:
        return None
    if isinstance(uncertainty, int | float):
        uncertainty = Uncertainty(float(uncertainty), 0.0, 0.0)
    return design_tolerance(
        list(pfs), uncertainty=uncertainty, time_limit_s=time_limit_s, members=members
    ).to_dict()


def report_design_or_warning(
    pfs: Sequence[PushFunction],
    uncertainty: Uncertainty | float | None = None,
    members: Sequence[PlanMember] | None = None,
) -> tuple[dict[str, Any] | None, str | None]:
    """:func:`report_design` within ``REPORT_DESIGN_LIMIT_S``, or None with the one warning a
    report gives when the design is not decided by then: a report is written with the
    section or without it, never not at all (docs/reports.md)."""
    time_limit_s = REPORT_DESIGN_LIMIT_S
    try:
        return report_design(pfs, uncertainty, time_limit_s, members), None
    except DesignTimeout:
        return None, (
            f"the report leaves out the sensor design: not decided within {time_limit_s:g} s "
            "(feederkit design sensor --time-limit S decides it)"
        )


def _limit_words(step: LengthStep) -> str:
    """Why a step's plan does not recognize the mix."""
    if step.length is None:
        return "no strong plan exists"
    return "the strong plan lists states of two parts together"
