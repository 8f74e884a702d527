"""The cell profile: the feeder described once (design.md, "Cell profile"; docs/cell.md).

A TOML file, ``feederkit.toml`` in the working directory or ``--cell FILE``::

    [sensor]  model = "tolerance"   # "tolerance" | "led" | "none"
              tolerance_mm = 0.2    # with model = "tolerance"
              pitch_mm = 0.5        # with model = "led"
              noise_mm = 0.05       # with model = "led" (default 0)
    [robot]   rotation_error_deg = 1.0
              pick_place_s = 1.2
              rotation_speed_deg_s = 180
    [belt]    speed_m_s = 0.1
              drop_to_fence_mm = 150

Every section and key is optional; unknown sections and keys are refused, and every bad
field is named on its own line (:class:`CellProfileError`). Command-line options override
the profile (:func:`resolve_settings`); every output names the profile it used
(:attr:`CellProfile.source`).

The cycle time of a plan (:func:`cycle_time`) follows the paper's operation (section 3.3):
the first alignment is the drop from the feeder and the drift to the fence; every later
operation is a pick, a rotation through the plan's angle, a place, and again the drift to
the fence, where the part aligns and is read.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from feederkit.errors import InputError
from feederkit.planning.options import ActionCosts
from feederkit.planning.stats import expected_seconds, worst_seconds
from feederkit.sensors import LED_MAX_NOISE_PITCHES, SensorModel, make_sensor, too_noisy
from feederkit.uncertainty import Uncertainty

DEFAULT_CELL_FILE = "feederkit.toml"
"""The profile read from the working directory when no ``--cell FILE`` is given."""

BUILT_IN = "built-in defaults"
"""The :attr:`CellProfile.source` when no profile file was read."""

SENSOR_MODELS = ("none", "tolerance", "led")


class CellProfileError(InputError):
    """A profile with bad fields; ``problems`` holds one line per bad field."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.problems = tuple(problems)
        super().__init__(f"{source}: " + "; ".join(problems))


@dataclass(frozen=True)
class SensorSection:
    """``[sensor]``: the model and its parameters (mm); see :mod:`feederkit.sensors`."""

    model: str = "none"
    tolerance_mm: float | None = None
    pitch_mm: float | None = None
    noise_mm: float = 0.0

    def sensor(self) -> SensorModel:
        """The sensor this section describes."""
        if self.model == "tolerance":
            return make_sensor(tolerance=self.tolerance_mm)
        if self.model == "led":
            return make_sensor(led_pitch=self.pitch_mm, noise=self.noise_mm)
        return make_sensor(sensorless=True)


@dataclass(frozen=True)
class RobotSection:
    """``[robot]``: rotation error (deg, design.md's "Uncertainty"), pick-and-place time (s),
    rotation speed (deg/s). The timing fields are None when the profile does not give them."""

    rotation_error_deg: float = 1.0
    pick_place_s: float | None = None
    rotation_speed_deg_s: float | None = None


@dataclass(frozen=True)
class BeltSection:
    """``[belt]``: belt speed (m/s) and the travel (mm) from the drop point to the fence."""

    speed_m_s: float | None = None
    drop_to_fence_mm: float | None = None


