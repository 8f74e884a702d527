"""The goal of a plan: inseparable states, a greatest fixpoint over pairs (sections 3.3, 8.4).

Two states are *inseparable* when no plan can ever either merge them into one state or tell
them apart by a reading: the greatest fixpoint of "their readings can agree, and every
action sends them to two different states that are again inseparable". The relation holds
between symmetric poses of one part (definitions 3, 8) and between states of parts with the
same push-diameter function (Lemma 8). A set of states is oriented (a goal) when every pair
in it is inseparable; a plan then reports all of them as correct answers. The same
fixpoint, over the cross pairs of two parts, decides whether two parts are distinguishable
(definition 11, :mod:`feederkit.mix.pairs`).

Under uncertainty an action sends a state to a *set* of states (nature picks). Two states are
then inseparable when they are *bisimilar*: their readings can agree, and for every action
every outcome of the one is matched by a *different* outcome of the other that is again
inseparable from it, and vice versa (the greatest such relation). Nature can then mirror any
run of the one by a run of the other, reading alike at every step and never merging, so no
strong plan can tell them apart or merge them: the relation is sound. With single outcomes it
is exactly the fixpoint above; symmetric poses of one part (whose outcome sets are rotated
copies) and Lemma 8 twins stay inseparable. docs/planning.md ("Strong plans") says more.

Nature can also keep two states *apart* without mirroring every run: their readings can
agree, they are not a goal together, and for every action *some* outcome of the one and
*some* different outcome of the other are again kept apart (:func:`kept_apart`, the
greatest such relation inside a set of pairs). Nature then keeps both in every reading set a
plan meets, so no strong plan orients a set holding such a pair: the cheap proof of
unresolvable pairs (:mod:`feederkit.planning.lumping`) and of "no strong plan exists"
(:mod:`feederkit.planning.solvable`).
"""

from __future__ import annotations

import bisect
import math
from collections import defaultdict
from collections.abc import Callable, Hashable, Iterable, Sequence
from typing import TypeVar

import numpy as np

from feederkit.angles import ANGLE_EPS, merge_boundaries, norm360
from feederkit.machine.model import PushAlignMachine, members, target_at
from feederkit.sensors import span

P = TypeVar("P", bound=Hashable)

Check = Callable[[], None]
"""A budget's poll (``Deadline.check`` of :mod:`feederkit.planning.budget`): raises to stop."""


def _no_check() -> None:
    return None


def prune_pairs(
    alive: set[P], dead: list[P], preds: dict[P, list[P]], check: Check = _no_check
) -> None:
    """The worklist step of a greatest fixpoint over state pairs, in place.

    Removes the ``dead`` pairs from ``alive`` and, transitively, every alive pair that some
    action sends to a removed one (``preds[q]``: the pairs that lead to ``q``). ``check``
    is polled once per pair (a budget stops the fixpoint by raising).
    """
    while dead:
        check()
        p = dead.pop()
        if p not in alive:
            continue
        alive.discard(p)
        dead.extend(q for q in preds.get(p, ()) if q in alive)


def greatest_fixpoint(
    alive: set[P], successors: Callable[[P], Iterable[P] | None], check: Check = _no_check
) -> set[P]:
    """The largest subset of ``alive`` closed under ``successors``, in place.

    ``successors(p)`` lists where the actions send pair ``p``, or is None when some action
    merges it (it is then separable). A pair is dropped when a successor is not alive.
    ``check`` is polled once per pair.
    """
    preds: dict[P, list[P]] = defaultdict(list)
    dead: list[P] = []
    for p in alive:
        check()
        nxt = successors(p)
        if nxt is None:
            dead.append(p)
            continue
        for q in nxt:
            if q not in alive:
                dead.append(p)
                break
            preds[q].append(p)
    prune_pairs(alive, dead, preds, check)
    return alive


def pair_successors(
    starts_a: Sequence[float],
    targets_a: Sequence[int],
    starts_b: Sequence[float],
    targets_b: Sequence[int],
) -> list[tuple[int, int]]:
    """Where the actions send a pair of states with these action maps: one pair per overlap
    range of the two (section 3.2.2), in rotation order."""
    bounds = merge_boundaries([starts_a, starts_b])
    m = len(bounds)
    out = []
    for k in range(m):
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        mid = (bounds[k] + hi) / 2.0
        out.append((target_at(starts_a, targets_a, mid), target_at(starts_b, targets_b, mid)))
    return out


def _norm360(a: np.ndarray) -> np.ndarray:
    """:func:`feederkit.angles.norm360` elementwise."""
    r = np.fmod(a, 360.0) + 0.0
    r = np.where(r < 0.0, r + 360.0, r)
    return np.where(r >= 360.0 - 1e-12, 0.0, r)


