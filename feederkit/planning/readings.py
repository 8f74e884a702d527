"""The readings of a set of states: its branches (section 6.1) and how likely each is.

The paper leaves the reading distribution open (section 6: "the expected number of
operations depends on the initial distribution of part orientations"). feederkit fixes it:

- the initial orientation is uniform on the circle, so the first alignment ends in state
  ``s`` with probability ``MachineState.weight`` (its resting range / 360);
- a reading error is uniform over the state's reading set: with ``ToleranceSensor(e)`` a
  state of diameter ``d`` reads uniformly in ``(d - e, d + e)`` (a physical state of diameter
  interval ``[lo, hi]`` in ``(lo - e, hi + e)``); with ``LedSensor(p, e)``
  the width is uniform in ``[d - e, d + e]`` (exactly ``d`` when ``e = 0``) and the count is
  the number of beams below it; without a sensor there is one reading.

A state therefore follows a branch ``[lo, hi]`` with the probability that its reading falls
in it, and its probability mass is split between the branches it can follow in that
proportion (with exact branching they add up to 1; with the components rule each state
follows one branch). Under uncertainty a state's mass moves to its outcome set, shared
equally among its outcomes (nature's choice is not a probability the model knows; the
expected number of operations is a tie-break, the worst case is what is guaranteed).
Planner and statistics use this same model.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterator

import numpy as np

from feederkit.machine import (
    Grouping,
    PushAlignMachine,
    ReadingBranch,
    bit_rows,
    members,
    search_space,
)


def reading_probability(machine: PushAlignMachine, branch: ReadingBranch, state: int) -> float:
    """Probability that ``state`` gives a reading in ``branch`` (the sensor's model)."""
    return machine.sensor.reading_probability(machine.states[state].sensed, branch.lo, branch.hi)


def maximal_sets(masks) -> tuple[int, ...]:
    """The distinct masks not contained in another, largest first."""
    out: list[int] = []
    for m in sorted(set(masks), key=lambda c: -c.bit_count()):
        if not any(m & o == m for o in out):
            out.append(m)
    return tuple(out)


CLIQUE_SCAN_STATES = 128
"""Up to this many states an image's members are taken in the order their reading runs end
by one scan of the machine's states; above it, by sorting the members."""

WALK_BITS = 32
"""``Readings.branch_keys`` walks each image's runs in Python when the images hold at most
this many states on average, and uses arrays above it: on the 50-part mix at 5 % under 1
degree (240 states) the walk took 0.25-0.4 of the arrays' time for a beam's sets of at most
four states and 0.85-0.9 for the larger ones; on the 100-part mix (478 states) 0.9 at 27 states
an image, 1.5 at 77 and 7 at 216 (docs/performance.md, "Solvability from the images alone;
reading keys walked")."""


class Readings:
    """The reading branches of the sets a search meets, cached per set.

    ``children(image)`` are the maximal branches (the length view: a subset of a set is
    oriented by the set's rotations in no more operations); ``all_children(image)`` every
    distinct one (the exact view). With exact branching a subset's branches are the whole
    machine's reading cells restricted to it, computed once; the sensor may offer a faster
    path (``Sensor.reading_windows``) when states are numbered by diameter.
    """

    def __init__(
        self, machine: PushAlignMachine, grouping: Grouping, insep: tuple[int, ...]
    ) -> None:
        self.machine = machine
        self.grouping = Grouping(grouping)
        self.insep = insep
        self._space = search_space(machine)
        self._diam = [s.sensed for s in machine.states]
        full = machine.all_states
        self.informative = machine.sensor.informative
        self.sensorless = not self.informative or all(
            b.mask == full for b in self._space.branches(full, Grouping.EXACT)
        )
        exact = self.grouping is Grouping.EXACT
        self._window = (machine.sensor.reading_windows(self._diam) or []) if exact else []
        self._window_first = _first_reaching(self._window)
        self._window_end = np.array([w.bit_length() for w in self._window], dtype=np.intp)
        self._cell_masks: list[int] | None = None
        self._cell_span: list[tuple[int, int]] = []
        self._runs = False
        """Whether each state's reading cells are one run of consecutive cells: the
        branches of an image are then the cliques of intervals (:meth:`_interval_cliques`)."""
        self._span_end: list[int] = []
        self._end_order: list[int] = []
        self._open_at: list[int] = []
        if exact and not self.sensorless:
            cells = self._space.branches(full, Grouping.EXACT)
            self._cell_masks = [b.mask for b in cells]
            span = [[len(cells), 0] for _ in range(machine.n)]
            for c, b in enumerate(cells):
                for i in members(b.mask):
                    span[i][0] = min(span[i][0], c)
                    span[i][1] = max(span[i][1], c + 1)
            self._cell_span = [(a, b) for a, b in span]
            self._runs = _cells_are_runs(self._cell_masks, self._cell_span)
            self._span_end = [b for _a, b in self._cell_span]
            self._end_order = sorted(range(machine.n), key=self._span_end.__getitem__)
            self._open_at = _open_at_ends(self._cell_span)
        self._branches: dict[int, tuple[ReadingBranch, ...]] = {}
        self._maximal: dict[int, tuple[int, ...]] = {}
        self._all: dict[int, tuple[int, ...]] = {}
        self._open: dict[int, dict[int, float] | None] = {}
        self._tables: dict[int, list[tuple[ReadingBranch, list[int], list[float]]]] = {}
        self._prob: dict[tuple[float | None, float | None, int], float] = {}
        self._shared: dict[tuple[int, int, int], float | None] = {}
        self._paired = 0
        """The states with an inseparable partner (``open_probability`` needs no look at
        an image without one)."""
        for i, row in enumerate(insep):
            if row:
                self._paired |= 1 << i
        self._quiet: tuple[int, tuple[int, ...]] | None = None

    def _quiet_table(self) -> tuple[int, tuple[int, ...]]:
        """The states whose reading closure carries no information, and their classes.

        Two states *read alike* when they lie in the same exact reading cells of the whole
        machine (the same reading set). A state is *quiet* when every state reachable from
        it under every sequence of actions (every outcome) reads alike with it; ``alike[i]``
        is the mask of states reading alike with ``i``. A set of quiet states of one class
        (section 4's situation inside section 6's search) only ever meets sets that read
        alike, so each of its actions has one branch: its image.
        """
        if self._quiet is not None:
            return self._quiet
        m = self.machine
        n = m.n
        key: list[list[int]] = [[] for _ in range(n)]
        if not self.sensorless:
            for c, b in enumerate(self._space.branches(m.all_states, Grouping.EXACT)):
                for i in members(b.mask):
                    key[i].append(c)
        by_key: dict[tuple[int, ...], int] = {}
        for i in range(n):
            k = tuple(key[i])
            by_key[k] = by_key.get(k, 0) | 1 << i
        alike = tuple(by_key[tuple(key[i])] for i in range(n))
        succ = [0] * n
        for i in range(n):
            for out in m.outcomes_of[i]:
                succ[i] |= out
        # The greatest set of states whose successors all read alike with them and are again
        # in the set: then everything reachable reads alike (alike classes are equivalences).
        quiet = 0
        for i in range(n):
            if succ[i] & ~alike[i] == 0:
                quiet |= 1 << i
        changed = True
        while changed:
            changed = False
            for i in members(quiet):
                if succ[i] & ~quiet:
                    quiet &= ~(1 << i)
                    changed = True
        # Each class must give one branch under the problem's own branching (belt and
        # braces: reading alike means one reading set, so every subset gives one branch).
        for c in set(alike):
            q = c & quiet
            if q and (self.children(q) != (q,) or self.all_children(q) != (q,)):
                quiet &= ~c
        self._quiet = (quiet, alike)
        return self._quiet

    def carries_no_information(self, mask: int) -> bool:
        """Whether no reading can split any set reachable from ``mask``: its members are
        quiet and read alike (:meth:`_quiet_table`), so it is a sensorless problem."""
        if not mask:
            return False
        quiet, alike = self._quiet_table()
        if mask & ~quiet:
            return False
        low = (mask & -mask).bit_length() - 1
        return mask & ~alike[low] == 0

    def branches(self, mask: int) -> tuple[ReadingBranch, ...]:
        """The reading branches of a set (cached)."""
        b = self._branches.get(mask)
        if b is None:
            b = tuple(self._space.branches(mask, self.grouping))
            self._branches[mask] = b
        return b

    def image_branches(self, image: int) -> tuple[ReadingBranch, ...]:
        """Every reading branch of an image (no sensor: the image itself, no reading)."""
        if not self.informative:
            return (ReadingBranch(None, None, image),)
        return self.branches(image)

    def all_children(self, image: int) -> tuple[int, ...]:
        """Every distinct reading branch set of an image, largest first (cached)."""
        out = self._all.get(image)
        if out is None:
            if self._cell_masks is not None:
                # Exact branching: the whole machine's reading cells restricted to the image.
                masks = self._restricted_cells(image)
            else:
                masks = {b.mask for b in self.branches(image)}
            out = tuple(sorted(masks, key=int.bit_count, reverse=True))
            self._all[image] = out
        return out

    def children(self, image: int) -> tuple[int, ...]:
        """The maximal reading branches of an image (cached)."""
        out = self._maximal.get(image)
        if out is None:
            if self._window:
                out = self._window_runs(image)
            elif self._runs:
                out = self._interval_cliques(image)
            elif self._cell_masks is not None:
                out = maximal_sets(self._restricted_cells(image))
            else:
                out = maximal_sets(b.mask for b in self.branches(image))
            self._maximal[image] = out
        return out

    def _window_runs(self, image: int) -> tuple[int, ...]:
        """Maximal branches from the sensor's reading windows (states numbered by diameter),
        largest first (:meth:`_walk_runs`)."""
        runs = list(self._walk_runs(image))
        if len(runs) > 1:
            runs.sort(key=int.bit_count, reverse=True)
        return tuple(runs)

    def _walk_runs(self, image: int) -> Iterator[int]:
        """The image's maximal runs along the reading axis, in order.

        A member's run (its window within the image) is maximal when it reaches further than
        the one before, so the walk jumps from run to run: the next maximal run is the one
        of the first member whose window reaches the first member past the last run
        (windows are runs whose both ends ascend), one mask operation per branch instead of
        one per member.
        """
        win = self._window
        first = self._window_first
        rest = image
        while rest:
            low = rest & -rest
            r = image & win[low.bit_length() - 1]
            yield r
            top = r.bit_length()
            above = image >> top
            if not above:
                return
            reach = first[top + (above & -above).bit_length() - 1]
            rest = image >> reach << reach

    def window_key(self, image: int) -> tuple[int, int]:
        """``choices.children_key`` of the image's maximal reading branches (the largest
        branch's size, the sizes added up) from :meth:`_walk_runs`, without making the
        branches (the reading windows must exist)."""
        largest = total = 0
        for r in self._walk_runs(image):
            c = r.bit_count()
            total += c
            if c > largest:
                largest = c
        return largest, total

    def branch_keys(self, images: list[int]) -> list[tuple[int, int]] | None:
        """Per image, the size of its largest maximal reading branch and the sizes of its
        maximal branches added up (``choices.children_key`` of :meth:`children`), for many
        images at once from the reading windows; None without them.

        A search ranks every overlap range of a set by these two numbers and makes the
        branches of only the few it tries. With the states numbered by diameter a member's
        run is its window within the image, so with ``P`` the image's running count of
        members, a run of the member ``i`` holds ``P[end(i)] - P[i]`` states, and it is
        maximal when it counts more members below its end than the previous member's run
        (the same runs as :meth:`_window_runs`): a few array operations over every image,
        where the runs themselves cost a loop per branch and image. Images of at most
        ``WALK_BITS`` states on average are walked instead (:meth:`window_key`): the arrays'
        fixed cost and their width (every state of the machine) then cost more.
        """
        if not self._window or not images:
            return None
        if sum(map(int.bit_count, images)) <= WALK_BITS * len(images):
            return [self.window_key(img) for img in images]
        return self._array_keys(images)

    def _array_keys(self, images: list[int]) -> list[tuple[int, int]]:
        """:meth:`branch_keys` by array operations over every image at once."""
        n = self.machine.n
        bits = bit_rows(images, n).astype(np.int32)
        counts = np.zeros((len(images), n + 1), dtype=np.int32)
        np.cumsum(bits, axis=1, out=counts[:, 1:])
        below_end = counts[:, self._window_end] * bits  # members before each run's end
        size = below_end - counts[:, :n] * bits
        reach = np.maximum.accumulate(below_end, axis=1)
        maximal = np.empty_like(below_end, dtype=bool)
        maximal[:, 0] = below_end[:, 0] > 0
        np.greater(below_end[:, 1:], reach[:, :-1], out=maximal[:, 1:])
        largest = size.max(axis=1).tolist()
        total = np.where(maximal, size, 0).sum(axis=1).tolist()
        return list(zip(largest, total, strict=True))

    def _interval_cliques(self, image: int) -> tuple[int, ...]:
        """The maximal reading branches of an image when each state's reading cells are a
        run (``_cell_span``): the maximal cliques of those intervals, by one sweep.

        Just before a member's run ends, the members read together are those begun before
        that cell and not ended before it (``_open_at[e] & image``). Taken in the order the
        runs end, such a set is maximal exactly when a member began since the previous end
        (it is then not inside the previous set; no run left out meets both the last begun
        and the ending one), and every maximal set is met so (the interval graphs' maximal
        cliques, Gilmore and Hoffman 1964). Largest first, then along the reading axis. The
        same sets as :func:`maximal_sets` of ``_restricted_cells``, without a look at every
        cell and every pair of sets.
        """
        if image & (image - 1) == 0:
            return (image,)
        if self.machine.n <= CLIQUE_SCAN_STATES:
            ends = [e for e in self._end_order if image >> e & 1]
        else:
            ends = sorted(members(image), key=self._span_end.__getitem__)
        open_at = self._open_at
        out = []
        last = 0
        for e in ends:
            c = image & open_at[e]
            if c & last != c:
                out.append(c)
            last = c
        if len(out) > 1:
            out.sort(key=int.bit_count, reverse=True)
        return tuple(out)

    def _restricted_cells(self, image: int) -> set[int]:
        """The image's states in each reading cell of the whole machine that meets it."""
        cm = self._cell_masks
        assert cm is not None
        span = self._cell_span
        ranges = sorted(span[i] for i in members(image))
        out = set()
        end = 0
        for a, b in ranges:
            for c in range(max(a, end), b):
                out.add(cm[c] & image)
            end = max(end, b)
        return out

    def probability(self, branch: ReadingBranch, state: int) -> float:
        """Probability that ``state`` gives a reading in ``branch`` (cached)."""
        key = (branch.lo, branch.hi, state)
        p = self._prob.get(key)
        if p is None:
            p = reading_probability(self.machine, branch, state)
            self._prob[key] = p
        return p

    def branch_table(self, image: int) -> list[tuple[ReadingBranch, list[int], list[float]]]:
        """Per reading branch of an image: the branch, its states and their probabilities."""
        table = self._tables.get(image)
        if table is None:
            table = []
            for b in self.image_branches(image):
                idx = members(b.mask)
                table.append((b, idx, [self.probability(b, s) for s in idx]))
            self._tables[image] = table
        return table

    def open_probability(self, image: int) -> dict[int, float] | None:
        """Per state of ``image``: the probability that its reading leaves it with others.

        From the sensor's closed form (``Sensor.shared_reading_probability``) when the
        reading windows apply and no two states of the image are inseparable; None
        otherwise (the branch table then decides).

        With the reading windows the states are numbered by diameter and their diameters
        ascend at both ends, so the readings a state shares with the others of the image
        are those it shares with its two neighbours in the image (an earlier state's
        reading set reaches no further into the state's than its nearer neighbour's does,
        and so for later ones). Each state's figure is therefore the sensor's closed form
        of (previous, state, next), cached per triple: the same float as from the whole
        image, for a few states' work instead of the image's.
        """
        if not self._window:
            return None
        if image in self._open:
            return self._open[image]
        idx = members(image)
        out: dict[int, float] | None = None
        if not (image & self._paired and any(self.insep[i] & image for i in idx)):
            out = {}
            win = self._window
            last = len(idx) - 1
            for j, s in enumerate(idx):
                # A neighbour whose readings never meet the state's is as good as none.
                a = idx[j - 1] if j and win[idx[j - 1]] >> s & 1 else -1
                b = idx[j + 1] if j < last and win[s] >> idx[j + 1] & 1 else -1
                key = (a, s, b)
                p = self._shared.get(key, _UNSET)
                if p is _UNSET:
                    p = self._shared[key] = self._shared_one(key)
                if p is None:
                    out = None
                    break
                out[s] = p
        self._open[image] = out
        return out

    def open_mass(self, image: int, moved: dict[int, float]) -> float | None:
        """``sum(w * open_probability(image)[t] for t, w in moved.items())``, the same float
        (``moved``: mass per state of ``image``, every state of it a key), or None where
        :meth:`open_probability` is None.

        Each state's figure is its (previous, state, next) triple's, the neighbours found
        by bit operations on ``image``: no member list or per-image table, since the sets
        a search meets seldom share an image.
        """
        if not self._window:
            return None
        if image & self._paired and any(self.insep[i] & image for i in members(image)):
            return None
        win = self._window
        shared = self._shared
        total = 0
        for s, w in moved.items():
            before = image & ((1 << s) - 1)
            a = before.bit_length() - 1 if before else -1
            if a >= 0 and not win[a] >> s & 1:
                a = -1
            after = image >> (s + 1)
            b = s + (after & -after).bit_length() if after else -1
            if b >= 0 and not win[s] >> b & 1:
                b = -1
            key = (a, s, b)
            p = shared.get(key, _UNSET)
            if p is _UNSET:
                p = shared[key] = self._shared_one(key)
            if p is None:
                return None
            total += w * p
        return total

    def _shared_one(self, key: tuple[int, int, int]) -> float | None:
        """The sensor's closed form for the middle state of ``(previous, state, next)``
        (-1: none), or None when it has none."""
        run = [i for i in key if i >= 0]
        shared = self.machine.sensor.shared_reading_probability([self._diam[i] for i in run])
        return None if shared is None else shared[run.index(key[1])]


_UNSET = object()


def _first_reaching(windows: list[int]) -> list[int]:
    """Per state ``j``, the first state whose reading window holds it (windows ``a..b``
    with both ends ascending, each holding its own state: :meth:`Sensor.reading_windows`).

    >>> _first_reaching([0b011, 0b010, 0b100])
    [0, 0, 2]
    """
    ends = [w.bit_length() for w in windows]
    out = []
    a = 0
    for j in range(len(windows)):
        while ends[a] <= j:
            a += 1
        out.append(a)
    return out


def _open_at_ends(span: list[tuple[int, int]]) -> list[int]:
    """Per state, the states whose runs of cells hold the last cell of its own run
    (``a <= end - 1 < b``): begun before its end and not ended before it. Prefix masks over
    the states by begin and suffix masks by end, one bisection each."""
    n = len(span)
    by_begin = sorted(range(n), key=lambda i: span[i][0])
    by_end = sorted(range(n), key=lambda i: span[i][1])
    begins = [span[i][0] for i in by_begin]
    ends = [span[i][1] for i in by_end]
    begun = [0]  # begun[k]: the first k states by begin
    for i in by_begin:
        begun.append(begun[-1] | 1 << i)
    left = [0] * (n + 1)  # left[k]: the states from the k-th by end on
    for k in range(n - 1, -1, -1):
        left[k] = left[k + 1] | 1 << by_end[k]
    out = []
    for _a, b in span:
        out.append(begun[bisect.bisect_left(begins, b)] & left[bisect.bisect_left(ends, b)])
    return out


def _cells_are_runs(cell_masks: list[int], span: list[tuple[int, int]]) -> bool:
    """Whether every state lies in exactly the cells of its span: each state's reading set
    is one run of consecutive cells (true of interval reading sets; checked, not assumed)."""
    delta = [0] * (len(cell_masks) + 1)
    for i, (a, b) in enumerate(span):
        if a < b:
            delta[a] ^= 1 << i
            delta[b] ^= 1 << i
    inside = 0
    for c, mask in enumerate(cell_masks):
        inside ^= delta[c]
        if inside != mask:
            return False
    return True
