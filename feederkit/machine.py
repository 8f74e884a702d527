"""The push-align machine: the abstract state machine the planners search (section 3.3).

States are the stable states of one or more parts (section 8.5: a state carries its part);
an action is a rotation in [0, 360); each state has a piecewise-constant action map (its
action ranges, definition 9); a reading set per state comes from the sensor model.
Planners see only this: states as bit masks, overlap ranges of a set, reading branches and
the goal test. Nothing here looks at geometry, so machines can be built by hand in tests.

The goal. Two states are *inseparable* when no plan can ever either merge them into one
state or tell them apart by a reading: the greatest fixpoint of "their readings can agree,
and every action sends them to two different states that are again inseparable". The
relation holds between symmetric poses of one part (definitions 3, 8) and between states of
parts with the same push-diameter function (Lemma 8). A set of states is oriented (a goal)
when every pair in it is inseparable; a plan then reports all of them as correct answers.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from feederkit.angles import norm360
from feederkit.mechanics.actions import ActionRange, action_ranges, merge_boundaries
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.sensors import Grouping, NoSensor, SensorModel, can_read_alike, split_by_reading


@dataclass(frozen=True)
class MachineState:
    """A state of the machine: stable state ``state`` of part ``part``.

    ``weight`` is the probability that the first alignment from a uniformly random
    orientation ends here (resting range / 360, divided by the number of parts).
    """

    part: int
    state: int
    diameter: float
    weight: float


@dataclass(frozen=True)
class PushAlignMachine:
    """States, action maps and sensor of a push-align feeder for one or more parts.

    ``action_maps[i]`` are state ``i``'s action ranges, sorted by ``lo`` (in [0, 360)), whose
    targets are machine state indices.
    """

    part_names: tuple[str, ...]
    states: tuple[MachineState, ...]
    action_maps: tuple[tuple[ActionRange, ...], ...]
    sensor: SensorModel

    @property
    def n(self) -> int:
        """Number of states."""
        return len(self.states)

    @property
    def all_states(self) -> int:
        """The bit mask of every state."""
        return (1 << len(self.states)) - 1


@dataclass(frozen=True)
class SetAction:
    """An overlap range of a set of states: rotations in ``(lo, hi)`` send the set to ``image``."""

    lo: float
    hi: float
    image: int

    @property
    def representative(self) -> float:
        """The middle of the range in [0, 360): the rotation a plan uses."""
        return norm360((self.lo + self.hi) / 2.0)

    @property
    def margin(self) -> float:
        """Half-width of the range (deg): the rotation error the action tolerates."""
        return (self.hi - self.lo) / 2.0


@dataclass(frozen=True)
class Branch:
    """States ``mask`` consistent with readings in the closed interval ``[lo, hi]`` (None: sensorless)."""

    lo: float | None
    hi: float | None
    mask: int


def mask_of(indices: Iterable[int]) -> int:
    """The bit mask of a collection of state indices."""
    m = 0
    for i in indices:
        m |= 1 << i
    return m


def members(mask: int) -> list[int]:
    """The state indices in a bit mask, ascending."""
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


def _snap(values: Sequence[float], eps: float) -> list[float]:
    """Replace values equal within ``eps`` (chained in sorted order) by their cluster's first value."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = list(values)
    rep = None
    for i in order:
        if rep is None or values[i] - rep > eps:
            rep = values[i]
        out[i] = rep
    return out


def build_machine(parts: Sequence[PushFunction], sensor: SensorModel | None = None) -> PushAlignMachine:
    """The machine of one part or a mix (section 8.5): the parts' states side by side.

    Diameters equal within a relative 1e-9 of the largest part are made exactly equal, so
    exact symmetry survives rounding.
    """
    sensor = NoSensor() if sensor is None else sensor
    offsets = []
    total = 0
    for pf in parts:
        offsets.append(total)
        total += pf.n
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in parts)
    diam = _snap([s.diameter for pf in parts for s in pf.states], eps)
    states = []
    maps = []
    k = 0
    for p, pf in enumerate(parts):
        widths = resting_widths(pf)
        for s in pf.states:
            states.append(MachineState(p, s.id, diam[k], widths[s.id] / 360.0 / len(parts)))
            ranges = action_ranges(pf, s.id)
            maps.append(tuple(ActionRange(r.lo, r.hi, r.target + offsets[p]) for r in ranges))
            k += 1
    return PushAlignMachine(
        part_names=tuple(pf.part.name for pf in parts),
        states=tuple(states),
        action_maps=tuple(maps),
        sensor=sensor,
    )