SMALL_MAPS = 48
"""Pairs of states with fewer action-range boundaries than this are merged in plain Python
(numpy's per-call cost is larger than the work)."""

DENSE_STATES = 4000
"""Up to this many states the fixpoint keeps the alive pairs in an n x n boolean array."""


class _PairCells:
    """The overlap ranges of two states' action maps (section 3.2.2).

    ``ranges(i, j)`` gives, for each cell of ``merge_boundaries([starts[i], starts[j]])`` in
    rotation order, the index of the range of ``i`` and of ``j`` holding the cell's middle
    (what :func:`target_at` looks up). Long maps are merged with numpy; the cells are
    exactly those of ``merge_boundaries`` (where a chain of boundaries closer than
    ``ANGLE_EPS`` spans more than it, so a gap test and the chained merge could differ, the
    merge itself is called).
    """

    def __init__(self, starts: Sequence[Sequence[float]]) -> None:
        self.starts = starts
        self.arrays = [np.asarray(s, dtype=float) for s in starts]

    def ranges(self, i: int, j: int) -> tuple[Sequence[int], Sequence[int]]:
        """Per cell, the range index of ``i`` and of ``j`` (lists, or arrays for long maps)."""
        sa, sb = self.starts[i], self.starts[j]
        if len(sa) + len(sb) < SMALL_MAPS:
            bounds = merge_boundaries([sa, sb])
            m = len(bounds)
            if not m:
                return [], []
            ka, kb = [], []
            # The cells before the last in rotation order: their middles ascend inside
            # [0, 360), so each map's count of boundaries at or below the middle only grows.
            la, lb = len(sa), len(sb)
            pa = pb = 0
            for k in range(m - 1):
                mid = (bounds[k] + bounds[k + 1]) / 2.0
                while pa < la and sa[pa] <= mid:
                    pa += 1
                while pb < lb and sb[pb] <= mid:
                    pb += 1
                ka.append(pa - 1)
                kb.append(pb - 1)
            mid = norm360((bounds[-1] + bounds[0] + 360.0) / 2.0)  # the cell across 360
            ka.append(bisect.bisect_right(sa, mid) - 1)
            kb.append(bisect.bisect_right(sb, mid) - 1)
            return ka, kb
        a, b = self.arrays[i], self.arrays[j]
        allb = np.sort(_norm360(np.concatenate((a, b))))
        keep = np.empty(len(allb), dtype=bool)
        keep[0] = True
        np.greater(np.diff(allb), ANGLE_EPS, out=keep[1:])
        nb = allb[keep]
        if len(nb) < len(allb) and np.any(allb - nb[np.cumsum(keep) - 1] > ANGLE_EPS):
            nb = np.asarray(merge_boundaries([sa, sb]))
        if len(nb) > 1 and nb[0] + 360.0 - nb[-1] <= ANGLE_EPS:
            nb = nb[:-1]
        his = np.empty(len(nb))
        his[:-1] = nb[1:]
        his[-1] = nb[0] + 360.0
        mid = _norm360((nb + his) / 2.0)
        ka = np.searchsorted(a, mid, side="right") - 1
        kb = np.searchsorted(b, mid, side="right") - 1
        return ka, kb


def inseparable_masks(machine: PushAlignMachine, check: Check | None = None) -> tuple[int, ...]:
    """For each state, the mask of states it is inseparable from (see the module docstring).

    Starts from the pairs whose readings can agree; drops a pair when some action merges it
    or sends it to a dropped pair, until nothing changes. ``check`` (a planning budget's
    poll) is called every few pairs and stops the fixpoint by raising.
    """
    check = _no_check if check is None else check
    n = machine.n
    alive = _alike_pairs(machine, check)
    cells = _PairCells(machine.starts)
    if not machine.deterministic:
        return _masks(_bisimilar(machine, alive, cells, check), n)
    targets = machine.targets

    def successors(p: tuple[int, int]) -> list[tuple[int, int]] | None:
        i, j = p
        ka, kb = cells.ranges(i, j)
        ti, tj = targets[i], targets[j]
        out = set()
        for x, y in zip(ka, kb, strict=True):
            a, b = ti[x], tj[y]
            if a == b:
                return None
            out.add((a, b) if a < b else (b, a))
        return list(out)

    if n > DENSE_STATES or not alive:
        greatest_fixpoint(alive, successors, check)
        return _masks(alive, n)
    arrays = [np.asarray(t, dtype=np.int64) for t in targets]

    def successor_arrays(p: tuple[int, int]) -> tuple[np.ndarray, np.ndarray] | None:
        i, j = p
        ka, kb = cells.ranges(i, j)
        a, b = arrays[i][ka], arrays[j][kb]
        if np.any(a == b):
            return None
        return np.minimum(a, b), np.maximum(a, b)

    return _masks(_dense_fixpoint(n, sorted(alive), successor_arrays, check), n)