@dataclass(frozen=True)
class CellProfile:
    """A feeder cell: sensor, robot and belt, and where the description came from."""

    sensor: SensorSection = field(default_factory=SensorSection)
    robot: RobotSection = field(default_factory=RobotSection)
    belt: BeltSection = field(default_factory=BeltSection)
    source: str = BUILT_IN

    def missing_timing(self) -> tuple[str, ...]:
        """The fields a cycle time needs that the profile does not give."""
        wanted = {
            "robot.pick_place_s": self.robot.pick_place_s,
            "robot.rotation_speed_deg_s": self.robot.rotation_speed_deg_s,
            "belt.speed_m_s": self.belt.speed_m_s,
            "belt.drop_to_fence_mm": self.belt.drop_to_fence_mm,
        }
        return tuple(k for k, v in wanted.items() if v is None)

    def to_dict(self) -> dict[str, Any]:
        """The profile as its three sections and ``source``, for JSON output."""
        return {
            "source": self.source,
            "sensor": {
                "model": self.sensor.model,
                "tolerance_mm": self.sensor.tolerance_mm,
                "pitch_mm": self.sensor.pitch_mm,
                "noise_mm": self.sensor.noise_mm,
            },
            "robot": {
                "rotation_error_deg": self.robot.rotation_error_deg,
                "pick_place_s": self.robot.pick_place_s,
                "rotation_speed_deg_s": self.robot.rotation_speed_deg_s,
            },
            "belt": {
                "speed_m_s": self.belt.speed_m_s,
                "drop_to_fence_mm": self.belt.drop_to_fence_mm,
            },
        }


# Per section, per key: (what the value must be, its check).
_POSITIVE = ("a finite positive number", lambda v: v > 0.0)
_NONNEGATIVE = ("zero or a finite positive number", lambda v: v >= 0.0)
_ROTATION = ("a number in [0, 90)", lambda v: 0.0 <= v < 90.0)
_FIELDS: dict[str, dict[str, tuple[str, Any] | None]] = {
    "sensor": {"model": None, "tolerance_mm": _POSITIVE, "pitch_mm": _POSITIVE,
               "noise_mm": _NONNEGATIVE},
    "robot": {"rotation_error_deg": _ROTATION, "pick_place_s": _NONNEGATIVE,
              "rotation_speed_deg_s": _POSITIVE},
    "belt": {"speed_m_s": _POSITIVE, "drop_to_fence_mm": _NONNEGATIVE},
}  # fmt: skip
_UNITS = {"mm": "mm", "deg": "degrees", "s": "seconds", "deg_s": "deg/s", "m_s": "m/s"}


def _unit(key: str) -> str:
    for suffix in ("deg_s", "m_s", "mm", "deg", "s"):
        if key.endswith("_" + suffix):
            return " " + _UNITS[suffix]
    return ""


MAX_OPERATION_S = 1e9
"""The most seconds a profile's pick and place, half turn or drift may take (about 32
years): beyond any cell, and far enough below the largest float that the seconds of a plan,
summed over its operations, stay finite."""


def _timing_problems(robot: RobotSection, belt: BeltSection) -> list[str]:
    """One line per time that the profile's fields, each valid, make longer than
    :data:`MAX_OPERATION_S` (or beyond a float): the pick and place, a half turn, the drift."""
    problems = []
    limit = f"must be at most {MAX_OPERATION_S:g} seconds"
    pick, speed = robot.pick_place_s, robot.rotation_speed_deg_s
    if pick is not None and pick > MAX_OPERATION_S:
        problems.append(f"robot.pick_place_s {limit}, got {pick:g}")
    if speed is not None and 180.0 / speed > MAX_OPERATION_S:
        turn = 180.0 / speed
        problems.append(f"180 / robot.rotation_speed_deg_s (a half turn) {limit}, got {turn:.3g}")
    if belt.speed_m_s is not None and belt.drop_to_fence_mm is not None:
        drift = belt.drop_to_fence_mm / (1000.0 * belt.speed_m_s)
        if drift > MAX_OPERATION_S:
            problems.append(
                f"belt.drop_to_fence_mm / (1000 * belt.speed_m_s) (the drift to the fence) "
                f"{limit}, got {drift:.3g}"
            )
    return problems


def _as_float(value: float) -> float:
    """``value`` as a float; an integer too large for one is infinite (a 300-digit integer
    is no number of seconds or millimetres, and must be named like ``1e400``)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _shown(value: object) -> str:
    """A profile's value as the message quotes it, a long one cut (a 300-digit integer)."""
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"


def _sections() -> str:
    return ", ".join(f"[{s}]" for s in _FIELDS)


