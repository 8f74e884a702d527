"""Verify a plan file on the kinematic model: every start, every reading, every branch.

For every part and every stable start (each stable orientation, and fence orientations just
inside both ends of each resting range), the plan is executed with every reading the sensor
model allows at each operation (both extremes of a tolerance's open interval and every branch
endpoint inside it; every LED count) along every branch whose closed interval holds the
reading (on a shared endpoint each must be right), and with rotations at the middle and just
inside both ends of each action's margin. Every run must end in a result that lists the
part's final state, and the longest run must take exactly the plan's stated length. The
file's stable states must also be the ones its hulls and COMs give. Paths that share a
(node, state) share their future, so the search is memoised and linear in plan size times
states.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from feederkit.angles import angle_close
from feederkit.errors import CheckFailed
from feederkit.mechanics.push import PushFunction, StableState, push, rotation_after
from feederkit.plans.execute import (
    KinematicModel,
    Trace,
    TraceStep,
    branches_holding,
    extreme_readings,
    finish,
    kinematic_model,
)
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor, led_counts

START_INSIDE_DEG = 1e-6
"""How far inside a resting range's ends the extreme starts are taken (deg)."""


@dataclass(frozen=True)
class PartCheck:
    """What was tried for one part: starts, complete paths, the most operations any run took."""

    part: str
    starts: int
    paths: int
    worst_operations: int
    failed_starts: int

    def to_dict(self) -> dict[str, Any]:
        """As JSON."""
        return {
            "part": self.part,
            "starts": self.starts,
            "paths": self.paths,
            "worst_operations": self.worst_operations,
            "failed_starts": self.failed_starts,
        }


@dataclass(frozen=True)
class VerificationReport:
    """The verification of a plan: per part, the failing paths, and inconsistencies of the file."""

    parts: tuple[PartCheck, ...]
    failures: tuple[Trace, ...] = ()
    problems: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """Whether every run succeeded and the file is consistent."""
        return not self.failures and not self.problems

    @property
    def paths(self) -> int:
        """Number of complete paths tried."""
        return sum(p.paths for p in self.parts)

    def first_problem(self) -> str | None:
        """The first counterexample or inconsistency, in one line (None when the plan passed)."""
        if self.problems:
            return self.problems[0]
        return self.failures[0].message if self.failures else None

    def to_dict(self) -> dict[str, Any]:
        """As JSON."""
        return {
            "ok": self.ok,
            "paths": self.paths,
            "parts": [p.to_dict() for p in self.parts],
            "problems": list(self.problems),
            "failures": [t.to_dict() for t in self.failures],
        }


@dataclass(frozen=True)
class _Failure:
    """A failing continuation from a node: the reading and branch chosen there, then the rest."""

    reading: float | None
    branch: int | None
    interval: tuple[float, float] | None
    rest: tuple[TraceStep, ...]
    final: StableState
    leaf: dict[str, Any] | None


@dataclass(frozen=True)
class _Outcome:
    paths: int
    worst: int
    failure: _Failure | None


def _candidate_readings(
    model: KinematicModel, p: int, node: dict[str, Any], d: float
) -> list[float | None]:
    """Every reading that can lead a state of diameter ``d`` down a different set of branches."""
    sensor = model.sensor
    if isinstance(sensor, NoSensor):
        return [None]
    if isinstance(sensor, LedSensor):
        c0, c1 = led_counts(sensor, d)
        return [c * sensor.pitch for c in range(c0, c1 + 1)]
    assert isinstance(sensor, ToleranceSensor)
    e = sensor.tolerance
    t = model.tiny_reading(p)
    low, high = extreme_readings(sensor, d, t)
    out = {low, high, d}
    for b in node["branches"]:
        for x in b["reading"]:
            # readings within t/2 of the open interval's ends count as its ends: rounding
            out.update(r for r in (x - t, x, x + t) if abs(r - d) < e - t / 2)
    return sorted(out)


def _margin_errors(margin: float) -> tuple[float, ...]:
    """Rotation errors tried for an action of this margin: none, and just inside both ends."""
    inside = margin - max(1e-6, 1e-3 * margin)
    return (0.0, -inside, inside) if inside > 0.0 else (0.0,)


