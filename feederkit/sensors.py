"""Sensor models: the readings each stable state can produce; branching by reading (section 5).

The reading is the part's diameter (width across the belt, mm) after alignment (design.md).

- :class:`NoSensor`: sensorless; every state gives the same (no) reading.
- :class:`ToleranceSensor`: a state of diameter ``d`` reads any value in the open interval
  ``(d - e, d + e)``.
- :class:`LedSensor`: beams at heights ``k * pitch`` (k = 1, 2, ...) above the fence; a width
  ``w`` blocks the beams below it, ``count = #{k : k * pitch < w}``; with alignment noise ``e``
  the width lies anywhere in ``[d - e, d + e]``. The reading is ``count * pitch`` mm.

Two states are indistinguishable when their reading sets overlap; an indistinguishable set
(definition 10) is a connected component of that relation, which is not transitive.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from feederkit.errors import InputError

Grouping = Literal["exact", "components"]


@dataclass(frozen=True)
class NoSensor:
    """No sensing: the sensorless case (section 4)."""

    model: str = "none"


@dataclass(frozen=True)
class ToleranceSensor:
    """A diameter sensor reading strictly within ``tolerance`` mm of the true diameter."""

    tolerance: float
    model: str = "tolerance"


@dataclass(frozen=True)
class LedSensor:
    """An LED array of beam pitch ``pitch`` mm with alignment noise ``noise`` mm."""

    pitch: float
    noise: float = 0.0
    model: str = "led"


SensorModel = NoSensor | ToleranceSensor | LedSensor


@dataclass(frozen=True)
class ReadingBranch:
    """The states consistent with each reading in the closed ``[lo, hi]`` (None: sensorless)."""

    lo: float | None
    hi: float | None
    members: tuple[int, ...]


def make_sensor(
    *,
    sensorless: bool = False,
    tolerance: float | None = None,
    led_pitch: float | None = None,
    noise: float | None = None,
) -> SensorModel:
    """The sensor model for the command line's options; impossible settings are bad input."""
    chosen = sum([sensorless, tolerance is not None, led_pitch is not None])
    if chosen > 1:
        raise InputError("choose one of --sensorless, --tolerance and --led-pitch")
    if noise is not None and led_pitch is None:
        raise InputError("--noise goes with --led-pitch")
    if tolerance is not None:
        if not math.isfinite(tolerance) or tolerance <= 0.0:
            raise InputError(f"--tolerance must be a positive number of mm, got {tolerance}")
        return ToleranceSensor(float(tolerance))
    if led_pitch is not None:
        if not math.isfinite(led_pitch) or led_pitch <= 0.0:
            raise InputError(f"--led-pitch must be a positive number of mm, got {led_pitch}")
        e = 0.0 if noise is None else noise
        if not math.isfinite(e) or e < 0.0:
            raise InputError(f"--noise must be zero or a positive number of mm, got {noise}")
        return LedSensor(float(led_pitch), float(e))
    return NoSensor()


def sensor_to_dict(sensor: SensorModel) -> dict[str, object]:
    """The plan file's ``sensor`` object."""
    if isinstance(sensor, ToleranceSensor):
        return {"model": "tolerance", "tolerance_mm": sensor.tolerance}
    if isinstance(sensor, LedSensor):
        return {"model": "led", "pitch_mm": sensor.pitch, "noise_mm": sensor.noise}
    return {"model": "none"}


def sensor_from_dict(data: object) -> SensorModel:
    """Read the plan file's ``sensor`` object."""
    if not isinstance(data, dict) or "model" not in data:
        raise InputError("the plan's 'sensor' must be an object with a 'model'")
    model = data["model"]
    try:
        if model == "none":
            return NoSensor()
        if model == "tolerance":
            return make_sensor(tolerance=float(data["tolerance_mm"]))
        if model == "led":
            return make_sensor(
                led_pitch=float(data["pitch_mm"]), noise=float(data.get("noise_mm", 0.0))
            )
    except (KeyError, TypeError, ValueError):
        raise InputError(f"the plan's {model!r} sensor lacks its parameters") from None
    raise InputError(f"unknown sensor model {model!r}")


def led_count(pitch: float, width: float) -> int:
    """Number of beams at heights ``k * pitch`` (k >= 1) strictly below ``width``."""
    if width <= 0.0:
        return 0
    return max(0, math.ceil(width / pitch - 1e-12) - 1)


LED_EDGE_REL = 1e-6
"""A width within this fraction of the pitch of a beam's height may block that beam or not."""


def led_counts(sensor: LedSensor, diameter: float) -> tuple[int, int]:
    """The smallest and largest beam count a state of this diameter can block.

    Widths within ``LED_EDGE_REL * pitch`` of a beam's height count both ways, so a diameter
    that sits on a beam (an exact multiple of the pitch) is not trusted to one count.
    """
    e = sensor.noise + LED_EDGE_REL * sensor.pitch
    return led_count(sensor.pitch, diameter - e), led_count(sensor.pitch, diameter + e)


