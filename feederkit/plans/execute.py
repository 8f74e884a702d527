"""Execute a plan file on the kinematic model: the part rebuilt from the file's hull and COM.

This is an independent check of the planner: it never looks at the push-align machine the
plan was made on, only at geometry (the push function of section 3.1, computed from the hull
and COM the file records) and at the plan file itself. A controller does the same steps: rotate
by ``action_deg``, let the part align (the push function), read the diameter, follow the
branch whose closed interval holds the reading.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

from feederkit.mechanics.push import PushFunction, StableState, push, push_function, rotation_after
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.fileformat import validate_plan
from feederkit.sensors import (
    LedSensor,
    NoSensor,
    SensorModel,
    ToleranceSensor,
    led_count,
    led_counts,
    sensor_from_dict,
)

ReadingChoice = Literal["nominal", "low", "high"] | Sequence[float | None]


@dataclass(frozen=True)
class KinematicModel:
    """A checked plan with its parts rebuilt from their hulls and COMs, and its sensor."""

    plan: dict[str, Any]
    sensor: SensorModel
    names: tuple[str, ...]
    parts: tuple[PushFunction, ...]

    def tiny_reading(self, part_index: int) -> float:
        """How far inside a tolerance's open reading interval its extreme readings are taken."""
        if not isinstance(self.sensor, ToleranceSensor):
            return 0.0
        e = self.sensor.tolerance
        return min(max(e * 1e-6, 2e-9 * self.parts[part_index].part.size), e / 4.0)


def rebuild_part(entry: dict[str, Any]) -> PushFunction:
    """The push function of a plan file's part, from its hull and COM only."""
    outline = make_outline(entry["name"], entry["hull"], com=entry["com"])
    return push_function(make_part(outline, revision=entry.get("revision")))


def kinematic_model(plan: dict[str, Any] | KinematicModel) -> KinematicModel:
    """Check a plan's structure and rebuild its parts (InputError for a broken plan)."""
    if isinstance(plan, KinematicModel):
        return plan
    validate_plan(plan)
    parts = tuple(rebuild_part(p) for p in plan["parts"])
    return KinematicModel(
        plan=plan,
        sensor=sensor_from_dict(plan["sensor"]),
        names=tuple(p["name"] for p in plan["parts"]),
        parts=parts,
    )


def nominal_reading(sensor: SensorModel, diameter: float) -> float | None:
    """The reading an exact sensor gives: the diameter, or the LED array's count times its pitch."""
    if isinstance(sensor, NoSensor):
        return None
    if isinstance(sensor, LedSensor):
        return led_count(sensor.pitch, diameter) * sensor.pitch
    return diameter


def extreme_readings(
    sensor: SensorModel, diameter: float, tiny: float
) -> tuple[float | None, float | None]:
    """The smallest and largest reading a state gives (``tiny`` inside a tolerance's interval)."""
    if isinstance(sensor, NoSensor):
        return None, None
    if isinstance(sensor, LedSensor):
        c0, c1 = led_counts(sensor, diameter)
        return c0 * sensor.pitch, c1 * sensor.pitch
    e = sensor.tolerance
    return diameter - e + tiny, diameter + e - tiny


def branches_holding(node: dict[str, Any], reading: float | None) -> list[int]:
    """The branches whose closed reading interval holds ``reading`` (all when sensorless)."""
    out = []
    for k, b in enumerate(node["branches"]):
        r = b["reading"]
        if r is None or (reading is not None and r[0] <= reading <= r[1]):
            out.append(k)
    return out


@dataclass(frozen=True)
class TraceStep:
    """One push-align operation as executed.

    ``number`` counts operations (1: the first alignment); ``action_deg`` is the rotation
    (None for the first alignment); ``theta_deg`` the fence orientation in the part frame when
    the part reached the fence; ``state``/``edge``/``diameter`` where it came to rest;
    ``reading`` what the sensor gave (None: sensorless); ``branch`` the index of the branch
    followed and ``interval`` its reading interval (``branch`` None: no branch holds the reading).
    """

    number: int
    action_deg: float | None
    theta_deg: float
    state: int
    edge: int
    diameter: float
    reading: float | None
    branch: int | None
    interval: tuple[float, float] | None
    rotation_error_deg: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """The step as JSON."""
        return {
            "operation": self.number,
            "action_deg": self.action_deg,
            "theta_deg": self.theta_deg,
            "state": self.state,
            "edge": self.edge,
            "diameter": self.diameter,
            "reading": self.reading,
            "branch": self.branch,
            "interval": None if self.interval is None else list(self.interval),
            "rotation_error_deg": self.rotation_error_deg,
        }


@dataclass(frozen=True)
class Trace:
    """One execution of a plan for one part from one start.

    ``result`` is the leaf's entries ``(part, state, pose_deg)`` (empty when the run stopped
    on a reading no branch holds); ``success``: the part's final (part, state) is among them.
    """

    part: str
    start_theta_deg: float
    steps: tuple[TraceStep, ...]
    final_state: int
    final_pose_deg: float
    result: tuple[tuple[str, int, float], ...]
    success: bool
    message: str

    def to_dict(self) -> dict[str, Any]:
        """The trace as JSON."""
        return {
            "part": self.part,
            "start_theta_deg": self.start_theta_deg,
            "steps": [s.to_dict() for s in self.steps],
            "final_state": self.final_state,
            "final_pose_deg": self.final_pose_deg,
            "result": [{"part": p, "state": s, "pose_deg": a} for p, s, a in self.result],
            "operations": len(self.steps),
            "success": self.success,
            "message": self.message,
        }