class _PartSearch:
    """The memoised search over (node, state) for one part."""

    def __init__(self, model: KinematicModel, p: int) -> None:
        self.model = model
        self.p = p
        self.pf: PushFunction = model.parts[p]
        self.name = model.names[p]
        self.memo: dict[tuple[int, int], _Outcome] = {}

    def after_push(self, node: dict[str, Any], number: int, state: StableState) -> _Outcome:
        """Outcome of every continuation once operation ``number`` of ``node`` left ``state``."""
        key = (id(node), state.id)
        if key in self.memo:
            return self.memo[key]
        paths, worst, failure = 0, number, None
        for reading in _candidate_readings(self.model, self.p, node, state.diameter):
            held = branches_holding(node, reading)
            if not held and failure is None:
                failure = _Failure(reading, None, None, (), state, None)
            for b in held:
                branch = node["branches"][b]
                interval = None if branch["reading"] is None else tuple(branch["reading"])
                nxt = branch["next"]
                if "result" in nxt:
                    paths += 1
                    ok = any(
                        e["part"] == self.name and e["state"] == state.id for e in nxt["result"]
                    )
                    if not ok and failure is None:
                        failure = _Failure(reading, b, interval, (), state, nxt)
                    continue
                for err in _margin_errors(nxt["margin_deg"]):
                    theta = rotation_after(state.normal_deg, nxt["action_deg"] + err)
                    s2 = push(self.pf, theta)
                    sub = self.after_push(nxt, number + 1, s2)
                    paths += sub.paths
                    worst = max(worst, sub.worst)
                    if sub.failure is not None and failure is None:
                        f = sub.failure
                        step = TraceStep(
                            number + 1,
                            nxt["action_deg"],
                            theta,
                            s2.id,
                            s2.edge,
                            s2.diameter,
                            f.reading,
                            f.branch,
                            f.interval,
                            err,
                        )
                        failure = _Failure(reading, b, interval, (step, *f.rest), f.final, f.leaf)
        out = _Outcome(paths, worst, failure)
        self.memo[key] = out
        return out

    def starts(self) -> list[float]:
        """Each stable orientation, and just inside both ends of its resting range."""
        out = []
        for s in self.pf.states:
            lo, hi = s.resting_range_deg
            out += [s.normal_deg, lo + START_INSIDE_DEG, hi - START_INSIDE_DEG]
        return out

    def run(self) -> tuple[PartCheck, list[Trace]]:
        root = self.model.plan["root"]
        paths, worst, failed = 0, 0, []
        starts = self.starts()
        for theta in starts:
            s0 = push(self.pf, theta)
            o = self.after_push(root, 1, s0)
            paths += o.paths
            worst = max(worst, o.worst)
            if o.failure is not None:
                f = o.failure
                first = TraceStep(
                    1, None, theta, s0.id, s0.edge, s0.diameter, f.reading, f.branch, f.interval
                )
                failed.append(finish(self.name, theta, (first, *f.rest), f.final, f.leaf))
        return PartCheck(self.name, len(starts), paths, worst, len(failed)), failed


def _state_problems(model: KinematicModel, p: int) -> list[str]:
    """Differences between the file's stable states and those its hull and COM give."""
    entry = model.plan["parts"][p]
    pf = model.parts[p]
    name = entry["name"]
    listed = {s["id"]: s for s in entry["stable_states"]}
    if set(listed) != {s.id for s in pf.states}:
        return [
            f"part {name!r}: the file lists stable states {sorted(listed)}, but its hull and COM "
            f"give {pf.n}"
        ]
    eps_d = 1e-9 * pf.part.size + 1e-12
    out = []
    for s in pf.states:
        f = listed[s.id]
        lo, hi = f["resting_range_deg"]
        same = (
            f["edge"] == s.edge
            and angle_close(f["normal_deg"], s.normal_deg, 1e-6)
            and angle_close(lo, s.resting_range_deg[0], 1e-6)
            and angle_close(hi, s.resting_range_deg[1], 1e-6)
            and abs(f["diameter"] - s.diameter) <= eps_d
            and angle_close(f["pose_deg"], s.pose_deg, 1e-6)
        )
        if not same:
            out.append(
                f"part {name!r} state {s.id}: the file says edge {f['edge']}, normal "
                f"{f['normal_deg']:.6g} deg, diameter {f['diameter']:.6g}, but its hull and COM "
                f"give edge {s.edge}, normal {s.normal_deg:.6g} deg, diameter {s.diameter:.6g}"
            )
    return out


def _pose_problems(model: KinematicModel) -> list[str]:
    """Result entries whose pose is not the pose of the state they name."""
    poses = {
        (p["name"], s["id"]): s["pose_deg"] for p in model.plan["parts"] for s in p["stable_states"]
    }
    out = []
    stack = [model.plan["root"]]
    while stack:
        node = stack.pop()
        if "result" in node:
            for e in node["result"]:
                want = poses[(e["part"], e["state"])]
                if not angle_close(e["pose_deg"], want, 1e-6):
                    out.append(
                        f"a result gives {e['part']} state {e['state']} the pose "
                        f"{e['pose_deg']:.6g} deg, but that state's pose is {want:.6g} deg"
                    )
        else:
            stack.extend(b["next"] for b in node["branches"])
    return out


def verify_plan(
    plan: dict[str, Any] | KinematicModel, part_indices: Sequence[int] | None = None
) -> VerificationReport:
    """Execute the plan on the kinematic model: every start, reading and branch (see the module).

    ``part_indices`` restricts the check to some of the plan's parts (default: all).
    Raises InputError when the plan is structurally broken.
    """
    model = kinematic_model(plan)
    indices = range(len(model.parts)) if part_indices is None else part_indices
    problems = _pose_problems(model)
    checks, failures = [], []
    length = model.plan["stats"]["length"]
    for p in indices:
        problems += _state_problems(model, p)
        check, failed = _PartSearch(model, p).run()
        if check.worst_operations > length:
            problems.append(
                f"part {check.part!r}: a run takes {check.worst_operations} operations, but the "
                f"plan's length is {length}"
            )
        checks.append(check)
        failures += failed
    longest = max(c.worst_operations for c in checks)
    if part_indices is None and not failures and longest < length:
        # every node is reachable (its states are images of every start), so some path is as
        # long as the tree: a shorter longest path means the stated length is wrong
        problems.append(f"the plan's length is {length}, but no path takes more than {longest}")
    return VerificationReport(tuple(checks), tuple(failures), tuple(problems))


def check_plan(plan: dict[str, Any] | KinematicModel) -> VerificationReport:
    """Verify a plan; a failure raises CheckFailed with the first counterexample in one line."""
    report = verify_plan(plan)
    if not report.ok:
        raise CheckFailed(f"the plan failed verification: {report.first_problem()}")
    return report