def can_read_alike(sensor: SensorModel, d1: float, d2: float) -> bool:
    """Whether two diameters can produce the same reading (their reading sets overlap)."""
    if isinstance(sensor, NoSensor):
        return True
    if isinstance(sensor, ToleranceSensor):
        return abs(d1 - d2) < 2.0 * sensor.tolerance
    a, b = led_counts(sensor, d1), led_counts(sensor, d2)
    return a[0] <= b[1] and b[0] <= a[1]


def indistinguishable_sets(
    sensor: SensorModel, diameters: Sequence[float]
) -> list[tuple[int, ...]]:
    """Definition 10: connected components of the overlap relation, sorted by diameter."""
    order = sorted(range(len(diameters)), key=lambda i: diameters[i])
    if isinstance(sensor, NoSensor):
        return [tuple(order)] if order else []
    groups: list[list[int]] = []
    reach = -math.inf
    closed = isinstance(sensor, LedSensor)  # LED counts are closed ranges, tolerances open
    for i in order:
        lo, hi = _reading_extent(sensor, diameters[i])
        if groups and (lo <= reach if closed else lo < reach):
            groups[-1].append(i)
            reach = max(reach, hi)
        else:
            groups.append([i])
            reach = hi
    return [tuple(g) for g in groups]


def _reading_extent(sensor: SensorModel, d: float) -> tuple[float, float]:
    """The smallest and largest reading of a diameter (counts for the LED array)."""
    if isinstance(sensor, ToleranceSensor):
        return d - sensor.tolerance, d + sensor.tolerance
    if isinstance(sensor, LedSensor):
        c0, c1 = led_counts(sensor, d)
        return float(c0), float(c1)
    return -math.inf, math.inf


def split_by_reading(
    sensor: SensorModel, diameters: Sequence[float], grouping: Grouping = "exact"
) -> list[ReadingBranch]:
    """Branch a set of states (given by their diameters) on the reading, in reading order.

    ``exact``: each reading leads to exactly the states that can produce it; consecutive
    readings with the same states form one branch. ``components``: the paper's rule, a
    reading names its whole indistinguishable set. Branch intervals are closed and may share
    endpoints; a reading on a shared endpoint is consistent with a subset of either branch.
    """
    n = len(diameters)
    if n == 0:
        return []
    if isinstance(sensor, NoSensor):
        return [ReadingBranch(None, None, tuple(range(n)))]
    if grouping == "components":
        out = []
        for comp in indistinguishable_sets(sensor, diameters):
            lo = min(_reading_extent(sensor, diameters[i])[0] for i in comp)
            hi = max(_reading_extent(sensor, diameters[i])[1] for i in comp)
            out.append(_branch(sensor, lo, hi, tuple(sorted(comp))))
        return out
    if isinstance(sensor, ToleranceSensor):
        e = sensor.tolerance
        points = sorted({d - e for d in diameters} | {d + e for d in diameters})
        cells = []
        for a, b in zip(points, points[1:], strict=False):
            x = (a + b) / 2.0
            members = tuple(i for i in range(n) if abs(diameters[i] - x) < e)
            cells.append((a, b, members))
    else:
        extents = [led_counts(sensor, d) for d in diameters]
        c_lo = min(c for c, _ in extents)
        c_hi = max(c for _, c in extents)
        cells = []
        for c in range(c_lo, c_hi + 1):
            members = tuple(i for i in range(n) if extents[i][0] <= c <= extents[i][1])
            cells.append((float(c), float(c), members))
    merged: list[list] = []
    for a, b, members in cells:
        if not members:
            continue
        if (
            merged
            and merged[-1][2] == members
            and merged[-1][1] >= a - (1 if isinstance(sensor, LedSensor) else 0)
        ):
            merged[-1][1] = b
        else:
            merged.append([a, b, members])
    return [_branch(sensor, a, b, members) for a, b, members in merged]


def _branch(sensor: SensorModel, lo: float, hi: float, members: tuple[int, ...]) -> ReadingBranch:
    if isinstance(sensor, LedSensor):
        return ReadingBranch(lo * sensor.pitch, hi * sensor.pitch, members)
    return ReadingBranch(lo, hi, members)


def reading_consistent(sensor: SensorModel, diameter: float, reading: float) -> bool:
    """Whether a state of this diameter can produce ``reading`` (mm)."""
    if isinstance(sensor, NoSensor):
        return True
    if isinstance(sensor, ToleranceSensor):
        return abs(reading - diameter) < sensor.tolerance
    c0, c1 = led_counts(sensor, diameter)
    c = round(reading / sensor.pitch)
    return c0 <= c <= c1