def _ops(k: int) -> str:
    return f"{k} operation" if k == 1 else f"{k} operations"


def leaf_entries(node: dict[str, Any]) -> tuple[tuple[str, int, float], ...]:
    """A result node's entries as ``(part, state, pose_deg)``."""
    return tuple((e["part"], e["state"], float(e["pose_deg"])) for e in node["result"])


def path_text(steps: Sequence[TraceStep]) -> str:
    """A run in one line: each operation's rotation (and error), state, reading and branch."""
    out = []
    for s in steps:
        rot = "align" if s.action_deg is None else f"rotate {s.action_deg:.6g}"
        if s.rotation_error_deg:
            rot += f"{s.rotation_error_deg:+.6g}"
        read = "" if s.reading is None else f", reads {s.reading:.10g}"
        branch = "no branch" if s.branch is None else f"branch {s.branch}"
        out.append(f"{s.number}: {rot} -> state {s.state}{read} -> {branch}")
    return "; ".join(out)


def finish(
    name: str,
    start: float,
    steps: Sequence[TraceStep],
    state: StableState,
    leaf: dict[str, Any] | None,
) -> Trace:
    """The trace of a run that ended in ``state`` at ``leaf`` (None: on an unheld reading).

    A failure's message gives the whole run in one line (:func:`path_text`).
    """
    steps = tuple(steps)
    head = f"{name} from theta {start:.10g} deg"
    if leaf is None:
        last = steps[-1]
        shown = "none" if last.reading is None else f"{last.reading:.10g} mm"
        msg = (
            f"{head}: reading {shown} at operation {last.number} (state {state.id}, diameter "
            f"{state.diameter:.6g} mm) is in no branch: a foreign part or a sensor fault; stop "
            f"[{path_text(steps)}]"
        )
        return Trace(name, start, steps, state.id, state.pose_deg, (), False, msg)
    result = leaf_entries(leaf)
    ok = any(p == name and s == state.id for p, s, _ in result)
    if ok:
        msg = (
            f"{head}: oriented in {_ops(len(steps))}, state {state.id} (edge {state.edge}), "
            f"pose {state.pose_deg:.6g} deg"
        )
    else:
        listed = ", ".join(f"{p} state {s}" for p, s, _ in result)
        msg = (
            f"{head}: ends in state {state.id} (edge {state.edge}) after {_ops(len(steps))}, "
            f"but the plan's result says {listed} [{path_text(steps)}]"
        )
    return Trace(name, start, steps, state.id, state.pose_deg, result, ok, msg)


def _pick_reading(
    model: KinematicModel, part_index: int, choice: ReadingChoice, step: int, diameter: float
) -> float | None:
    if isinstance(choice, str):
        if choice == "nominal":
            return nominal_reading(model.sensor, diameter)
        low, high = extreme_readings(model.sensor, diameter, model.tiny_reading(part_index))
        if choice == "low":
            return low
        if choice == "high":
            return high
        raise ValueError(f"unknown reading choice {choice!r}")
    if step >= len(choice):
        raise ValueError(f"no reading given for operation {step + 1}")
    return choice[step]


def execute(
    plan: dict[str, Any] | KinematicModel,
    part_index: int,
    start_theta_deg: float,
    reading_choice: ReadingChoice = "nominal",
) -> Trace:
    """Run a plan for part ``part_index``, fence orientation ``start_theta_deg`` at first contact.

    ``reading_choice``: ``"nominal"`` (the exact diameter, or its LED count), ``"low"`` or
    ``"high"`` (the extremes the sensor model allows), or one reading per operation. On a
    reading that several branches hold (a shared endpoint) the first is followed; a reading
    that no branch holds stops the run (``success`` False, the message says so).
    """
    model = kinematic_model(plan)
    if not 0 <= part_index < len(model.parts):
        raise ValueError(f"the plan has no part {part_index}")
    pf = model.parts[part_index]
    name = model.names[part_index]
    node: dict[str, Any] = model.plan["root"]
    state = push(pf, start_theta_deg)
    theta = float(start_theta_deg)
    steps: list[TraceStep] = []
    while "result" not in node:
        action = node["action_deg"]
        if action is not None:
            theta = rotation_after(state.normal_deg, action)
            state = push(pf, theta)
        reading = _pick_reading(model, part_index, reading_choice, len(steps), state.diameter)
        held = branches_holding(node, reading)
        b = held[0] if held else None
        interval = (
            None
            if b is None or node["branches"][b]["reading"] is None
            else tuple(node["branches"][b]["reading"])
        )
        steps.append(
            TraceStep(
                len(steps) + 1,
                action,
                theta,
                state.id,
                state.edge,
                state.diameter,
                reading,
                b,
                interval,
            )
        )
        if b is None:
            return finish(name, start_theta_deg, steps, state, None)
        node = node["branches"][b]["next"]
    return finish(name, start_theta_deg, steps, state, node)
