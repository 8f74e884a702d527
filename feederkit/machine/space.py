"""The planners' search space: sets of states of a push-align machine (section 3.3).

A node of a plan's search holds the set of states consistent with the operations so far (a
bit mask). For a set this module gives its overlap ranges (section 3.2.2) with their
images (under uncertainty: the ranges of rotations over which every member's outcome set
stays the same, the image the union of those sets), its reading branches (section 5), and
whether it is oriented (the goal, see :mod:`feederkit.machine.inseparable`) or holds only
states of rejected landings (a reject leaf).
:class:`SearchSpace` owns the per-machine tables these need; :func:`search_space` builds
one per machine, once.
"""

from __future__ import annotations

import bisect
import operator
import weakref
from collections.abc import Callable, Iterator
from functools import cached_property

import numpy as np

from feederkit.angles import ANGLE_EPS, norm360
from feederkit.machine.inseparable import inseparable_masks
from feederkit.machine.model import OverlapRange, PushAlignMachine, mask_of, members
from feederkit.sensors import Grouping, ReadingBranch

_NUMPY_MIN_EVENTS = 256
"""Sets with at least this many action-range boundaries are swept with numpy."""

_CELL_TABLE_MIN = 100
"""Machines with fewer action-range boundaries in all keep the pure Python cells (faster)."""

_LIST_CELLS_MAX = 64
"""Sets with fewer action-range boundaries than this get their cells in pure Python
(:meth:`SearchSpace.cell_lists`)."""

_CELL_TABLE_MAX = 10_000_000
"""The most entries (cells times states, 4 bytes each) of :attr:`SearchSpace.cell_table`."""

_OUTCOME_TABLE_BYTES = 64_000_000
"""The largest :attr:`SearchSpace.outcome_cell_table` (cells times states times the largest
outcome set, 2 bytes each)."""


