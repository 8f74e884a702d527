"""Distinguishability of pairs of parts under a sensor model, decided exactly (section 8.4).

Two parts are distinguishable (definition 11) when an action sequence makes their readings
differ. Decided here exactly, not only by Theorem 9's sufficient condition: a state of part A
and a state of part B are *inseparable* when their readings can agree and every action sends
them to two states that are again inseparable (a greatest fixpoint over the pairs of the two
parts' product machine, by the fixpoint of :mod:`feederkit.machine.inseparable`;
two different parts' states are never merged into one). The parts are recognizable from any
start iff no pair of their states is inseparable.

If one pair is inseparable, every state of each part is in some inseparable pair: from any
state some action reaches every resting range. The witness is therefore the list of
inseparable pairs, with the reason in words. With noise the relation is not transitive
(Lemma 10): it is reported for pairs of parts, never as classes.
"""

from __future__ import annotations

import functools
import itertools
from array import array
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.machine import greatest_fixpoint, pair_successors
from feederkit.mechanics.actions import action_ranges
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mix.signatures import (
    ANGLE_TOL_DEG,
    LENGTH_TOL_MM,
    Signature,
    matching_shifts,
    signature,
)
from feederkit.sensors import Sensor

REASON_SAME_PDF = (
    "same push-diameter function (Lemma 8): identical mechanical behaviour and diameters"
)
REASON_SENSORLESS = (
    "no sensor: readings carry no information, parts cannot be recognized (section 8.6)"
)
REASON_SINGLE = (
    "every state of both parts reads alike to the sensor, whatever their diameters: to it they "
    "have a single diameter value (section 8.4)"
)
REASON_SAME_DIAMETERS = (
    "these states keep equal diameters under every action "
    "(the push-diameter functions agree on them)"
)
REASON_TOLERANCE = (
    "diameters the sensor can read alike: every action keeps these states reading alike"
)


@dataclass(frozen=True, slots=True)
class PairWitness:
    """Two parts that no plan can tell apart, and why.

    ``states_a[k]`` (a stable state id of ``part_a``) and ``states_b[k]`` (of ``part_b``) are
    the k-th inseparable pair: if the part is in one of them no action sequence ever makes
    its readings differ from those of the other. ``kind`` names the reason in one word:
    ``same-push-diameter``, ``sensorless``, ``single-diameter``, ``same-diameters``,
    ``tolerance`` or ``uncertainty`` (no strong plan under the declared uncertainty).
    Slotted: a catalog's analysis holds a million of them.
    """

    part_a: str
    part_b: str
    states_a: tuple[int, ...]
    states_b: tuple[int, ...]
    reason: str
    kind: str = "tolerance"
    index_a: int = 0
    index_b: int = 1

    @property
    def pairs(self) -> tuple[tuple[int, int], ...]:
        """The inseparable (state of a, state of b) pairs."""
        return tuple(zip(self.states_a, self.states_b, strict=True))

    def to_dict(self) -> dict[str, object]:
        """``{"part_a", "part_b", "states_a", "states_b", "reason", "kind"}`` for reports and
        ``--json``: ``kind`` lets a script tell a pair no sensor separates from one a finer
        sensor may, without parsing ``reason``."""
        return {
            "part_a": self.part_a,
            "part_b": self.part_b,
            "states_a": list(self.states_a),
            "states_b": list(self.states_b),
            "reason": self.reason,
            "kind": self.kind,
        }


def _ranges(pf: PushFunction) -> list[tuple[list[float], list[int]]]:
    out = []
    for s in pf.states:
        rs = action_ranges(pf, s.id)
        out.append(([r.lo for r in rs], [r.target for r in rs]))
    return out