def _alike_pairs(machine: PushAlignMachine, check: Check) -> set[tuple[int, int]]:
    """The pairs ``i < j`` of states that can read alike (``Sensor.can_read_alike``).

    By the low end of their diameters, each state is asked only against those whose low
    end is within its high end plus the sensor's ``reading_reach`` (no pair farther apart
    reads alike): on a 200-part mix at 1 % that is a tenth of all pairs.
    """
    sensor = machine.sensor
    d = [s.sensed for s in machine.states]
    n = len(d)
    reach = sensor.reading_reach()
    alive: set[tuple[int, int]] = set()
    if not math.isfinite(reach):
        for i in range(n):
            check()
            di = d[i]
            alive.update((i, j) for j in range(i + 1, n) if sensor.can_read_alike(di, d[j]))
        return alive
    spans = [span(x) for x in d]
    order = sorted(range(n), key=lambda i: spans[i][0])
    for at, i in enumerate(order):
        check()
        di = d[i]
        limit = spans[i][1] + reach
        limit += 1e-9 * max(1.0, abs(limit))  # rounding: never skip a pair that reads alike
        for j in order[at + 1 :]:
            if spans[j][0] > limit:
                break
            if sensor.can_read_alike(di, d[j]):
                alive.add((i, j) if i < j else (j, i))
    return alive


def _dense_fixpoint(
    n: int,
    pairs: list[tuple[int, int]],
    successors: Callable[[tuple[int, int]], tuple[np.ndarray, np.ndarray] | None],
    check: Check,
) -> set[tuple[int, int]]:
    """:func:`greatest_fixpoint` in rounds over arrays: the alive pairs an ``n x n``
    boolean table, every pair's successors one flat array; each round drops, at once, the
    pairs with a successor no longer alive."""
    owner: list[np.ndarray] = []
    lo: list[np.ndarray] = []
    hi: list[np.ndarray] = []
    live = np.ones(len(pairs), dtype=bool)
    for k, p in enumerate(pairs):
        check()
        nxt = successors(p)
        if nxt is None:
            live[k] = False
            continue
        owner.append(np.full(len(nxt[0]), k, dtype=np.int64))
        lo.append(nxt[0])
        hi.append(nxt[1])
    pi = np.array([p[0] for p in pairs], dtype=np.int64)
    pj = np.array([p[1] for p in pairs], dtype=np.int64)
    table = np.zeros((n, n), dtype=bool)
    table[pi[live], pj[live]] = True
    own = np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64)
    slo = np.concatenate(lo) if lo else own
    shi = np.concatenate(hi) if hi else own
    while True:
        check()
        keep = live[own]
        own, slo, shi = own[keep], slo[keep], shi[keep]
        broken = own[~table[slo, shi]]
        if len(broken) == 0:
            break
        dead = np.unique(broken)
        live[dead] = False
        table[pi[dead], pj[dead]] = False
    return {pairs[k] for k in np.flatnonzero(live).tolist()}


def _masks(pairs: set[tuple[int, int]], n: int) -> tuple[int, ...]:
    """Per state, the mask of its partners in ``pairs`` (never itself)."""
    masks = [0] * n
    for i, j in pairs:
        masks[i] |= 1 << j
        masks[j] |= 1 << i
    return tuple(masks)


def _drop(alive: set[tuple[int, int]], adj: list[int], p: tuple[int, int]) -> None:
    """Drop the pair ``p`` from ``alive`` and from its states' masks (:func:`_masks`)."""
    alive.discard(p)
    i, j = p
    adj[i] &= ~(1 << j)
    adj[j] &= ~(1 << i)


def pair_outcomes(machine: PushAlignMachine, i: int, j: int) -> list[tuple[int, int]]:
    """The outcome sets ``(of i, of j)`` (masks) on each overlap range of the two states'
    action maps (section 3.2.2), in rotation order."""
    starts, outs = machine.starts, machine.outcomes_of
    bounds = merge_boundaries([starts[i], starts[j]])
    m = len(bounds)
    out = []
    for k in range(m):
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        mid = (bounds[k] + hi) / 2.0
        out.append((target_at(starts[i], outs[i], mid), target_at(starts[j], outs[j], mid)))
    return out


PASS_MIN_SHARE = 0.05
"""The outcome-set fixpoint goes on by passes over every pair while a pass drops at least
this share of the pairs left, then by a worklist (:func:`_bisimilar`)."""