def parse_cell(data: dict[str, Any], source: str) -> CellProfile:
    """A profile from the parsed TOML tables; CellProfileError names every bad field."""
    problems: list[str] = []
    bad_model = False
    values: dict[str, dict[str, Any]] = {name: {} for name in _FIELDS}
    for section, table in data.items():
        if not isinstance(table, dict) and section not in _FIELDS:  # before any [section]
            owner = [s for s, keys in _FIELDS.items() if section in keys]
            where = f"[{owner[0]}]" if owner else f"one of {_sections()}"
            problems.append(f"{section} is a key outside any section: it goes in {where}")
            continue
        if section not in _FIELDS:
            problems.append(f"unknown section [{section}] (the sections are {', '.join(_FIELDS)})")
            continue
        if not isinstance(table, dict):
            problems.append(f"{section} must be a table ([{section}])")
            continue
        for key, value in table.items():
            name = f"{section}.{key}"
            if key not in _FIELDS[section]:
                known = ", ".join(_FIELDS[section])
                problems.append(f"unknown key {name} (the keys of [{section}] are {known})")
                continue
            check = _FIELDS[section][key]
            if check is None:  # sensor.model
                if value not in SENSOR_MODELS:
                    bad_model = True
                    problems.append(
                        f"{name} must be one of {', '.join(map(repr, SENSOR_MODELS))}, "
                        f"got {_shown(value)}"
                    )
                    continue
                values[section][key] = value
                continue
            what, ok = check
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not math.isfinite(_as_float(value))
                or not ok(float(value))
            ):
                problems.append(f"{name} must be {what} of{_unit(key)}, got {_shown(value)}")
                continue
            values[section][key] = float(value)
    sensor = values["sensor"]
    model = sensor.get("model", "none")
    # The keys given, valid or not: a bad value is named above, not missing as well.
    given = data.get("sensor") if isinstance(data.get("sensor"), dict) else {}
    needs = {"tolerance": "tolerance_mm", "led": "pitch_mm"}
    if model in needs and needs[model] not in given and not bad_model:
        problems.append(f"sensor.{needs[model]} is required with model = {model!r}")
    for key, owner in (("tolerance_mm", "tolerance"), ("pitch_mm", "led"), ("noise_mm", "led")):
        if key in given and model != owner and not bad_model:
            problems.append(f"sensor.{key} goes with model = {owner!r}, but the model is {model!r}")
    pitch, noise = sensor.get("pitch_mm"), sensor.get("noise_mm", 0.0)
    if model == "led" and pitch is not None and too_noisy(noise, pitch):
        problems.append(
            f"sensor.noise_mm must be at most {LED_MAX_NOISE_PITCHES} times sensor.pitch_mm "
            f"({LED_MAX_NOISE_PITCHES * pitch:g} mm), got {noise:g}: no LED array is that far off"
        )
    robot, belt = RobotSection(**values["robot"]), BeltSection(**values["belt"])
    problems += _timing_problems(robot, belt)
    if problems:
        raise CellProfileError(source, problems)
    return CellProfile(sensor=SensorSection(**sensor), robot=robot, belt=belt, source=source)


def read_cell(path: str | Path) -> CellProfile:
    """Read and validate a profile file; InputError when it is missing, a folder or not TOML."""
    p = Path(path)
    if p.is_dir():
        raise InputError(f"{p}: a folder, not a cell profile file")
    if not p.is_file():
        raise InputError(f"{p}: no such cell profile")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not a valid TOML file ({exc})") from None
    except UnicodeDecodeError:
        raise InputError(f"{p}: not a UTF-8 text file") from None
    return parse_cell(data, str(p))


def load_cell(path: str | Path | None = None, *, directory: str | Path = ".") -> CellProfile:
    """The profile of ``--cell FILE`` if given, else ``feederkit.toml`` in ``directory`` if it
    exists, else the built-in defaults (no sensor, 1 deg rotation error, no timing)."""
    if path is not None:
        return read_cell(path)
    default = Path(directory) / DEFAULT_CELL_FILE
    if default.exists():  # a folder or an unreadable file is refused, not passed over
        return read_cell(default)
    return CellProfile()


