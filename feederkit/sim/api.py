"""The simulator's library API: one push-align operation, and a plan over many trials.

``simulate_push`` drops one part at one fence orientation and compares the outcome with
the push function (section 3.1). ``simulate_plan`` executes a plan's tree (design.md)
trial by trial, each trial a part of the plan's mix at a uniformly random orientation,
sampling the plan's declared uncertainty and the friction (:mod:`feederkit.sim.sampling`).

A run with failures is data, not an error: ``simulate_plan`` returns the summary whatever
the success rate. Bad input raises InputError; a plan that fails verification at its
declared uncertainty (``feederkit.plans.verify.check_declared``) raises CheckFailed before
any trial runs, as ``run`` and ``report`` refuse it too.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np

from feederkit.errors import InputError
from feederkit.mechanics.push import StableState, push, push_function
from feederkit.part import Part
from feederkit.plans.fileformat import plan_to_dict
from feederkit.plans.model import Plan, push_function_of
from feederkit.plans.readplan import as_plan
from feederkit.plans.verify import check_declared
from feederkit.sim.pushalign import PushAligner, PushOutcome, SettleRule
from feederkit.sim.real import REAL_SETTLE_RULE, RealPart
from feederkit.sim.sampling import (
    FrictionRange,
    draw_rotation_error,
    draw_trial,
    friction_range,
    nature_rng,
    perturbed_part,
)
from feederkit.sim.scene import SceneConfig
from feederkit.sim.summary import (
    PoseRuleWords,
    PushMiss,
    SimSettings,
    SimulationSummary,
    TrialResult,
    certified_bounds,
    sensor_width_slack,
    width_accuracy_warning,
)
from feederkit.sim.trial import PoseRule, TrialModel, divergent_distance, run_trial
from feederkit.uncertainty import IDEAL

DEFAULT_BELT_SPEED = 0.1
DEFAULT_FRICTION_BELT = 0.5
DEFAULT_FRICTION_FENCE = 0.2
DEFAULT_FRICTION_BELT_RANGE = FrictionRange(0.4, 0.6)
"""Belt friction drawn per trial: a rubber or PU belt on a delrin part, ±20 % about 0.5."""
DEFAULT_FRICTION_FENCE_RANGE = FrictionRange(0.1, 0.3)
"""Fence friction drawn per trial: a polished steel or UHMW fence, 0.2 ± 0.1."""

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


def _models(plan: Plan) -> list[TrialModel]:
    """Each member's model at the plan's declared uncertainty (the one it was verified on), in
    the order of the plan's parts."""
    from feederkit.plans.strong import strong_model

    model = strong_model(plan_to_dict(plan))
    return [
        TrialModel(mech, diam, plan.sensor)
        for mech, diam in zip(model.mechanics, model.diameters, strict=True)
    ]


def _label(name: str, landing: str | None) -> str:
    """A plan member in words: ``NAME``, or ``NAME (LANDING)`` in a plan over landings."""
    return name if landing is None else f"{name} ({landing})"


def _member_shares(plan: Plan) -> np.ndarray | None:
    """The members' prior shares, normalised (design.md, "Landings"); None when a member has
    none (every member equally likely, drawn as before shares existed)."""
    shares = [getattr(pp, "share", None) for pp in plan.parts]
    if any(x is None for x in shares):
        return None
    total = float(sum(shares))
    if not (math.isfinite(total) and total > 0.0) or any(x < 0.0 for x in shares):
        raise InputError(
            f"the plan's member shares must be non-negative with a positive sum, got {shares}"
        )
    return np.asarray(shares, dtype=float) / total


def check_rotation_noise(rotation_noise_deg: float | None, *, ideal: bool = False) -> None:
    """Refuse a rotation noise outside [0, 180] degrees, or any with ``ideal``: ``--ideal``
    samples nothing and rotates exactly (docs/simulation.md), so a noise would be ignored."""
    if rotation_noise_deg is None:
        return
    if not (math.isfinite(rotation_noise_deg) and 0.0 <= rotation_noise_deg <= 180.0):
        raise InputError(
            f"--rotation-noise must be in [0, 180] degrees, got {rotation_noise_deg:g}"
        )
    if ideal:
        raise InputError(
            "--ideal rotates exactly (it samples nothing), so --rotation-noise cannot go with "
            "it: drop one of them"
        )