def _bisimilar(
    machine: PushAlignMachine,
    alive: set[tuple[int, int]],
    cells: _PairCells,
    check: Check,
) -> set[tuple[int, int]]:
    """The greatest bisimulation inside ``alive`` (pairs ``i < j``), in place: a pair stays
    while, on every overlap range, each outcome of either state has a different outcome of
    the other that is still paired with it.

    Passes over the pairs first, each pair asked until a case fails and dropped at once
    (most pairs of a mix or a near-round part fall in the first pass, at their first case);
    once a pass drops fewer than ``PASS_MIN_SHARE`` of the pairs left, a worklist: a pair
    is looked at again only when a pair its cases mention was dropped (a long chain of
    drops then costs no pass per link). The pairs alive are kept as a bit mask per state,
    so an outcome set is matched by one OR per state. A near-round 64-gon with 1 % radial
    noise at 0.3 mm under 1 degree (states by diameter): 0.05 s, where the worklist alone
    took 2 s and the pairs looked up one by one 17 s (``benchmarks/bench_goal_relation.py``).
    """
    outs = machine.outcomes_of
    # The pairs alive as a bit mask per state (``adj[x]`` never holds ``x``): an outcome
    # set is matched by bit operations, one per state, not by looking at every pair.
    adj = list(_masks(alive, machine.n))
    idx: dict[int, list[int]] = {}

    def states(mask: int) -> list[int]:
        hit = idx.get(mask)
        if hit is None:
            hit = idx[mask] = members(mask)
        return hit

    def near(mask: int) -> int:
        """The states paired (alive) with some state of ``mask``."""
        r = 0
        for y in states(mask):
            r |= adj[y]
        return r

    def matched(a: int, b: int) -> bool:
        # Every state of each outcome set paired with some state of the other.
        return not a & ~near(b) and not b & ~near(a)

    cases: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for p in alive:
        check()
        i, j = p
        ka, kb = cells.ranges(i, j)
        oi, oj = outs[i], outs[j]
        cases[p] = sorted({(oi[x], oj[y]) for x, y in zip(ka, kb, strict=True)})
    while alive:
        before = len(alive)
        for p in sorted(alive):
            check()
            if not all(matched(a, b) for a, b in cases[p]):
                _drop(alive, adj, p)
        if len(alive) == before:
            return alive
        if before - len(alive) < PASS_MIN_SHARE * before:
            break
    # Who mentions whom: a pair's cases name the alive pairs (x, y) of an outcome of each
    # state, found per x as the outcomes of the other state it meets.
    users: dict[tuple[int, int], list[tuple[int, int]]] = defaultdict(list)
    for p in alive:
        check()
        partner: dict[int, int] = {}
        for a, b in cases[p]:
            for x in states(a):
                partner[x] = partner.get(x, 0) | b
        named = set()
        for x, b in partner.items():
            for y in members(b & adj[x]):
                named.add((x, y) if x < y else (y, x))
        for q in named:
            users[q].append(p)
    todo = sorted(alive)
    queued = set(todo)
    while todo:
        check()
        p = todo.pop()
        queued.discard(p)
        if p in alive and not all(matched(a, b) for a, b in cases[p]):
            _drop(alive, adj, p)
            for u in users.get(p, ()):
                if u in alive and u not in queued:
                    queued.add(u)
                    todo.append(u)
    return alive


def kept_apart(
    machine: PushAlignMachine,
    pairs: Iterable[tuple[int, int]],
    check: Check | None = None,
) -> set[tuple[int, int]]:
    """The pairs of ``pairs`` (``i < j``) nature can keep apart for ever: the greatest subset
    such that on every overlap range of a pair (section 3.2.2) some outcome of the one and a
    *different* outcome of the other again form a kept pair.

    Sound for unresolvability when ``pairs`` are pairs that can read alike and are not a
    goal: nature answers every action with such outcomes and every reading with one both can
    give, so every set a plan meets holds a kept pair, which is not a goal; no leaf is a
    goal. It can miss pairs whose plans fail only on a larger set (three states each pair of
    which some action merges, but no action all three). With single outcomes a kept pair is
    bisimilar, so none is kept outside the inseparable relation.

    Rounds over the pairs until none is dropped (each pair's cases made once, by
    :func:`pair_outcomes`); ``check`` is polled once per pair and stops it by raising.
    """
    check = _no_check if check is None else check
    alive = set(pairs)
    cases = {}
    for p in alive:
        check()
        cases[p] = sorted(set(pair_outcomes(machine, *p)))
    # The kept pairs as a bit mask per state (``adj[x]`` never holds ``x``): whether an
    # outcome of the one and a different outcome of the other form a kept pair is one AND
    # per state of the one.
    adj = list(_masks(alive, machine.n))
    idx: dict[int, list[int]] = {}

    def keeps(a: int, b: int) -> bool:
        xs = idx.get(a)
        if xs is None:
            xs = idx[a] = members(a)
        return any(adj[x] & b for x in xs)

    changed = True
    while changed:
        changed = False
        for p in sorted(alive):
            check()
            if not all(keeps(a, b) for a, b in cases[p]):
                _drop(alive, adj, p)
                changed = True
    return alive
