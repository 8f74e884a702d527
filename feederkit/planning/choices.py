"""The representative actions of a set of states, for the planners (sections 3.2.2, 6.1).

A set's overlap ranges (one per distinct outcome, the widest, then the smallest rotation),
above a margin floor, each with the reading branches its image can leave.

The ranges a plan rotates in are **cells** (:func:`~feederkit.angles.boundary_cells`): the
open intervals between consecutive action-range boundaries of the set's members
(boundaries within ``ANGLE_EPS`` grouped as :func:`~feederkit.angles.merge_boundaries`
groups them), over which every member keeps one outcome (one outcome set under
uncertainty). A cell's middle is the representative and its half-width the margin, so the
representative is at least the margin from every boundary of every member: in the ideal
model each member's turned fence orientation is at least the margin from every divergent
orientation (section 3.1: a part pushed exactly at one never settles); under uncertainty
no member's outcome set changes within the margin. Neighbouring cells with the same image
are not joined, since the boundary between them is some member's.

Cells no wider than ``ANGLE_EPS`` (1e-7 deg) are never used: no robot holds such a
rotation, and rebuilding the push function moves boundaries by about 1e-12 deg. Every
wider cell is offered, so the planners' lengths are optimal among plans whose rotations
all keep a margin above ``ANGLE_EPS / 2`` (docs/conventions.md); a shorter plan may exist
only through narrower cells.
"""

from __future__ import annotations

import bisect
import itertools
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from feederkit.angles import ANGLE_EPS, cells_between, norm360, width_key
from feederkit.machine import OverlapRange, PushAlignMachine, members, search_space
from feederkit.planning.readings import Readings

Poll = Callable[[], None]
"""A deadline's ``check``: raises Timeout once the time or memory is out."""

POLL_CELLS = 32
"""A set's actions or branch keys made one at a time poll the caller's deadline once per
this many (each a split of an image's reading branches)."""