class SearchSpace:
    """A machine's sets of states, with the tables their queries share (built on first use).

    The space refers to its machine weakly (the registry of :func:`search_space` must not
    keep machines alive): whoever asks holds the machine.
    """

    def __init__(self, machine: PushAlignMachine) -> None:
        self._machine = weakref.ref(machine)
        self._rows: dict[int, list[int]] = {}
        self._bit_rows: dict[int, list[int]] = {}
        self._pickers: dict[int, Callable[[list[int]], tuple[int, ...]]] = {}
        # Pairs nature keeps apart per (grouping, goal relation): planning.solvable.kept_pairs.
        self.kept: dict[tuple[object, tuple[int, ...]], frozenset[tuple[int, int]]] = {}

    @property
    def machine(self) -> PushAlignMachine:
        """The machine whose sets these are."""
        m = self._machine()
        if m is None:
            raise ReferenceError("the machine of this search space is gone")
        return m

    @cached_property
    def triples(self) -> tuple[tuple[tuple[float, int, int], ...], ...]:
        """Per state ``i``, its action-range starts as ``(lo, i, target)``; under uncertainty
        ``(lo, i, targets mask)``."""
        m = self.machine
        table = m.targets if m.deterministic else m.outcomes_of
        return tuple(
            tuple((lo, i, t) for lo, t in zip(m.starts[i], table[i], strict=True))
            for i in range(m.n)
        )

    @cached_property
    def numpy_table(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Per-state boundary and target arrays, when every state has as many ranges, each
        one target, and there are at most 64 states (the images then fit an unsigned 64-bit
        word)."""
        maps = self.machine.action_maps
        if not self.machine.deterministic:
            return None
        if 0 < self.machine.n <= 64 and len({len(rs) for rs in maps}) == 1:
            los = np.array([[r.lo for r in rs] for rs in maps], dtype=float)
            tgs = np.array(self.machine.targets, dtype=np.int64)
            return los, tgs
        return None

    @cached_property
    def set_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """Per state its range starts and outcome masks, flattened (``starts``, ``state``,
        ``mask`` arrays and each state's last mask), when outcome sets fit a signed 64-bit
        word (at most 62 states)."""
        m = self.machine
        if not 0 < m.n <= 62:
            return None
        lo = np.array([x for i in range(m.n) for x in m.starts[i]], dtype=float)
        st = np.array([i for i in range(m.n) for _ in m.starts[i]], dtype=np.int64)
        mk = np.array([x for i in range(m.n) for x in m.outcomes_of[i]], dtype=np.int64)
        last = np.array([m.outcomes_of[i][-1] for i in range(m.n)], dtype=np.int64)
        return lo, st, mk, last

    @cached_property
    def cell_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """Every state's action-range starts sorted together (``bounds``, their ``owner``
        states), the distinct start angles, and per cell between consecutive distinct
        starts each state's target there (``targets[cell, state]``); None under outcome
        sets, or when the machine has fewer than ``_CELL_TABLE_MIN`` boundaries or the table
        would exceed ``_CELL_TABLE_MAX`` entries. A set's cells and
        images (:meth:`cells_and_images`) are read off it."""
        m = self.machine
        if not m.deterministic or m.n == 0:
            return None
        count = sum(len(x) for x in m.starts)
        if count < _CELL_TABLE_MIN or count * m.n > _CELL_TABLE_MAX:
            return None
        return _per_cell(m, m.targets, np.int32)

    @cached_property
    def set_cell_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """:attr:`cell_table` under outcome sets: the same ``bounds``, ``owner`` and distinct
        starts, and per cell each state's outcome set there (``outcomes[cell, state]``, a
        mask); None for a deterministic machine, more than 62 states (masks in a signed
        64-bit word), or a table over ``_CELL_TABLE_MAX`` entries. Kept for small machines
        too: the sweep over outcome sets costs about twice as much on a two-part machine of
        36 boundaries."""
        m = self.machine
        if m.deterministic or not 0 < m.n <= 62:
            return None
        count = sum(len(x) for x in m.starts)
        if count * m.n > _CELL_TABLE_MAX:
            return None
        return _per_cell(m, m.outcomes_of, np.int64)

    @cached_property
    def outcome_cell_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """:attr:`set_cell_table` for machines of more than 62 states, whose outcome sets do
        not fit a word: per cell each state's outcome set as up to ``K`` state indices
        (``outcomes[cell, state, :]``, -1 beyond its outcomes; ``K`` the largest outcome set
        of the machine); None for a deterministic machine, 62 states or fewer, or a table
        over ``_OUTCOME_TABLE_BYTES``. A large mix under uncertainty then gets its sets'
        cells and images from numpy, as a small one does (the sweep in Python was two
        fifths of the anytime search on a 50-part mix)."""
        m = self.machine
        if m.deterministic or m.n <= 62:
            return None
        k = max(x.bit_count() for xs in m.outcomes_of for x in xs)
        cells = len({x for xs in m.starts for x in xs})
        if cells * m.n * k * 2 > _OUTCOME_TABLE_BYTES:
            return None
        lists = tuple([members(x) + [-1] * (k - x.bit_count()) for x in xs] for xs in m.outcomes_of)
        return _per_cell(m, lists, np.int16)

    @cached_property
    def _cell_starts(self) -> list[float] | None:
        """The distinct start angles of :attr:`cell_table` as a list (for bisection)."""
        table = self.cell_table
        return None if table is None else table[2].tolist()

    def targets_at(self, mask: int, rotation: float) -> list[int] | None:
        """Each member's target (a state index, ascending members) under ``rotation``
        (deg, in [0, 360)), read off :attr:`cell_table`; None without the table.

        A row of the table holds between consecutive distinct starts of all states, so it
        is the row of the cell that begins at or before ``rotation``: the same lookup as
        :func:`~feederkit.machine.model.target_at` (the range starting at or before it; before the
        first start, the last one, which wraps).
        """
        starts = self._cell_starts
        if starts is None:
            return None
        at = bisect.bisect_right(starts, rotation) - 1
        rows = self._rows
        row = rows.get(at)
        if row is None:
            row = rows[at] = self.cell_table[3][at].tolist()  # type: ignore[index]
        return [row[i] for i in members(mask)]

    def target_masks_at(self, mask: int, rotation: float) -> tuple[int, ...] | None:
        """:meth:`targets_at` as outcome masks (``1 << target`` per member), the tuple the
        planners' ``Choices.targets`` holds; None without the table. Each row's masks and
        each set's picker of its members' columns are made once."""
        starts = self._cell_starts
        if starts is None:
            return None
        at = bisect.bisect_right(starts, rotation) - 1
        row = self._bit_rows.get(at)
        if row is None:
            row = self._bit_rows[at] = [1 << t for t in self.cell_table[3][at].tolist()]  # type: ignore[index]
        pick = self._pickers.get(mask)
        if pick is None:
            pick = self._pickers[mask] = _picker(members(mask))
        return pick(row)

    def cell_lists(self, mask: int) -> tuple[list[float], list[float], list[int]] | None:
        """:meth:`cells_and_images` as lists, in pure Python, for a set of a deterministic
        machine whose members have fewer than ``_LIST_CELLS_MAX`` boundaries in all (numpy's
        fixed cost per call is then most of the work); None otherwise, or where
        :meth:`cells_and_images` is None. The same floats: the same subtractions, middles
        and lookups, one cell at a time."""
        table = self.cell_table
        if table is None or not mask:
            return None
        starts = self.machine.starts
        idx = members(mask)
        sb = [x for i in idx for x in starts[i]]
        if len(sb) >= _LIST_CELLS_MAX:
            return None
        sb.sort()
        distinct = self._cell_starts
        assert distinct is not None
        rows = self._bit_rows
        los: list[float] = []
        his: list[float] = []
        images: list[int] = []
        pick = self._pickers.get(mask)
        if pick is None:
            pick = self._pickers[mask] = _picker(idx)
        last = len(sb) - 1
        for j, lo in enumerate(sb):
            hi = sb[j + 1] if j < last else sb[0] + 360.0
            width = hi - lo
            if width <= ANGLE_EPS:
                continue
            if width <= 4.0 * ANGLE_EPS:
                return None
            mid = (lo + hi) / 2.0
            if mid >= 360.0:
                mid -= 360.0
            at = bisect.bisect_right(distinct, mid) - 1
            row = rows.get(at)
            if row is None:
                row = rows[at] = [1 << t for t in table[3][at].tolist()]
            img = 0
            for bit in pick(row):
                img |= bit
            los.append(lo)
            his.append(hi)
            images.append(img)
        return los, his, images

    def cells_and_images(self, mask: int) -> tuple[np.ndarray, np.ndarray, list[int]] | None:
        """The set's cells (``lo``, ``hi`` arrays: consecutive boundaries of its members
        more than ``ANGLE_EPS`` apart, as :func:`~feederkit.angles.cells_between` gives them)
        and the image of each (the set's image at the cell's middle), vectorised.

        Under outcome sets the image is the union of the members' outcome sets
        (:attr:`set_cell_table`, or :attr:`outcome_cell_table` beyond 62 states). None
        without a table, or when some cell is within a few ``ANGLE_EPS`` of the narrowest
        kept width (there the boundary clustering of :meth:`overlap_cells` decides, and
        callers use it).
        """
        kind = "targets"
        table = self.cell_table
        if table is None:
            kind, table = "masks", self.set_cell_table
        if table is None:
            kind, table = "lists", self.outcome_cell_table
        if table is None or not mask:
            return None
        bounds, owner, distinct, targets = table
        n = self.machine.n
        inside = np.zeros(n, dtype=bool)
        idx = members(mask)
        inside[idx] = True
        sb = bounds[inside[owner]]
        lo = sb
        hi = np.append(sb[1:], sb[0] + 360.0)
        width = hi - lo
        keep = width > ANGLE_EPS
        if np.any(keep & (width <= 4.0 * ANGLE_EPS)):
            return None
        lo, hi = lo[keep], hi[keep]
        mid = (lo + hi) / 2.0
        mid = np.where(mid >= 360.0, mid - 360.0, mid)
        at = np.searchsorted(distinct, mid, side="right") - 1
        rows = targets[np.ix_(at, idx)]
        if kind == "masks":
            return lo, hi, np.bitwise_or.reduce(rows, axis=1).tolist()
        if kind == "lists":
            # Each member's outcomes side by side; -1 (no outcome) marks a spare column.
            rows = rows.reshape(len(lo), -1).astype(np.int64)
            rows[rows < 0] = n
        bits = np.zeros((len(lo), n + 1), dtype=bool)
        bits[np.arange(len(lo))[:, None], rows] = True
        packed = np.packbits(bits[:, :n], axis=1, bitorder="little")
        raw, width = packed.tobytes(), packed.shape[1]
        images = [int.from_bytes(raw[k : k + width], "little") for k in range(0, len(raw), width)]
        return lo, hi, images

    @cached_property
    def bisimilar(self) -> tuple[int, ...]:
        """For each state, the mask of states no plan can tell it from or merge it with
        (:func:`~feederkit.machine.inseparable.inseparable_masks`)."""
        return inseparable_masks(self.machine)

    @cached_property
    def rejected(self) -> int:
        """The mask of the states of rejected members (``MachineState.reject``)."""
        return mask_of(i for i, s in enumerate(self.machine.states) if s.reject)

    @cached_property
    def alike(self) -> tuple[int, ...]:
        """For each state, the states a leaf may list with it: every state of another
        member, and those of its own member recorded as alike (``MachineState.alike``:
        near-congruent poses, or ideal twins; any when nothing is recorded, a machine built
        by hand or the ideal model)."""
        states = self.machine.states
        of_part: dict[int, int] = {}
        for i, s in enumerate(states):
            of_part[s.part] = of_part.get(s.part, 0) | 1 << i
        full = self.machine.all_states
        out = []
        for i, a in enumerate(states):
            own = of_part[a.part]
            if a.look_alike is None:
                out.append(full)
                continue
            keep = full & ~own | 1 << i
            for j in members(own):
                if a.alike(states[j]):
                    keep |= 1 << j
            out.append(keep)
        return tuple(out)

    @cached_property
    def inseparable(self) -> tuple[int, ...]:
        """For each state, the mask of states a plan need not tell it from: the goal relation.

        The :attr:`bisimilar` states that look alike (:attr:`alike`) and, for a state of a
        rejected member, every other state of a rejected member: a set of only rejected
        states ends in a reject leaf as soon as the plan knows it (design.md "Landings"),
        whichever of them the part is in. Two poses of one part that merely *behave* alike
        under the declared uncertainty (a large rotation error lets every action send each
        to every state) are bisimilar, yet a leaf listing them does not orient the part:
        they stay apart here, and ``PlanningOptions.lumping`` decides whether a plan may list
        them (docs/planning.md, "Poses that only behave alike are not the goal"). Without
        rejected members and such pairs it is :attr:`bisimilar` itself.
        """
        base = tuple(b & a for b, a in zip(self.bisimilar, self.alike, strict=True))
        rej = self.rejected
        if not rej:
            return base
        return tuple(b | (rej & ~(1 << i)) if rej >> i & 1 else b for i, b in enumerate(base))

    def is_goal(self, mask: int) -> bool:
        """Whether every pair of states in ``mask`` is inseparable: the set is oriented."""
        return is_goal(self.inseparable, mask)

    def overlap_cells(self, mask: int) -> list[tuple[float, float, int]]:
        """The overlap ranges of a set as plain ``(lo, hi, image)`` tuples, neighbours with
        equal images merged (for planners' inner loops).

        The cells are those of ``merge_boundaries`` (boundaries within ANGLE_EPS merged),
        each with the image of its middle rotation, found by one sweep over the sorted
        boundaries that keeps each member's successor up to date: O(k n log(k n)) for k
        states of a part with n. Large sets of one part are swept with numpy. Every rotation
        inside a merged range sends the set to the same image, but a merged range may hold a
        member's boundary (a divergent orientation) inside it, so its half-width is not a
        margin: planners rotate in :meth:`~feederkit.planning.choices.Choices.fixed_cells`.
        """
        idx = members(mask)
        table = self.numpy_table
        cells = None
        if table is not None and len(idx) * table[0].shape[1] >= _NUMPY_MIN_EVENTS:
            cells = _cells_numpy(self, mask, idx, table)
        if cells is None and not self.machine.deterministic and self.set_table is not None:
            cells = _cells_numpy_sets(self, mask, idx, self.set_table)
        if cells is None:
            sweep = _cells_sweep if self.machine.deterministic else _cells_sweep_sets
            cells = sweep(self, mask, idx)
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

    def overlap_ranges(self, mask: int) -> list[OverlapRange]:
        """The overlap ranges of a set of states (section 3.2.2), equal neighbours merged."""
        return [OverlapRange(lo, hi, img) for lo, hi, img in self.overlap_cells(mask)]

    def branches(self, mask: int, grouping: Grouping | str = Grouping.EXACT) -> list[ReadingBranch]:
        """Split a set of states by the sensor reading (exact reading branching by default).

        A state with a diameter interval reads anything any width in it can read.
        """
        idx = members(mask)
        states = self.machine.states
        return self.machine.sensor.split([states[i].sensed for i in idx], grouping, idx)


def _per_cell(
    m: PushAlignMachine, values: tuple[list, ...], dtype: type
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every state's action-range starts sorted together, their owner states, the distinct
    starts, and per cell between consecutive distinct starts each state's value of its range
    there (``values[state][range]``: a target, an outcome mask, or an outcome set's state
    indices padded to one length)."""
    b = np.fromiter((x for i in range(m.n) for x in m.starts[i]), float)
    own = np.fromiter((i for i in range(m.n) for _ in m.starts[i]), np.int64)
    order = np.argsort(b, kind="stable")
    distinct = np.unique(b)
    mids = (distinct + np.append(distinct[1:], distinct[0] + 360.0)) / 2.0
    mids = np.where(mids >= 360.0, mids - 360.0, mids)
    rows: np.ndarray | None = None
    for i in range(m.n):
        at = np.searchsorted(np.asarray(m.starts[i]), mids, side="right") - 1
        per_range = np.asarray(values[i], dtype=dtype)
        if rows is None:
            rows = np.empty((len(distinct), m.n, *per_range.shape[1:]), dtype=dtype)
        rows[:, i] = per_range[at]
    assert rows is not None
    return b[order], own[order], distinct, rows


def _picker(idx: list[int]) -> Callable[[list[int]], tuple[int, ...]]:
    """A function taking a row's entries at ``idx`` (in that order) as a tuple."""
    if len(idx) == 1:
        i = idx[0]
        return lambda row: (row[i],)
    return operator.itemgetter(*idx)  # type: ignore[return-value]


_spaces: dict[int, SearchSpace] = {}


def search_space(machine: PushAlignMachine) -> SearchSpace:
    """The machine's search space, built once per machine (dropped with the machine)."""
    key = id(machine)
    space = _spaces.get(key)
    if space is None or space._machine() is not machine:
        space = SearchSpace(machine)
        _spaces[key] = space
        weakref.finalize(machine, _spaces.pop, key, None)
    return space


def is_goal(insep: tuple[int, ...] | list[int], mask: int) -> bool:
    """Whether every pair of states in ``mask`` is inseparable (``insep[i]``: the states
    ``i`` is inseparable from): the set is oriented, a plan may stop."""
    m = mask
    while m:
        low = m & -m
        i = low.bit_length() - 1
        if mask & ~insep[i] & ~low:
            return False
        m ^= low
    return True


def overlap_cells(machine: PushAlignMachine, mask: int) -> list[tuple[float, float, int]]:
    """``search_space(machine).overlap_cells(mask)``."""
    return search_space(machine).overlap_cells(mask)


def overlap_ranges(machine: PushAlignMachine, mask: int) -> list[OverlapRange]:
    """``search_space(machine).overlap_ranges(mask)``."""
    return search_space(machine).overlap_ranges(mask)


def branches(
    machine: PushAlignMachine, mask: int, grouping: Grouping | str = Grouping.EXACT
) -> list[ReadingBranch]:
    """``search_space(machine).branches(mask, grouping)``."""
    return search_space(machine).branches(mask, grouping)


def inseparable(machine: PushAlignMachine) -> tuple[int, ...]:
    """``search_space(machine).inseparable``: per state, the states it is inseparable from."""
    return search_space(machine).inseparable


def _sweep_clusters(
    space: SearchSpace, idx: list[int]
) -> tuple[list[tuple[float, int, int]], Iterator[tuple[float, float, int, int]]]:
    """The sorted boundary events ``(angle, state, target)`` of a set's members and its
    cells ``(lo, hi, first, end)``, whose events are ``evs[first:end]``, for the pure Python
    sweeps.

    The boundaries are clustered exactly as :func:`~feederkit.angles.merge_boundaries`
    does. A last cluster within ANGLE_EPS of the first across 360 degrees wraps into it; its
    events are dropped, since they only restart each member's last action range, where the
    sweep starts. A cell whose last event is at or past its middle is narrower than its own
    boundary cluster: there the swept image belongs to a neighbour, and callers ask the
    machine for the image at the middle.
    """
    triples = space.triples
    evs = [e for i in idx for e in triples[i]]
    evs.sort()
    eps = ANGLE_EPS
    reps: list[float] = []
    starts: list[int] = []
    for k, (b, _i, _t) in enumerate(evs):
        if not reps or b - reps[-1] > eps:
            reps.append(b)
            starts.append(k)
    n_ev = len(evs)
    if len(reps) > 1 and reps[0] + 360.0 - reps[-1] <= eps:
        reps.pop()
        n_ev = starts.pop()
    if not reps:
        return evs, iter(())
    his = [*reps[1:], reps[0] + 360.0]
    return evs, zip(reps, his, starts, [*starts[1:], n_ev], strict=True)


def _cells_sweep(space: SearchSpace, mask: int, idx: list[int]) -> list[list]:
    """The cells ``[lo, hi, image]`` of a set, by a sweep in pure Python."""
    machine = space.machine
    targets = machine.targets
    evs, clusters = _sweep_clusters(space, idx)
    # Before the first boundary every member is in its last action range.
    count: dict[int, int] = {}
    cur: dict[int, int] = {}
    img = 0
    for i in idx:
        t = targets[i][-1]
        cur[i] = t
        c = count.get(t, 0)
        if c == 0:
            img |= 1 << t
        count[t] = c + 1
    cells: list[list] = []
    for lo, hi, first, end in clusters:
        for _b, i, t in evs[first:end]:
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
        mid = (lo + hi) / 2.0
        if evs[end - 1][0] >= mid:  # a degenerate cell narrower than its own boundary cluster
            cells.append([lo, hi, machine.image(mask, norm360(mid))])
        else:
            cells.append([lo, hi, img])
    return cells


def _cells_sweep_sets(space: SearchSpace, mask: int, idx: list[int]) -> list[list]:
    """The cells ``[lo, hi, image]`` of a set whose members have outcome *sets* (a sweep).

    The image of a cell is the union of its members' outcome sets there; a count per target
    state keeps it up to date as each member's outcome set changes at a boundary.
    """
    machine = space.machine
    outs = machine.outcomes_of
    evs, clusters = _sweep_clusters(space, idx)
    count = [0] * machine.n
    cur: dict[int, int] = {}
    img = 0

    def add(t: int, sign: int) -> int:
        nonlocal img
        while t:
            low = t & -t
            b = low.bit_length() - 1
            c = count[b] + sign
            count[b] = c
            if c == 0:
                img &= ~low
            elif c == 1 and sign > 0:
                img |= low
            t ^= low
        return img

    for i in idx:
        cur[i] = outs[i][-1]
        add(cur[i], 1)
    cells: list[list] = []
    for lo, hi, first, end in clusters:
        for _b, i, t in evs[first:end]:
            old = cur[i]
            if old == t:
                continue
            cur[i] = t
            add(old, -1)
            add(t, 1)
        mid = (lo + hi) / 2.0
        if evs[end - 1][0] >= mid:  # a degenerate cell narrower than its own boundary cluster
            cells.append([lo, hi, machine.image(mask, norm360(mid))])
        else:
            cells.append([lo, hi, img])
    return cells


def _numpy_sweep(
    b: np.ndarray, st: np.ndarray, tg: np.ndarray, initial: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[int, float]]] | None:
    """The sweep vectorised, for the numpy cells: sorted boundaries ``b``, at which member
    row ``st`` takes value ``tg`` (a target or an outcome mask; ``initial`` before the first
    boundary).

    Returns the cells' ``lo`` and ``hi`` (clustered as in :func:`_sweep_clusters`), each
    member's value per cell (``values[row, cell]``) and the cells narrower than their own
    boundary cluster with their middles; None when a cluster spans more than ANGLE_EPS (a
    chain of close boundaries, where merge_boundaries's rule differs: use the sweep).
    """
    eps = ANGLE_EPS
    new = np.empty(len(b), dtype=bool)
    new[0] = True
    new[1:] = np.diff(b) > eps
    first = np.flatnonzero(new)
    last = np.append(first[1:] - 1, len(b) - 1)
    if np.any(b[last] - b[first] > eps):
        return None
    cid = np.cumsum(new) - 1
    reps = b[first]
    m = len(reps)
    if m > 1 and reps[0] + 360.0 - reps[-1] <= eps:
        keep = cid < m - 1
        st, tg, cid = st[keep], tg[keep], cid[keep]
        last = last[:-1]
        m -= 1
        reps = reps[:m]
    grid = np.full((len(initial), m + 1), -1, dtype=np.int64)
    grid[:, 0] = initial
    grid[st, cid + 1] = tg
    pos = np.where(grid >= 0, np.arange(m + 1), 0)
    np.maximum.accumulate(pos, axis=1, out=pos)
    values = np.take_along_axis(grid, pos, axis=1)[:, 1:]
    his = np.append(reps[1:], reps[0] + 360.0)
    mids = (reps + his) / 2.0
    narrow = [(c, float(mids[c])) for c in np.flatnonzero(b[last] >= mids).tolist()]
    return reps, his, values, narrow