def inseparable_cross_pairs(
    pf_a: PushFunction,
    pf_b: PushFunction,
    sensor: Sensor,
    *,
    _ranges_a: Sequence[tuple[list[float], list[int]]] | None = None,
    _ranges_b: Sequence[tuple[list[float], list[int]]] | None = None,
) -> list[tuple[int, int]]:
    """The inseparable pairs (state of a, state of b): the greatest fixpoint of section 8.4.

    Start from the pairs whose readings can agree; drop a pair when some action sends it to a
    dropped pair (or to a pair whose readings cannot agree), until nothing changes. This is
    :func:`feederkit.machine.inseparable` on the two-part machine, restricted to its cross
    pairs (which are closed under actions and never merge).
    """
    ra = _ranges_a if _ranges_a is not None else _ranges(pf_a)
    rb = _ranges_b if _ranges_b is not None else _ranges(pf_b)
    eps = DIAMETER_REL_EPS * max(pf_a.part.size, pf_b.part.size)
    da = [s.diameter for s in pf_a.states]
    db = [s.diameter for s in pf_b.states]

    def alike(i: int, j: int) -> bool:
        return abs(da[i] - db[j]) <= eps or sensor.can_read_alike(da[i], db[j])

    alive = {(i, j) for i in range(pf_a.n) for j in range(pf_b.n) if alike(i, j)}
    if len(alive) == pf_a.n * pf_b.n:
        # Every cross pair reads alike: every successor is alive, nothing is ever dropped.
        return sorted(alive)
    if not any((0, j) in alive and _lands_alike(ra[0], rb[j], alike) for j in range(pf_b.n)):
        # State 0 of a must be inseparable from some state of b when any pair is (module
        # docstring); a pair is only if its first actions already land reading alike.
        return []

    def successors(p: tuple[int, int]) -> list[tuple[int, int]]:
        (la, ta), (lb, tb) = ra[p[0]], rb[p[1]]
        return pair_successors(la, ta, lb, tb)

    return sorted(greatest_fixpoint(alive, successors))


def _lands_alike(
    range_a: tuple[list[float], list[int]],
    range_b: tuple[list[float], list[int]],
    alike: Callable[[int, int], bool],
) -> bool:
    """Whether every action sends the two states to states that read alike (one step of the
    fixpoint: necessary for the pair to be inseparable)."""
    return all(alike(x, y) for x, y in pair_successors(*range_a, *range_b))


def _reason(
    pf_a: PushFunction,
    pf_b: PushFunction,
    sensor: Sensor,
    pairs: Sequence[tuple[int, int]],
    sig_a: Signature | None,
    sig_b: Signature | None,
) -> tuple[str, str]:
    if not sensor.informative:
        return "sensorless", REASON_SENSORLESS
    sa = sig_a or signature(pf_a)
    sb = sig_b or signature(pf_b)
    if matching_shifts(sa, sb, angle_tol=ANGLE_TOL_DEG, length_tol=LENGTH_TOL_MM):
        return "same-push-diameter", REASON_SAME_PDF
    diams = [s.diameter for s in pf_a.states] + [s.diameter for s in pf_b.states]
    if all(sensor.can_read_alike(x, y) for x in diams for y in diams):
        return "single-diameter", _single_reason(sensor.describe())
    da = [s.diameter for s in pf_a.states]
    db = [s.diameter for s in pf_b.states]
    if all(abs(da[i] - db[j]) <= LENGTH_TOL_MM for i, j in pairs):
        return "same-diameters", REASON_SAME_DIAMETERS
    return "tolerance", _tolerance_reason(sensor.describe())


@functools.lru_cache(maxsize=64)
def _single_reason(described: str) -> str:
    """:data:`REASON_SINGLE` naming the sensor, one string per sensor (as below)."""
    return REASON_SINGLE + f" ({described})"


@functools.lru_cache(maxsize=64)
def _tolerance_reason(described: str) -> str:
    """One string per sensor for every witness that cites it (a catalog holds a million)."""
    return REASON_TOLERANCE + f" ({described})"


def distinguishable(
    pf_a: PushFunction,
    pf_b: PushFunction,
    sensor: Sensor,
    *,
    index_a: int = 0,
    index_b: int = 1,
) -> PairWitness | None:
    """None when some action sequence tells the two parts apart from any start (definition 11),
    else the witness: the inseparable state pairs and the reason in words.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> from feederkit.sensors import ToleranceSensor
    >>> def pf(name, w, h):
    ...     return push_function(make_part(make_outline(name, [(0, 0), (w, 0), (w, h), (0, h)])))
    >>> distinguishable(pf("square", 10, 10), pf("rect", 20, 10), ToleranceSensor(0.5)) is None
    True
    >>> distinguishable(pf("a", 20, 10), pf("b", 20, 10), ToleranceSensor(0.5)).kind
    'same-push-diameter'
    """
    pairs = inseparable_cross_pairs(pf_a, pf_b, sensor)
    if not pairs:
        return None
    return _witness(pf_a, pf_b, sensor, pairs, None, None, index_a, index_b)


