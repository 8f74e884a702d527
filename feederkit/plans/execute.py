"""Execute a plan on the kinematic model: each part rebuilt from the plan's hull and COM.

This is an independent check of the planner: it never looks at the push-align machine the
plan was made on, only at geometry (the push function of section 3.1, computed from the hull
and COM the plan records) and at the plan itself. A controller does the same steps: rotate
by ``action_deg``, let the part align (the push function), read the diameter, follow the
branch whose closed interval holds the reading (:meth:`~feederkit.plans.model.Branch.holds`).
A run that ends in a reject leaf (design.md, "Landings": a landing the next station cannot
take) is right when the leaf lists the part's landing and state; its message says "reject".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from feederkit.mechanics.push import StableState, push, rotation_after
from feederkit.plans.model import Leaf, Plan, ResultEntry, Step, member_label, push_function_of
from feederkit.plans.readplan import as_plan
from feederkit.sensors import Sensor
from feederkit.words import plural

ReadingChoice = Literal["nominal", "low", "high"] | Sequence[float | None]


def reading_inset(sensor: Sensor, size: float) -> float:
    """How far inside an open reading interval its extreme readings are taken (mm).

    A tolerance sensor never reads its interval's ends (design.md); a millionth of the
    tolerance, at least a few ulps of the part's size, keeps a run's extremes inside it.
    """
    reach = sensor.reading_reach()
    if not math.isfinite(reach):
        return 0.0
    e = reach / 2.0
    return min(max(e * 1e-6, 2e-9 * size), e / 4.0)


ROUNDING_REL = 1e-12
"""Reading sets that overlap by less than this fraction of the part's size only touch: two
open intervals meeting at a breakpoint tolerance (``d1 - e == d2 + e``) may overlap by an ulp
in floating point, as the planner's reading cells (midpoint tests) already assume."""


def rounding_inset(size: float) -> float:
    """How far inside an open reading end a verifier starts reading (mm): rounding only,
    far below any branch a plan can hold (docs/conventions.md)."""
    return ROUNDING_REL * size


def extreme_readings(
    sensor: Sensor, diameter: float, inset: float
) -> tuple[float | None, float | None]:
    """The smallest and largest reading a state gives (``inset`` inside an open interval)."""
    probes = sensor.probe_readings(diameter, inset)
    if not probes:
        return None, None
    return min(probes), max(probes)


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

    ``result`` is the leaf's entries (empty when the run stopped on a reading no branch
    holds); ``success``: the part's final (part, landing, state) is among them. ``landing``
    is the member's landing (None: a plan not made over landings); ``reject``: the run ended
    in a reject leaf, the part is to be recirculated or re-dropped; ``unrecognized``: it
    ended, rightly, in an accept leaf naming several members (:attr:`Leaf.unrecognized`).
    """

    part: str
    start_theta_deg: float
    steps: tuple[TraceStep, ...]
    final_state: int
    final_pose_deg: float
    result: tuple[ResultEntry, ...]
    success: bool
    message: str
    landing: str | None = None
    reject: bool = False
    unrecognized: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The trace as JSON."""
        return {
            "part": self.part,
            "landing": self.landing,
            "start_theta_deg": self.start_theta_deg,
            "steps": [s.to_dict() for s in self.steps],
            "final_state": self.final_state,
            "final_pose_deg": self.final_pose_deg,
            "result": [entry_dict(e) for e in self.result],
            "reject": self.reject,
            "unrecognized": self.unrecognized,
            "operations": len(self.steps),
            "success": self.success,
            "message": self.message,
        }


def entry_dict(e: ResultEntry) -> dict[str, Any]:
    """A result entry as the plan file writes it (``landing`` only when planned over
    landings)."""
    out: dict[str, Any] = {"part": e.part}
    if e.landing is not None:
        out["landing"] = e.landing
    out.update(state=e.state, pose_deg=e.pose_deg)
    return out


def leaf_entries(leaf: Leaf) -> tuple[tuple[str, int, float], ...]:
    """A leaf's entries as ``(part, state, pose_deg)``."""
    return tuple((e.part, e.state, e.pose_deg) for e in leaf.results)


