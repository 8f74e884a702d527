"""The planning problem: a push-align machine compiled for fast search over sets of states.

States are bit masks (section 3.3: a node of the search holds the set of states consistent
with the operations so far). For each set the problem lists its representative actions
(the overlap ranges of section 3.2.2, keeping those with at least ``min_margin``), each with
the sets of states the reading can leave (``branches``, section 6.1). Everything is cached
per set, so every planner on the same problem shares the work.
"""

from __future__ import annotations

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
from feederkit.sensors import Grouping, NoSensor


@dataclass(frozen=True)
class Act:
    """A representative action of a set: its overlap range and the reading branches of its image.

    ``children`` are the branch masks that no other branch contains, largest first: a
    subset of a set is oriented by the set's plan, in no more operations and with no
    smaller margins, so only these decide the worst case.
    """

    action: SetAction
    children: tuple[int, ...]

    @property
    def rotation(self) -> float:
        """The rotation a plan uses (deg, [0, 360))."""
        return self.action.representative


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

    ``actions(mask)`` keeps only useful actions: one per distinct outcome (largest margin,
    then smallest rotation), none leaving a reading whose set contains ``mask`` (it cannot
    shorten a plan: a subset of a solvable set is solvable in no more steps).
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
        self.sep = tuple(
            self.full & ~self.insep[i] & ~(1 << i) for i in range(self.n)
        )
        self.sensorless = isinstance(machine.sensor, NoSensor) or all(
            b.mask == self.full for b in branches(machine, self.full, "exact")
        )
        self._actions: dict[int, tuple[Act, ...]] = {}
        self._branches: dict[int, tuple[Branch, ...]] = {}
        self._goal: dict[int, bool] = {}
        self._maximal: dict[int, tuple[int, ...]] = {}
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
        self._cells: dict[int, list[tuple[float, float, int]]] = {}
        self._targets: dict[tuple[int, float], tuple[int, ...]] = {}
        self._prob: dict[tuple[float | None, float | None, int], float] = {}

    def with_margin(self, min_margin: float) -> Problem:
        """The same problem keeping only actions with at least ``min_margin``."""
        return Problem(self.machine, self.grouping, min_margin, self.insep, self.distinct_maps)

    def act_branches(self, act: Act) -> tuple[Branch, ...]:
        """Every reading branch after ``act`` (no sensor: the one image, no reading)."""
        if isinstance(self.machine.sensor, NoSensor):
            return (Branch(None, None, act.action.image),)
        return self.branches(act.action.image)

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

    def cells(self, mask: int) -> list[tuple[float, float, int]]:
        """The set's useful overlap ranges as ``(lo, hi, image)``, widest first (cached).

        One per distinct image (or per distinct map of the members, with
        ``distinct_maps``): the widest, then the smallest rotation. Ranges narrower than
        twice the margin floor, and ranges whose image contains the set, are dropped.
        """
        cells = self._cells.get(mask)
        if cells is not None:
            return cells
        best: dict[object, tuple[float, float, int]] = {}
        floor = 2.0 * self.min_margin
        for cell in overlap_cells(self.machine, mask):
            lo, hi, img = cell
            if hi - lo < floor or img & mask == mask:
                continue
            key: object = img
            if self.distinct_maps:
                key = self.targets(mask, SetAction(lo, hi, img))
            old = best.get(key)
            if old is None or _wider(cell, old):
                best[key] = cell
        cells = sorted(best.values(), key=lambda c: (c[0] - c[1], norm360((c[0] + c[1]) / 2.0)))
        self._cells[mask] = cells
        return cells

    def act(self, mask: int, cell: tuple[float, float, int]) -> Act | None:
        """The action of one cell with its branches; None when a branch contains the set."""
        lo, hi, img = cell
        sa = SetAction(lo, hi, img)
        if self.sensorless:
            return Act(sa, (img,))
        children = self.children(img)
        if any(c & mask == mask for c in children):
            return None
        return Act(sa, children)

    def children(self, image: int) -> tuple[int, ...]:
        """The maximal reading branches of an image (cached); see :class:`Act`."""
        out = self._maximal.get(image)
        if out is None:
            if self._cell_masks is not None:
                out = maximal_sets(self._restricted_cells(image))
            else:
                out = maximal_sets(b.mask for b in self.branches(image))
            self._maximal[image] = out
        return out

    def _restricted_cells(self, image: int) -> set[int]:
        """The image's states in each reading cell of the whole machine that meets it.

        With exact branching a subset's branches are the whole machine's cells restricted
        to it, so the cells are computed once (``_cell_masks``); each state's cells form a
        run ``_cell_span[i]``.
        """
        cm = self._cell_masks
        out = set()
        m = image
        while m:
            low = m & -m
            a, b = self._cell_span[low.bit_length() - 1]
            for c in range(a, b):
                out.add(cm[c] & image)
            m ^= low
        return out

    def actions(self, mask: int) -> tuple[Act, ...]:
        """Useful representative actions of a set (``cells``), most promising first (cached)."""
        acts = self._actions.get(mask)
        if acts is not None:
            return acts
        out = [a for a in (self.act(mask, c) for c in self.cells(mask)) if a is not None]
        out.sort(
            key=lambda a: (
                a.children[0].bit_count(),
                sum(c.bit_count() for c in a.children),
                -a.action.margin,
                a.rotation,
            )
        )
        acts = tuple(out)
        self._actions[mask] = acts
        return acts

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
            p = reading_probability(self.machine.sensor, branch, self.machine.states[state].diameter)
            self._prob[key] = p
        return p

    def max_margin(self, mask: int) -> float:
        """Largest margin of any action of the set, ignoring the floor."""
        return max(sa.margin for sa in overlap_ranges(self.machine, mask))


def _wider(a: tuple[float, float, int], b: tuple[float, float, int]) -> bool:
    """The wider cell first (larger margin), then the smaller representative rotation."""
    wa, wb = a[1] - a[0], b[1] - b[0]
    if wa != wb:
        return wa > wb
    return norm360((a[0] + a[1]) / 2.0) < norm360((b[0] + b[1]) / 2.0)