MODEL_BELT_SPEED_M_S = 0.1
"""The belt speed (m/s) the physics check measured the model's push bands and overshoot at
(docs/uncertainty.md, "Overshoot")."""


@dataclass(frozen=True)
class CellSettings:
    """What a planning command uses: the profile with the command line's overrides applied.

    ``overrides`` names the command-line options that replaced profile fields.
    """

    profile: CellProfile
    sensor: SensorModel
    rotation_error_deg: float
    overrides: tuple[str, ...] = ()

    def describe(self) -> str:
        """One line naming the profile and the overrides, for every output."""
        return f"cell profile: {self.describe_source()}"

    def describe_source(self) -> str:
        """The profile's source and the overrides: ``feederkit.toml (overridden: --tolerance)``."""
        text = self.profile.source
        if self.overrides:
            text += f" (overridden: {', '.join(self.overrides)})"
        return text

    def belt_warning(self) -> str | None:
        """A warning when the profile's belt runs faster than the physics check measured the
        model at (``mechanics.uncertain.OVERSHOOT_DEG_MM``: a part turns into a state at
        about the belt's speed over its size and may overshoot it, farther as the square of
        the speed); None otherwise."""
        v = self.profile.belt.speed_m_s
        if v is None or v <= MODEL_BELT_SPEED_M_S:
            return None
        ratio = v / MODEL_BELT_SPEED_M_S  # squared by a product: inf, not OverflowError
        return (
            f"the belt runs at {v:g} m/s ({self.profile.source}); the model's overshoot of "
            f"shallow states was measured at {MODEL_BELT_SPEED_M_S:g} m/s and grows as the "
            f"square of the speed ({ratio * ratio:.3g} times here): check "
            f"the plan with feederkit simulate --belt-speed {v:g}"
        )

    def costs(self) -> ActionCosts | None:
        """The profile's action costs, or None when it gives no timing."""
        return None if self.profile.missing_timing() else action_costs(self.profile)

    def to_dict(self) -> dict[str, Any]:
        """``{"profile", "overrides", "sensor", "rotation_error_deg"}`` for JSON output."""
        return {
            "profile": self.profile.source,
            "overrides": list(self.overrides),
            "sensor": self.sensor.to_dict(),
            "rotation_error_deg": self.rotation_error_deg,
        }


def resolve_settings(
    profile: CellProfile,
    *,
    sensorless: bool = False,
    tolerance: float | None = None,
    led_pitch: float | None = None,
    noise: float | None = None,
    rotation_error: float | None = None,
) -> CellSettings:
    """The sensor and settings of ``profile`` with the command line's options on top.

    Any of ``--sensorless``, ``--tolerance`` and ``--led-pitch`` replaces the profile's
    sensor (``--noise`` with it, else the profile's LED noise); ``--noise`` alone changes
    the noise of the profile's LED array. InputError for impossible values.
    """
    overrides: list[str] = []
    if sensorless or tolerance is not None or led_pitch is not None:
        overrides += [
            name
            for name, given in (
                ("--sensorless", sensorless),
                ("--tolerance", tolerance is not None),
                ("--led-pitch", led_pitch is not None),
                ("--noise", noise is not None),
            )
            if given
        ]
        if noise is None and led_pitch is not None and profile.sensor.model == "led":
            noise = profile.sensor.noise_mm
        sensor = make_sensor(
            sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
        )
    elif noise is not None:
        if profile.sensor.model != "led":
            raise InputError(
                f"--noise goes with --led-pitch or a profile whose sensor is an LED array "
                f"({profile.source} has model = {profile.sensor.model!r})"
            )
        overrides.append("--noise")
        sensor = make_sensor(led_pitch=profile.sensor.pitch_mm, noise=noise)
    else:
        sensor = profile.sensor.sensor()
    r = profile.robot.rotation_error_deg
    if rotation_error is not None:
        # The one validation of a rotation error (finite, in [0, 90) degrees), its flag named
        # last as the command line names every term's (cli.common.with_flags).
        try:
            r = Uncertainty(rotation_error_deg=float(rotation_error)).rotation_error_deg
        except InputError as exc:
            raise InputError(f"{exc} (--rotation-error)") from None
        overrides.append("--rotation-error")
    return CellSettings(profile, sensor, r, tuple(overrides))