def _witness(pf_a, pf_b, sensor, pairs, sig_a, sig_b, index_a, index_b, shared=None) -> PairWitness:
    """The witness of an inseparable pair of parts; equal state tuples are one object in
    ``shared`` (a catalog's witnesses repeat a few patterns, such as every state)."""
    kind, reason = _reason(pf_a, pf_b, sensor, pairs, sig_a, sig_b)
    states_a = tuple(i for i, _ in pairs)
    states_b = tuple(j for _, j in pairs)
    if shared is not None:
        states_a = shared.setdefault(states_a, states_a)
        states_b = shared.setdefault(states_b, states_b)
    return PairWitness(
        part_a=pf_a.part.name,
        part_b=pf_b.part.name,
        states_a=states_a,
        states_b=states_b,
        reason=reason,
        kind=kind,
        index_a=index_a,
        index_b=index_b,
    )


def _covers(
    xs: Sequence[float], ys: Sequence[float], alike: Callable[[float, float], bool]
) -> bool:
    return all(any(alike(x, y) for y in ys) for x in xs)


QUANTILE_BINS = 8
"""The landing distribution of diameters is summarised by its mean over this many equal
slices of probability (see :func:`landing_profile`)."""

HASH_BINS = (1, 3, 6)
"""The slices whose means key the candidate grid (three, so 27 neighbouring cells)."""


def landing_profile(pf: PushFunction, bins: int = QUANTILE_BINS) -> list[float]:
    """The diameter a push-align operation leaves, as a distribution over the rotation,
    summarised by the mean of its quantile function over ``bins`` equal slices.

    From any state, rotating by a uniform angle and pushing lands in state ``k`` for a
    rotation set as wide as ``k``'s resting range, so the distribution is the same for
    every start: diameter ``d_k`` with weight ``w_k / 360``. If two states of two parts are
    inseparable, every rotation sends them to states that read alike (module docstring), a
    coupling of the two distributions in which diameters differ by at most the sensor's
    reach: their infinity-Wasserstein distance, and so the difference of the means of any
    slice of their quantile functions, is at most the reach. Slice means, unlike the
    quantiles at fixed levels, move continuously with the widths (rounding cannot flip them).
    """
    widths = resting_widths(pf)
    total = sum(widths)
    order = sorted(range(pf.n), key=lambda k: pf.states[k].diameter)
    out = [0.0] * bins
    cum = 0.0
    for k in order:
        lo, hi = cum, cum + widths[k] / total
        cum = hi
        d = pf.states[k].diameter
        b0 = min(bins - 1, int(lo * bins))
        b = b0
        while b < bins and b / bins < hi:
            a, z = max(lo, b / bins), min(hi, (b + 1) / bins)
            if z > a:
                out[b] += d * (z - a) * bins
            b += 1
    return out


class CandidatePairs(Sequence[tuple[int, int]]):
    """Sorted pairs ``(i, j)``, ``i < j``, of part indices, held as two int32 arrays.

    A 50,000-part catalog over both landings leaves 2.6 million candidate pairs: as Python
    tuples they took about 240 MB, here 21 MB. Iterating yields plain tuples of ints.
    """

    __slots__ = ("_a", "_b")
    _CHUNK = 1 << 16

    def __init__(self, a: np.ndarray, b: np.ndarray) -> None:
        order = np.lexsort((b, a))
        self._a = np.ascontiguousarray(a[order], dtype=np.int32)
        self._b = np.ascontiguousarray(b[order], dtype=np.int32)

    def __len__(self) -> int:
        return len(self._a)

    def __getitem__(self, k):  # type: ignore[override]
        if isinstance(k, slice):
            return [(int(x), int(y)) for x, y in zip(self._a[k], self._b[k], strict=True)]
        return (int(self._a[k]), int(self._b[k]))

    def __iter__(self):
        for s in range(0, len(self._a), self._CHUNK):
            yield from zip(
                self._a[s : s + self._CHUNK].tolist(),
                self._b[s : s + self._CHUNK].tolist(),
                strict=True,
            )

    def __eq__(self, other: object) -> bool:
        if isinstance(other, CandidatePairs):
            return bool(np.array_equal(self._a, other._a) and np.array_equal(self._b, other._b))
        return isinstance(other, Sequence) and list(self) == list(other)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"CandidatePairs({len(self)} pairs)"


