"""Values the simulator reports: pushes, trials and the summary of a run (with ``to_dict``).

Also the pure judgements the summary carries (docs/simulation.md): the success rate's 95 %
Wilson interval, what the plan certifies against what was sampled, and whether the plan's
sensor is finer than the simulator's widths are accurate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from feederkit.plans.model import Certificate
from feederkit.sensors import LedSensor, Sensor, ToleranceSensor
from feederkit.sim.sampling import FrictionRange, TrialDraw
from feederkit.uncertainty import IDEAL, Uncertainty

if TYPE_CHECKING:
    from feederkit.sim.real import RealPart

Z_95 = 1.959964
"""The normal quantile of a two-sided 95 % interval."""

INTERVAL_METHOD = "wilson"
"""How the success rate's interval is computed: the Wilson score interval."""

WIDTH_ACCURACY_MM = 0.3
"""How close a simulated width comes to the push function's diameter, in mm at the simulated
size: docs/simulation.md, "Agreement with the push function": on 40 mm parts over belt speeds
0.03-0.3 m/s and the friction ranges the part rests with "its width within about 0.3 mm of
the diameter" (``benchmarks/bench_sim.py``). A sensor finer than this reads the simulator's
width error, not the plan's."""


def _r(x: float | None, nd: int = 4) -> float | None:
    return None if x is None else round(float(x), nd)