def expectation_words(members: Sequence[Any]) -> str:
    """What a plan's expected figures (operations, seconds) average over, in a few words.

    ``members`` are the plan's parts (``PlanPart``: ``name``, ``landing``, ``share``). The
    expectation is over the members' prior shares (the mix shares, times the landing
    probabilities over landings; equal when the plan stores none) and, within a member,
    over a start orientation drawn uniformly (each stable state weighted by its resting
    range; docs/plans.md, "stats").
    """
    uniform = "uniform start orientation"
    if len(members) == 1:
        return uniform
    landings = any(m.landing is not None for m in members)
    if any(m.share is None for m in members):
        return f"{'members' if landings else 'parts'} equally likely, {uniform}"
    if not landings:
        over = "mix shares"
    elif len({m.name for m in members}) == 1:
        over = "landing probabilities"
    else:
        over = "mix shares × landing probabilities"
    return f"over the {over}, {uniform}"


@dataclass(frozen=True)
class CycleTime:
    """Seconds per part of a plan in a cell, expected and in the worst case, and the parts
    per minute they give.

    The expectation is the plan's expected length's (:func:`expectation_words`): over the
    members' prior shares (mix shares, times the landing probabilities over landings) and a
    uniform start orientation within each member; the worst case is the slowest path.
    """

    expected_s: float
    worst_s: float

    @property
    def parts_per_minute(self) -> float | None:
        """60 / expected seconds (None when a part takes no time)."""
        return 60.0 / self.expected_s if self.expected_s > 0.0 else None

    @property
    def worst_parts_per_minute(self) -> float | None:
        """60 / worst seconds (None when a part takes no time)."""
        return 60.0 / self.worst_s if self.worst_s > 0.0 else None

    def to_dict(self) -> dict[str, float | None]:
        """``{"expected_s", "worst_s", "parts_per_minute", "worst_parts_per_minute"}``."""
        return {
            "expected_s": self.expected_s,
            "worst_s": self.worst_s,
            "parts_per_minute": self.parts_per_minute,
            "worst_parts_per_minute": self.worst_parts_per_minute,
        }


def rotation_deg(action_deg: float) -> float:
    """How far the robot turns for a plan's rotation: the shorter way round (deg).

    A rotation by ``a`` and by ``a - 360`` leave the part in the same pose.
    """
    a = action_deg % 360.0
    return min(a, 360.0 - a)


def action_costs(profile: CellProfile) -> ActionCosts:
    """The seconds of an operation in the cell, as the planners take them
    (:class:`~feederkit.planning.options.ActionCosts`); InputError naming the timing fields
    the profile does not give, CellProfileError those that make a time too long to compute
    with (a profile not read by :func:`parse_cell`)."""
    missing = profile.missing_timing()
    if missing:
        raise InputError(
            f"{profile.source}: a cycle time needs {', '.join(missing)} in the cell profile"
        )
    problems = _timing_problems(profile.robot, profile.belt)
    if problems:
        raise CellProfileError(profile.source, problems)
    drift = profile.belt.drop_to_fence_mm / (profile.belt.speed_m_s * 1000.0)  # type: ignore[operator]
    return ActionCosts(
        pick_place_s=profile.robot.pick_place_s,  # type: ignore[arg-type]
        rotation_speed_deg_s=profile.robot.rotation_speed_deg_s,  # type: ignore[arg-type]
        drift_s=drift,
    )


