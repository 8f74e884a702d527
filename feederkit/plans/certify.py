"""How much uncertainty a plan takes: its certificate, and the largest uncertainty with any
strong plan.

:func:`certificate` states a made plan's largest rotation error and shape tolerance
(:func:`~feederkit.plans.strong.max_rotation_error_deg`,
:func:`~feederkit.plans.strong.max_shape_tolerance_mm`) and :func:`ideal_length` its optimal
length on the ideal model, each within what is left of the time limit
(:class:`~feederkit.planning.tree.Certificate`). When no strong plan exists,
:func:`largest_uncertainty` bisects over machine builds for the largest declared uncertainty
at which one does (a strong plan at an uncertainty is one at every smaller one: outcome sets
and reading intervals shrink).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

from feederkit.machine import PushAlignMachine
from feederkit.machine.build import build_machine
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.uncertain import PUSH_BAND_DEG, ordinary_push_band_deg
from feederkit.planning.api import shortest_length, strong_plan_exists
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import PlanningOptions
from feederkit.planning.tree import Certificate
from feederkit.plans.strong import max_rotation_error_deg, max_shape_tolerance_mm
from feederkit.plans.timelimit import OUTPUT_SHARE, seconds_left
from feederkit.sensors import Sensor
from feederkit.uncertainty import Uncertainty
from feederkit.words import at_most


def certificate(
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
        left = seconds_left(options, started, OUTPUT_SHARE, output_s)
        try:
            figures.append(
                figure(data, deadline=None if left is None else Deadline(max(left, 0.0)))
            )
        except Timeout:
            figures.append(given)
            cut.append(name)
    rotation, shape = figures
    return Certificate(rotation, shape, None), cut


def ideal_length(
    ideal: PushAlignMachine, options: PlanningOptions, started: float, output_s: float = 0.0
) -> int | None:
    """The optimal length on the ideal model (the certificate's ``ideal_length``: the length
    search alone, ``shortest_length``), within what is left of the time limit less
    ``OUTPUT_SHARE`` of it and ``output_s`` seconds; None when no time is left or the length
    is not proven in it, or when the ideal model cannot meet the options (e.g. a margin
    floor it cannot keep)."""
    left = seconds_left(options, started, OUTPUT_SHARE, output_s)
    if left is not None and left <= 0.0:
        return None
    opts = options if left is None else replace(options, time_limit_s=left)
    return shortest_length(ideal, opts)


BISECT_STEPS = 12
"""Bisection steps for the largest uncertainty at which a strong plan exists (to 1/4096)."""


VIBRATION_OBSTACLE = (
    "a strong plan exists only on the ideal model (rotation error 0): what leaves none is not "
    "the rotation error but the feeder's vibration, which any declared uncertainty switches "
    "on ({push_band}, the push bands, a push may roll on over a shallow well, and fragile "
    "states merge: docs/uncertainty.md), so no smaller rotation error helps; "
    "--rotation-error 0 plans on the ideal model, with no margin for that vibration"
)
"""The largest rotation error with a strong plan, in words, when it is 0 and nothing else is
declared: every positive rotation error switches the vibration on (push bands, merged fragile
states), and that is what no plan survives, however small the rotation error. A template:
``push_band`` is :func:`push_band_words` of the parts."""


def push_band_words(push_functions: Sequence[PushFunction]) -> str:
    """The words "a push starting within B° of a hilltop may end on either side", B the push
    band the parts have at an ordinary hilltop (:func:`~feederkit.mechanics.uncertain.
    ordinary_push_band_deg`): :data:`PUSH_BAND_DEG`, wider on a small slender part (up to
    ``SLENDER_BAND_DEG``), which is named; over a mix, the range and the widest part."""
    bands = {pf.part.name: ordinary_push_band_deg(pf.part) for pf in push_functions}
    name, widest = max(bands.items(), key=_second, default=("", PUSH_BAND_DEG))
    narrowest = min(bands.values(), default=PUSH_BAND_DEG)
    if widest <= PUSH_BAND_DEG:
        within = f"{PUSH_BAND_DEG:g}° of a hilltop"
    elif narrowest == widest:  # a part's landings, or slender parts alike
        within = f"{widest:.3g}° of a hilltop (the band of a small slender part)"
    else:
        within = (
            f"{narrowest:.3g}-{widest:.3g}° of a hilltop ({widest:.3g}° on {name}, a small "
            "slender part)"
        )
    return f"a push starting within {within} may end on either side"


def _second(item: tuple[str, float]) -> float:
    return item[1]


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
        left = None if stop is None else stop - time.monotonic()
        if left is not None and left <= 0.0:
            return None  # out of time: no machine built for nothing (each build costs)
        machine = build_machine(push_functions, sensor, unc) if build is None else build(unc)
        return decided_exists(machine, options, left)

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
        band = push_band_words(push_functions) if at_zero_is_ideal else ""
        words.append(r.said("rotation error", "deg", vibration=band))
    if u.shape_tolerance_mm > 0.0:
        t = _largest(
            exists,
            lambda x: Uncertainty(u.rotation_error_deg, x, u.com_tolerance_mm),
            u.shape_tolerance_mm,
        )
        if t.value is not None:
            words.append(t.said("shape tolerance", "mm"))
    if not words:
        return _tolerance_words(u, exists, push_band_words(push_functions))
    return " and ".join(words)


def decided_exists(
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

    def said(self, what: str, unit: str, *, vibration: str = "") -> str:
        """In words; ``vibration`` (when 0 is the ideal model): the parts' push band words
        (:func:`push_band_words`), for a plan only at 0, which means the vibration any
        positive value switches on leaves none (:data:`VIBRATION_OBSTACLE`)."""
        value = self.value or 0.0
        if self.done and value == 0.0 and vibration:
            return VIBRATION_OBSTACLE.format(push_band=vibration)
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


def _tolerance_words(
    u: Uncertainty, exists: Callable[[Uncertainty], bool | None], push_band: str
) -> str:
    """In words, when no rotation error, however small, has a strong plan under the declared
    shape and COM tolerances (nor any shape tolerance under the declared rotation error):
    the tolerances are what is left to loosen. Names the COM tolerance when it alone leaves
    none, and the largest rotation error with a plan once both are 0. Only when that is 0 is
    the feeder's vibration, which any positive rotation error switches on, the cause
    (tried first, at the bisection's smallest step: the one machine build it then takes;
    ``push_band``: :func:`push_band_words` of the parts)."""
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
                f"{'them' if len(declared) > 1 else 'it'}: "
                f"{VIBRATION_ONLY.format(push_band=push_band)}"
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
    "what leaves none is the feeder's vibration, which any declared uncertainty switches on "
    "({push_band}, the push bands, a push may roll on over a shallow well, and fragile states "
    "merge: docs/uncertainty.md); only the ideal model (rotation error 0, no shape or COM "
    "tolerance) has a plan, with no margin for that vibration"
)
""":func:`_tolerance_words`' cause when no rotation error above 0 has a strong plan even
without the declared tolerances (:data:`VIBRATION_OBSTACLE`'s case, the tolerances too). A
template: ``push_band`` is :func:`push_band_words` of the parts."""