def wilson(k: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """The Wilson score interval (95 % by default) of ``k`` successes in ``n`` trials.

    Unlike the normal approximation it stays inside [0, 1] and is not empty at 0 or ``n``
    successes (Wilson 1927), which is where a plan's physics check usually lands.

    >>> [round(x, 4) for x in wilson(40, 40)]
    [0.9124, 1.0]
    """
    if n <= 0 or not 0 <= k <= n:
        raise ValueError(f"need 0 <= k <= n and n > 0, got k={k}, n={n}")
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


def _percent(x: float, round_up: bool) -> str:
    """``x`` (a fraction) in percent to 0.1, rounded outward so an interval never shrinks."""
    tenths = math.ceil(1000.0 * x - 1e-9) if round_up else math.floor(1000.0 * x + 1e-9)
    return f"{tenths / 10:.1f}".removesuffix(".0")


def success_words(successes: int, trials: int) -> str:
    """``40 of 40 (100.0 %; 95 % Wilson interval 91.2-100 %)``: the rate and its interval,
    the interval's ends rounded outward.

    >>> success_words(19, 20)
    '19 of 20 (95.0 %; 95 % Wilson interval 76.3-99.2 %)'
    """
    lo, hi = wilson(successes, trials)
    return (
        f"{successes} of {trials} ({100.0 * successes / trials:.1f} %; 95 % Wilson interval "
        f"{_percent(lo, False)}-{_percent(hi, True)} %)"
    )


def push_words(agreements: int, settled: int, physical: int | None = None) -> str:
    """``agreements`` of ``settled`` pushes ending where the push function says, and the
    ``physical`` ones in the same physical state of the plan's model when more.

    >>> push_words(22, 48, 48).split("; ")[1]
    "48 of 48 (100.0%) in the same physical state (the plan's model merges states a ..."
    """
    rate = 100.0 * agreements / settled if settled else 100.0
    out = f"{agreements} of {settled} settled pushes ({rate:.1f}%) end where the push function says"
    if physical is not None and physical > agreements:
        prate = 100.0 * physical / settled if settled else 100.0
        out += (
            f"; {physical} of {settled} ({prate:.1f}%) in the same physical state (the plan's "
            "model merges states a vibration knocks over)"
        )
    return out


@dataclass(frozen=True)
class Certified:
    """What a plan holds: the largest rotation error (deg) and shape tolerance (mm) under which
    it still reaches its results.

    From the plan's certificate when it carries one (design.md, plan file
    ``stats.certificate``); otherwise the declared rotation error plus the smallest margin
    (a margin is slack beyond the declared error: docs/plans.md) and the declared shape
    tolerance. ``rotation_error_deg`` is None for a plan without rotations (no rotation
    error reaches it).
    """

    rotation_error_deg: float | None
    shape_tolerance_mm: float
    from_certificate: bool

    @property
    def verb(self) -> str:
        """The verb for the figure: "certifies" (its certificate, proven on the feeder
        model) or "claims" (no certificate: the declared figures plus the smallest margin,
        which on the ideal model can overstate the feeder)."""
        return "certifies" if self.from_certificate else "claims"

    def words(self) -> str:
        """The bounds in one line, saying where they come from."""
        rot = (
            "any rotation error (no rotation)"
            if self.rotation_error_deg is None
            else f"rotation error up to ±{self.rotation_error_deg:.4g} deg"
        )
        source = (
            "its certificate"
            if self.from_certificate
            else "no certificate: the declared uncertainty plus the smallest margin"
        )
        return f"{rot}, shape tolerance up to {self.shape_tolerance_mm:.4g} mm ({source})"

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {
            "rotation_error_deg": _r(self.rotation_error_deg, 6),
            "shape_tolerance_mm": _r(self.shape_tolerance_mm, 6),
            "source": "certificate" if self.from_certificate else "declared plus smallest margin",
        }


def certified_bounds(
    declared: Uncertainty, min_margin_deg: float | None, certificate: Certificate | None
) -> Certified:
    """What the plan holds (see :class:`Certified`): its certificate when it has one, else its
    declared uncertainty plus its smallest margin (the ideal model's smallest margin alone)."""
    if certificate is not None:
        # A plan with no rotation holds any error: its certificate's 90 is no figure to read.
        rot = None if min_margin_deg is None else certificate.max_rotation_error_deg
        return Certified(rot, certificate.max_shape_tolerance_mm, True)
    rot = None if min_margin_deg is None else declared.rotation_error_deg + min_margin_deg
    return Certified(rot, declared.shape_tolerance_mm, False)


def beyond_certified_note(
    rotation_error_deg: float, shape_tolerance_mm: float, certified: Certified
) -> str | None:
    """One line when the sampled rotation error or shape tolerance exceeds what the plan
    certifies (then failures are the stress test's, not the plan's); None otherwise.

    >>> print(beyond_certified_note(8.0, 0.0, Certified(3.15, 0.0, True)))
    sampled rotation error ±8 deg is beyond what the plan certifies (±3.15 deg): failures are ...
    """
    over = []
    rot = certified.rotation_error_deg
    if rot is not None and rotation_error_deg > rot:
        over.append(
            (f"rotation error ±{rotation_error_deg:.4g} deg", f"±{rot:.4g} deg"),
        )
    if shape_tolerance_mm > certified.shape_tolerance_mm:
        over.append(
            (
                f"shape tolerance {shape_tolerance_mm:.4g} mm",
                f"{certified.shape_tolerance_mm:.4g} mm",
            )
        )
    if not over:
        return None
    sampled = " and ".join(a for a, _ in over)
    held = ", ".join(b for _, b in over)
    verb = "are" if len(over) > 1 else "is"
    return (
        f"sampled {sampled} {verb} beyond what the plan {certified.verb} ({held}): failures are "
        "expected"
    )


def sensor_width_slack(sensor: Sensor) -> tuple[float, str] | None:
    """The width error (mm) the plan's sensor absorbs, and the sensor in words; None for a
    sensorless plan (nothing is read).

    A tolerance sensor's reading may lie anywhere within its tolerance of the diameter; an LED
    array's width within its alignment noise (a width past a beam's height blocks it).
    """
    if isinstance(sensor, ToleranceSensor):
        return sensor.tolerance, f"the sensor tolerance ±{sensor.tolerance:.4g} mm"
    if isinstance(sensor, LedSensor):
        return sensor.noise, (
            f"the LED array's alignment noise ±{sensor.noise:.4g} mm (pitch {sensor.pitch:.4g} mm)"
        )
    return None


def width_accuracy_warning(slack: tuple[float, str] | None, scale: float = 1.0) -> str | None:
    """One line when the plan's sensor absorbs no more width error than the simulator's widths
    are accurate to (:data:`WIDTH_ACCURACY_MM` at the simulated size, divided by ``scale``, the
    factor a part's lengths were multiplied by in the physics); None otherwise. At the
    accuracy itself it warns: a width that far off reads at the end of the window, or past it.

    >>> width_accuracy_warning((0.31, "tolerance ±0.31 mm")) is None
    True
    >>> print(width_accuracy_warning((0.3, "tolerance ±0.3 mm")))
    tolerance ±0.3 mm is no coarser than the simulator's width accuracy (about 0.3 mm, ...
    """
    if slack is None:
        return None
    mm, words = slack
    accuracy = WIDTH_ACCURACY_MM / scale
    if mm > accuracy:
        return None
    scaled = (
        ""
        if scale == 1.0
        else f"; {accuracy:.3g} mm at the plan's size, simulated at {scale:.3g} times its size"
    )
    return (
        f"{words} is no coarser than the simulator's width accuracy (about "
        f"{WIDTH_ACCURACY_MM:g} mm, docs/simulation.md{scaled}): 'reading in no branch' "
        "failures then measure the simulator's width error, not the plan"
    )


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
    same_physical: bool | None = None
    """Whether the simulated state and the predicted one lie in one physical state of the
    plan's model (which merges stable states whose barrier is below the vibration it
    assumes, docs/planning.md "Strong plans"); None without the model or a settled state."""

    @property
    def agrees(self) -> bool:
        """Whether the simulated push ended where the push function says."""
        return self.settled and self.simulated_state == self.predicted_state

    @property
    def agrees_physically(self) -> bool:
        """Whether it ended where the push function says, or in the same physical state."""
        return self.agrees or bool(self.same_physical)

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
            "same_physical": self.same_physical,
        }