_DOMINATORS = 8
"""The length view tests an image against this many smaller ones for dominance."""
_NUMPY_MIN_BOUNDS = 256
"""Sets with at least this many action-range boundaries get their cells from numpy."""


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
        self._fixed: dict[int, list[tuple[float, float, int]]] = {}
        self._branch_keys: dict[int, tuple[int, int]] = {}

    def fixed_cells(self, mask: int) -> list[tuple[float, float, int]]:
        """The set's cells as ``(lo, hi, image)``, in angular order (cached; see the module).

        The :func:`~feederkit.angles.boundary_cells` of the members' action-range
        boundaries: no member's boundary lies inside one, none is ``ANGLE_EPS`` wide or
        less. The image is that of the search space's overlap range holding the cell
        (those ranges tile the circle and end on boundaries).
        """
        hit = self._fixed.get(mask)
        if hit is not None:
            return hit
        starts = self.machine.starts  # each in [0, 360), ascending
        ranges = sorted(
            (norm360(lo), norm360(lo) + (hi - lo), img)
            for lo, hi, img in self._space.overlap_cells(mask)
        )
        los = [r[0] for r in ranges]
        idx = members(mask)
        count = sum(len(starts[i]) for i in idx)
        if count >= _NUMPY_MIN_BOUNDS:
            b = np.sort(np.fromiter(itertools.chain.from_iterable(starts[i] for i in idx), float))
            lo = b
            hi = np.append(b[1:], b[0] + 360.0)
            keep = hi - lo > ANGLE_EPS
            lo, hi = lo[keep], hi[keep]
            mid = (lo + hi) / 2.0
            mid = np.where(mid >= 360.0, mid - 360.0, mid)
            at = np.searchsorted(np.asarray(los), mid, side="right") - 1
            out = [
                (a, z, ranges[k][2])
                for a, z, k in zip(lo.tolist(), hi.tolist(), at.tolist(), strict=True)
            ]
        else:
            bounds = sorted(itertools.chain.from_iterable(starts[i] for i in idx))
            out = []
            for a, z in cells_between(bounds):
                x = (a + z) / 2.0
                x = x - 360.0 if x >= 360.0 else x
                k = bisect.bisect_right(los, x) - 1  # -1: the last range, which wraps past 360
                out.append((a, z, ranges[k][2]))
        self._fixed[mask] = out
        return out

    def cell_at(self, mask: int, x: float) -> tuple[float, float, int] | None:
        """The cell of :meth:`fixed_cells` holding the rotation ``x`` (in [0, 360)) strictly
        inside, from the members' boundaries alone (no cell table of the set); None when
        ``x`` lies on a boundary or in no cell wider than ``ANGLE_EPS``.

        A set's cell around a rotation is bounded by the nearest boundary of any member on
        each side, and its image is the members' outcomes there (constant inside a cell).
        For a subset of a set whose cell holds ``x`` this costs a bisection per member
        instead of the subset's whole cell table (``Refiner.follow``).
        """
        starts = self.machine.starts
        idx = members(mask)
        lo = hi = None
        wrap_lo, wrap_hi = -1.0, 720.0
        for i in idx:
            s = starts[i]
            k = bisect.bisect_right(s, x)
            if k > 0:
                if s[k - 1] == x:
                    return None
                if lo is None or s[k - 1] > lo:
                    lo = s[k - 1]
            nxt = s[k] if k < len(s) else s[0] + 360.0
            if hi is None or nxt < hi:
                hi = nxt
            wrap_lo, wrap_hi = max(wrap_lo, s[-1]), min(wrap_hi, s[0] + 360.0)
        if lo is None:  # before every boundary: the cell that wraps past 360
            lo, hi = wrap_lo, wrap_hi
        if hi is None or hi - lo <= ANGLE_EPS:
            return None
        img = 0
        for t in self._outcomes_at(mask, x):
            img |= t
        return (lo, hi, img)

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
        if not self.distinct_maps:
            listed = self._space.cell_lists(mask)
            if listed is not None:
                return self._keep_cells(mask, useful, _widest_per_image(*listed, floor))
        fast = None if self.distinct_maps else self._space.cells_and_images(mask)
        if fast is not None:
            # The same cells and images as fixed_cells, from the machine's cell table.
            los, his, imgs = fast
            keep = np.flatnonzero(his - los >= floor)
            kept = [imgs[k] for k in keep.tolist()]
            return self._keep_cells(mask, useful, _widest_cells(los[keep], his[keep], kept))
        for cell in self.fixed_cells(mask):
            lo, hi, img = cell
            if hi - lo < floor:
                continue
            key: object = img
            if self.distinct_maps:
                key = self.targets(mask, OverlapRange(lo, hi, img))
            old = best.get(key)
            if old is None or _wider(cell, old):
                best[key] = cell
        keyed = [
            (-width_key(hi - lo), norm360((lo + hi) / 2.0), img, lo, hi)
            for lo, hi, img in best.values()
        ]
        keyed.sort()
        return self._keep_cells(mask, useful, [(lo, hi, img) for _w, _r, img, lo, hi in keyed])

    def _keep_cells(
        self, mask: int, useful: bool, cells: list[tuple[float, float, int]]
    ) -> list[tuple[float, float, int]]:
        """Cache the set's cells and its useful ones (without those whose image contains
        the set); return the kind asked for."""
        self._cells[(mask, False)] = cells
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

    def exact_actions(self, mask: int, check: Poll | None = None) -> tuple[Act, ...]:
        """Every action of the set above the margin floor with all its branch sets (cached).

        The margin of a merged overlap range holds for the set but not for its subsets (a
        subset's image can change inside it where the set's does not), so margins and
        margin floors are not monotone under subsets: the stages that depend on margins
        use this exact view. ``check`` (a deadline's) is polled every ``POLL_CELLS``
        actions made: a set of hundreds of states has thousands.
        """
        acts = self._exact.get(mask)
        if acts is None:
            made = []
            for n, c in enumerate(self.cells(mask, useful=False)):
                if check is not None and n % POLL_CELLS == POLL_CELLS - 1:
                    check()
                made.append(self.act(mask, c, exact=True))
            acts = self._exact[mask] = tuple(made)  # type: ignore[assignment]
        return acts  # type: ignore[return-value]

    def search_actions(self, mask: int, check: Poll | None = None) -> Iterator[Act]:
        """The actions the length search uses: the length view when lengths are monotone
        under subsets (no margin floor), else the exact view; ``check`` as in
        :meth:`useful_cells` and :meth:`exact_actions`."""
        if self.min_margin == 0.0:
            return self.lazy_actions(mask, check)
        return iter(self.exact_actions(mask, check))

    def actions(self, mask: int) -> tuple[Act, ...]:
        """Useful representative actions of a set (``lazy_actions``, all made; cached)."""
        acts = self._actions.get(mask)
        if acts is None:
            for _ in self.lazy_actions(mask):
                pass
            acts = self._actions[mask]
        return acts

    def lazy_actions(self, mask: int, check: Poll | None = None) -> Iterator[Act]:
        """The length view's actions, made only as far as a search consumes them.

        In :meth:`useful_cells`'s order (the smallest largest reading branch first): the
        search usually succeeds, or fails at a memoised depth, long before the last one.
        ``check`` as in :meth:`useful_cells`.
        """
        done = self._actions.get(mask)
        if done is not None:
            yield from done
            return
        state = self._lazy.get(mask)
        if state is None:
            state = self._lazy[mask] = [iter(self.useful_cells(mask, check)), []]
        cells, made = state
        i = 0
        while True:
            if i < len(made):
                yield made[i]
                i += 1
                continue
            cell = next(cells, None)
            if cell is None:
                self._lazy.pop(mask, None)
                self._actions.setdefault(mask, tuple(made))
                return
            made.append(self.useful_act(cell))

    def branch_sets(self, mask: int, check: Poll | None = None) -> set[tuple[int, ...]]:
        """The distinct branch tuples of the actions :meth:`search_actions` offers,
        unordered: what a pass over every action of a set needs
        (:func:`~feederkit.planning.solvable.solve`), from the images alone, without ranking
        the cells or making the actions.

        In the length view an image holding one of the ``_DOMINATORS`` smallest useful
        images (by size, then value: the same tuples whatever is cached) is left out, as
        :meth:`useful_cells` leaves such images out (its dominators picked by size, then
        width, so the two may leave out different actions): its action needs no fewer
        operations, so a set's length is the same either way. The images are the same with
        ``distinct_maps`` (which keeps one cell per map of the members, not per image).
        ``check`` is polled every ``POLL_CELLS`` reading splits, as in :meth:`useful_cells`.
        """
        if self.min_margin > 0.0:
            return {a.children for a in self.exact_actions(mask, check)}
        images: list[int] | None = None
        if (mask, True) not in self._cells:
            listed = self._space.cell_lists(mask)
            if listed is not None:
                images = listed[2]
            else:
                fast = self._space.cells_and_images(mask)
                if fast is not None:
                    images = fast[2]
        if images is None:
            images = [c[2] for c in self.cells(mask)]
        useful = sorted(
            {img for img in images if img & mask != mask}, key=lambda i: (i.bit_count(), i)
        )
        kept: list[int] = []
        out: set[tuple[int, ...]] = set()
        sensorless = self.readings.sensorless
        for n, img in enumerate(useful):
            if _holds_one(img, kept):
                continue
            if len(kept) < _DOMINATORS:
                kept.append(img)
            if check is not None and n % POLL_CELLS == POLL_CELLS - 1:
                check()
            out.add((img,) if sensorless else self.readings.children(img))
        return out

    def useful_act(self, cell: tuple[float, float, int]) -> Act:
        """The length view's action of one of :meth:`useful_cells`: its maximal reading
        branches (none holds the set: each lies inside the image, which does not)."""
        img = cell[2]
        return Act(
            OverlapRange(*cell), (img,) if self.readings.sensorless else self.readings.children(img)
        )

    def useful_cells(self, mask: int, check: Poll | None = None) -> list[tuple[float, float, int]]:
        """The cells of :meth:`lazy_actions`, ranked before any action is made: a caller
        that ranks them makes only the actions it keeps (:meth:`useful_act`).

        Ordered by :func:`search_key` (the smallest largest branch, then the fewest states
        over all branches: the likeliest to succeed; then the smallest image, the widest).
        A cell whose image contains one of the first ``_DOMINATORS`` images (smallest
        first) is left out (dominated): the branches of a subset lie inside the
        branches of the set (each reading cell, or component, restricted), and a subset
        needs no more operations; testing against every earlier image costs more than it
        saves on sets with hundreds of ranges. No cell's image holds the set
        (:meth:`cells`), so no branch does. The branch keys come from the readings' windows
        for every cell at once where they apply (``Readings.branch_keys``), else per image,
        a split of its reading branches each, ``check`` (a deadline's) polled every
        ``POLL_CELLS`` of them: under the components rule the largest root of a 200-part
        mix at 0.5 % has 4,013 cells, 4.6 s of splits.
        """
        cells = sorted(self.cells(mask), key=lambda c: (c[2].bit_count(), c[0] - c[1]))
        kept: list[int] = []
        undominated: list[tuple[float, float, int]] = []
        for cell in cells:
            img = cell[2]
            if _holds_one(img, kept):  # sorted by size: only an earlier image lies inside
                continue
            if len(kept) < _DOMINATORS:
                kept.append(img)
            undominated.append(cell)
        keys = None
        if not self.readings.sensorless:
            keys = self.readings.branch_keys([c[2] for c in undominated])
        if keys is None:
            keys = []
            for n, c in enumerate(undominated):
                if check is not None and n % POLL_CELLS == POLL_CELLS - 1:
                    check()
                keys.append(self.branch_key(c[2]))
        ranked = sorted(
            ((*key, c[2].bit_count(), c[0] - c[1]), n)
            for n, (key, c) in enumerate(zip(keys, undominated, strict=True))
        )
        return [undominated[n] for _key, n in ranked]

    def search_key(self, cell: tuple[float, float, int]) -> tuple[int, int, int, float]:
        """:func:`search_key` of a cell with its image's maximal branches (the image itself
        without a sensor), their :func:`children_key` cached per image."""
        return (*self.branch_key(cell[2]), cell[2].bit_count(), cell[0] - cell[1])

    def branch_key(self, img: int) -> tuple[int, int]:
        """:func:`children_key` of an image's maximal branches (the image itself without a
        sensor), cached per image."""
        key = self._branch_keys.get(img)
        if key is None:
            children = (img,) if self.readings.sensorless else self.readings.children(img)
            key = self._branch_keys[img] = children_key(children)
        return key

    def targets(self, mask: int, sa: OverlapRange) -> tuple[int, ...]:
        """Where each member of ``mask`` (ascending) can go under the range's representative:
        its outcome set, a mask (one bit in the ideal model)."""
        return self.targets_at(mask, sa.lo, sa.representative)

    def targets_at(self, mask: int, lo: float, rotation: float) -> tuple[int, ...]:
        """:meth:`targets` of the set's cell that begins at ``lo``, ``rotation`` its
        representative (cached per set and cell)."""
        key = (mask, lo)
        t = self._targets.get(key)
        if t is None:
            t = self._targets[key] = self._outcomes_at(mask, rotation)
        return t

    def _outcomes_at(self, mask: int, x: float) -> tuple[int, ...]:
        """Each member's outcome set (a mask) under the rotation ``x``: from the search
        space's table when it has one, else from the machine."""
        row = self._space.target_masks_at(mask, x)
        if row is not None:
            return row
        return tuple(self.machine.outcomes(i, x) for i in members(mask))


