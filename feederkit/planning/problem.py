"""The planning problem: a push-align machine compiled for fast search over sets of states.

States are bit masks (section 3.3: a node of the search holds the set of states consistent
with the operations so far). For each set the problem lists its representative actions
(the overlap ranges of section 3.2.2, keeping those with at least ``min_margin``), each with
the sets of states the reading can leave (``branches``, section 6.1). Everything is cached
per set, so every planner on the same problem shares the work.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from feederkit.angles import norm360
from feederkit.machine import (
    Branch,
    PushAlignMachine,
    SetAction,
    branches,
    inseparable,
    members,
    overlap_cells,
    overlap_ranges,
    successor,
)
from feederkit.planning.readings import reading_probability
from feederkit.sensors import Grouping, NoSensor, ToleranceSensor


@dataclass(frozen=True)
class Act:
    """A representative action of a set: its overlap range and the reading branches of its image.

    ``children`` are branch masks, largest first. In the length view (``Problem.actions``)
    only those no other branch contains: a subset of a set is oriented by the set's
    rotations in no more operations, so only these decide the worst-case length. In the
    exact view (``Problem.exact_actions``) all of them.
    """

    action: SetAction
    children: tuple[int, ...]

    @property
    def rotation(self) -> float:
        """The rotation a plan uses (deg, [0, 360))."""
        return self.action.representative


def _windows(diam: list[float], tol: float) -> list[int]:
    """Per state ``a`` (states numbered by diameter), the mask of states ``a..b`` whose diameter
    is below ``diam[a] + 2 tol``: those that can read alike with ``a`` from above.

    Empty when the numbering is not by diameter, or when some pair of diameters differs by
    twice the tolerance to within rounding (the reading cells then decide).
    """
    n = len(diam)
    if any(diam[i] > diam[i + 1] for i in range(n - 1)):
        return []
    two = 2.0 * tol
    fuzz = 1e-9 * max(max(diam, default=1.0), two)
    out = []
    b = 0
    for a in range(n):
        b = max(b, a)
        while b < n and diam[b] - diam[a] < two:
            b += 1
        near = [j for j in (b - 1, b) if a <= j < n]
        if any(abs(diam[j] - diam[a] - two) < fuzz for j in near):
            return []
        out.append(((1 << b) - 1) ^ ((1 << a) - 1))
    return out


def maximal_sets(masks) -> tuple[int, ...]:
    """The distinct masks not contained in another, largest first."""
    out: list[int] = []
    for m in sorted(set(masks), key=lambda c: -c.bit_count()):
        if not any(m & o == m for o in out):
            out.append(m)
    return tuple(out)


def popcount(mask: int) -> int:
    """Number of states in a mask."""
    return mask.bit_count()


class Problem:
    """A machine, a reading grouping and a margin floor, with per-set caches.

    ``actions(mask)`` (the length view) keeps only useful actions: one per distinct outcome
    (largest margin, then smallest rotation), none leaving a reading whose set contains
    ``mask`` (it cannot shorten a plan: a subset of a solvable set is solvable in no more
    steps, using the same rotations). ``exact_actions(mask)`` keeps them all.
    """

    def __init__(
        self,
        machine: PushAlignMachine,
        grouping: Grouping = "exact",
        min_margin: float = 0.0,
        insep: tuple[int, ...] | None = None,
        distinct_maps: bool = False,
    ) -> None:
        self.machine = machine
        self.grouping = grouping
        self.min_margin = min_margin
        self.distinct_maps = distinct_maps
        self.n = machine.n
        self.full = machine.all_states
        self.insep = inseparable(machine) if insep is None else insep
        self.sep = tuple(self.full & ~self.insep[i] & ~(1 << i) for i in range(self.n))
        self.sensorless = isinstance(machine.sensor, NoSensor) or all(
            b.mask == self.full for b in branches(machine, self.full, "exact")
        )
        self._actions: dict[int, tuple[Act, ...]] = {}
        self._branches: dict[int, tuple[Branch, ...]] = {}
        self._goal: dict[int, bool] = {}
        self._maximal: dict[int, tuple[int, ...]] = {}
        self._all_children: dict[int, tuple[int, ...]] = {}
        self._exact: dict[int, tuple[Act, ...]] = {}
        self._lazy: dict[int, list] = {}
        self._open: dict[int, dict[int, float] | None] = {}
        self._tables: dict[int, list[tuple[Branch, list[int], list[float]]]] = {}
        self._diam = [s.diameter for s in machine.states]
        self._tolerance: float | None = None
        self._window: list[int] = []
        if grouping == "exact" and isinstance(machine.sensor, ToleranceSensor):
            self._window = _windows(self._diam, machine.sensor.tolerance)
            if self._window:
                self._tolerance = machine.sensor.tolerance
        self._cell_masks: list[int] | None = None
        self._cell_span: list[tuple[int, int]] = []
        if grouping == "exact" and not self.sensorless:
            cells = branches(machine, self.full, "exact")
            self._cell_masks = [b.mask for b in cells]
            span = [[len(cells), 0] for _ in range(self.n)]
            for c, b in enumerate(cells):
                for i in members(b.mask):
                    span[i][0] = min(span[i][0], c)
                    span[i][1] = max(span[i][1], c + 1)
            self._cell_span = [(a, b) for a, b in span]
        self._cells: dict[tuple[int, bool], list[tuple[float, float, int]]] = {}
        self._targets: dict[tuple[int, float], tuple[int, ...]] = {}
        self._prob: dict[tuple[float | None, float | None, int], float] = {}

    def with_margin(self, min_margin: float) -> Problem:
        """The same problem keeping only actions with at least ``min_margin``."""
        return Problem(self.machine, self.grouping, min_margin, self.insep, self.distinct_maps)

    def branch_table(self, img: int) -> list[tuple[Branch, list[int], list[float]]]:
        """Per reading branch of an image: the branch, its states and their probabilities."""
        table = self._tables.get(img)
        if table is None:
            table = []
            for b in self.image_branches(img):
                idx = members(b.mask)
                table.append((b, idx, [self.probability(b, s) for s in idx]))
            self._tables[img] = table
        return table

    def open_probability(self, image: int) -> dict[int, float] | None:
        """Per state of ``image``: the probability that its reading leaves it with others.

        Under a tolerance sensor, when no two states of the image are inseparable, a reading
        orients exactly when it comes from one state alone: the part of the state's reading
        interval that its neighbours in diameter order do not reach. None when this shortcut
        does not apply (the branch table then decides).
        """
        if self._tolerance is None:
            return None
        hit = self._open.get(image)
        if hit is not None or image in self._open:
            return hit
        idx = members(image)
        out: dict[int, float] | None = {}
        if any(self.insep[i] & image for i in idx):
            out = None
        else:
            e = self._tolerance
            d = self._diam
            k = len(idx)
            for t, s in enumerate(idx):
                lo = d[s] - e if t == 0 else max(d[s] - e, d[idx[t - 1]] + e)
                hi = d[s] + e if t == k - 1 else min(d[s] + e, d[idx[t + 1]] - e)
                out[s] = 1.0 - max(0.0, hi - lo) / (2.0 * e)
        self._open[image] = out
        return out

    def act_branches(self, act: Act) -> tuple[Branch, ...]:
        """Every reading branch after ``act`` (no sensor: the one image, no reading)."""
        return self.image_branches(act.action.image)

    def image_branches(self, img: int) -> tuple[Branch, ...]:
        """Every reading branch of an image (no sensor: the image itself, no reading)."""
        if isinstance(self.machine.sensor, NoSensor):
            return (Branch(None, None, img),)
        return self.branches(img)

    def is_goal(self, mask: int) -> bool:
        """Whether every pair of states in ``mask`` is inseparable (the set is oriented)."""
        g = self._goal.get(mask)
        if g is None:
            g = True
            m = mask
            sep = self.sep
            while m:
                low = m & -m
                if mask & sep[low.bit_length() - 1]:
                    g = False
                    break
                m ^= low
            self._goal[mask] = g
        return g

    def branches(self, mask: int) -> tuple[Branch, ...]:
        """The reading branches of a set (cached)."""
        b = self._branches.get(mask)
        if b is None:
            b = tuple(branches(self.machine, mask, self.grouping))
            self._branches[mask] = b
        return b

    def cells(self, mask: int, useful: bool = True) -> list[tuple[float, float, int]]:
        """The set's overlap ranges as ``(lo, hi, image)``, widest first (cached).

        One per distinct image (or per distinct map of the members, with
        ``distinct_maps``): the widest, then the smallest rotation. Ranges narrower than
        twice the margin floor are dropped, and with ``useful`` those whose image contains
        the set (see :meth:`actions`).
        """
        cells = self._cells.get((mask, useful))
        if cells is not None:
            return cells
        best: dict[object, tuple[float, float, int]] = {}
        floor = 2.0 * self.min_margin
        for cell in overlap_cells(self.machine, mask):
            lo, hi, img = cell
            if hi - lo < floor:
                continue
            key: object = img
            if self.distinct_maps:
                key = self.targets(mask, SetAction(lo, hi, img))
            old = best.get(key)
            if old is None or _wider(cell, old):
                best[key] = cell
        keyed = [(lo - hi, norm360((lo + hi) / 2.0), img, lo, hi) for lo, hi, img in best.values()]
        keyed.sort()
        cells = [(lo, hi, img) for _w, _r, img, lo, hi in keyed]
        self._cells[(mask, False)] = cells
        # The useful ones: without those whose image contains the set.
        self._cells[(mask, True)] = [c for c in cells if c[2] & mask != mask]
        return self._cells[(mask, useful)]

    def act(self, mask: int, cell: tuple[float, float, int], exact: bool = False) -> Act | None:
        """The action of one cell with its branch sets.

        By default (the length view) only the maximal branches, and None when one of them
        contains the set. ``exact``: every distinct branch set, never None.
        """
        lo, hi, img = cell
        sa = SetAction(lo, hi, img)
        if self.sensorless:
            return Act(sa, (img,))
        if exact:
            return Act(sa, self.all_children(img))
        children = self.children(img)
        if any(c & mask == mask for c in children):
            return None
        return Act(sa, children)

    def all_children(self, image: int) -> tuple[int, ...]:
        """Every distinct reading branch set of an image, largest first (cached)."""
        out = self._all_children.get(image)
        if out is None:
            if self._tolerance is not None:
                masks = self._tolerance_runs(image)
            else:
                masks = {b.mask for b in self.branches(image)}
            out = tuple(sorted(masks, key=int.bit_count, reverse=True))
            self._all_children[image] = out
        return out

    def _tolerance_runs(self, image: int) -> set[int]:
        """Every reading branch set of an image under a tolerance sensor (states by diameter).

        As the reading grows, state ``i`` becomes possible at ``d_i - e`` and impossible at
        ``d_i + e``, in diameter order both times, so the possible states are always a run.
        """
        e = self._tolerance
        d = self._diam
        idx = members(image)
        prefix = [0]
        for i in idx:
            prefix.append(prefix[-1] | 1 << i)
        k = len(idx)
        enter = [d[i] - e for i in idx]
        leave = [d[i] + e for i in idx]
        out = set()
        a = b = 0
        # Between consecutive event values v < w the possible states are those entered by
        # v and not left by v: a run idx[a:b].
        for v in sorted(set(enter) | set(leave))[:-1]:
            while b < k and enter[b] <= v:
                b += 1
            while a < k and leave[a] <= v:
                a += 1
            if a < b:
                out.add(prefix[b] ^ prefix[a])
        return out

    def exact_actions(self, mask: int) -> tuple[Act, ...]:
        """Every action of the set above the margin floor with all its branch sets (cached).

        The margin of a merged overlap range holds for the set but not for its subsets (a
        subset's image can change inside it where the set's does not), so margins and
        margin floors are not monotone under subsets: the stages that depend on margins
        use this exact view.
        """
        acts = self._exact.get(mask)
        if acts is None:
            acts = tuple(self.act(mask, c, exact=True) for c in self.cells(mask, useful=False))
            self._exact[mask] = acts  # type: ignore[assignment]
        return acts  # type: ignore[return-value]

    def search_actions(self, mask: int) -> Iterator[Act]:
        """The actions the length search uses: the length view when lengths are monotone
        under subsets (no margin floor), else the exact view."""
        return self.lazy_actions(mask) if self.min_margin == 0.0 else iter(self.exact_actions(mask))

    def children(self, image: int) -> tuple[int, ...]:
        """The maximal reading branches of an image (cached); see :class:`Act`."""
        out = self._maximal.get(image)
        if out is None:
            if self._tolerance is not None:
                out = self._tolerance_windows(image)
            elif self._cell_masks is not None:
                out = maximal_sets(self._restricted_cells(image))
            if out is None:
                out = maximal_sets(b.mask for b in self.branches(image))
            self._maximal[image] = out
        return out

    def _tolerance_windows(self, image: int) -> tuple[int, ...]:
        """Maximal branches under a tolerance sensor, states numbered by diameter.

        The states that can give one reading are a run of the image whose extreme diameters
        differ by less than twice the tolerance; ``_window[a]`` holds the states from ``a``
        up to that reach, so each member's run is one mask operation, and a run is maximal
        when it reaches further than the one before.
        """
        win = self._window
        runs = []
        top = -1
        m = image
        while m:
            low = m & -m
            r = image & win[low.bit_length() - 1]
            t = r.bit_length()
            if t > top:
                runs.append(r)
                top = t
            m ^= low
        if len(runs) > 1:
            runs.sort(key=int.bit_count, reverse=True)
        return tuple(runs)

    def _restricted_cells(self, image: int) -> set[int]:
        """The image's states in each reading cell of the whole machine that meets it.

        With exact branching a subset's branches are the whole machine's cells restricted
        to it, so the cells are computed once (``_cell_masks``); each state's cells form a
        run ``_cell_span[i]``.
        """
        cm = self._cell_masks
        span = self._cell_span
        ranges = sorted(span[i] for i in members(image))
        out = set()
        end = 0
        for a, b in ranges:
            for c in range(max(a, end), b):
                out.add(cm[c] & image)
            end = max(end, b)
        return out

    def actions(self, mask: int) -> tuple[Act, ...]:
        """Useful representative actions of a set (``cells``), most promising first (cached)."""
        acts = self._actions.get(mask)
        if acts is not None:
            return acts
        out = [a for a in (self.act(mask, c) for c in self.cells(mask)) if a is not None]
        # Cells come widest first, then by rotation; a stable sort keeps that among equals.
        out.sort(key=_order)
        acts = tuple(out)
        self._actions[mask] = acts
        return acts

    def lazy_actions(self, mask: int) -> Iterator[Act]:
        """The length view's actions, made only as far as a search consumes them.

        Smallest image first (a proxy for the smallest branches), then the widest; the
        search usually succeeds, or fails at a memoised depth, long before the last one.
        """
        done = self._actions.get(mask)
        if done is not None:
            yield from done
            return
        state = self._lazy.get(mask)
        if state is None:
            cells = sorted(self.cells(mask), key=lambda c: (c[2].bit_count(), c[0] - c[1]))
            state = self._lazy[mask] = [cells, 0, []]
        cells, _, made = state
        i = 0
        while True:
            if i < len(made):
                yield made[i]
                i += 1
            elif state[1] < len(cells):
                act = self.act(mask, cells[state[1]])
                state[1] += 1
                if act is not None:
                    made.append(act)
            else:
                self._lazy.pop(mask, None)
                self._actions.setdefault(mask, tuple(made))
                return

    def targets(self, mask: int, sa: SetAction) -> tuple[int, ...]:
        """Where each member of ``mask`` (ascending) goes under the range's representative."""
        key = (mask, sa.lo)
        t = self._targets.get(key)
        if t is None:
            rep = sa.representative
            t = tuple(successor(self.machine, i, rep) for i in members(mask))
            self._targets[key] = t
        return t

    def probability(self, branch: Branch, state: int) -> float:
        """Probability that ``state`` gives a reading in ``branch`` (see ``readings``)."""
        key = (branch.lo, branch.hi, state)
        p = self._prob.get(key)
        if p is None:
            p = reading_probability(
                self.machine.sensor, branch, self.machine.states[state].diameter
            )
            self._prob[key] = p
        return p

    def max_margin(self, mask: int) -> float:
        """Largest margin of any action of the set, ignoring the floor."""
        return max(sa.margin for sa in overlap_ranges(self.machine, mask))


def _order(a: Act) -> tuple[int, int]:
    """Search order: the smallest largest branch first, then the fewest states in all."""
    ch = a.children
    return (ch[0].bit_count(), sum(c.bit_count() for c in ch) if len(ch) > 1 else 0)


def _wider(a: tuple[float, float, int], b: tuple[float, float, int]) -> bool:
    """The wider cell first (larger margin), then the smaller representative rotation."""
    wa, wb = a[1] - a[0], b[1] - b[0]
    if wa != wb:
        return wa > wb
    return norm360((a[0] + a[1]) / 2.0) < norm360((b[0] + b[1]) / 2.0)
