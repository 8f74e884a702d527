"""The simulator's library API: one push-align operation, and a plan over many trials.

``simulate_push`` drops one part at one fence orientation and compares the outcome with
the push function (section 3.1). ``simulate_plan`` executes a plan file's tree (design.md)
trial by trial, each trial a part of the plan's mix at a uniformly random orientation.

A run with failures is data, not an error: ``simulate_plan`` returns the summary whatever
the success rate; only bad input raises (InputError).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from feederkit.errors import InputError
from feederkit.mechanics.push import StableState, push, push_function
from feederkit.part import Part
from feederkit.sim.planfile import read_plan
from feederkit.sim.pushalign import PushAligner, PushOutcome, SettleRule
from feederkit.sim.scene import SceneConfig
from feederkit.sim.summary import PushMiss, SimSettings, SimulationSummary, TrialResult
from feederkit.sim.trial import divergent_distance, run_trial

DEFAULT_BELT_SPEED = 0.1
DEFAULT_FRICTION_BELT = 0.5
DEFAULT_FRICTION_FENCE = 0.2

Progress = Callable[[int, int], None]
"""Called as ``progress(done, total)`` after each trial."""


@dataclass(frozen=True)
class PushCheck:
    """A simulated push-align operation next to the push function's prediction."""

    outcome: PushOutcome
    state: (
        StableState | None
    )  # the stable state the part rests in (None: unsettled or unstable edge)
    predicted: StableState  # push(pf, theta)
    divergent_distance_deg: float

    @property
    def agrees(self) -> bool:
        """Whether the part rests on the edge the push function predicts."""
        return self.state is not None and self.state.edge == self.predicted.edge


def scene_config(
    belt_speed: float = DEFAULT_BELT_SPEED,
    friction_belt: float = DEFAULT_FRICTION_BELT,
    friction_fence: float = DEFAULT_FRICTION_FENCE,
) -> SceneConfig:
    """A validated scene configuration; impossible settings are bad input."""
    if not (math.isfinite(belt_speed) and 0.0 < belt_speed <= 5.0):
        raise InputError(f"--belt-speed must be in (0, 5] m/s, got {belt_speed:g}")
    for label, mu in (("--friction-belt", friction_belt), ("--friction-fence", friction_fence)):
        if not (math.isfinite(mu) and 0.0 <= mu <= 5.0):
            raise InputError(f"{label} must be a friction coefficient in [0, 5], got {mu:g}")
    if friction_belt <= 0.0:
        raise InputError(
            "--friction-belt must be positive: a frictionless belt cannot carry the part"
        )
    return SceneConfig(
        belt_speed=float(belt_speed),
        friction_belt=float(friction_belt),
        friction_fence=float(friction_fence),
    )


@lru_cache(maxsize=16)
def _aligner(part: Part, config: SceneConfig, rule: SettleRule) -> PushAligner:
    return PushAligner(part, config, rule)


def simulate_push(
    part: Part,
    theta_deg: float,
    *,
    belt_speed: float = DEFAULT_BELT_SPEED,
    friction_belt: float = DEFAULT_FRICTION_BELT,
    friction_fence: float = DEFAULT_FRICTION_FENCE,
    rule: SettleRule | None = None,
) -> PushCheck:
    """Drop ``part`` at fence orientation ``theta_deg`` and compare with the push function."""
    if not math.isfinite(theta_deg):
        raise InputError(f"the drop orientation must be a finite angle, got {theta_deg!r}")
    config = scene_config(belt_speed, friction_belt, friction_fence)
    aligner = _aligner(part, config, rule or SettleRule())
    pf = push_function(part)
    out = aligner.align(theta_deg)
    state = None
    if out.edge is not None:
        state = next((s for s in pf.states if s.edge == out.edge), None)
    return PushCheck(out, state, push(pf, theta_deg), divergent_distance(pf, theta_deg))


def simulate_plan(
    plan: dict,
    trials: int,
    seed: int,
    rotation_noise_deg: float = 0.0,
    belt_speed: float = DEFAULT_BELT_SPEED,
    friction_belt: float = DEFAULT_FRICTION_BELT,
    friction_fence: float = DEFAULT_FRICTION_FENCE,
    progress: Progress | None = None,
    *,
    rule: SettleRule | None = None,
) -> SimulationSummary:
    """Simulate a plan file's JSON object over ``trials`` trials.

    Each trial draws a part of the mix uniformly and a start orientation uniformly on the
    circle; every robot rotation gets an error drawn uniformly from
    ``[-rotation_noise_deg, +rotation_noise_deg]``. Trial ``i`` uses its own generator
    seeded with ``(seed, i)``, so a trial's outcome does not depend on the others.
    """
    if isinstance(trials, bool) or not isinstance(trials, int) or trials < 1:
        raise InputError(f"--trials must be a positive integer, got {trials!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"--seed must be a non-negative integer, got {seed!r}")
    if not (math.isfinite(rotation_noise_deg) and 0.0 <= rotation_noise_deg <= 180.0):
        raise InputError(
            f"--rotation-noise must be in [0, 180] degrees, got {rotation_noise_deg:g}"
        )
    config = scene_config(belt_speed, friction_belt, friction_fence)
    rule = rule or SettleRule()
    sim_plan = read_plan(plan)
    aligners = {pp.name: PushAligner(pp.part, config, rule) for pp in sim_plan.parts}
    names = [pp.name for pp in sim_plan.parts]
    t0 = time.perf_counter()
    results: list[TrialResult] = []
    for i in range(trials):
        rng = np.random.default_rng([seed, i])
        name = names[int(rng.integers(len(names)))]
        start = float(rng.uniform(0.0, 360.0))

        def error(rng: np.random.Generator = rng) -> float:
            if rotation_noise_deg == 0.0:
                return 0.0
            return float(rng.uniform(-rotation_noise_deg, rotation_noise_deg))

        results.append(run_trial(sim_plan, name, aligners[name], start, error, index=i))
        if progress is not None:
            progress(i + 1, trials)
    wall = time.perf_counter() - t0
    pushes = [(r, p) for r in results for p in r.pushes]
    settled = [(r, p) for r, p in pushes if p.settled]
    misses = tuple(
        PushMiss(
            r.index,
            r.part,
            p.step,
            p.theta_drop_deg,
            p.divergent_distance_deg,
            p.predicted_margin_deg,
            p.predicted_state,
            p.simulated_state,
        )
        for r, p in settled
        if not p.agrees
    )
    return SimulationSummary(
        settings=SimSettings(
            trials=trials,
            seed=seed,
            rotation_noise_deg=float(rotation_noise_deg),
            belt_speed=config.belt_speed,
            friction_belt=config.friction_belt,
            friction_fence=config.friction_fence,
            timestep=config.timestep,
        ),
        parts=tuple(names),
        part_trials=tuple(sum(r.part == n for r in results) for n in names),
        part_successes=tuple(
            sum(r.part == n and r.outcome == "success" for r in results) for n in names
        ),
        scales=tuple(aligners[n].scale for n in names),
        min_margin_deg=sim_plan.min_margin_deg,
        successes=sum(r.outcome == "success" for r in results),
        failures=tuple(r for r in results if r.outcome == "failure"),
        unsettled=tuple(r for r in results if r.outcome == "unsettled"),
        pushes=len(pushes),
        settled_pushes=len(settled),
        push_agreements=len(settled) - len(misses),
        push_misses=misses,
        wall_time_s=wall,
        sim_time_s=sum(p.sim_time_s for _, p in pushes),
    )