def children_key(children: tuple[int, ...]) -> tuple[int, int]:
    """The search order of an action with these reading branches: the smallest largest
    branch, then the fewest states over all branches (the most a reading tells apart).

    >>> children_key((0b0111, 0b1000)), children_key((0b0011, 0b0110))
    ((3, 4), (2, 4))
    """
    sizes = [c.bit_count() for c in children]
    return max(sizes), sum(sizes)


def search_key(
    cell: tuple[float, float, int], children: tuple[int, ...]
) -> tuple[int, int, int, float]:
    """The length search's order of a set's cells (``Choices.useful_cells``):
    :func:`children_key` of the cell's reading branches, then the smallest image, then the
    widest."""
    return (*children_key(children), cell[2].bit_count(), cell[0] - cell[1])


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


def _holds_one(img: int, kept: list[int]) -> bool:
    """Whether the image ``img`` holds one of the images ``kept`` (a loop, not ``any()``: the
    dominance test is a large part of a pass over a set's actions)."""
    for k in kept:  # noqa: SIM110 (a generator costs more here)
        if k & img == k:
            return True
    return False


def _widest_per_image(
    los: list[float], his: list[float], imgs: list[int], floor: float
) -> list[tuple[float, float, int]]:
    """:meth:`Choices.cells` from a set's cells as lists (``SearchSpace.cell_lists``): the
    widest cell of each image at least ``floor`` wide (then the smaller rotation), widest
    first; the same steps as its numpy path, one cell at a time."""
    keys = [
        (-width_key(hi - lo), k)
        for k, (lo, hi) in enumerate(zip(los, his, strict=True))
        if hi - lo >= floor
    ]
    keys.sort()
    if all(a[0] < b[0] for a, b in itertools.pairwise(keys)):
        # No two widths alike: the first cell of each image is its widest, in final order.
        seen: set[int] = set()
        out = []
        for _w, k in keys:
            img = imgs[k]
            if img not in seen:
                seen.add(img)
                out.append((los[k], his[k], img))
        return out
    # Per image the wider cell, then the smaller rotation (_wider), the first of equals.
    best: dict[int, tuple[int, float, int, float, float]] = {}
    for w, k in keys:
        lo, hi, img = los[k], his[k], imgs[k]
        entry = (w, norm360((lo + hi) / 2.0), img, lo, hi)
        old = best.get(img)
        if old is None or entry[:2] < old[:2]:
            best[img] = entry
    keyed = sorted(best.values())
    return [(lo, hi, img) for _w, _r, img, lo, hi in keyed]


