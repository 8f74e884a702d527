"""Values the simulator reports: pushes, trials and the summary of a run (with ``to_dict``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from feederkit.sim.sampling import FrictionRange, TrialDraw
from feederkit.uncertainty import IDEAL, Uncertainty


def _r(x: float | None, nd: int = 4) -> float | None:
    return None if x is None else round(float(x), nd)


@dataclass(frozen=True)
class PushRecord:
    """One simulated push-align operation of a trial.

    ``theta_drop_deg`` is the fence orientation (part frame) the part was dropped at, after
    the rotation and its error; ``expected_state`` what the plan expects (the push function
    at the nominal orientation), ``predicted_state`` the push function at the actual drop
    orientation, ``simulated_state`` where the part came to rest in MuJoCo (None when it
    never settled or rests on an edge that is no stable state). ``divergent_distance_deg``
    is how far the drop was from a divergent orientation, ``predicted_margin_deg`` how far
    the predicted stable orientation is from one (small for a near-metastable edge, which
    the part's momentum can carry it past).
    """

    step: int
    action_deg: float | None
    rotation_error_deg: float
    theta_drop_deg: float
    divergent_distance_deg: float
    predicted_margin_deg: float
    expected_state: int
    predicted_state: int
    simulated_state: int | None
    edge: int | None
    settled: bool
    width_mm: float
    reading: float | None
    branch: int | None
    sim_time_s: float
    in_model: bool = True

    @property
    def agrees(self) -> bool:
        """Whether the simulated push ended where the push function says."""
        return self.settled and self.simulated_state == self.predicted_state

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {
            "step": self.step,
            "action_deg": _r(self.action_deg),
            "rotation_error_deg": _r(self.rotation_error_deg),
            "theta_drop_deg": _r(self.theta_drop_deg),
            "divergent_distance_deg": _r(self.divergent_distance_deg),
            "predicted_margin_deg": _r(self.predicted_margin_deg),
            "expected_state": self.expected_state,
            "predicted_state": self.predicted_state,
            "simulated_state": self.simulated_state,
            "edge": self.edge,
            "settled": self.settled,
            "width_mm": _r(self.width_mm),
            "reading": _r(self.reading),
            "branch": self.branch,
            "sim_time_s": _r(self.sim_time_s),
            "in_model": self.in_model,
        }


@dataclass(frozen=True)
class TrialResult:
    """One trial: a part of the plan's mix dropped at ``start_deg`` and the plan executed.

    ``outcome`` is ``success``, ``failure`` or ``unsettled``; for the last two ``step`` is
    the push-align operation that went wrong (1 = the first alignment), ``reason`` says how,
    ``cause`` is what broke (``feederkit.sim.trial.CAUSES``) and ``predicted`` whether the
    plan's model allowed everything that happened (False: a model error). ``draw`` is nature's
    draw for the trial (None under ``--ideal``: nothing drawn).
    """

    index: int
    part: str
    start_deg: float
    outcome: str
    step: int | None
    reason: str | None
    final_state: int | None
    pushes: tuple[PushRecord, ...]
    cause: str | None = None
    predicted: bool | None = None
    draw: TrialDraw | None = None
    landing: str | None = None
    rejected: bool = False

    @property
    def wrong_accept(self) -> bool:
        """A part that ended in an accepting leaf not naming its landing and state (design.md,
        "Landings": the next station takes a part it should not)."""
        return self.outcome == "failure" and self.cause == "wrong result" and not self.rejected

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {
            "trial": self.index,
            "part": self.part,
            "landing": self.landing,
            "rejected": self.rejected,
            "start_deg": _r(self.start_deg),
            "outcome": self.outcome,
            "step": self.step,
            "cause": self.cause,
            "predicted": self.predicted,
            "reason": self.reason,
            "draw": None if self.draw is None else self.draw.to_dict(),
            "final_state": self.final_state,
            "pushes": [p.to_dict() for p in self.pushes],
        }


@dataclass(frozen=True)
class PushMiss:
    """A settled simulated push that ended elsewhere than the push function predicts."""

    trial: int
    part: str
    step: int
    theta_deg: float
    divergent_distance_deg: float
    predicted_margin_deg: float
    predicted_state: int
    simulated_state: int | None

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {
            "trial": self.trial,
            "part": self.part,
            "step": self.step,
            "theta_deg": _r(self.theta_deg),
            "divergent_distance_deg": _r(self.divergent_distance_deg),
            "predicted_margin_deg": _r(self.predicted_margin_deg),
            "predicted_state": self.predicted_state,
            "simulated_state": self.simulated_state,
        }


@dataclass(frozen=True)
class SimSettings:
    """The settings of a simulation run (SI units, degrees).

    ``sampled`` is the uncertainty drawn from (the plan's declared one, IDEAL under
    ``--ideal``); ``rotation_noise_deg`` the rotation error actually drawn (the declared one
    unless overridden); ``friction_belt`` and ``friction_fence`` the nominal coefficients and
    ``*_range`` the ranges drawn from.
    """

    trials: int
    seed: int
    rotation_noise_deg: float
    belt_speed: float
    friction_belt: float
    friction_fence: float
    timestep: float
    sampled: Uncertainty = IDEAL
    ideal: bool = False
    friction_belt_range: FrictionRange | None = None
    friction_fence_range: FrictionRange | None = None
    contact: str = field(default="")

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        fb = self.friction_belt_range or FrictionRange(self.friction_belt, self.friction_belt)
        ff = self.friction_fence_range or FrictionRange(self.friction_fence, self.friction_fence)
        return {
            "trials": self.trials,
            "seed": self.seed,
            "ideal": self.ideal,
            "sampled_uncertainty": self.sampled.to_dict(),
            "rotation_noise_deg": self.rotation_noise_deg,
            "belt_speed_m_s": self.belt_speed,
            "friction_belt": self.friction_belt,
            "friction_fence": self.friction_fence,
            "friction_belt_range": [fb.lo, fb.hi],
            "friction_fence_range": [ff.lo, ff.hi],
            "timestep_s": self.timestep,
            "contact": self.contact,
        }


@dataclass(frozen=True)
class SimulationSummary:
    """The outcome of simulating a plan over many trials.

    ``trials == successes + len(failures) + len(unsettled)``; ``part_trials`` and
    ``part_successes`` split them by the members of the mix (``parts``: ``NAME`` or
    ``NAME (LANDING)``). ``rejects`` of the successes ended in a reject leaf that names the
    member (design.md, "Landings"); ``wrong_accepts`` of the failures in an accepting leaf that
    does not. Push agreement counts the
    settled pushes that ended where the push function predicts from the actual drop
    orientation (physics against the kinematic model, whatever the rotation error).
    """

    settings: SimSettings
    parts: tuple[str, ...]
    part_trials: tuple[int, ...]
    part_successes: tuple[int, ...]
    scales: tuple[float, ...]
    min_margin_deg: float | None
    successes: int
    failures: tuple[TrialResult, ...]
    unsettled: tuple[TrialResult, ...]
    pushes: int
    settled_pushes: int
    push_agreements: int
    push_misses: tuple[PushMiss, ...]
    wall_time_s: float
    sim_time_s: float
    rejects: int = 0
    """Successes that ended in a reject leaf naming the member's landing (correct rejects)."""

    @property
    def wrong_accepts(self) -> int:
        """Failures that ended in an accepting leaf not naming the part's landing and state."""
        return sum(r.wrong_accept for r in self.failures)

    @property
    def trials(self) -> int:
        """Number of trials run."""
        return self.settings.trials

    @property
    def success_rate(self) -> float:
        """Successes over trials."""
        return self.successes / self.trials if self.trials else math.nan

    @property
    def push_agreement(self) -> float:
        """Fraction of settled pushes that agree with the push function (1.0 when none)."""
        return self.push_agreements / self.settled_pushes if self.settled_pushes else 1.0

    @property
    def went_wrong(self) -> tuple[TrialResult, ...]:
        """Every failed or unsettled trial, those the model did not predict (model errors)
        first, then by trial."""
        rows = list(self.failures) + list(self.unsettled)
        return tuple(sorted(rows, key=lambda r: (bool(r.predicted), r.index)))

    @property
    def model_errors(self) -> int:
        """Trials that went wrong where the plan's model did not predict what happened."""
        return sum(not r.predicted for r in self.went_wrong)

    def by_cause(self) -> dict[str, int]:
        """How many trials went wrong by each cause (``feederkit.sim.trial.CAUSES``)."""
        out: dict[str, int] = {}
        for r in self.went_wrong:
            key = r.cause or "unknown"
            out[key] = out.get(key, 0) + 1
        return out

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form (``--json``): integers ``trials`` and ``successes``, the failures
        (model errors first)."""
        return {
            "trials": self.trials,
            "successes": self.successes,
            "success_rate": _r(self.success_rate, 6),
            "rejects": self.rejects,
            "wrong_accepts": self.wrong_accepts,
            "model_errors": self.model_errors,
            "by_cause": self.by_cause(),
            "went_wrong": [r.to_dict() for r in self.went_wrong],
            "failures": [f.to_dict() for f in self.failures],
            "unsettled": [u.to_dict() for u in self.unsettled],
            "pushes": self.pushes,
            "settled_pushes": self.settled_pushes,
            "push_agreements": self.push_agreements,
            "push_agreement": _r(self.push_agreement, 6),
            "push_misses": [m.to_dict() for m in self.push_misses],
            "parts": list(self.parts),
            "per_part": [
                {"part": p, "trials": t, "successes": k}
                for p, t, k in zip(self.parts, self.part_trials, self.part_successes, strict=True)
            ],
            "scale": [_r(s, 6) for s in self.scales],
            "min_margin_deg": _r(self.min_margin_deg),
            "settings": self.settings.to_dict(),
            "wall_time_s": _r(self.wall_time_s, 3),
            "sim_time_s": _r(self.sim_time_s, 3),
        }
