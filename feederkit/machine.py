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

import numpy as np

from feederkit.angles import ANGLE_EPS, norm360
from feederkit.mechanics.actions import (
    ActionRange,
    RotationRange,
    action_ranges,
    merge_boundaries,
)
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.sensors import (
    Grouping,
    NoSensor,
    SensorModel,
    ToleranceSensor,
    can_read_alike,
    split_by_reading,
)


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
class SetAction(RotationRange):
    """An overlap range of a set of states: rotations in ``(lo, hi)`` send the set to ``image``.

    ``representative`` (the middle) is the rotation a plan uses; ``margin`` (the half-width)
    the rotation error it tolerates.
    """

    image: int


@dataclass(frozen=True)
class Branch:
    """States ``mask`` consistent with readings in the closed interval ``[lo, hi]``.

    ``lo`` and ``hi`` are None when there is no sensor.
    """

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
    """Replace values equal within ``eps`` (chained in sorted order) by their cluster's first."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = list(values)
    rep = None
    for i in order:
        if rep is None or values[i] - rep > eps:
            rep = values[i]
        out[i] = rep
    return out


def build_machine(
    parts: Sequence[PushFunction], sensor: SensorModel | None = None
) -> PushAlignMachine:
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
    los, targets = _lookup(machine)[state]
    k = bisect.bisect_right(los, norm360(action)) - 1
    return targets[k]  # k = -1 (before the first start) is the last range, which wraps


def _lookup(machine: PushAlignMachine) -> list[tuple[list[float], list[int]]]:
    """Per state, its range starts and targets (cached on the machine)."""
    table = machine.__dict__.get("_lookup")
    if table is None:
        table = [([r.lo for r in rs], [r.target for r in rs]) for rs in machine.action_maps]
        machine.__dict__["_lookup"] = table
    return table


def image(machine: PushAlignMachine, mask: int, action: float) -> int:
    """The set of states a set of states goes to under one rotation."""
    out = 0
    for i in members(mask):
        out |= 1 << successor(machine, i, action)
    return out


def _cell_events(machine: PushAlignMachine) -> tuple[tuple[tuple[float, int], ...], ...]:
    """Per state, its action-range starts ``(lo, target)`` (cached on the machine)."""
    ev = machine.__dict__.get("_events")
    if ev is None:
        ev = tuple(tuple((r.lo, r.target) for r in rs) for rs in machine.action_maps)
        machine.__dict__["_events"] = ev
    return ev


_NUMPY_MIN_EVENTS = 256
"""Sets with at least this many action-range boundaries are swept with numpy."""


def _numpy_table(machine: PushAlignMachine):
    """Per-state boundary and target arrays when every state has as many ranges and n <= 64."""
    if "_table" in machine.__dict__:
        return machine.__dict__["_table"]
    maps = machine.action_maps
    table = None
    if 0 < machine.n <= 64 and len({len(rs) for rs in maps}) == 1:
        los = np.array([[r.lo for r in rs] for rs in maps], dtype=float)
        tgs = np.array([[r.target for r in rs] for rs in maps], dtype=np.int64)
        table = (los, tgs)
    machine.__dict__["_table"] = table
    return table


def _cells_sweep(machine: PushAlignMachine, mask: int, idx: list[int]) -> list[list]:
    """The cells ``[lo, hi, image]`` of a set, by a sweep in pure Python."""
    events = _cell_events(machine)
    triples = _cell_triples(machine)
    evs = [e for i in idx for e in triples[i]]
    evs.sort()
    eps = ANGLE_EPS
    # Cluster the sorted boundaries exactly as merge_boundaries does.
    reps: list[float] = []
    starts: list[int] = []
    for k, (b, _i, _t) in enumerate(evs):
        if not reps or b - reps[-1] > eps:
            reps.append(b)
            starts.append(k)
    n_ev = len(evs)
    if len(reps) > 1 and reps[0] + 360.0 - reps[-1] <= eps:
        # The last cluster wraps into the first: its events restart each member's last range.
        reps.pop()
        n_ev = starts.pop()
    m = len(reps)
    # Before the first boundary every member is in its last action range.
    count: dict[int, int] = {}
    cur: dict[int, int] = {}
    img = 0
    for i in idx:
        t = events[i][-1][1]
        cur[i] = t
        c = count.get(t, 0)
        if c == 0:
            img |= 1 << t
        count[t] = c + 1
    cells: list[list] = []
    for k in range(m):
        end = starts[k + 1] if k + 1 < m else n_ev
        lo = reps[k]
        hi = reps[k + 1] if k + 1 < m else reps[0] + 360.0
        mid = (lo + hi) / 2.0
        last_b = lo
        for _b, i, t in evs[starts[k] : end]:
            last_b = _b
            old = cur[i]
            if old == t:
                continue
            cur[i] = t
            c = count[old] - 1
            count[old] = c
            if c == 0:
                img &= ~(1 << old)
            c = count.get(t, 0)
            if c == 0:
                img |= 1 << t
            count[t] = c + 1
        if last_b >= mid:  # a degenerate cell narrower than its own boundary cluster
            cells.append([lo, hi, image(machine, mask, norm360(mid))])
        else:
            cells.append([lo, hi, img])
    return cells


def _cells_numpy(machine: PushAlignMachine, mask: int, idx: list[int], table) -> list[list] | None:
    """The cells of ``_cells_sweep`` by numpy (None: clusters too irregular, use the sweep)."""
    los, tgs = table
    k, r = len(idx), los.shape[1]
    sel = np.array(idx)
    lo_all = los[sel].ravel()
    order = np.argsort(lo_all, kind="stable")
    b = lo_all[order]
    st = np.repeat(np.arange(k), r)[order]
    tg = tgs[sel].ravel()[order]
    eps = ANGLE_EPS
    new = np.empty(len(b), dtype=bool)
    new[0] = True
    new[1:] = np.diff(b) > eps
    first = np.flatnonzero(new)
    last = np.append(first[1:] - 1, len(b) - 1)
    if np.any(b[last] - b[first] > eps):
        return None  # a chain of close boundaries: merge_boundaries's rule differs
    cid = np.cumsum(new) - 1
    reps = b[first]
    m = len(reps)
    if m > 1 and reps[0] + 360.0 - reps[-1] <= eps:
        keep = cid < m - 1
        st, tg, cid = st[keep], tg[keep], cid[keep]
        last = last[:-1]
        m -= 1
        reps = reps[:m]
    grid = np.full((k, m + 1), -1, dtype=np.int64)
    grid[:, 0] = tgs[sel, -1]
    grid[st, cid + 1] = tg
    pos = np.where(grid >= 0, np.arange(m + 1), 0)
    np.maximum.accumulate(pos, axis=1, out=pos)
    targets = np.take_along_axis(grid, pos, axis=1)[:, 1:]
    bits = np.left_shift(np.uint64(1), targets.astype(np.uint64))
    imgs = np.bitwise_or.reduce(bits, axis=0)
    his = np.append(reps[1:], reps[0] + 360.0)
    mids = (reps + his) / 2.0
    bad = np.flatnonzero(b[last] >= mids)
    if len(bad):
        imgs = imgs.astype(object)
        for c in bad.tolist():  # a degenerate cell narrower than its own boundary cluster
            imgs[c] = image(machine, mask, norm360(float(mids[c])))
    # Merge neighbours with equal images here; overlap_cells merges the rest.
    keep = np.ones(m, dtype=bool)
    keep[1:] = imgs[1:] != imgs[:-1]
    starts = np.flatnonzero(keep)
    ends = np.append(starts[1:] - 1, m - 1)
    return [
        [lo, hi, int(im)]
        for lo, hi, im in zip(
            reps[starts].tolist(), his[ends].tolist(), imgs[starts].tolist(), strict=True
        )
    ]


def _cell_triples(machine: PushAlignMachine) -> tuple[tuple[tuple[float, int, int], ...], ...]:
    """Per state ``i``, its action-range starts as ``(lo, i, target)`` (cached on the machine)."""
    ev = machine.__dict__.get("_triples")
    if ev is None:
        ev = tuple(
            tuple((r.lo, i, r.target) for r in rs) for i, rs in enumerate(machine.action_maps)
        )
        machine.__dict__["_triples"] = ev
    return ev


def overlap_ranges(machine: PushAlignMachine, mask: int) -> list[SetAction]:
    """The overlap ranges of a set of states (section 3.2.2), neighbours with equal images merged.

    Merging is sound: every rotation inside the merged range sends the set to the same image,
    so its half-width is the rotation error the action really tolerates.
    """
    return [SetAction(lo, hi, img) for lo, hi, img in overlap_cells(machine, mask)]


def overlap_cells(machine: PushAlignMachine, mask: int) -> list[tuple[float, float, int]]:
    """``overlap_ranges`` as plain ``(lo, hi, image)`` tuples (for planners' inner loops).

    The cells are those of ``merge_boundaries`` (boundaries within ANGLE_EPS merged), each
    with the image of its middle rotation, found by one sweep over the sorted boundaries
    that keeps each member's successor up to date: O(k n log(k n)) for k states of a part
    with n. Large sets of one part are swept with numpy.
    """
    idx = members(mask)
    table = _numpy_table(machine)
    if table is not None and len(idx) * table[0].shape[1] >= _NUMPY_MIN_EVENTS:
        cells = _cells_numpy(machine, mask, idx, table)
    else:
        cells = None
    if cells is None:
        cells = _cells_sweep(machine, mask, idx)
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
    return [(lo, hi, img) for lo, hi, img in merged]


def branches(machine: PushAlignMachine, mask: int, grouping: Grouping = "exact") -> list[Branch]:
    """Split a set of states by the sensor reading (exact reading branching by default)."""
    if grouping == "exact" and isinstance(machine.sensor, ToleranceSensor):
        return _tolerance_branches(machine, mask, machine.sensor.tolerance)
    idx = members(mask)
    split = split_by_reading(machine.sensor, [machine.states[i].diameter for i in idx], grouping)
    return [Branch(b.lo, b.hi, mask_of(idx[j] for j in b.members)) for b in split]


def _tolerance_branches(machine: PushAlignMachine, mask: int, e: float) -> list[Branch]:
    """``split_by_reading`` for a tolerance sensor and exact branching, by one sweep.

    Same cells and the same membership test (``|d - x| < e`` at each cell's middle) as
    ``feederkit.sensors.split_by_reading``; the states of a cell are a run of the set sorted
    by diameter, so two pointers find them.
    """
    states = machine.states
    order = members(mask)
    ds = [states[i].diameter for i in order]
    if any(ds[i] > ds[i + 1] for i in range(len(ds) - 1)):
        order.sort(key=lambda i: states[i].diameter)
        ds = [states[i].diameter for i in order]
    prefix = [0]
    for i in order:
        prefix.append(prefix[-1] | 1 << i)
    points = sorted({d - e for d in ds} | {d + e for d in ds})
    k = len(ds)
    a = b = 0
    out: list[list] = []
    last_run = None
    for lo, hi in zip(points, points[1:], strict=False):
        x = (lo + hi) / 2.0
        while a < k and ds[a] < x and not abs(ds[a] - x) < e:
            a += 1
        b = max(b, a)
        while b < k and abs(ds[b] - x) < e:
            b += 1
        if a == b:
            last_run = None
            continue
        if last_run == (a, b):
            out[-1][1] = hi
            continue
        out.append([lo, hi, prefix[b] ^ prefix[a]])
        last_run = (a, b)
    return [Branch(lo, hi, m) for lo, hi, m in out]


def prune_pairs(
    alive: set[tuple[int, int]],
    dead: list[tuple[int, int]],
    preds: dict[tuple[int, int], list[tuple[int, int]]],
) -> None:
    """The worklist step of a greatest fixpoint over state pairs, in place.

    Removes the ``dead`` pairs from ``alive`` and, transitively, every alive pair that some
    action sends to a removed one (``preds[q]``: the pairs that lead to ``q``).
    """
    while dead:
        p = dead.pop()
        if p not in alive:
            continue
        alive.discard(p)
        dead.extend(q for q in preds.get(p, ()) if q in alive)


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
    prune_pairs(alive, dead, preds)
    out = [0] * n
    for i, j in alive:
        out[i] |= 1 << j
        out[j] |= 1 << i
    return tuple(out)


def is_goal(insep: Sequence[int], mask: int) -> bool:
    """Whether every pair of states in ``mask`` is inseparable: the set is oriented."""
    return all(not mask & ~insep[i] & ~(1 << i) for i in members(mask))
