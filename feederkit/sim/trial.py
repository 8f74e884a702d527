"""Execute a plan on the simulated feeder for one part and one start orientation.

A controller executes a node by rotating the part by ``action_deg`` (none at the root),
letting it align, reading the width and following the branch whose closed interval holds
the reading (design.md). Here the rotation starts from where the part really rests in the
simulation, the robot adds its rotation error, and MuJoCo does the aligning.
"""

from __future__ import annotations

from collections.abc import Callable

from feederkit.angles import norm360
from feederkit.mechanics.push import PushFunction, push
from feederkit.sim.planfile import Leaf, PlanPart, SimPlan, Step
from feederkit.sim.pushalign import PushAligner
from feederkit.sim.readings import reading_of
from feederkit.sim.summary import PushRecord, TrialResult


def divergent_distance(pf: PushFunction, theta_deg: float) -> float:
    """Angular distance (deg) from ``theta`` to the nearest divergent orientation."""
    t = norm360(theta_deg)
    return min(min(norm360(t - d), norm360(d - t)) for d in pf.divergent_deg)


def _state_id(pp: PlanPart, theta_deg: float) -> int:
    return pp.state_of_edge[push(pp.pf, theta_deg).edge]


def _mismatch_reason(rec: PushRecord) -> str:
    if rec.simulated_state is None:
        return f"the part came to rest on hull edge {rec.edge}, which is no stable state"
    if rec.simulated_state == rec.predicted_state:
        return (
            f"the rotation error ({rec.rotation_error_deg:+.2f} deg) carried the part into the "
            f"resting range of state {rec.simulated_state} instead of {rec.expected_state}"
        )
    return (
        f"the simulated push settled in state {rec.simulated_state} where the push function "
        f"gives {rec.predicted_state} (dropped {rec.divergent_distance_deg:.2f} deg from a "
        "divergent orientation)"
    )


def run_trial(
    plan: SimPlan,
    part_name: str,
    aligner: PushAligner,
    start_deg: float,
    rotation_error: Callable[[], float],
    index: int = 0,
) -> TrialResult:
    """Execute ``plan`` on ``part_name`` dropped first at fence orientation ``start_deg``.

    ``rotation_error()`` gives the robot's error (deg, counter-clockwise) for each rotation.
    The step that went wrong is the first push whose simulated state differs from the state
    the plan expects from the part's actual previous state; failing that, the step whose
    reading no branch holds, or the last one when the plan's result is wrong.
    """
    pp = plan.part(part_name)
    node = plan.root
    records: list[PushRecord] = []
    first_wrong: tuple[int, str] | None = None
    rest_theta = start_deg
    state: int | None = None

    def finish(outcome: str, step: int | None, reason: str | None) -> TrialResult:
        return TrialResult(
            index, part_name, norm360(start_deg), outcome, step, reason, state, tuple(records)
        )

    while isinstance(node, Step):
        step = len(records) + 1
        if node.action_deg is None:
            nominal, err = norm360(start_deg), 0.0
        else:
            nominal, err = norm360(rest_theta - node.action_deg), rotation_error()
        theta = norm360(nominal - err)
        out = aligner.align(theta)
        sim_state = pp.state_of_edge.get(out.edge) if out.edge is not None else None
        reading = reading_of(plan.sensor, out.width_mm) if out.settled else None
        branch = node.follow(reading) if out.settled and sim_state is not None else None
        rec = PushRecord(
            step=step,
            action_deg=node.action_deg,
            rotation_error_deg=err,
            theta_drop_deg=theta,
            divergent_distance_deg=divergent_distance(pp.pf, theta),
            predicted_margin_deg=divergent_distance(pp.pf, push(pp.pf, theta).normal_deg),
            expected_state=_state_id(pp, nominal),
            predicted_state=_state_id(pp, theta),
            simulated_state=sim_state,
            edge=out.edge,
            settled=out.settled,
            width_mm=out.width_mm,
            reading=reading,
            branch=branch,
            sim_time_s=out.sim_time_s,
        )
        records.append(rec)
        state = sim_state
        if not out.settled:
            return finish(
                "unsettled", step, f"the part never settled within {aligner.max_time_s:.3g} s"
            )
        if first_wrong is None and sim_state != rec.expected_state:
            first_wrong = (step, _mismatch_reason(rec))
        if sim_state is None:
            return finish("failure", *(first_wrong or (step, _mismatch_reason(rec))))
        if branch is None:
            msg = f"the reading {reading:.3f} mm lies in no branch of the plan"
            if first_wrong is not None:
                return finish("failure", first_wrong[0], f"{first_wrong[1]}; then {msg}")
            return finish("failure", step, msg)
        rest_theta = out.theta_end_deg
        node = node.branches[branch].next
    assert isinstance(node, Leaf)
    if state is not None and node.accepts(part_name, state):
        return finish("success", None, None)
    if first_wrong is not None:
        return finish("failure", *first_wrong)
    return finish(
        "failure",
        len(records),
        f"every push went as the plan expects but its result does not hold state {state}",
    )