def operation_seconds(action_deg: float | None, profile: CellProfile) -> float:
    """Seconds of one push-align operation: the first (``action_deg`` None) is the drift
    from the drop to the fence; a later one adds the pick and place and the rotation."""
    return action_costs(profile).seconds(action_deg)


def cycle_time(plan: Any, profile: CellProfile) -> CycleTime:
    """The expected and worst seconds per part of a plan in the cell ``profile``.

    ``plan`` is a planner's result (``machine`` and ``root``) or anything with such a
    ``result`` (a made plan). Expected: start states weighted as the machine says (its
    ``MachineState.weight``: the mix shares), outcomes and readings as for the plan's
    expected length (:func:`feederkit.planning.stats.expected_seconds`); worst: the slowest
    path of the tree.
    """
    result = getattr(plan, "result", plan)
    costs = action_costs(profile)
    machine, root = result.machine, result.root
    mass = sum(s.weight for s in machine.states)
    return CycleTime(expected_seconds(machine, root, costs) / mass, worst_seconds(root, costs))


def cycle_time_dict(plan: Any, settings: CellSettings) -> dict[str, Any] | None:
    """``{"profile", "expected_s", "worst_s", "parts_per_minute", "worst_parts_per_minute"}``
    for JSON output and reports, or None when the profile has no timing fields."""
    if settings.profile.missing_timing():
        return None
    return {"profile": settings.describe_source(), **cycle_time(plan, settings.profile).to_dict()}


TIMING_FIELDS = 4
"""The fields a cycle time needs (:meth:`CellProfile.missing_timing`)."""


def _rate(ppm: float) -> str:
    """Parts per minute in words: one decimal, in powers of ten past a million (a profile
    whose every time is near 0 gave a 300-digit figure)."""
    return f"{ppm:.1f}" if ppm < 1e6 else f"{ppm:.3g}"


def annotate_cycle_time(made: Any, settings: CellSettings) -> dict[str, Any] | None:
    """Put :func:`cycle_time_dict` of a made plan in its plan file as ``stats.cycle_time``
    (null when the profile has no timing) and the profile it was made with as
    ``stats.cell_profile`` (design.md: every output names the profile it used), before the
    file is written or stored, so reports and ``changeover show`` find them; return the
    cycle time."""
    cycle = cycle_time_dict(made, settings)
    made.plan["stats"]["cycle_time"] = cycle
    made.plan["stats"]["cell_profile"] = settings.describe_source()
    return cycle


def cycle_time_text(
    cycle: dict[str, Any] | None,
    profile: str | None = None,
    *,
    name_profile: bool = True,
    missing: Sequence[str] = (),
) -> str:
    """A ``cycle_time_dict`` in words, for terminal output and reports; ``profile`` names
    the profile when there is no cycle time (``CellSettings.describe``) and ``missing`` the
    timing fields it lacks (:meth:`CellProfile.missing_timing`); ``name_profile`` False
    leaves the profile out of a known cycle time (an output whose header names it)."""
    if cycle is None:
        where = f" ({profile})" if profile else ""
        some = 0 < len(missing) < TIMING_FIELDS  # else none at all, or not known which
        lacks = f"no {', '.join(missing)}" if some else "no robot and belt timing"
        return f"cycle time: not known, the cell profile gives {lacks}{where}; see docs/cell.md"
    ppm = cycle.get("parts_per_minute")
    rate = "" if ppm is None else f", {_rate(ppm)} parts/min"
    worst = cycle.get("worst_parts_per_minute")
    worst_rate = "" if worst is None else f", {_rate(worst)} parts/min"
    where = f" (cell profile: {cycle['profile']})" if name_profile else ""
    return (
        f"cycle time: {cycle['expected_s']:.2f} s per part expected{rate}; "
        f"{cycle['worst_s']:.2f} s at worst{worst_rate}{where}"
    )
