"""Sensorless planning (section 4): breadth-first search and Goldberg's backchaining.

Breadth-first search explores sets of states level by level from a set until a goal.

Backchaining (Goldberg 1993, for push functions; O(n) steps, Chen & Ierardi 1995) works on
the circle of orientations. The push function is monotone and maps arcs to arcs, so a plan
collapses a finite set of states exactly when it collapses one of the set's arc hulls (the
circle minus one gap between neighbouring states). With ``D_1`` the widest resting range
and ``D_{k+1}`` the longest arc whose push image (from the stable orientation of its first
range to that of its last) is shorter than ``D_k``, a closed arc of length ``L`` collapses
in ``k`` push-align operations iff ``L < D_k``. A part whose push function has period ``T``
is oriented up to that symmetry: the same recursion on the circle of circumference ``T``.

The circle is read off the machine's action maps (state ``i``'s range to ``j`` is
``(psi_i - rho_j, psi_i - lambda_j)``, definition 9), so hand-built machines work as long as
they are push functions; ``push_circle`` returns None otherwise.

References
----------
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10,
201-225 (the backchaining algorithm).
Chen, Y.-B. and Ierardi, D. J. (1995). The complexity of oblivious plans for orienting and
distinguishing polygonal parts. Algorithmica 14, 367-397 (the O(n) bound on its length).
Akella, S. and Mason, M. T. (1999), section 4 (sensorless plans on the push-align machine).
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.angles import ANGLE_EPS, norm360
from feederkit.machine import PushAlignMachine, bit_rows
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.problem import Problem

_TOL = 1e-6
"""Angles (deg) read off action maps agree within this."""


@dataclass(frozen=True)
class PushCircle:
    """A one-part push machine on the circle of circumference ``period`` (the push period).

    States ``order[c]`` (c < ``classes``) represent the symmetry classes; state ``i`` is in
    class ``cls[i]``; ``pos[c]`` is its stable orientation from the first class's, ``left[c]``
    and ``right[c]`` the extents of its resting range on either side.
    """

    period: float
    cls: tuple[int, ...]
    pos: tuple[float, ...]
    left: tuple[float, ...]
    right: tuple[float, ...]

    @property
    def classes(self) -> int:
        """Number of states up to symmetry."""
        return len(self.pos)


def _delta(a: float, b: float) -> float:
    """Signed difference a - b on the circle, in [-180, 180)."""
    return (a - b + 180.0) % 360.0 - 180.0


def push_circle(machine: PushAlignMachine, insep: tuple[int, ...]) -> PushCircle | None:
    """The circle of a one-part machine whose maps form a push function; None if they do not.

    Also None when the machine's inseparable pairs are not exactly the push symmetry classes.
    """
    n = machine.n
    if n == 0 or len({s.part for s in machine.states}) != 1 or not machine.deterministic:
        return None  # outcome sets: the arc images of backchaining are no longer exact
    maps = machine.action_maps
    to: list[dict[int, tuple[float, float]]] = []
    for i in range(n):
        d = {t: (r.lo, r.hi) for r, t in zip(maps[i], machine.targets[i], strict=True)}
        if len(d) != n or len(maps[i]) != n:
            return None
        to.append(d)
    rho = [norm360(-to[0][j][0]) for j in range(n)]
    lam = [norm360(-to[0][j][1]) for j in range(n)]
    psi = [norm360(to[i][i][0] + rho[i]) for i in range(n)]
    for i in range(n):
        for j in range(n):
            lo, hi = to[i][j]
            if abs(_delta(lo, psi[i] - rho[j])) > _TOL or abs(_delta(hi, psi[i] - lam[j])) > _TOL:
                return None
    order = sorted(range(n), key=lambda i: psi[i])
    left = [norm360(psi[i] - lam[i]) for i in order]
    right = [norm360(rho[i] - psi[i]) for i in order]
    ang = [psi[i] for i in order]
    shift = n
    for k in range(1, n):
        if n % k:
            continue
        t = norm360(ang[k] - ang[0])
        if all(
            abs(_delta(ang[(c + k) % n], ang[c] + t)) < _TOL
            and abs(left[(c + k) % n] - left[c]) < _TOL
            and abs(right[(c + k) % n] - right[c]) < _TOL
            for c in range(n)
        ):
            shift = k
            break
    period = 360.0 * shift / n
    cls = [0] * n
    for c, i in enumerate(order):
        cls[i] = c % shift
    for i in range(n):
        same = 0
        for j in range(n):
            if j != i and cls[j] == cls[i]:
                same |= 1 << j
        if same != insep[i]:
            return None
    pos = tuple(norm360(ang[c] - ang[0]) for c in range(shift))
    return PushCircle(period, tuple(cls), pos, tuple(left[:shift]), tuple(right[:shift]))


_NUMPY_HULL_MIN = 24
"""Sets with this many states or more get their hull from numpy (a Python loop below)."""


class Backchain:
    """Goldberg's backchaining table ``D_k`` and the minimum length of any set of states."""

    def __init__(self, circle: PushCircle) -> None:
        self.c = circle
        k = circle.classes
        t = circle.period
        # For each class c: the other classes in counter-clockwise order with the running
        # maximum of (arc + right extent), so the next D is a binary search per class.
        self._arcs: list[list[float]] = []
        self._best: list[list[float]] = []
        for a in range(k):
            arcs, best = [], []
            run = -math.inf
            for step in range(k):
                b = (a + step) % k
                arc = (circle.pos[b] - circle.pos[a]) % t if step else 0.0
                run = max(run, arc + circle.right[b])
                arcs.append(arc)
                best.append(run)
            self._arcs.append(arcs)
            self._best.append(best)
        d = [0.0, max(circle.left[a] + circle.right[a] for a in range(k))]
        while d[-1] <= t + ANGLE_EPS:
            nxt = max(
                circle.left[a]
                + self._best[a][bisect.bisect_left(self._arcs[a], d[-1] - ANGLE_EPS) - 1]
                for a in range(k)
            )
            if nxt <= d[-1] + ANGLE_EPS:
                break
            d.append(nxt)
        self.table = d
        self._state_pos = [circle.pos[c] for c in circle.cls]
        # The states in the order of their positions, for the vectorised hull of big sets.
        self._order = np.argsort(np.asarray(self._state_pos), kind="stable")
        self._sorted_pos = np.asarray(self._state_pos)[self._order]
        self._pos_list: list[float] = self._sorted_pos.tolist()
        # A set's bits renumbered by position, a byte at a time: bit r of the result is the
        # state of rank r (one table of 256 masks per byte of state numbers).
        rank = [0] * len(self._state_pos)
        for r, i in enumerate(self._order.tolist()):
            rank[i] = r
        self._rank_bytes: list[list[int]] = []
        for base in range(0, len(rank), 8):
            table = [0] * 256
            for byte in range(1, 256):
                low = byte & -byte
                state = base + low.bit_length() - 1
                table[byte] = table[byte ^ low] | (1 << rank[state] if state < len(rank) else 0)
            self._rank_bytes.append(table)
        self._lengths: dict[int, float] = {}

    def hull(self, mask: int) -> float:
        """Length of the shortest arc holding the set's classes (0: one class)."""
        t = self.c.period
        if mask.bit_count() >= _NUMPY_HULL_MIN:
            n = len(self._state_pos)
            raw = np.frombuffer(mask.to_bytes((n + 7) // 8, "little"), dtype=np.uint8)
            inside = np.unpackbits(raw, bitorder="little")[:n].astype(bool)
            at = self._sorted_pos[inside[self._order]]  # ascending; equal positions: gaps 0
            if at[-1] == at[0]:
                return 0.0
            gap = max(float(np.max(np.diff(at))), float(at[0] + t - at[-1]))
            return t - gap
        if not mask:
            return 0.0
        if mask >> len(self._state_pos):
            raise ValueError(f"the set {mask:#x} holds states the machine does not have")
        # The members in the order of their positions (bits renumbered by rank), then the
        # largest gap between neighbours on the circle.
        ranked = 0
        for table in self._rank_bytes:
            if not mask:
                break
            ranked |= table[mask & 255]
            mask >>= 8
        pos = self._pos_list
        low = ranked & -ranked
        first = prev = pos[low.bit_length() - 1]
        ranked ^= low
        gap = 0.0
        while ranked:
            low = ranked & -ranked
            at = pos[low.bit_length() - 1]
            ranked ^= low
            if at - prev > gap:
                gap = at - prev
            prev = at
        if prev == first:
            return 0.0
        return t - max(gap, first + t - prev)

    def length(self, mask: int) -> float:
        """Minimum number of operations collapsing the set (inf: never; memoised: plans
        built from the table ask for the same images many times)."""
        v = self._lengths.get(mask)
        if v is None:
            h = self.hull(mask)
            if h == 0.0:
                v = 0
            else:
                k = bisect.bisect_left(self.table, h + ANGLE_EPS)
                v = k if k < len(self.table) else math.inf
            self._lengths[mask] = v
        return v

    def lengths_of_sets(self, masks: Sequence[int]) -> np.ndarray:
        """:meth:`length` of each of ``masks`` as one float array (not memoised), by
        :meth:`lengths_of`: a step of :func:`~feederkit.planning.fallback.sensorless_plan`
        weighs every reading set of every rotation, a few hundred, where one at a time
        each cost a loop over its members.

        >>> chain = Backchain(PushCircle(360.0, (0, 1, 2), (0.0, 120.0, 240.0),
        ...                              (60.0,) * 3, (60.0,) * 3))
        >>> chain.lengths_of_sets([7, 5, 2]).tolist() == [chain.length(m) for m in (7, 5, 2)]
        True
        """
        return self.lengths_of(bit_rows(masks, len(self._state_pos)))

    def lengths_of(self, inside: np.ndarray) -> np.ndarray:
        """:meth:`length` of many sets at once (not memoised): ``inside`` holds a row per
        set and a column per state, True for its members. The same floats as
        :meth:`hull`, one array operation each: each member's gap from the member before
        it by position, the largest of them and the gap that wraps around the circle.

        >>> import numpy as np
        >>> from feederkit.planning.sensorless import PushCircle
        >>> chain = Backchain(PushCircle(360.0, (0, 1, 2), (0.0, 120.0, 240.0),
        ...                              (60.0,) * 3, (60.0,) * 3))
        >>> inside = np.array([[1, 1, 1], [1, 0, 1], [0, 1, 0]], dtype=bool)
        >>> chain.lengths_of(inside).tolist() == [chain.length(m) for m in (7, 5, 2)]
        True
        """
        t = self.c.period
        pos = self._sorted_pos
        m = inside[:, self._order]  # columns by position
        cols = np.arange(m.shape[1])
        last = np.maximum.accumulate(np.where(m, cols, -1), axis=1)
        prev = np.full_like(last, -1)
        prev[:, 1:] = last[:, :-1]  # the member before each column (-1: none)
        gaps = np.where(m & (prev >= 0), pos - pos[np.maximum(prev, 0)], 0.0)
        first = pos[np.argmax(m, axis=1)]
        end = pos[np.maximum(last[:, -1], 0)]
        hull = t - np.maximum(gaps.max(axis=1, initial=0.0), first + t - end)
        hull = np.where(end == first, 0.0, hull)
        k = np.searchsorted(np.asarray(self.table), hull + ANGLE_EPS, side="left")
        out = np.where(k < len(self.table), k, np.inf).astype(float)
        out[hull == 0.0] = 0.0
        return out


class BackchainWorst(WorstCase):
    """The worst-case oracle of a sensorless push machine, answered by backchaining."""

    def __init__(
        self, problem: Problem, chain: Backchain, deadline: Deadline | None = None
    ) -> None:
        super().__init__(problem, deadline)
        self.chain = chain

    def within(self, mask: int, k: int) -> bool:
        """Whether the set collapses in at most ``k`` operations."""
        return self.chain.length(mask) <= k

    def length(self, mask: int, limit: int | None = None) -> int:
        """Minimum number of operations for the set."""
        v = self.chain.length(mask)
        if v == math.inf:
            raise ValueError("the set cannot be oriented")
        return int(v)


def bfs_length(problem: Problem, mask: int, deadline: Deadline | None = None) -> int:
    """Minimum number of sensorless operations orienting ``mask``, by breadth-first search."""
    deadline = deadline or Deadline(None)
    if problem.is_goal(mask):
        return 0
    seen = {mask}
    frontier = deque([(mask, 0)])
    while frontier:
        deadline.check()
        cur, d = frontier.popleft()
        for act in problem.choices.search_actions(cur, deadline.limits):
            img = act.children[0]
            if problem.is_goal(img):
                return d + 1
            if img not in seen:
                seen.add(img)
                frontier.append((img, d + 1))
    raise ValueError("the set cannot be oriented")