def _exact_images(
    space: SearchSpace, mask: int, imgs: np.ndarray, narrow: list[tuple[int, float]]
) -> np.ndarray:
    """``imgs`` with each narrow cell's image (``(cell, middle)`` from :func:`_numpy_sweep`)
    replaced by the set's image at its middle."""
    if narrow:
        imgs = imgs.astype(object)
        for c, mid in narrow:
            imgs[c] = space.machine.image(mask, norm360(mid))
    return imgs


def _cells_numpy_sets(space: SearchSpace, mask: int, idx: list[int], table) -> list[list] | None:
    """The cells of ``_cells_sweep_sets`` by numpy (None: clusters too irregular)."""
    lo_all, st_all, mk_all, last = table
    sel = np.zeros(space.machine.n, dtype=bool)
    sel[idx] = True
    keep = sel[st_all]
    lo_s, st_s, mk_s = lo_all[keep], st_all[keep], mk_all[keep]
    order = np.argsort(lo_s, kind="stable")
    b = lo_s[order]
    row_of = np.full(space.machine.n, -1, dtype=np.int64)
    row_of[idx] = np.arange(len(idx))
    if len(b) == 0:
        return None
    swept = _numpy_sweep(b, row_of[st_s[order]], mk_s[order], last[idx])
    if swept is None:
        return None
    reps, his, outs, narrow = swept
    imgs = _exact_images(space, mask, np.bitwise_or.reduce(outs, axis=0), narrow)
    return [
        [lo, hi, int(im)]
        for lo, hi, im in zip(reps.tolist(), his.tolist(), imgs.tolist(), strict=True)
    ]


def _cells_numpy(space: SearchSpace, mask: int, idx: list[int], table) -> list[list] | None:
    """The cells of ``_cells_sweep`` by numpy (None: clusters too irregular, use the sweep)."""
    los, tgs = table
    k, r = len(idx), los.shape[1]
    sel = np.array(idx)
    lo_all = los[sel].ravel()
    order = np.argsort(lo_all, kind="stable")
    st = np.repeat(np.arange(k), r)[order]
    swept = _numpy_sweep(lo_all[order], st, tgs[sel].ravel()[order], tgs[sel, -1])
    if swept is None:
        return None
    reps, his, targets, narrow = swept
    bits = np.left_shift(np.uint64(1), targets.astype(np.uint64))
    imgs = _exact_images(space, mask, np.bitwise_or.reduce(bits, axis=0), narrow)
    # Merge neighbours with equal images here; overlap_cells merges the rest.
    m = len(reps)
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
