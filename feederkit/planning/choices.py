"""The representative actions of a set of states, for the planners (sections 3.2.2, 6.1).

A set's overlap ranges (one per distinct outcome, the widest, then the smallest rotation),
above a margin floor, each with the reading branches its image can leave.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from feederkit.angles import norm360
from feederkit.machine import OverlapRange, PushAlignMachine, members, search_space
from feederkit.planning.readings import Readings


@dataclass(frozen=True)
class Act:
    """A representative action of a set: its overlap range and the reading branches of its image.

    ``children`` are branch masks, largest first. In the length view (``Choices.actions``)
    only those no other branch contains: a subset of a set is oriented by the set's
    rotations in no more operations, so only these decide the worst-case length. In the
    exact view (``Choices.exact_actions``) all of them.
    """

    action: OverlapRange
    children: tuple[int, ...]

    @property
    def rotation(self) -> float:
        """The rotation a plan uses (deg, [0, 360))."""
        return self.action.representative


class Choices:
    """The actions of the sets a search meets, cached per set.

    ``actions(mask)`` (the length view) keeps only useful actions: one per distinct
    outcome (largest margin, then smallest rotation), none leaving a reading whose set
    contains ``mask`` (it cannot shorten a plan: a subset of a solvable set is solvable in
    no more steps, using the same rotations). ``exact_actions(mask)`` keeps them all.
    """

    def __init__(
        self,
        machine: PushAlignMachine,
        readings: Readings,
        min_margin: float = 0.0,
        distinct_maps: bool = False,
    ) -> None:
        self.machine = machine
        self.readings = readings
        self.min_margin = min_margin
        self.distinct_maps = distinct_maps
        self._space = search_space(machine)
        self._cells: dict[tuple[int, bool], list[tuple[float, float, int]]] = {}
        self._actions: dict[int, tuple[Act, ...]] = {}
        self._exact: dict[int, tuple[Act, ...]] = {}
        self._lazy: dict[int, list] = {}
        self._targets: dict[tuple[int, float], tuple[int, ...]] = {}

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
        for cell in self._space.overlap_cells(mask):
            lo, hi, img = cell
            if hi - lo < floor:
                continue
            key: object = img
            if self.distinct_maps:
                key = self.targets(mask, OverlapRange(lo, hi, img))
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
        sa = OverlapRange(lo, hi, img)
        if self.readings.sensorless:
            return Act(sa, (img,))
        if exact:
            return Act(sa, self.readings.all_children(img))
        children = self.readings.children(img)
        if any(c & mask == mask for c in children):
            return None
        return Act(sa, children)

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

    def targets(self, mask: int, sa: OverlapRange) -> tuple[int, ...]:
        """Where each member of ``mask`` (ascending) can go under the range's representative:
        its outcome set, a mask (one bit in the ideal model)."""
        key = (mask, sa.lo)
        t = self._targets.get(key)
        if t is None:
            rep = sa.representative
            t = tuple(self.machine.outcomes(i, rep) for i in members(mask))
            self._targets[key] = t
        return t


def spread(masses, outcomes) -> dict[int, float]:
    """Each member's mass moved to its outcome set, shared equally among its outcomes."""
    moved: dict[int, float] = {}
    for w, out in zip(masses, outcomes, strict=True):
        if out & (out - 1) == 0:
            t = out.bit_length() - 1
            moved[t] = moved.get(t, 0.0) + w
            continue
        ts = members(out)
        share = w / len(ts)
        for t in ts:
            moved[t] = moved.get(t, 0.0) + share
    return moved


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