def successor(machine: PushAlignMachine, state: int, action: float) -> int:
    """Where ``state`` goes under a rotation strictly inside one of its action ranges."""
    ranges = machine.action_maps[state]
    a = norm360(action)
    k = bisect.bisect_right([r.lo for r in ranges], a) - 1
    return ranges[k].target if k >= 0 else ranges[-1].target


def image(machine: PushAlignMachine, mask: int, action: float) -> int:
    """The set of states a set of states goes to under one rotation."""
    out = 0
    for i in members(mask):
        out |= 1 << successor(machine, i, action)
    return out


def overlap_ranges(machine: PushAlignMachine, mask: int) -> list[SetAction]:
    """The overlap ranges of a set of states (section 3.2.2), neighbours with equal images merged.

    Merging is sound: every rotation inside the merged range sends the set to the same image,
    so its half-width is the rotation error the action really tolerates.
    """
    idx = members(mask)
    bounds = merge_boundaries([[r.lo for r in machine.action_maps[i]] for i in idx])
    m = len(bounds)
    cells: list[list] = []
    for k in range(m):
        lo = bounds[k]
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        cells.append([lo, hi, image(machine, mask, (lo + hi) / 2.0)])
    merged: list[list] = []
    for cell in cells:
        if merged and merged[-1][2] == cell[2]:
            merged[-1][1] = cell[1]
        else:
            merged.append(cell)
    if len(merged) > 1 and merged[0][2] == merged[-1][2]:
        last = merged.pop()
        merged[0][0] = last[0] - 360.0 if last[0] > merged[0][0] else last[0]
        if merged[0][0] < 0.0:
            merged[0][0] += 360.0
            merged[0][1] += 360.0
    if len(merged) == 1:
        merged[0][0], merged[0][1] = 0.0, 360.0
    return [SetAction(lo, hi, img) for lo, hi, img in merged]


def branches(machine: PushAlignMachine, mask: int, grouping: Grouping = "exact") -> list[Branch]:
    """Split a set of states by the sensor reading (exact reading branching by default)."""
    idx = members(mask)
    split = split_by_reading(machine.sensor, [machine.states[i].diameter for i in idx], grouping)
    return [Branch(b.lo, b.hi, mask_of(idx[j] for j in b.members)) for b in split]


def inseparable(machine: PushAlignMachine) -> tuple[int, ...]:
    """For each state, the mask of states it is inseparable from (see the module docstring).

    A greatest fixpoint over state pairs: start from pairs whose readings can agree, drop a
    pair when some action merges it or sends it to a dropped pair, until nothing changes.
    """
    n = machine.n
    sensor = machine.sensor
    d = [s.diameter for s in machine.states]
    los = [[r.lo for r in machine.action_maps[i]] for i in range(n)]
    alive: set[tuple[int, int]] = {
        (i, j) for i in range(n) for j in range(i + 1, n) if can_read_alike(sensor, d[i], d[j])
    }
    succ: dict[tuple[int, int], set[tuple[int, int]]] = {}
    dead: list[tuple[int, int]] = []
    for i, j in alive:
        bounds = merge_boundaries([los[i], los[j]])
        nxt: set[tuple[int, int]] = set()
        merged = False
        for k, lo in enumerate(bounds):
            hi = bounds[k + 1] if k + 1 < len(bounds) else bounds[0] + 360.0
            a = successor(machine, i, (lo + hi) / 2.0)
            b = successor(machine, j, (lo + hi) / 2.0)
            if a == b:
                merged = True
                break
            nxt.add((a, b) if a < b else (b, a))
        if merged:
            dead.append((i, j))
        else:
            succ[(i, j)] = nxt
    preds: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for p, nxt in succ.items():
        for q in nxt:
            if q not in alive:
                dead.append(p)
            preds.setdefault(q, []).append(p)
    while dead:
        p = dead.pop()
        if p not in alive:
            continue
        alive.discard(p)
        dead.extend(q for q in preds.get(p, ()) if q in alive)
    out = [0] * n
    for i, j in alive:
        out[i] |= 1 << j
        out[j] |= 1 << i
    return tuple(out)


def is_goal(insep: Sequence[int], mask: int) -> bool:
    """Whether every pair of states in ``mask`` is inseparable: the set is oriented."""
    for i in members(mask):
        if mask & ~insep[i] & ~(1 << i):
            return False
    return True
