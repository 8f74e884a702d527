"""Make a verified plan file for one part or a mix: machine, planner, file, verification.

Every plan is verified on the kinematic model before anyone writes or prints it; a plan that
fails is a bug, reported as CheckFailed with the first counterexample.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from feederkit.machine import build_machine
from feederkit.mechanics.push import PushFunction
from feederkit.planning.api import plan as plan_machine
from feederkit.planning.tree import PlanResult
from feederkit.plans.fileformat import plan_to_dict
from feederkit.plans.verify import VerificationReport, check_plan
from feederkit.sensors import SensorModel


@dataclass(frozen=True)
class MadePlan:
    """A plan file's object, the planner's result it came from, and its verification."""

    plan: dict[str, Any]
    result: PlanResult
    report: VerificationReport


def make_plan(
    parts: Sequence[PushFunction],
    sensor: SensorModel,
    *,
    objective: str = "worst",
    min_margin: float = 0.0,
    grouping: str = "exact",
    time_limit: float | None = None,
) -> MadePlan:
    """Plan for ``parts`` (one part, or a mix: section 8.5) and verify the plan file.

    Raises InputError for bad options, PlanningError when no plan meets the request, and
    CheckFailed when the plan fails verification.
    """
    machine = build_machine(list(parts), sensor)
    result = plan_machine(
        machine,
        objective=objective,  # type: ignore[arg-type]
        min_margin=min_margin,
        grouping=grouping,
        time_limit=time_limit,
    )
    data = plan_to_dict(result, parts)
    return MadePlan(data, result, check_plan(data))