def entry_text(e: ResultEntry) -> str:
    """A result entry in words: ``PART (LANDING) state S``."""
    return f"{member_label(e.part, e.landing)} state {e.state}"


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
    leaf: Leaf | None,
    landing: str | None = None,
) -> Trace:
    """The trace of a run of member ``(name, landing)`` that ended in ``state`` at ``leaf``
    (None: on an unheld reading).

    A failure's message gives the whole run in one line (:func:`path_text`); a run that
    ends in a reject leaf listing its state is right, and its message says "reject"; one that
    ends in an accept leaf naming several members is right too, but its message names them
    and says the plan cannot tell them apart, never "oriented".
    """
    steps = tuple(steps)
    head = f"{member_label(name, landing)} from theta {start:.10g} deg"
    if leaf is None:
        last = steps[-1]
        shown = "none" if last.reading is None else f"{last.reading:.10g} mm"
        msg = (
            f"{head}: reading {shown} at operation {last.number} (state {state.id}, diameter "
            f"{state.diameter:.6g} mm) is in no branch: a foreign part or a sensor fault; stop "
            f"[{path_text(steps)}]"
        )
        return Trace(name, start, steps, state.id, state.pose_deg, (), False, msg, landing=landing)
    result = leaf.results
    ok = leaf.accepts(name, state.id, landing)
    ops = plural(len(steps), "operation")
    if ok and leaf.reject:
        side = "" if landing is None else f" (landing {landing})"
        msg = (
            f"{head}: reject{side} after {ops}, resting in state {state.id} "
            f"(edge {state.edge}): the next station cannot take it; recirculate or re-drop"
        )
    elif ok and leaf.unrecognized:
        msg = (
            f"{head}: ends after {ops} at a result that lists {_listing(result)}: the plan "
            f"cannot tell them apart, so the controller knows only that the part is one of "
            f"them (this run rests in state {state.id} (edge {state.edge}), pose "
            f"{state.pose_deg:.6g} deg)"
        )
    elif ok:
        msg = (
            f"{head}: oriented in {ops}, state {state.id} (edge {state.edge}), "
            f"pose {state.pose_deg:.6g} deg"
        )
    else:
        listed = ", ".join(entry_text(e) for e in result)
        said = "rejects" if leaf.reject else "says"
        msg = (
            f"{head}: ends in state {state.id} (edge {state.edge}) after {ops}, "
            f"but the plan's result {said} {listed} [{path_text(steps)}]"
        )
    return Trace(
        name,
        start,
        steps,
        state.id,
        state.pose_deg,
        result,
        ok,
        msg,
        landing=landing,
        reject=leaf.reject,
        unrecognized=ok and leaf.unrecognized,
    )


def _listing(entries: Sequence[ResultEntry]) -> str:
    """A result's entries in words: ``A state 0 and B state 0`` (:func:`entry_text`)."""
    words = [entry_text(e) for e in entries]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _pick_reading(
    plan: Plan, part_index: int, choice: ReadingChoice, step: int, diameter: float
) -> float | None:
    if isinstance(choice, str):
        if choice == "nominal":
            return plan.sensor.nominal_reading(diameter)
        inset = reading_inset(plan.sensor, plan.parts[part_index].size)
        low, high = extreme_readings(plan.sensor, diameter, inset)
        if choice == "low":
            return low
        if choice == "high":
            return high
        raise ValueError(f"unknown reading choice {choice!r}")
    if step >= len(choice):
        raise ValueError(f"no reading given for operation {step + 1}")
    return choice[step]


def execute(
    plan: Plan | Mapping[str, Any],
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
    plan = as_plan(plan)
    if not 0 <= part_index < len(plan.parts):
        raise ValueError(f"the plan has no part {part_index}")
    pf = push_function_of(plan.parts[part_index])
    name = plan.parts[part_index].name
    landing = plan.parts[part_index].landing
    node: Step | Leaf = plan.root
    state = push(pf, start_theta_deg)
    theta = float(start_theta_deg)
    steps: list[TraceStep] = []
    while isinstance(node, Step):
        if node.action_deg is not None:
            theta = rotation_after(state.normal_deg, node.action_deg)
            state = push(pf, theta)
        reading = _pick_reading(plan, part_index, reading_choice, len(steps), state.diameter)
        b = node.follow(reading)
        interval = None if b is None else node.branches[b].reading
        steps.append(
            TraceStep(
                len(steps) + 1,
                node.action_deg,
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
            return finish(name, start_theta_deg, steps, state, None, landing)
        node = node.branches[b].next
    return finish(name, start_theta_deg, steps, state, node, landing)