@dataclass(frozen=True)
class TrialResult:
    """One trial: a part of the plan's mix dropped at ``start_deg`` and the plan executed.

    ``outcome`` is ``success``, ``failure`` or ``unsettled``; for the last two ``step`` is
    the push-align operation that went wrong (1 = the first alignment), ``reason`` says how,
    ``cause`` is what broke (``feederkit.sim.trial.CAUSES``) and ``predicted`` whether the
    plan's model allowed everything that happened (False: a model error). ``draw`` is nature's
    draw for the trial (None under ``--ideal``: nothing drawn). For a member simulated on its
    own outline (``simulate --part``) ``final_deg`` is where it finally rested (fence
    orientation, deg) and ``pose_error_deg`` how far that is from every state the leaf names
    (:class:`feederkit.sim.trial.PoseRule`); both None otherwise, and then not in the JSON.
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
    final_deg: float | None = None
    unrecognized: bool = False
    """A success that ended in an accept leaf naming several members (the plan cannot tell
    them apart, :attr:`~feederkit.plans.model.Leaf.unrecognized`)."""
    pose_error_deg: float | None = None

    @property
    def wrong_accept(self) -> bool:
        """A part that ended in an accepting leaf not naming its landing and state (design.md,
        "Landings": the next station takes a part it should not)."""
        return self.outcome == "failure" and self.cause == "wrong result" and not self.rejected

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        out: dict[str, object] = {
            "trial": self.index,
            "part": self.part,
            "landing": self.landing,
            "rejected": self.rejected,
            "unrecognized": self.unrecognized,
            "start_deg": _r(self.start_deg),
            "outcome": self.outcome,
            "step": self.step,
            "cause": self.cause,
            "predicted": self.predicted,
            "reason": self.reason,
            "draw": None if self.draw is None else self.draw.to_dict(),
            "final_state": self.final_state,
        }
        if self.final_deg is not None or self.pose_error_deg is not None:
            out["final_deg"] = _r(self.final_deg)
            err = self.pose_error_deg
            out["pose_error_deg"] = None if err is None or math.isinf(err) else _r(err)
        out["pushes"] = [p.to_dict() for p in self.pushes]
        return out


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
    unless ``--rotation-noise`` overrides it, up to 180 deg, beyond what an ``Uncertainty``
    holds); :attr:`sampled_dict` puts the two together. ``friction_belt`` and
    ``friction_fence`` are the nominal coefficients and ``*_range`` the ranges drawn from.
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

    @property
    def sampled_dict(self) -> dict[str, float]:
        """The uncertainty actually sampled, under design.md's names: the shape and COM
        tolerance drawn and the rotation error drawn (``rotation_noise_deg``)."""
        return {**self.sampled.to_dict(), "rotation_error_deg": self.rotation_noise_deg}

    def sampled_words(self) -> str:
        """What was sampled, in words (the command line and the report say it alike)."""
        if self.ideal:
            return "nothing sampled (--ideal)"
        fb, ff = self.friction_belt_range, self.friction_fence_range
        return (
            f"sampled: rotation error ±{self.rotation_noise_deg:g} deg per rotation, vertices "
            f"within {self.sampled.shape_tolerance_mm:g} mm, COM within "
            f"{self.sampled.com_tolerance_mm:g} mm, friction belt {fb.text() if fb else '-'} / "
            f"fence {ff.text() if ff else '-'}"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        fb = self.friction_belt_range or FrictionRange(self.friction_belt, self.friction_belt)
        ff = self.friction_fence_range or FrictionRange(self.friction_fence, self.friction_fence)
        return {
            "trials": self.trials,
            "seed": self.seed,
            "ideal": self.ideal,
            "sampled_uncertainty": self.sampled_dict,
            "sampled": self.sampled_words(),
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
    member (design.md, "Landings"), ``unrecognized`` in an accept leaf that names it among
    other members (right, but the part is not known); ``wrong_accepts`` of the failures in an
    accepting leaf that does not. Push agreement counts the
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
    unrecognized: int = 0
    """Successes that ended in an accept leaf naming several members (:attr:`TrialResult.
    unrecognized`): right by the plan's contract, yet the part is not known."""
    physical_agreements: int | None = None
    """Settled pushes that ended where the push function says or in the same physical state
    of the plan's model (:attr:`PushRecord.agrees_physically`); None without the model."""
    certified: Certified | None = None
    """What the plan holds (:func:`certified_bounds`); None when not known."""
    width_warning: str | None = None
    """The plan's sensor is finer than the simulated widths (:func:`width_accuracy_warning`)."""
    real_parts: tuple[RealPart, ...] = ()
    """The members simulated on their own outlines (``simulate --part``); empty: every member
    on the plan's hull, and the JSON is as before."""
    pose_rule: PoseRuleWords | None = None
    """How those members' trials are judged (None without ``--part``)."""
    members: tuple[tuple[str, str | None], ...] = ()
    """Each member's part name and landing (None: a plan not over landings), as the plan file
    names them, beside its label in ``parts``: the JSON's ``per_part`` gives both, so that a
    reader need not split a label (part names are free text)."""
    sizes: tuple[float, ...] = ()
    """Each member's size (mm, its hull's diameter) before :attr:`scales` (empty: not known)."""

    def geometry_warnings(self) -> list[str]:
        """The members simulated on a part beyond the plan's declared shape tolerance, one
        line each (:meth:`~feederkit.sim.real.RealPart.tolerance_warning`)."""
        found = (r.tolerance_warning() for r in self.real_parts)
        return [w for w in found if w is not None]

    def scale_notes(self) -> list[str]:
        """One line per member simulated at another size than its own (docs/simulation.md,
        "Scale"): its trials say nothing of the real part's dynamics."""
        notes = []
        for i, (label, scale) in enumerate(zip(self.parts, self.scales, strict=True)):
            if scale == 1.0:
                continue
            which = "small" if scale > 1.0 else "large"
            sized = ""
            if i < len(self.sizes):
                size = self.sizes[i]
                sized = f"a {size:.3g} mm part at {size * scale:.3g} mm, "
            notes.append(
                f"{label} was simulated at {scale:.3g}x its size ({sized}as docs/simulation.md "
                f'"Scale" says): the dynamics of the real {which} part are not checked'
            )
        return notes

    def geometry(self) -> list[tuple[str, str]]:
        """Each member and the geometry simulated for it, in words."""
        real = {r.label: r for r in self.real_parts}
        return [(p, real[p].words() if p in real else f"{p}: the plan's hull") for p in self.parts]

    @property
    def success_interval(self) -> tuple[float, float]:
        """The 95 % Wilson score interval of the success rate."""
        return wilson(self.successes, self.trials)

    def success_words(self) -> str:
        """Successes of trials, the rate and its 95 % Wilson interval, in words."""
        return success_words(self.successes, self.trials)

    def push_words(self) -> str:
        """The push agreement in words, with the pushes that ended in the predicted state's
        physical state when that is more (a merged state's facets are one state to the
        plan: ending on another of them is no miss)."""
        return push_words(self.push_agreements, self.settled_pushes, self.physical_agreements)

    @property
    def beyond_certified(self) -> str | None:
        """A note when the sampled rotation error or shape tolerance exceeds what the plan
        certifies (None otherwise, or when that is not known)."""
        if self.certified is None:
            return None
        st = self.settings
        return beyond_certified_note(
            st.rotation_noise_deg, st.sampled.shape_tolerance_mm, self.certified
        )

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
            "success_interval_95": [_r(x, 6) for x in self.success_interval],
            "interval_method": INTERVAL_METHOD,
            "success_words": self.success_words(),
            "rejects": self.rejects,
            "unrecognized": self.unrecognized,
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
            "physical_agreements": self.physical_agreements,
            "push_words": self.push_words(),
            "push_misses": [m.to_dict() for m in self.push_misses],
            "parts": list(self.parts),
            "per_part": [
                {"part": p, "trials": t, "successes": k, **self._member_keys(i)}
                for i, (p, t, k) in enumerate(
                    zip(self.parts, self.part_trials, self.part_successes, strict=True)
                )
            ],
            "scale": [_r(s, 6) for s in self.scales],
            "scale_notes": self.scale_notes(),
            "min_margin_deg": _r(self.min_margin_deg),
            "certified": None if self.certified is None else self.certified.to_dict(),
            "beyond_certified": self.beyond_certified,
            "width_accuracy_warning": self.width_warning,
            "settings": self.settings.to_dict(),
            "wall_time_s": _r(self.wall_time_s, 3),
            "sim_time_s": _r(self.sim_time_s, 3),
            **self._geometry_dict(),
        }

    def _member_keys(self, i: int) -> dict[str, object]:
        """``name`` and ``landing`` of member ``i`` for its ``per_part`` entry (none when
        the summary does not know them)."""
        if i >= len(self.members):
            return {}
        name, landing = self.members[i]
        return {"name": name, "landing": landing}

    def _geometry_dict(self) -> dict[str, object]:
        """``geometry`` and ``success_rule`` for a run with ``--part``; nothing otherwise."""
        if not self.real_parts:
            return {}
        real = {r.label: r for r in self.real_parts}
        return {
            "geometry": [
                real[p].to_dict()
                if p in real
                else {"part": p, "simulated": "plan hull", "source": None}
                for p in self.parts
            ],
            "success_rule": None if self.pose_rule is None else self.pose_rule.to_dict(),
            "warnings": self.geometry_warnings(),
        }


@dataclass(frozen=True)
class PoseRuleWords:
    """The success rule of members simulated on their own outlines, as reported: the part must
    finally rest within ``rotation_error_deg + settle_tolerance_deg`` of the resting range,
    under the plan's declared uncertainty, of a state the leaf names."""

    rotation_error_deg: float
    settle_tolerance_deg: float

    @property
    def limit_deg(self) -> float:
        """The allowed distance (deg) from a named state's resting range."""
        return self.rotation_error_deg + self.settle_tolerance_deg

    def words(self) -> str:
        """The rule in one line."""
        return (
            f"a part on its own outline succeeds when it finally rests within "
            f"{self.limit_deg:g} deg (declared rotation error {self.rotation_error_deg:g} + "
            f"settle tolerance {self.settle_tolerance_deg:g}) of the resting range, under the "
            "plan's declared uncertainty, of a state the result names"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {
            "limit_deg": _r(self.limit_deg, 6),
            "rotation_error_deg": _r(self.rotation_error_deg, 6),
            "settle_tolerance_deg": _r(self.settle_tolerance_deg, 6),
            "words": self.words(),
        }
