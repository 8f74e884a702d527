"""Execute a plan on the simulated feeder for one part and one start orientation.

A controller executes a node by rotating the part by ``action_deg`` (none at the root),
letting it align, reading the width and following the branch whose closed interval holds
the reading (design.md). Here the rotation starts from where the part really rests in the
simulation, the robot adds its rotation error, and MuJoCo does the aligning.

Every operation is compared with the plan's own model (:class:`TrialModel`: the mechanics of
the declared uncertainty, :mod:`feederkit.mechanics.uncertain`): the outcome set the model
allows after the rotation from where the part rested, and the readings it allows there. A
failed trial names its step, its cause and whether the model predicted what happened; an
outcome the model did not predict is a model error, not a fault of the plan.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from feederkit.angles import norm360
from feederkit.mechanics.outcomes import outcome_set
from feederkit.mechanics.push import PushFunction, push
from feederkit.mechanics.uncertain import UncertainMechanics
from feederkit.plans.model import Leaf, Plan, PlanPart, Step, push_function_of
from feederkit.sensors import Sensor
from feederkit.sim.pushalign import TILT_MAX_DEG, PushAligner, range_distance
from feederkit.sim.summary import PushRecord, TrialResult

CAUSES = ("never settled", "unstable edge", "reading in no branch", "wrong result")
"""What broke in a failed trial (the summary groups failures by these)."""


def divergent_distance(pf: PushFunction, theta_deg: float) -> float:
    """Angular distance (deg) from ``theta`` to the nearest divergent orientation."""
    t = norm360(theta_deg)
    return min(min(norm360(t - d), norm360(d - t)) for d in pf.divergent_deg)


@dataclass(frozen=True)
class _SimPart:
    """A plan's part with its push function and the plan's state id of each resting edge."""

    part: PlanPart
    pf: PushFunction
    state_of_edge: dict[int, int]


def _sim_part(part: PlanPart) -> _SimPart:
    return _SimPart(part, push_function_of(part), {s.edge: s.id for s in part.states})


def member_of(plan: Plan, name: str, landing: str | None) -> PlanPart:
    """The plan member ``(name, landing)`` (a plan file before landings: by name alone)."""
    return plan.part(name) if landing is None else plan.part(name, landing)


def leaf_holds(leaf: Leaf, name: str, state: int, landing: str | None) -> bool:
    """Whether ``leaf`` names member ``(name, landing)`` resting in ``state`` (design.md,
    "Landings": a reject leaf names the landings and states it rejects)."""
    if landing is None:
        return leaf.accepts(name, state)
    return leaf.accepts(name, state, landing)


def _state_id(pp: _SimPart, theta_deg: float) -> int:
    return pp.state_of_edge[push(pp.pf, theta_deg).edge]


@dataclass(frozen=True)
class TrialModel:
    """The plan's model of one part: its mechanics under the declared uncertainty and the
    diameter interval of each physical state (as :func:`feederkit.plans.strong.strong_model`
    builds them, so the simulator judges by the model the plan was verified on)."""

    mechanics: UncertainMechanics
    diameters: tuple[tuple[float, float], ...]
    sensor: Sensor

    def physical(self, state: int) -> frozenset[int]:
        """The physical states a part resting in ideal ``state`` is in (a transient state:
        those it surely moves on to)."""
        x = self.mechanics.state_of[state]
        return frozenset({x}) if x is not None else self.mechanics.destinations[state]

    def outcomes(self, before: int | None, action_deg: float | None) -> frozenset[int] | None:
        """The physical states the model allows after the rotation from ideal state
        ``before`` (None at the root: every state)."""
        if action_deg is None or before is None:
            return None
        out: set[int] = set()
        for x in self.physical(before):
            out |= outcome_set(self.mechanics, x, action_deg)
        return frozenset(out)

    def transient(self, state: int) -> bool:
        """Whether the model says a part never stays in ideal ``state`` (its barrier is below
        the vibration the model assumes)."""
        return self.mechanics.state_of[state] is None

    def allows(self, before: int | None, action_deg: float | None, after: int) -> bool:
        """Whether resting in ideal state ``after`` is an outcome the model allows (never a
        transient state: the model says the part moves on)."""
        if self.transient(after):
            return False
        allowed = self.outcomes(before, action_deg)
        return allowed is None or bool(self.physical(after) & allowed)

    def reads(self, state: int, reading: float | None) -> bool:
        """Whether the model allows ``reading`` of a part resting in ideal ``state``."""
        if reading is None or not self.sensor.informative:
            return True
        return any(self.sensor.consistent(self.diameters[x], reading) for x in self.physical(state))


@dataclass(frozen=True)
class PoseRule:
    """Success judged by where the part rests, for a member simulated on its own outline
    (``simulate --part``, docs/simulation.md "A part's own outline").

    ``rest[s]`` holds the resting ranges (fence orientations, deg, ``hi`` may pass 360) the
    plan's model gives ideal state ``s`` under the plan's declared uncertainty: those of the
    physical states holding it (merged facets, widened by the shape and COM tolerances; the
    states it surely moves on to when transient). A part resting at ``theta`` is in a state a
    leaf names when ``theta`` lies within ``limit_deg`` (the declared rotation error plus the
    simulator's settle tolerance) of one of that state's ranges.
    """

    limit_deg: float
    rest: Mapping[int, tuple[tuple[float, float], ...]]

    @classmethod
    def of(cls, part: PlanPart, model: TrialModel | None, limit_deg: float) -> PoseRule:
        """The rule for a plan member (without the model: each state's ideal normal)."""
        rest: dict[int, tuple[tuple[float, float], ...]] = {}
        for s in part.states:
            if model is None:
                rest[s.id] = ((s.normal_deg, s.normal_deg),)
            else:
                states = model.mechanics.states
                rest[s.id] = tuple(states[x].rest_deg for x in sorted(model.physical(s.id)))
        return cls(float(limit_deg), rest)

    def distance(self, state: int, theta_deg: float) -> float:
        """Angular distance (deg) from ``theta`` to the resting ranges of ideal ``state``."""
        return min(range_distance(theta_deg, lo, hi) for lo, hi in self.rest[state])

    def leaf_error(self, leaf: Leaf, name: str, landing: str | None, theta_deg: float) -> float:
        """How far (deg) ``theta`` lies from every state ``leaf`` names for member ``(name,
        landing)`` (infinite when it names none of its states)."""
        states = [r.state for r in leaf.results if r.part == name and r.landing == landing]
        return min((self.distance(s, theta_deg) for s in states), default=math.inf)


def run_trial(
    plan: Plan,
    part_name: str,
    aligner: PushAligner,
    start_deg: float,
    rotation_error: Callable[[], float],
    index: int = 0,
    *,
    model: TrialModel | None = None,
    state_of_edge: Sequence[int | None] | None = None,
    landing: str | None = None,
    pose: PoseRule | None = None,
) -> TrialResult:
    """Execute ``plan`` on ``part_name`` dropped first at fence orientation ``start_deg``.

    ``rotation_error()`` gives the robot's error (deg, counter-clockwise) for each rotation.
    ``state_of_edge`` maps the simulated part's hull edges to the plan's stable states (a
    perturbed part's basins; default the drawn part's stable edges). Each operation is
    judged by ``model`` (the plan's, see :class:`TrialModel`; None: the push function at the
    nominal orientation). A failed trial's step is the first operation the model did not
    predict (``predicted`` False: a model error), else the one where the plan broke (its
    cause one of :data:`CAUSES`). Branches are followed by the plan's one rule
    (:meth:`~feederkit.plans.model.Branch.holds`). ``landing`` names the member of a plan over
    landings (design.md, "Landings"); a trial ending in a reject leaf that names the member's
    landing and state is a success with ``rejected`` set, one ending in a non-reject leaf that
    does not name them a ``wrong result`` failure (a wrong accept).

    ``pose`` (a member simulated on its own outline): the part's state after each operation
    is the plan's state whose resting range holds where it rests (its basin), an operation
    resting farther than ``pose.limit_deg`` from that state's resting range under the plan's
    uncertainty is outside the model, and the trial succeeds when the part finally rests
    within ``pose.limit_deg`` of a state the leaf names (:class:`PoseRule`).
    """
    pp = _sim_part(member_of(plan, part_name, landing))
    edges = dict(pp.state_of_edge) if state_of_edge is None else dict(enumerate(state_of_edge))
    node: Step | Leaf = plan.root
    records: list[PushRecord] = []
    unpredicted: tuple[int, str] | None = None
    rest_theta = start_deg
    final_theta: float | None = None
    pose_error: float | None = None
    state: int | None = None

    def finish(
        outcome: str,
        step: int | None,
        cause: str | None,
        why: str | None,
        rejected: bool = False,
        unrecognized: bool = False,
    ) -> TrialResult:
        predicted = None
        if outcome != "success":
            predicted = unpredicted is None and outcome != "unsettled"
            if unpredicted is not None:
                step, why = unpredicted[0], f"{unpredicted[1]}; then {why}"
        return TrialResult(
            index,
            part_name,
            norm360(start_deg),
            outcome,
            step,
            why,
            state,
            tuple(records),
            cause=cause,
            predicted=predicted,
            landing=landing,
            rejected=rejected,
            unrecognized=unrecognized,
            final_deg=final_theta,
            pose_error_deg=pose_error,
        )

    while isinstance(node, Step):
        step = len(records) + 1
        if node.action_deg is None:
            nominal, err = norm360(start_deg), 0.0
        else:
            nominal, err = norm360(rest_theta - node.action_deg), rotation_error()
        theta = norm360(nominal - err)
        out = aligner.align(theta)
        if pose is not None:
            sim_state = _state_id(pp, out.theta_end_deg) if out.settled else None
            final_theta = out.theta_end_deg if out.settled else None
        else:
            sim_state = edges.get(out.edge) if out.edge is not None else None
        reading = plan.sensor.read(out.width_mm) if out.settled else None
        branch = node.follow(reading) if out.settled and sim_state is not None else None
        expected = _state_id(pp, nominal)
        predicted = _state_id(pp, theta)
        same_physical = None
        if model is None:
            in_model = sim_state == expected
            reads = True
        else:
            in_model = sim_state is not None and model.allows(state, node.action_deg, sim_state)
            reads = sim_state is None or model.reads(sim_state, reading)
            if sim_state is not None:
                same_physical = bool(model.physical(sim_state) & model.physical(predicted))
        off_rest = None
        if pose is not None and sim_state is not None:
            off_rest = pose.distance(sim_state, out.theta_end_deg)
            in_model = in_model and off_rest <= pose.limit_deg
        rec = PushRecord(
            step=step,
            action_deg=node.action_deg,
            rotation_error_deg=err,
            theta_drop_deg=theta,
            divergent_distance_deg=divergent_distance(pp.pf, theta),
            predicted_margin_deg=divergent_distance(pp.pf, push(pp.pf, theta).normal_deg),
            expected_state=expected,
            predicted_state=predicted,
            simulated_state=sim_state,
            edge=out.edge,
            settled=out.settled,
            width_mm=out.width_mm,
            reading=reading,
            branch=branch,
            sim_time_s=out.sim_time_s,
            in_model=in_model and reads,
            same_physical=same_physical,
        )
        records.append(rec)
        if not out.settled:
            state = None
            return finish(
                "unsettled",
                step,
                "never settled",
                f"the part never settled within {aligner.max_time_s:.3g} s"
                + (
                    f": it ended {out.tilt_deg:.0f} deg out of the belt's plane (it tipped "
                    "onto an edge or over: the planar model does not hold for it)"
                    if out.tilt_deg > TILT_MAX_DEG
                    else ""
                ),
            )
        if unpredicted is None and off_rest is not None and off_rest > pose.limit_deg:
            unpredicted = (
                step,
                f"the part rests at {out.theta_end_deg:.2f} deg, {off_rest:.2f} deg from where "
                f"the plan's model rests state {sim_state} (more than {pose.limit_deg:g}): its "
                "outline rests elsewhere than the plan's hull",
            )
        elif unpredicted is None and not in_model:
            unpredicted = (step, _unpredicted_reason(rec, state, model))
        elif unpredicted is None and not reads:
            unpredicted = (step, f"the reading {reading:.4f} mm is outside what the model allows")
        state = sim_state
        if sim_state is None:
            return finish(
                "failure",
                step,
                "unstable edge",
                f"the part came to rest on hull edge {rec.edge}, which is no stable state",
            )
        if branch is None:
            return finish(
                "failure",
                step,
                "reading in no branch",
                f"the reading {reading:.4f} mm lies in no branch of step {step}",
            )
        rest_theta = out.theta_end_deg
        node = node.branches[branch].next
    assert isinstance(node, Leaf)
    reject = bool(getattr(node, "reject", False))
    several = node.unrecognized  # right, but the part is not known
    if pose is not None and final_theta is not None:
        pose_error = pose.leaf_error(node, part_name, landing, final_theta)
        if pose_error <= pose.limit_deg:
            return finish("success", None, None, None, rejected=reject, unrecognized=several)
        leaf = "reject result" if reject else "result"
        far = (
            f"{pose_error:.2f} deg from the resting range of the nearest state the plan's {leaf} "
            f"names (allowed {pose.limit_deg:g} deg)"
            if math.isfinite(pose_error)
            else f"and the plan's {leaf} names none of its states"
        )
        return finish(
            "failure",
            len(records),
            "wrong result",
            f"the part rests at {final_theta:.2f} deg, {far}",
            rejected=reject,
        )
    if state is not None and leaf_holds(node, part_name, state, landing):
        return finish("success", None, None, None, rejected=reject, unrecognized=several)
    what = f"state {state}" if landing is None else f"landing {landing}, state {state}"
    leaf = "reject result" if reject else "result"
    return finish(
        "failure",
        len(records),
        "wrong result",
        f"the plan's {leaf} does not hold {what}",
        rejected=reject,
    )


def _unpredicted_reason(rec: PushRecord, before: int | None, model: TrialModel | None) -> str:
    """Why an operation is outside the model, in words."""
    if model is None:
        return (
            f"the rotation error ({rec.rotation_error_deg:+.2f} deg) or the physics sent the part "
            f"to state {rec.simulated_state} instead of {rec.expected_state}"
        )
    if rec.simulated_state is not None and model.transient(rec.simulated_state):
        return (
            f"the part stayed in state {rec.simulated_state}, which the plan's model says it "
            "always leaves (a barrier below the vibration it assumes): a model error"
        )
    allowed = model.outcomes(before, rec.action_deg)
    if allowed is None:
        return f"the part rested in state {rec.simulated_state}, which the model does not allow"
    ideal = sorted({m for x in allowed for m in model.mechanics.states[x].members})
    return (
        f"the part rested in state {rec.simulated_state} after rotation {rec.action_deg:.4g} deg "
        f"(error {rec.rotation_error_deg:+.2f} deg), which the plan's model does not allow "
        f"(it allows states {ideal}): a model error"
    )
