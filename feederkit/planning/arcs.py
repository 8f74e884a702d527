"""Shortest sensorless chains of several push-function parts: A* over their arc hulls.

Where the readings carry nothing on a machine of several parts (:mod:`~feederkit.planning.
quiet`), a set's length is that of the shortest chain of rotations orienting every part at
once. Per part, a chain collapses a set of its states exactly when it collapses one of the
set's arc hulls (the circle minus one gap between neighbouring states; Goldberg 1993): the
push function is monotone, so the composed map sends an arc to the arc between its ends'
images, and when every state lands on one orientation the ends of the hull that starts past
the wrap land there too. An arc is its first state and its number of steps to its last (or
the whole circle), so the parts' arcs together are a state space of at most
``prod(k (k + 1))`` states for parts of ``k`` states up to symmetry, where the sets of states
are ``2 ** n``; a rotation changes an arc only where one of its ends crosses a resting-range
boundary, so the rotations worth trying are the cells between those crossings.

:class:`ArcSpace` runs A* over these states from every combination of the set's hulls, with
the largest of the parts' backchaining lengths as the heuristic (exact for one part,
consistent for several: one operation lowers each part's length by at most one), and so
gives the set's exact length and a chain of that length. Both landings of the random
1000-point outline at 3 % on the ideal model (two parts of 32 states): 26 operations after
the first alignment, proven, where A* over sets had proven 21 when the time ran out and the
widening beams had found 26.

References
----------
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10,
201-225 (arc hulls, backchaining).
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), section 4 (sensorless plans).
Hart, P. E., Nilsson, N. J. and Raphael, B. (1968). A formal basis for the heuristic
determination of minimum cost paths. IEEE Transactions on Systems Science and Cybernetics
4(2) (A*).
Pohl, I. (1970). Heuristic search viewed as path finding in a graph. Artificial
Intelligence 1(3-4), 193-204 (weighted A*).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from feederkit.angles import ANGLE_EPS
from feederkit.planning.andor import part_chains
from feederkit.planning.problem import Problem

ARC_STATES_MAX = 4_000_000
"""The arc search applies only where the parts' arcs together make at most this many states
(its tables hold one entry per state)."""

CHUNK = 256
"""The search expands up to this many states of its top bucket in one array pass."""

POLL_STATES = 16
"""The search polls its deadline once per this many states expanded: a poll then stands for
about as much work as one of the set searches' (a third of a millisecond), so the
tie-breaking stages' budget, a multiple of the proof's polls, means the same time."""

_EPS = 1e-9
"""Arc lengths (deg) below this are a point; above the period less this, the circle."""

_FAR = 10_000
"""The heuristic of an arc no chain collapses (never opened)."""

_UNSEEN = np.iinfo(np.int16).max
"""The depth of an arc state not yet reached."""


@dataclass(frozen=True)
class ArcPart:
    """One part's circle for the arc search: ``k`` states up to symmetry at positions
    ``pos`` (ascending from 0) on a circle of circumference ``period``, ``ends[c]`` the end of
    state ``c``'s resting range and ``start`` the start of state 0's, its backchaining table
    ``table`` (Goldberg's ``D_k``), and ``states[c]`` the machine's states of class ``c`` (a
    mask)."""

    k: int
    period: float
    pos: np.ndarray
    ends: np.ndarray
    start: float
    table: tuple[float, ...]
    states: tuple[int, ...]

    @property
    def arcs(self) -> int:
        """Arcs ``(a, m)``, numbered ``a * (k + 1) + m``: ``m`` steps from state ``a``
        (``m == k``: the whole circle)."""
        return self.k * (self.k + 1)

    def length_of(self, a: int, m: int) -> float:
        """The arc's length (deg)."""
        if m == 0:
            return 0.0
        if m >= self.k:
            return self.period
        return float((self.pos[(a + m) % self.k] - self.pos[a]) % self.period)

    def chain_length(self, length: float) -> float:
        """The fewest operations collapsing an arc of ``length`` (Goldberg's table)."""
        if length <= _EPS:
            return 0
        # As Backchain.length: the first D_j above the length (within ANGLE_EPS).
        j = int(np.searchsorted(np.asarray(self.table), length + ANGLE_EPS, side="left"))
        return j if j < len(self.table) else math.inf

    def push(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The push of orientations ``x`` (lifted): each one's state and its stable
        orientation on the lifted circle."""
        y = x - self.start
        turns = np.floor(y / self.period)
        c = np.searchsorted(self.ends - self.start, y - turns * self.period, side="right")
        c = np.minimum(c, self.k - 1)
        return c, self.pos[c] + turns * self.period


class _Table:
    """One part's arcs' moves (:meth:`ArcSpace._moves_of`) in flat arrays, filled as arcs
    are met: arc ``a``'s cut rotations are ``cuts[first[a]:first[a] + size[a]]`` and their
    images ``outs[...]`` (``first[a] < 0``: not made yet)."""

    def __init__(self, arcs: int) -> None:
        self.first = np.full(arcs, -1, dtype=np.int64)
        self.size = np.zeros(arcs, dtype=np.int64)
        self.cuts = np.empty(0)
        self.outs = np.empty(0, dtype=np.int64)
        self._used = 0

    def add(self, arcs: list[int], moves: Callable[[int], tuple[np.ndarray, np.ndarray]]) -> None:
        """Make the moves of ``arcs`` (none made yet), growing the arrays by doubling."""
        made = [moves(a) for a in arcs]
        need = self._used + sum(len(c) for c, _o in made)
        if need > len(self.cuts):
            grow = max(need, 2 * len(self.cuts))
            self.cuts = np.concatenate([self.cuts[: self._used], np.empty(grow - self._used)])
            self.outs = np.concatenate(
                [self.outs[: self._used], np.empty(grow - self._used, dtype=np.int64)]
            )
        for a, (c, o) in zip(arcs, made, strict=True):
            self.first[a], self.size[a] = self._used, len(c)
            self.cuts[self._used : self._used + len(c)] = c
            self.outs[self._used : self._used + len(c)] = o
            self._used += len(c)


class ArcSpace:
    """The arc states of a problem's parts and A* over them (module docstring).

    Built by :func:`arc_space`; :meth:`shortest_chain` answers one set.
    """

    def __init__(self, problem: Problem, parts: list[ArcPart], masks: list[int]) -> None:
        self.p = problem
        self.parts = parts
        self.masks = masks
        self.reached = 0
        """The least f-value the last :meth:`shortest_chain` left open."""
        self._tables: dict[int, _Table] = {}
        self._h = [
            np.array(
                [min(pt.chain_length(pt.length_of(a // (pt.k + 1), a % (pt.k + 1))), _FAR)
                 for a in range(pt.arcs)],
                dtype=np.int64,
            )
            for pt in parts
        ]  # fmt: skip

    def _moves_of(self, i: int, arc: int) -> tuple[np.ndarray, np.ndarray]:
        """Part ``i``'s arc under every rotation: the rotations (deg, ascending in
        [0, 360)) where its image changes, and the image from each to the next (the last
        to the first, past 360). Rotations act as ``x -> x + theta``; kept in the part's
        :class:`_Table`."""
        pt = self.parts[i]
        a, m = divmod(arc, pt.k + 1)
        u = float(pt.pos[a])
        length = pt.length_of(a, m)
        turns = round(360.0 / pt.period)
        ends = [u] if m == 0 else [u, u + length]
        cuts = np.concatenate(
            [((pt.ends - e) % pt.period)[None, :] + pt.period * np.arange(turns)[:, None]
             for e in ends]
        ).ravel() % 360.0  # fmt: skip
        cuts = np.unique(cuts)
        mids = (cuts + np.append(cuts[1:], cuts[0] + 360.0)) / 2.0
        c0, p0 = pt.push(u + mids)
        if m == 0:
            out = c0 * (pt.k + 1)
        else:
            c1, p1 = pt.push(u + length + mids)
            span = p1 - p0
            steps = np.where(
                span <= _EPS, 0, np.where(span >= pt.period - _EPS, pt.k, (c1 - c0) % pt.k)
            )
            out = c0 * (pt.k + 1) + steps
        return cuts, out.astype(np.int64)

    def _hulls(self, i: int, mask: int) -> list[int]:
        """The arcs of part ``i`` that are hulls of the set's states of that part."""
        pt = self.parts[i]
        present = sorted({c for c in range(pt.k) if mask & pt.states[c]})
        if len(present) == 1:
            return [present[0] * (pt.k + 1)]
        out = []
        for j, c in enumerate(present):
            first = present[(j + 1) % len(present)]  # the hull past the gap after c
            out.append(first * (pt.k + 1) + (c - first) % pt.k)
        return out

    def shortest_chain(
        self,
        mask: int,
        cap: int | None,
        check: Callable[[], None],
        floor: float = 0.0,
        weight: float = 1.0,
    ) -> list[list[tuple[float, float]]] | None:
        """A shortest chain orienting ``mask`` as the ranges of rotations of each operation,
        in the machine's convention (``(lo, hi)`` with ``0 <= lo < 360``, ``hi`` past 360
        when it wraps): those where the arcs go as the chain has them. Any rotation inside
        one will do, so each step may take any range of its set inside one (the arcs' ends
        are states of the set, so the set's ranges lie inside the arcs'). None: no
        chain within ``cap`` operations, or none at all. ``check`` is polled every
        ``POLL_STATES`` states expanded; ``reached`` is then the least f-value the search
        left open (a lower bound on the set's length), also when ``check`` raises.

        ``floor`` (deg): only ranges at least twice as wide. Where this finds no chain,
        no chain keeps every margin at least ``floor``; a chain found may keep less (its
        set's ranges can be narrower than the arcs'). Its tables hold a few bytes per arc
        state (``ARC_STATES_MAX`` of them at most).

        ``weight`` above 1: weighted A* (the heuristic times ``weight``), a chain at most
        that many times as long as the shortest, found sooner; ``reached`` and ``cap``
        then mean nothing (Pohl 1970).
        """
        parts = [i for i, part in enumerate(self.masks) if mask & part]
        sizes = [self.parts[i].arcs for i in parts]
        stride = [int(np.prod(sizes[j + 1 :], dtype=np.int64)) for j in range(len(parts))]
        total = int(np.prod(sizes, dtype=np.int64))
        best = np.full(total, _UNSEEN, dtype=np.int16)
        parent = np.full(total, -1, dtype=np.int32)
        # Open states in buckets by (f, -g): the least f first, the deepest among them (a
        # goal sooner); unit steps and integer lengths make the buckets few.
        buckets: dict[tuple[float, int], list[int]] = {}
        keys: list[tuple[float, int]] = []

        def push(f: float, g: int, codes: list[int]) -> None:
            key = (f, -g)
            bucket = buckets.get(key)
            if bucket is None:
                bucket = buckets[key] = []
                heapq.heappush(keys, key)
            bucket.extend(codes)

        def h_of(arcs: list[np.ndarray]) -> np.ndarray:
            out = self._h[parts[0]][arcs[0]]
            for j in range(1, len(parts)):
                out = np.maximum(out, self._h[parts[j]][arcs[j]])
            return out

        starts = np.zeros(1, dtype=np.int64)
        for j, i in enumerate(parts):
            hulls = np.asarray(self._hulls(i, mask), dtype=np.int64)
            starts = (starts[:, None] + hulls[None, :] * stride[j]).ravel()
        starts = np.unique(starts)
        best[starts] = 0
        start_h = h_of([(starts // stride[j]) % sizes[j] for j in range(len(parts))])
        for h in np.unique(start_h).tolist():
            if h < _FAR:
                push(weight * h, 0, starts[start_h == h].tolist())
        self.reached = 0
        expanded = 0
        while keys:
            key = keys[0]
            bucket = buckets[key]
            # The top bucket's last CHUNK states at once (one array pass each step); the
            # children may open a deeper bucket of the same f, asked first next round.
            codes = np.asarray(bucket[-CHUNK:], dtype=np.int64)
            del bucket[-CHUNK:]
            if not bucket:
                heapq.heappop(keys)
                del buckets[key]
            f, g = key[0], -key[1]
            codes = codes[best[codes] == g]
            if not len(codes):
                continue
            self.reached = max(self.reached, int(f))
            if cap is not None and f > cap:
                return None
            arcs = [(codes // stride[j]) % sizes[j] for j in range(len(parts))]
            if f == g:
                goal = self._goal_among(parts, arcs)
                if goal is not None:
                    return self._ranges(int(codes[goal]), parent, parts, stride, sizes, floor)
            for _ in range((expanded + len(codes)) // POLL_STATES - expanded // POLL_STATES):
                check()
            expanded += len(codes)
            nxt, source = self._expand(parts, arcs, stride, floor)
            fresh = best[nxt] > g + 1  # most were met no deeper: few are left
            nxt, source = nxt[fresh], source[fresh]
            if not len(nxt):
                continue
            nxt, first = np.unique(nxt, return_index=True)
            hs = h_of([(nxt // stride[j]) % sizes[j] for j in range(len(parts))])
            keep = hs < _FAR
            nxt, hs, first = nxt[keep], hs[keep], first[keep]
            best[nxt] = g + 1
            parent[nxt] = codes[source[first]]
            for h in np.unique(hs).tolist():
                push(g + 1 + weight * h, g + 1, nxt[hs == h].tolist())
        return None

    def _table(self, i: int, arcs: np.ndarray) -> _Table:
        """Part ``i``'s :meth:`_moves_of` end to end, with those of ``arcs`` made if new:
        only the arcs the search meets are made, as a part of many states has many."""
        table = self._tables.get(i)
        if table is None:
            table = self._tables[i] = _Table(self.parts[i].arcs)
        new = arcs[table.first[arcs] < 0]
        if len(new):
            table.add(np.unique(new).tolist(), lambda arc: self._moves_of(i, arc))
        return table

    def _expand(
        self, parts: list[int], arcs: list[np.ndarray], stride: list[int], floor: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_next` of many arc states at once (``arcs[j]``: part ``j``'s arc of each):
        the states one rotation leads to, repeats included, and the index of the state each
        comes from.

        Each state's cuts are keyed ``720 * index + cut``, so that one sort orders them by
        state, then by rotation; the keys only order (two cuts they could swap are closer
        than ``ANGLE_EPS``, a range no action takes), the widths come from the cuts."""
        count = len(arcs[0])
        base = 720.0 * np.arange(count)
        keys, cuts, outs, owners, heads, sizes = [], [], [], [], [], []
        for j, i in enumerate(parts):
            table = self._table(i, arcs[j])
            lo, size = table.first[arcs[j]], table.size[arcs[j]]
            part_cuts, part_outs = table.cuts, table.outs
            ends = np.cumsum(size)
            at = np.arange(int(ends[-1])) - np.repeat(ends - size - lo, size)
            owners.append(np.repeat(np.arange(count), size))
            cuts.append(part_cuts[at])
            keys.append(base[owners[-1]] + cuts[-1])
            outs.append(part_outs[at])
            heads.append(ends - size)
            sizes.append(size)
        order = np.argsort(np.concatenate(keys), kind="stable")
        src = np.repeat(np.arange(len(parts)), [len(c) for c in cuts])[order]
        owner = np.concatenate(owners)[order]
        cut = np.concatenate(cuts)[order]
        # Each state's ranges: from each cut to the next, its last to its first past 360.
        last = np.ones(len(owner), dtype=bool)
        last[:-1] = owner[1:] != owner[:-1]
        head = np.flatnonzero(np.concatenate(([True], last[:-1])))
        ends = np.empty_like(cut)
        ends[:-1] = cut[1:]
        ends[last] = cut[head] + 360.0
        wide = ends - cut > max(ANGLE_EPS, 2.0 * floor - 1e-12)
        mine = owner[wide]
        nxt = np.zeros(len(mine), dtype=np.int64)
        for j in range(len(parts)):
            # Part j's cuts up to each range's start in its state, less one: the image past
            # the last of them (none: the state's last, wrapping), as _next's search.
            seen = np.cumsum(src == j)
            before = np.concatenate(([0], seen))[head]
            k = (seen - before[owner])[wide] - 1
            k = np.where(k < 0, sizes[j][mine] - 1, k)
            nxt += outs[j][heads[j][mine] + k] * stride[j]
        return nxt, mine

    def _goal_among(self, parts: list[int], arcs: list[np.ndarray]) -> int | None:
        """The index of the first state among ``arcs`` (as in :meth:`_expand`) that is a
        goal (:meth:`_is_goal`), or None."""
        points = np.ones(len(arcs[0]), dtype=bool)
        for j, i in enumerate(parts):
            points &= arcs[j] % (self.parts[i].k + 1) == 0
        for n in np.flatnonzero(points).tolist():
            if self._is_goal(parts, [int(a[n]) for a in arcs]):
                return n
        return None

    def _next(
        self, parts: list[int], arcs: list[int], stride: list[int], floor: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The arc states one rotation leads to from ``arcs`` (one per range of rotations,
        repeats included), each range's start and width (deg, ``x -> x + theta``): the
        ranges between the arcs' ends' crossings, those no wider than ``ANGLE_EPS`` (no
        action, as in ``Choices.cells``) or narrower than ``2 * floor`` left out."""
        moves = []
        for i, a in zip(parts, arcs, strict=True):
            table = self._table(i, np.asarray([a]))
            span = slice(table.first[a], table.first[a] + table.size[a])
            moves.append((table.cuts[span], table.outs[span]))
        cuts = np.concatenate([c for c, _o in moves])
        cuts.sort()  # repeats make ranges of width 0, left out below
        ends = np.empty_like(cuts)
        ends[:-1] = cuts[1:]
        ends[-1] = cuts[0] + 360.0
        widths = ends - cuts
        wide = widths > max(ANGLE_EPS, 2.0 * floor - 1e-12)
        cuts, widths = cuts[wide], widths[wide]
        mids = cuts + widths * 0.5
        nxt = None
        for j, (c, o) in enumerate(moves):
            at = c.searchsorted(mids, "right") - 1  # -1: the last, wrapping
            term = o.take(at) * stride[j]
            nxt = term if nxt is None else nxt + term
        assert nxt is not None  # a set has a part
        return nxt, cuts, widths

    def _ranges(
        self,
        code: int,
        parent: np.ndarray,
        parts: list[int],
        stride: list[int],
        sizes: list[int],
        floor: float,
    ) -> list[list[tuple[float, float]]]:
        """The chain ending at ``code``, first step first: per step the ranges of rotations
        leading from its state to the next, in the machine's convention (a rotation by
        ``theta`` here is the machine's ``-theta``)."""
        path = [code]
        while parent[path[-1]] >= 0:
            path.append(int(parent[path[-1]]))
        path.reverse()
        out = []
        for here, there in zip(path, path[1:], strict=False):
            arcs = [(here // stride[j]) % sizes[j] for j in range(len(parts))]
            nxt, cuts, widths = self._next(parts, arcs, stride, floor)
            step = []
            for k in np.flatnonzero(nxt == there).tolist():
                lo = float((-(cuts[k] + widths[k])) % 360.0)
                step.append((lo, lo + float(widths[k])))
            out.append(step)
        return out

    def _is_goal(self, parts: list[int], arcs: list[int]) -> bool:
        """Whether every part's arc is a point and the points' states make a goal."""
        states = 0
        for i, arc in zip(parts, arcs, strict=True):
            pt = self.parts[i]
            a, m = divmod(int(arc), pt.k + 1)
            if m:
                return False
            states |= pt.states[a]
        return self.p.is_goal(states)


def arc_space(problem: Problem, chains=None) -> ArcSpace | None:
    """The arc search of ``problem`` given its parts' backchaining tables (``chains``, as
    :func:`~feederkit.planning.andor.part_chains` gives them; made here when not given), or
    None where it does not apply: a margin floor (asked first: a margin probe's problem
    makes no tables), some state in no part with a table, more than ``ARC_STATES_MAX`` arc
    states, or a goal relation that pairs some state with only some of another part's
    symmetric states (the goal of collapsed arcs is then not a product)."""
    if problem.min_margin != 0.0:
        return None
    if chains is None:
        chains = part_chains(problem)
    if not chains:
        return None
    covered = 0
    for part, _local, _chain in chains:
        covered |= part
    if covered != problem.full:
        return None
    parts: list[ArcPart] = []
    masks: list[int] = []
    total = 1
    for part, local, chain in chains:
        circle = chain.c
        k = circle.classes
        states = [0] * k
        for g, lo in local.items():
            states[circle.cls[lo]] |= 1 << g
        pos = np.asarray(circle.pos, dtype=np.float64)
        parts.append(
            ArcPart(
                k=k,
                period=circle.period,
                pos=pos,
                ends=pos + np.asarray(circle.right, dtype=np.float64),
                start=float(pos[0] - circle.left[0]),
                table=tuple(chain.table),
                states=tuple(states),
            )
        )
        masks.append(part)
        total *= k * (k + 1)
    if total > ARC_STATES_MAX:
        return None
    classes = [c for pt in parts for c in pt.states]
    for i in range(problem.n):
        row = problem.insep[i] | 1 << i
        if any(row & c and row & c != c for c in classes):
            return None
    return ArcSpace(problem, parts, masks)