def simulate_plan(
    plan: Plan | Mapping[str, Any],
    trials: int,
    seed: int,
    rotation_noise_deg: float | None = None,
    belt_speed: float = DEFAULT_BELT_SPEED,
    friction_belt: float | str | tuple[float, float] | FrictionRange | None = None,
    friction_fence: float | str | tuple[float, float] | FrictionRange | None = None,
    progress: Progress | None = None,
    *,
    ideal: bool = False,
    rule: SettleRule | None = None,
    check: bool = True,
    config: SceneConfig | None = None,
    real: Sequence[RealPart] = (),
    real_rule: SettleRule | None = None,
) -> SimulationSummary:
    """Simulate a plan (or a plan file's JSON object, checked) over ``trials`` trials.

    Each trial draws a member of the mix (a part, or a part in one of its landings:
    design.md, "Landings") by the plan's shares (uniformly when it has none) and a start
    orientation uniformly on the circle, and (unless ``ideal``) nature's draw
    (:mod:`feederkit.sim.sampling`): a part perturbed within the declared shape and COM
    tolerances, the friction coefficients from their ranges (``friction_*``: a number,
    ``LO:HI`` or a pair; default ``DEFAULT_FRICTION_*_RANGE``), and per rotation an error
    uniform in ``[-r, +r]``, ``r`` the declared rotation error (``rotation_noise_deg``
    overrides it, to stress a plan beyond its claim; with ``ideal``, which rotates exactly,
    it is bad input). Trial ``i`` draws from generators
    seeded with ``(seed, i)``, so a trial's outcome does not depend on the others. Every
    operation is judged by the plan's model, and the feeder breathes on a resting part with
    the vibration that model assumes (``PushAligner``'s ``vibration_mm``: a part stays only
    where a barrier above it holds it).

    The plan is verified at its declared uncertainty first (CheckFailed when it fails);
    ``check=False`` skips that, to watch how a plan known to be wrong fails physically.

    ``real`` (:func:`feederkit.sim.real.real_parts`, ``simulate --part``): members simulated on
    the part a SOURCE holds, its outline's exact hull and its own COM, instead of the plan's
    hull; they settle by ``real_rule`` (default :data:`~feederkit.sim.real.REAL_SETTLE_RULE`)
    on their outline's own resting ranges, nature's draw perturbs nothing of them (the same
    draws are made, so starts, frictions and rotation errors are those of a run without it),
    and their trials are judged by where the part rests (:class:`~feederkit.sim.trial.PoseRule`:
    within the declared rotation error plus ``rule.align_tol_deg`` of the resting range of a
    state the leaf names). Without ``real`` nothing changes.
    """
    if isinstance(trials, bool) or not isinstance(trials, int) or trials < 1:
        raise InputError(f"--trials must be a positive integer, got {trials!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"--seed must be a non-negative integer, got {seed!r}")
    check_rotation_noise(rotation_noise_deg, ideal=ideal)
    fb = _range(friction_belt, DEFAULT_FRICTION_BELT_RANGE, "--friction-belt")
    ff = _range(friction_fence, DEFAULT_FRICTION_FENCE_RANGE, "--friction-fence")
    if fb.lo <= 0.0:
        raise InputError(
            "--friction-belt must be positive: a frictionless belt cannot carry the part"
        )
    base = scene_config(belt_speed, fb.nominal, ff.hi if ff.hi > 0.0 else 0.0)
    if config is not None:
        base = replace(config, belt_speed=base.belt_speed)
    rule = rule or SettleRule()
    sim_plan = as_plan(plan)
    if check:
        check_declared(sim_plan)
    sampled = IDEAL if ideal else sim_plan.uncertainty
    noise = (
        0.0
        if ideal
        else (
            sampled.rotation_error_deg if rotation_noise_deg is None else float(rotation_noise_deg)
        )
    )
    shapes = sampled.shape_tolerance_mm > 0.0 or sampled.com_tolerance_mm > 0.0
    members = list(sim_plan.parts)
    own = {r.member: r for r in real}
    if len(own) != len(real) or any(not 0 <= k < len(members) for k in own):
        raise InputError("each real part must name a different member of the plan")
    real_rule = real_rule or REAL_SETTLE_RULE
    models = _models(sim_plan)
    breath = [x.mechanics.vibration_mm for x in models]
    aligners = [
        PushAligner(own[k].part, base, real_rule, rests=own[k].rests, vibration_mm=breath[k])
        if k in own
        else PushAligner(push_function_of(pp).part, base, rule, vibration_mm=breath[k])
        for k, pp in enumerate(members)
    ]
    limit = sim_plan.uncertainty.rotation_error_deg + real_rule.align_tol_deg
    poses = {k: PoseRule.of(members[k], models[k], limit) for k in own}
    shares = _member_shares(sim_plan)
    landings = [getattr(pp, "landing", None) for pp in members]
    labels = [_label(pp.name, x) for pp, x in zip(members, landings, strict=True)]
    t0 = time.perf_counter()
    results: list[TrialResult] = []
    member_of_trial: list[int] = []
    for i in range(trials):
        rng = np.random.default_rng([seed, i])
        if shares is None:
            k = int(rng.integers(len(members)))
        else:
            k = int(rng.choice(len(members), p=shares))
        start = float(rng.uniform(0.0, 360.0))
        pp = members[k]
        name = pp.name
        aligner, edges = aligners[k], None
        if ideal:
            draw = None
            aligner.set_friction(fb.nominal, ff.nominal)

            def error() -> float:
                return 0.0

        else:
            nature = nature_rng(seed, i)
            draw = draw_trial(nature, len(pp.hull), sampled, fb, ff)
            if k in own:  # the part itself: nothing of its shape is drawn
                draw = replace(
                    draw,
                    vertex_offsets=tuple((0.0, 0.0) for _ in draw.vertex_offsets),
                    com_offset=(0.0, 0.0),
                )
            elif shapes:
                perturbed = perturbed_part(pp, push_function_of(pp), draw)
                aligner = PushAligner(
                    perturbed.part, base, rule, scale=aligners[k].scale, vibration_mm=breath[k]
                )
                edges = perturbed.basin_of_edge
            aligner.set_friction(draw.friction_belt, draw.friction_fence)

            def error(nature: np.random.Generator = nature) -> float:
                return draw_rotation_error(nature, noise)

        result = run_trial(
            sim_plan,
            name,
            aligner,
            start,
            error,
            index=i,
            model=models[k],
            state_of_edge=edges,
            landing=landings[k],
            pose=poses.get(k),
        )
        results.append(replace(result, draw=draw))
        member_of_trial.append(k)
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

    reported = sampled
    if own and len(own) == len(members):  # no member's shape was drawn
        reported = replace(sampled, shape_tolerance_mm=0.0, com_tolerance_mm=0.0)

    def wrong(outcome: str) -> tuple[TrialResult, ...]:
        rows = [r for r in results if r.outcome == outcome]
        return tuple(sorted(rows, key=lambda r: (bool(r.predicted), r.index)))

    return SimulationSummary(
        settings=SimSettings(
            trials=trials,
            seed=seed,
            rotation_noise_deg=noise,
            belt_speed=base.belt_speed,
            friction_belt=fb.nominal,
            friction_fence=ff.nominal,
            timestep=base.timestep,
            sampled=reported,
            ideal=ideal,
            friction_belt_range=fb,
            friction_fence_range=ff,
            contact=contact_words(base),
        ),
        parts=tuple(labels),
        members=tuple((pp.name, x) for pp, x in zip(members, landings, strict=True)),
        part_trials=tuple(member_of_trial.count(k) for k in range(len(members))),
        part_successes=tuple(
            sum(
                m == k and r.outcome == "success"
                for m, r in zip(member_of_trial, results, strict=True)
            )
            for k in range(len(members))
        ),
        scales=tuple(a.scale for a in aligners),
        sizes=tuple(a.part.size for a in aligners),
        min_margin_deg=sim_plan.stats.min_margin_deg,
        certified=certified_bounds(
            sim_plan.uncertainty, sim_plan.stats.min_margin_deg, sim_plan.stats.certificate
        ),
        width_warning=width_accuracy_warning(
            sensor_width_slack(sim_plan.sensor), min(a.scale for a in aligners)
        ),
        successes=sum(r.outcome == "success" for r in results),
        rejects=sum(r.outcome == "success" and r.rejected for r in results),
        unrecognized=sum(r.outcome == "success" and r.unrecognized for r in results),
        failures=wrong("failure"),
        unsettled=wrong("unsettled"),
        pushes=len(pushes),
        settled_pushes=len(settled),
        push_agreements=len(settled) - len(misses),
        physical_agreements=(
            sum(p.agrees_physically for _trial, p in settled)
            if any(p.same_physical is not None for _trial, p in settled)
            else None
        ),
        push_misses=misses,
        wall_time_s=wall,
        sim_time_s=sum(p.sim_time_s for _, p in pushes),
        real_parts=tuple(own[k] for k in sorted(own)),
        pose_rule=(
            PoseRuleWords(sim_plan.uncertainty.rotation_error_deg, real_rule.align_tol_deg)
            if own
            else None
        ),
    )


def _range(
    value: float | str | tuple[float, float] | FrictionRange | None,
    default: FrictionRange,
    label: str,
) -> FrictionRange:
    if value is None:
        return default
    if isinstance(value, FrictionRange):
        return friction_range((value.lo, value.hi), label)
    return friction_range(value, label)


def contact_words(config: SceneConfig) -> str:
    """The contact settings in words (docs/simulation.md says why these)."""
    return (
        f"{config.cone} cones, impratio {config.impratio:g}, "
        f"{config.iterations} iterations, noslip_iterations {config.noslip_iterations}"
    )