def candidate_pairs(pfs: Sequence[PushFunction], sensor: Sensor) -> CandidatePairs:
    """Pairs of parts that may be unrecognizable, found without an all-pairs pass.

    Two necessary conditions, both from the parts alone: every state of each part reads
    alike some state of the other (any inseparable pair reaches every state, see the module
    docstring; so also the smallest diameters read alike, and the largest), and their
    :func:`landing_profile` slices differ by at most the sensor's reach. Parts are hashed
    on a grid of three slice means with cells as wide as the reach, so only neighbouring
    cells are compared; the full tests then run on those pairs only. A sensorless model
    gives every pair.
    """
    n = len(pfs)
    if not sensor.informative:
        a, b = np.triu_indices(n, 1)
        return CandidatePairs(a, b)
    reach = sensor.reading_reach()
    diams = [sorted(s.diameter for s in pf.states) for pf in pfs]
    eps = [DIAMETER_REL_EPS * pf.part.size for pf in pfs]
    biggest = max((pf.part.size for pf in pfs), default=0.0)
    # Slack for rounding: the profiles are sums of products of diameters and widths.
    cell = reach + max(eps, default=0.0) + 1e-9 * biggest + 1e-12
    profiles = np.array([landing_profile(pf) for pf in pfs], dtype=float).reshape(n, QUANTILE_BINS)
    keys = np.floor(profiles[:, list(HASH_BINS)] / cell).astype(np.int64)
    grid: dict[tuple[int, ...], list[int]] = defaultdict(list)
    for i, key in enumerate(map(tuple, keys.tolist())):
        grid[key].append(i)

    def alike(x: float, y: float) -> bool:
        return sensor.can_read_alike(x, y) or abs(x - y) <= cell - reach

    out_a, out_b = array("i"), array("i")
    steps = list(itertools.product((-1, 0, 1), repeat=len(HASH_BINS)))
    for key, here in grid.items():
        there_all = []
        for step in steps:
            there = grid.get(tuple(k + d for k, d in zip(key, step, strict=True)))
            if there:
                there_all.extend(there)
        if not there_all:
            continue
        others = np.array(sorted(there_all), dtype=np.int64)
        for i in here:
            js = others[others > i]
            if len(js) == 0:
                continue
            close = np.all(np.abs(profiles[js] - profiles[i]) <= cell, axis=1)
            lo_i, hi_i = diams[i][0], diams[i][-1]
            for j in js[close].tolist():
                dj = diams[j]
                if not (alike(lo_i, dj[0]) and alike(hi_i, dj[-1])):
                    continue
                if _covers(diams[i], dj, alike) and _covers(dj, diams[i], alike):
                    out_a.append(i)
                    out_b.append(j)
    return CandidatePairs(np.frombuffer(out_a, np.int32), np.frombuffer(out_b, np.int32))


def unrecognizable_pairs(
    pfs: Sequence[PushFunction],
    sensor: Sensor,
    candidates: Sequence[tuple[int, int]] | None = None,
    *,
    signatures: Sequence[Signature] | None = None,
) -> list[PairWitness]:
    """Every pair of parts of a mix that no plan can tell apart, each with its witness.

    Exact (the greatest fixpoint of :func:`inseparable_cross_pairs`) on the pairs that
    :func:`candidate_pairs` leaves (or ``candidates``, if given, already computed by it);
    the others cannot be unrecognizable. Sorted by part index. ``signatures``, when the
    caller has them (one per part), name the witnesses' reasons without recomputing them.

    A part's action ranges are made at its first pair and dropped after its last, so a
    catalog's analysis holds those of the parts in between only.
    """
    todo = candidate_pairs(pfs, sensor) if candidates is None else candidates
    last: dict[int, int] = {}
    for t, (i, j) in enumerate(todo):
        last[i] = last[j] = t
    ranges: dict[int, list] = {}
    sigs: dict[int, Signature] = {}
    shared: dict[tuple[int, ...], tuple[int, ...]] = {}
    out = []
    for t, (i, j) in enumerate(todo):
        for k in (i, j):
            if k not in ranges:
                ranges[k] = _ranges(pfs[k])
        pairs = inseparable_cross_pairs(
            pfs[i], pfs[j], sensor, _ranges_a=ranges[i], _ranges_b=ranges[j]
        )
        if pairs:
            for k in (i, j):
                if k not in sigs:
                    sigs[k] = signature(pfs[k]) if signatures is None else signatures[k]
            out.append(_witness(pfs[i], pfs[j], sensor, pairs, sigs[i], sigs[j], i, j, shared))
        for k in (i, j):
            if last[k] == t:
                ranges.pop(k, None)
                sigs.pop(k, None)
    return out


__all__ = [
    "CandidatePairs",
    "PairWitness",
    "candidate_pairs",
    "distinguishable",
    "inseparable_cross_pairs",
    "landing_profile",
    "unrecognizable_pairs",
]
