"""Make a verified plan file for one part or a mix: machine, planner, file, verification.

Every plan is verified before anyone writes or prints it; a plan that fails is a bug,
reported as CheckFailed with the first counterexample (docs/architecture.md). The planning
options arrive as one validated :class:`PlanningOptions` value, the declared uncertainty as
one :class:`~feederkit.uncertainty.Uncertainty` (design.md's default: rotation error 1
degree). On the ideal model the plan is verified on the kinematic model
(:func:`~feederkit.plans.verify.check_plan`); under uncertainty it is a strong plan, verified
for every outcome and reading (:func:`~feederkit.plans.strong.verify_strong`). Every plan
carries its certificate (:class:`~feederkit.planning.tree.Certificate`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from feederkit.errors import InputError, PlanningError
from feederkit.machine.build import build_machine
from feederkit.mechanics.push import PushFunction
from feederkit.planning.api import NoStrongPlan, strong_plan_exists
from feederkit.planning.api import plan as plan_machine
from feederkit.planning.options import PlanningOptions
from feederkit.planning.tree import Certificate, PlanResult
from feederkit.plans.fileformat import plan_to_dict
from feederkit.plans.strong import (
    ideal_view,
    max_rotation_error_deg,
    max_shape_tolerance_mm,
    verify_strong,
)
from feederkit.plans.verify import VerificationReport, check_plan
from feederkit.sensors import Sensor, sensor_warnings
from feederkit.uncertainty import IDEAL, Uncertainty, check_for_part

ROBOT_MARGIN_DEG = 1.0
"""Below this smallest margin a plan relies on rotations more exact than a robot turns: a
rotation error of the margin's size sends the part across an action range's boundary
(section 3.2.2), so such a plan is flagged."""

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


def margin_warning(min_margin_deg: float) -> str | None:
    """One line when a plan's smallest margin is below :data:`ROBOT_MARGIN_DEG`, else None."""
    if not min_margin_deg < ROBOT_MARGIN_DEG:
        return None
    return (
        f"the plan's smallest margin is \u00b1{min_margin_deg:.2g}\u00b0: no robot holds "
        f"\u00b1{min_margin_deg:.2g}\u00b0, a rotation error that small can send the part to "
        "another state; ask for a minimum margin or check the plan with feederkit simulate"
    )


BISECT_STEPS = 12
"""Bisection steps for the largest uncertainty at which a strong plan exists (to 1/4096)."""


def make_plan(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    certify: bool = True,
) -> MadePlan:
    """Plan for ``push_functions`` (one part, or a mix: section 8.5) and verify the plan file.

    ``options`` default to ``PlanningOptions()``. ``uncertainty``
    defaults to ``Uncertainty()`` (rotation error 1 degree); ``IDEAL`` is the paper's model.
    ``certify=False`` skips the certificate (the plan file then has none; for callers that
    re-plan many times, such as property tests). The result's ``warnings`` flag (on the
    ideal model) a smallest margin below :data:`ROBOT_MARGIN_DEG` and a sensor that reads
    every state alike. Raises InputError
    for bad options or a shape tolerance too large for a part, PlanningError when no plan
    meets the request (under uncertainty: naming the largest uncertainty with a strong
    plan), and CheckFailed when the plan fails verification.
    """
    opts = PlanningOptions() if options is None else options
    if not isinstance(opts, PlanningOptions):
        raise InputError(f"the planning options must be PlanningOptions, got {opts!r}")
    unc = Uncertainty() if uncertainty is None else uncertainty
    if not isinstance(unc, Uncertainty):
        raise InputError(f"the uncertainty must be an Uncertainty, got {unc!r}")
    pfs = list(push_functions)
    for pf in pfs:
        check_for_part(unc, pf.part)
    _check_resolution(sensor, pfs)
    machine = build_machine(pfs, sensor, unc)
    try:
        result = plan_machine(machine, opts)
    except NoStrongPlan as exc:
        raise PlanningError(f"{exc}; {largest_uncertainty(pfs, sensor, unc, opts)}") from None
    if unc.is_ideal:
        data = with_uncertainty(plan_to_dict(result, pfs), unc)
        report = check_plan(data)
        ideal_length = result.length
    else:
        ideal = build_machine(pfs, sensor, IDEAL)
        data = with_uncertainty(plan_to_dict(ideal_view(result, ideal), pfs), unc)
        report = verify_strong(data)
        ideal_length = plan_machine(ideal, opts).length if certify else None
    if certify:
        cert = Certificate(
            max_rotation_error_deg=max_rotation_error_deg(data),
            max_shape_tolerance_mm=max_shape_tolerance_mm(data),
            ideal_length=ideal_length,
        )
        data["stats"]["certificate"] = cert.to_dict()
        result = replace(result, certificate=cert)
    diameters = sorted({round(s.diameter, DIAMETER_DIGITS) for pf in pfs for s in pf.states})
    warnings = sensor_warnings(sensor, diameters)
    margin = margin_warning(result.min_margin) if unc.is_ideal else None
    if margin is not None:
        warnings.append(margin)
    return MadePlan(data, result, report, tuple(warnings))


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


def largest_uncertainty(
    push_functions: Sequence[PushFunction],
    sensor: Sensor,
    uncertainty: Uncertainty,
    options: PlanningOptions,
) -> str:
    """In words: the largest rotation error (and shape tolerance) with a strong plan.

    Bisection over machine builds (a strong plan existing at an uncertainty exists at every
    smaller one: outcome sets and reading intervals shrink), ``BISECT_STEPS`` steps.
    """
    u = uncertainty

    def exists(unc: Uncertainty) -> bool:
        return strong_plan_exists(build_machine(push_functions, sensor, unc), options)

    def largest(make, top: float) -> float | None:
        if not exists(make(0.0)):
            return None
        lo, hi = 0.0, top
        for _ in range(BISECT_STEPS):
            mid = (lo + hi) / 2.0
            lo, hi = (mid, hi) if exists(make(mid)) else (lo, mid)
        return lo

    words = []
    r = largest(
        lambda x: Uncertainty(x, u.shape_tolerance_mm, u.com_tolerance_mm), u.rotation_error_deg
    )
    if r is not None:
        words.append(f"the largest rotation error with a strong plan is {r:.4g} deg")
    if u.shape_tolerance_mm > 0.0:
        t = largest(
            lambda x: Uncertainty(u.rotation_error_deg, x, u.com_tolerance_mm), u.shape_tolerance_mm
        )
        if t is not None:
            words.append(f"the largest shape tolerance with one is {t:.4g} mm")
    if not words:
        return (
            "even a rotation error near 0 leaves no strong plan: the resting states the "
            "vibration merges cannot be told apart; plan on the ideal model (rotation error 0)"
        )
    return " and ".join(words)