def _widest_cells(
    lo: np.ndarray, hi: np.ndarray, imgs: list[int]
) -> list[tuple[float, float, int]]:
    """:meth:`Choices.cells` from a set's cells as arrays, vectorised: per image the wider
    cell, then the smaller representative rotation (:func:`_wider`), the first of equals;
    widest first, then the smaller rotation. The same floats as :func:`~feederkit.angles.width_key`
    and :func:`~feederkit.angles.norm360` of each cell, one array operation each."""
    wkey = np.rint((hi - lo) * 1e9)
    mid = np.fmod((lo + hi) / 2.0, 360.0) + 0.0
    mid = np.where(mid < 0.0, mid + 360.0, mid)
    mid = np.where(mid >= 360.0 - 1e-12, 0.0, mid)
    ids: dict[int, int] = {}
    group = np.fromiter((ids.setdefault(img, len(ids)) for img in imgs), np.intp, len(imgs))
    order = np.lexsort((mid, -wkey, group))  # stable: the first of equals stays first
    first = np.ones(len(order), dtype=bool)
    first[1:] = group[order[1:]] != group[order[:-1]]
    best = order[first]
    best = best[np.lexsort((mid[best], -wkey[best]))]
    lo_l, hi_l = lo[best].tolist(), hi[best].tolist()
    return [(a, z, imgs[k]) for a, z, k in zip(lo_l, hi_l, best.tolist(), strict=True)]


def _wider(a: tuple[float, float, int], b: tuple[float, float, int]) -> bool:
    """The wider cell first (larger margin), then the smaller representative rotation."""
    wa, wb = width_key(a[1] - a[0]), width_key(b[1] - b[0])
    if wa != wb:
        return wa > wb
    return norm360((a[0] + a[1]) / 2.0) < norm360((b[0] + b[1]) / 2.0)
