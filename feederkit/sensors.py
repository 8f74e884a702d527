"""Sensor models: the readings each stable state can produce; branching by reading (section 5).

The reading is the part's diameter (width across the belt, mm) after alignment (design.md).
Every model implements the :class:`Sensor` protocol, so the machine, the planners, plan
files, execution, reports and the simulator never ask which model they hold:

- :class:`NoSensor`: sensorless (section 4); every state gives the same (no) reading.
- :class:`ToleranceSensor`: a state of diameter ``d`` reads any value in the open interval
  ``(d - e, d + e)``.
- :class:`LedSensor`: beams at heights ``k * pitch`` (k = 1, 2, ...) above the fence; a width
  ``w`` blocks the beams below it, ``count = #{k : k * pitch < w}``; with alignment noise ``e``
  the width lies anywhere in ``[d - e, d + e]``. The reading is ``count * pitch`` mm; a plan
  file's branch over counts ``a..b`` holds ``[(a - 1/4) pitch, (b + 1/4) pitch]``
  (:meth:`LedSensor.window`), so any arithmetic for the product matches.

A state's diameter may be an interval ``(lo, hi)`` (a physical resting state under
uncertainty, docs/uncertainty.md): it reads anything any diameter in the interval can read.
Every method taking a diameter takes either; a float is the point interval (the ideal model).

Two states are indistinguishable when their reading sets overlap; an indistinguishable set
(definition 10) is a connected component of that relation, which is not transitive.

>>> s = ToleranceSensor(0.5)
>>> s.can_read_alike(10.0, 10.9), s.can_read_alike(10.0, 11.0)
(True, False)
>>> [b.members for b in s.split([10.0, 10.9, 12.0])]
[(0,), (0, 1), (1,), (2,)]
>>> LedSensor(1.0).nominal_reading(2.5)
2.0
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Protocol, runtime_checkable

from feederkit.errors import InputError


class Grouping(StrEnum):
    """How a set of states is branched on the reading.

    ``exact``: each reading leads to exactly the states that can produce it. ``components``:
    the paper's rule (section 6), a reading names its whole indistinguishable set.
    """

    EXACT = "exact"
    COMPONENTS = "components"


@dataclass(frozen=True)
class ReadingBranch:
    """The states consistent with the readings in the closed ``[lo, hi]`` (None: sensorless).

    ``mask`` has bit ``k`` set for each consistent state ``k`` (the label the caller gave the
    state: its position in the diameters split, or its machine index).
    """

    lo: float | None
    hi: float | None
    mask: int

    @property
    def members(self) -> tuple[int, ...]:
        """The consistent states, ascending."""
        out = []
        m = self.mask
        while m:
            low = m & -m
            out.append(low.bit_length() - 1)
            m ^= low
        return tuple(out)


Labels = Sequence[int] | None
"""Bit indices for the states whose diameters are split (None: their positions)."""

Diameter = float | tuple[float, float]
"""A state's diameter (mm): exact, or an interval ``(lo, hi)`` of the widths it can show."""


def span(diameter: Diameter) -> tuple[float, float]:
    """A diameter as its interval ``(lo, hi)``; a float is the point interval.

    >>> span(3.0), span((2.0, 2.5))
    ((3.0, 3.0), (2.0, 2.5))
    """
    if isinstance(diameter, tuple):
        return float(diameter[0]), float(diameter[1])
    return diameter, diameter


def _points(diameters: Sequence[Diameter]) -> bool:
    """Whether every diameter is exact (a float or a point interval)."""
    return all(not isinstance(d, tuple) or d[0] == d[1] for d in diameters)


def _exact(diameters: Sequence[Diameter]) -> list[float]:
    """Exact diameters as floats (callers check :func:`_points` first)."""
    return [d[0] if isinstance(d, tuple) else d for d in diameters]


@runtime_checkable
class Sensor(Protocol):
    """What every sensor model answers (section 5): one home for reading sets and branching."""

    @property
    def model(self) -> str:
        """The plan file's model name: ``none``, ``tolerance`` or ``led``."""
        ...

    @property
    def informative(self) -> bool:
        """False for the sensorless model, whose readings say nothing."""
        ...

    def reading_interval(self, diameter: Diameter) -> tuple[float, float] | None:
        """The smallest and largest reading (mm) a state of this diameter can give.

        None without a sensor. A tolerance sensor's ends are open (never read exactly).
        """
        ...

    def branch_reach(self, diameter: Diameter) -> tuple[float, float] | None:
        """Bounds on the branches a state of this diameter can follow: a branch ``[lo, hi]``
        with ``hi`` below the first or ``lo`` above the second holds none of its readings
        (:meth:`reads_into` is false, :meth:`reading_probability` is 0), so a verifier
        indexing a node's branches by interval need look no further. None without a sensor.
        """
        ...

    def consistent(self, diameter: Diameter, reading: float) -> bool:
        """Whether a state of this diameter can produce ``reading`` (mm)."""
        ...

    def reads_into(self, diameter: Diameter, lo: float, hi: float) -> bool:
        """Whether a state of this diameter can give some reading in the closed ``[lo, hi]``."""
        ...

    def can_read_alike(self, d1: Diameter, d2: Diameter) -> bool:
        """Whether two diameters can produce the same reading (their reading sets overlap)."""
        ...

    def reading_reach(self) -> float:
        """The largest diameter difference (mm) two states can have and still read alike."""
        ...

    def nominal_reading(self, diameter: Diameter) -> float | None:
        """The reading of an exact width equal to ``diameter`` (None sensorless)."""
        ...

    def read(self, width: float) -> float | None:
        """What the sensor reports for a measured width (mm), as the simulator sees it."""
        ...

    def probe_readings(self, diameter: Diameter, inset: float) -> tuple[float, ...]:
        """Readings that exercise a state's whole reading set: its extremes and nominal.

        ``inset`` is how far inside an open interval the extremes are taken.
        """
        ...

    def reading_probability(self, diameter: Diameter, lo: float | None, hi: float | None) -> float:
        """Probability that a state gives a reading in ``[lo, hi]`` (readings uniform over
        the state's reading set: the width for the LED array)."""
        ...

    def split(
        self,
        diameters: Sequence[float],
        grouping: Grouping | str = Grouping.EXACT,
        labels: Labels = None,
    ) -> list[ReadingBranch]:
        """Branch a set of states (given by their diameters) on the reading, in reading order.

        Branch intervals are closed and may share endpoints; a reading on a shared endpoint
        is consistent with a subset of either branch. Each branch's ``mask`` sets bit
        ``labels[j]`` (default ``j``) for the j-th diameter.
        """
        ...

    def indistinguishable_sets(self, diameters: Sequence[float]) -> list[tuple[int, ...]]:
        """Definition 10: connected components of the overlap relation, sorted by diameter."""
        ...

    def reading_windows(self, diameters: Sequence[float]) -> list[int] | None:
        """For diameters in ascending order (intervals: both ends ascending), per state
        ``a`` the mask of states ``a..b`` that can read alike with it from above (a fast
        path for the planners).

        The states that can give one reading are then a run whose ends read alike. None
        when the sensor offers no such shortcut, or when some pair sits on the edge of
        reading alike within rounding (the reading cells then decide).
        """
        ...

    def shared_reading_probability(self, diameters: Sequence[float]) -> list[float] | None:
        """For diameters in ascending order (intervals: both ends ascending), none of them
        inseparable, per state the probability that its reading could also come from
        another of them (a fast path for the expected objective). None when the sensor
        offers no closed form.
        """
        ...

    def uncovered_reading(
        self, diameter: Diameter, intervals: Sequence[tuple[float, float]]
    ) -> float | None:
        """A reading (mm) this state can give that none of the closed ``intervals`` holds, or
        None when they cover its whole reading set (interval arithmetic, not sampling)."""
        ...

    def narrowed(self, inset: float) -> Sensor:
        """The sensor as a verifier reads it: readings within ``inset`` mm of an open end of
        a reading set are not taken (design.md: a tolerance sensor never reads its ends;
        rounding can make two ends that touch overlap by an ulp; ``inset`` is a rounding
        margin, ``feederkit.plans.execute.rounding_inset``). Models with closed reading sets
        return themselves."""
        ...

    def describe(self) -> str:
        """The model and its parameters in words, for people."""
        ...

    def to_dict(self) -> dict[str, Any]:
        """The plan file's ``sensor`` object."""
        ...


@dataclass(frozen=True)
class NoSensor:
    """No sensing: the sensorless case (section 4)."""

    model: str = "none"

    @property
    def informative(self) -> bool:
        return False

    def reading_interval(self, diameter: Diameter) -> tuple[float, float] | None:
        return None

    def branch_reach(self, diameter: Diameter) -> tuple[float, float] | None:
        return None

    def consistent(self, diameter: Diameter, reading: float) -> bool:
        return True

    def reads_into(self, diameter: Diameter, lo: float, hi: float) -> bool:
        return True

    def can_read_alike(self, d1: Diameter, d2: Diameter) -> bool:
        return True

    def reading_reach(self) -> float:
        return math.inf

    def nominal_reading(self, diameter: Diameter) -> float | None:
        return None

    def read(self, width: float) -> float | None:
        return None

    def probe_readings(self, diameter: Diameter, inset: float) -> tuple[float, ...]:
        return ()

    def reading_probability(self, diameter: Diameter, lo: float | None, hi: float | None) -> float:
        return 1.0

    def split(
        self,
        diameters: Sequence[float],
        grouping: Grouping | str = Grouping.EXACT,
        labels: Labels = None,
    ) -> list[ReadingBranch]:
        n = len(diameters)
        return [ReadingBranch(None, None, _mask(range(n), labels))] if n else []

    def indistinguishable_sets(self, diameters: Sequence[float]) -> list[tuple[int, ...]]:
        order = sorted(range(len(diameters)), key=lambda i: diameters[i])
        return [tuple(order)] if order else []

    def reading_windows(self, diameters: Sequence[float]) -> list[int] | None:
        return None

    def shared_reading_probability(self, diameters: Sequence[float]) -> list[float] | None:
        return None

    def uncovered_reading(
        self, diameter: Diameter, intervals: Sequence[tuple[float, float]]
    ) -> float | None:
        return None

    def narrowed(self, inset: float) -> NoSensor:
        return self

    def describe(self) -> str:
        return "no sensor: a sensorless plan"

    def to_dict(self) -> dict[str, Any]:
        return {"model": "none"}


@dataclass(frozen=True)
class ToleranceSensor:
    """A diameter sensor reading strictly within ``tolerance`` mm of the true diameter."""

    tolerance: float
    model: str = "tolerance"

    @property
    def informative(self) -> bool:
        return True

    def reading_interval(self, diameter: Diameter) -> tuple[float, float] | None:
        lo, hi = span(diameter)
        return max(0.0, lo - self.tolerance), hi + self.tolerance

    def branch_reach(self, diameter: Diameter) -> tuple[float, float] | None:
        # reads_into and a positive share both need lo < d_hi + e and hi > d_lo - e.
        lo, hi = span(diameter)
        return lo - self.tolerance, hi + self.tolerance

    def consistent(self, diameter: Diameter, reading: float) -> bool:
        if not isinstance(diameter, tuple):
            return abs(reading - diameter) < self.tolerance
        lo, hi = diameter
        return lo - self.tolerance < reading < hi + self.tolerance

    def reads_into(self, diameter: Diameter, lo: float, hi: float) -> bool:
        a, b = span(diameter)
        return a - self.tolerance < hi and b + self.tolerance > lo

    def can_read_alike(self, d1: Diameter, d2: Diameter) -> bool:
        if not isinstance(d1, tuple) and not isinstance(d2, tuple):
            return abs(d1 - d2) < 2.0 * self.tolerance
        (a1, b1), (a2, b2) = span(d1), span(d2)
        two = 2.0 * self.tolerance
        return a1 - b2 < two and a2 - b1 < two

    def reading_reach(self) -> float:
        return 2.0 * self.tolerance

    def nominal_reading(self, diameter: Diameter) -> float | None:
        lo, hi = span(diameter)
        return (lo + hi) / 2.0

    def read(self, width: float) -> float | None:
        return width

    def probe_readings(self, diameter: Diameter, inset: float) -> tuple[float, ...]:
        e = self.tolerance
        lo, hi = span(diameter)
        return (max(inset, lo - e + inset), (lo + hi) / 2.0, hi + e - inset)

    def reading_probability(self, diameter: Diameter, lo: float | None, hi: float | None) -> float:
        if lo is None or hi is None:
            return 1.0
        return _uniform_share(lo, hi, span(diameter), self.tolerance)

    def uncovered_reading(
        self, diameter: Diameter, intervals: Sequence[tuple[float, float]]
    ) -> float | None:
        # The reading set is the open interval (lo - e, hi + e), clipped at 0.
        d_lo, d_hi = span(diameter)
        start, end = max(0.0, d_lo - self.tolerance), d_hi + self.tolerance
        cur = start  # readings up to cur are covered (cur itself only once an interval holds it)
        for a, b in sorted(intervals):
            if b <= cur:
                continue
            if a > cur:
                return (cur + min(a, end)) / 2.0 if cur < end else None
            cur = b
            if cur >= end:
                return None
        return (cur + end) / 2.0 if cur < end else None

    def split(
        self,
        diameters: Sequence[float],
        grouping: Grouping | str = Grouping.EXACT,
        labels: Labels = None,
    ) -> list[ReadingBranch]:
        """The reading cells: between consecutive ends ``d -/+ e`` (clipped at 0) the states
        within ``e`` of the cell's middle, neighbours with equal states merged.

        Those states are a run of the diameters in ascending order, so two pointers find
        them in one sweep: O(n log n) for n states.
        """
        if Grouping(grouping) is Grouping.COMPONENTS:
            return _component_branches(self, diameters, labels)
        if not _points(diameters):
            return _interval_branches(self, diameters, labels)
        diameters = _exact(diameters)
        e = self.tolerance
        order = sorted(range(len(diameters)), key=lambda j: diameters[j])
        ds = [diameters[j] for j in order]
        prefix = [0]
        for j in order:
            prefix.append(prefix[-1] | 1 << (j if labels is None else labels[j]))
        points = sorted({max(0.0, d - e) for d in ds} | {d + e for d in ds})
        k = len(ds)
        a = b = 0
        out: list[list] = []
        last_run = None
        for lo, hi in zip(points, points[1:], strict=False):
            x = (lo + hi) / 2.0
            while a < k and ds[a] < x and not abs(ds[a] - x) < e:
                a += 1
            b = max(b, a)
            while b < k and abs(ds[b] - x) < e:
                b += 1
            if a == b:
                last_run = None
                continue
            if last_run == (a, b):
                out[-1][1] = hi
                continue
            out.append([lo, hi, prefix[b] ^ prefix[a]])
            last_run = (a, b)
        return [ReadingBranch(lo, hi, m) for lo, hi, m in out]

    def indistinguishable_sets(self, diameters: Sequence[float]) -> list[tuple[int, ...]]:
        return _components(diameters, lambda d: self.reading_interval(d), closed=False)

    def reading_windows(self, diameters: Sequence[Diameter]) -> list[int] | None:
        # The states a reading r can come from, lo - e < r < hi + e, are a run.
        spans = _ascending_spans(diameters)
        if spans is None:
            return None
        n = len(spans)
        two = 2.0 * self.tolerance
        fuzz = 1e-9 * max(max((hi for _lo, hi in spans), default=1.0), two)
        out = []
        b = 0
        for a in range(n):
            b = max(b, a)
            top = spans[a][1]
            while b < n and spans[b][0] - top < two:
                b += 1
            near = [j for j in (b - 1, b) if a <= j < n]
            if any(abs(spans[j][0] - top - two) < fuzz for j in near):
                return None
            out.append(((1 << b) - 1) ^ ((1 << a) - 1))
        return out

    def shared_reading_probability(self, diameters: Sequence[Diameter]) -> list[float] | None:
        # A reading orients exactly when it comes from one state alone: the part of the
        # state's reading set that its neighbours in diameter order do not reach.
        spans = _ascending_spans(diameters)
        if spans is None:
            return None
        k = len(spans)
        e = self.tolerance
        out = []
        for t, (d_lo, d_hi) in enumerate(spans):
            lo = d_lo - e if t == 0 else max(d_lo - e, spans[t - 1][1] + e)
            hi = d_hi + e if t == k - 1 else min(d_hi + e, spans[t + 1][0] - e)
            out.append(1.0 - max(0.0, hi - lo) / (d_hi - d_lo + 2.0 * e))
        return out

    def narrowed(self, inset: float) -> ToleranceSensor:
        return ToleranceSensor(max(self.tolerance - inset, self.tolerance / 2.0))

    def describe(self) -> str:
        return f"diameter sensor: a reading lies within \u00b1{self.tolerance:.12g} mm of it"

    def to_dict(self) -> dict[str, Any]:
        return {"model": "tolerance", "tolerance_mm": self.tolerance}


LED_EDGE_REL = 1e-6
"""A width within this fraction of the pitch of a beam's height may block that beam or not."""

LED_MAX_NOISE_PITCHES = 1000
"""The largest alignment noise an LED array may declare, in beam pitches: the reading
branches are made one beam count at a time, so a noise of 10^5 pitches took 13 s and one of
10^7 exhausted the memory; no array is misaligned by a thousand beams (a unit mistake)."""

READING_EPS = 1e-9
"""Readings within this fraction of the pitch of a beam count are taken as that count."""

LED_WINDOW_REL = 0.25
"""A plan file's LED window reaches this fraction of the pitch beyond its outer beam counts
(:meth:`LedSensor.window`)."""

LED_WINDOW_DIGITS = 4
"""An LED window's ends keep this many decimals beyond the pitch's first significant one
(never fewer than 6: nanometres), :func:`led_window_decimals`."""


def led_window_decimals(pitch: float) -> int:
    """Decimals (mm) an LED window's ends are rounded to: 6, more for a pitch below 0.01 mm,
    so the rounding stays within 1e-4 of the pitch.

    >>> led_window_decimals(0.05), led_window_decimals(2.0), led_window_decimals(1e-4)
    (6, 6, 8)
    """
    return max(6, math.ceil(-math.log10(pitch)) + LED_WINDOW_DIGITS)


def led_count(pitch: float, width: float) -> int:
    """Number of beams at heights ``k * pitch`` (k >= 1) strictly below ``width``."""
    if width <= 0.0:
        return 0
    return max(0, math.ceil(width / pitch - 1e-12) - 1)


@dataclass(frozen=True)
class LedSensor:
    """An LED array of beam pitch ``pitch`` mm with alignment noise ``noise`` mm."""

    pitch: float
    noise: float = 0.0
    model: str = "led"

    @property
    def informative(self) -> bool:
        return True

    def counts(self, diameter: Diameter) -> tuple[int, int]:
        """The smallest and largest beam count a state of this diameter can block.

        Widths within ``LED_EDGE_REL * pitch`` of a beam's height count both ways, so a
        diameter that sits on a beam (an exact multiple of the pitch) is not trusted to one
        count.
        """
        e = self.noise + LED_EDGE_REL * self.pitch
        lo, hi = span(diameter)
        return led_count(self.pitch, lo - e), led_count(self.pitch, hi + e)

    def count_of(self, reading: float) -> int:
        """The beam count a reading (mm) stands for."""
        return round(reading / self.pitch)

    def window(self, c_lo: int, c_hi: int) -> tuple[float, float]:
        """The closed reading interval a plan file gives a branch over beam counts
        ``c_lo..c_hi``: ``[(c_lo - 1/4) p, (c_hi + 1/4) p]``, ends rounded to
        :func:`led_window_decimals` and clipped at 0.

        design.md: a controller follows the branch whose closed interval holds the reading,
        the beam count times the pitch. However it computes that product (float64 or float32,
        ``c / (1 / p)``, fixed-point micrometres, decimal), it lands within a quarter pitch of
        ``c * p``, so in the window of its count. The windows of different branches stay half
        a pitch apart: a reading half-way between the counts of two branches is in neither.

        >>> LedSensor(0.05).window(17, 17), LedSensor(0.05).window(13, 14)
        ((0.8375, 0.8625), (0.6375, 0.7125))
        >>> LedSensor(0.05).window(0, 1)
        (0.0, 0.0625)
        """
        q = LED_WINDOW_REL * self.pitch
        digits = led_window_decimals(self.pitch)
        return max(0.0, round(c_lo * self.pitch - q, digits)), round(c_hi * self.pitch + q, digits)

    def counts_held(self, lo: float, hi: float) -> tuple[int, int]:
        """The first and last beam count whose reading the closed ``[lo, hi]`` holds (empty
        when first > last): a window of :meth:`window`, or an older file's zero-width one
        at the float64 product ``c * p`` (within ``READING_EPS`` of the pitch)."""
        p = self.pitch
        return math.ceil(lo / p - READING_EPS), math.floor(hi / p + READING_EPS)

    def reading_interval(self, diameter: Diameter) -> tuple[float, float] | None:
        c0, c1 = self.counts(diameter)
        return c0 * self.pitch, c1 * self.pitch

    def branch_reach(self, diameter: Diameter) -> tuple[float, float] | None:
        # reads_into: the branch holds a count c0..c1 (counts_held); a positive share: the
        # widths (first * p, (last + 1) * p] of its counts meet [d_lo - e, d_hi + e].
        c0, c1 = self.counts(diameter)
        p, e = self.pitch, self.noise
        slack = 2.0 * READING_EPS * p
        d_lo, d_hi = span(diameter)
        return min(c0 * p, d_lo - e - p) - slack, max(c1 * p, d_hi + e) + slack

    def consistent(self, diameter: Diameter, reading: float) -> bool:
        c0, c1 = self.counts(diameter)
        return c0 <= self.count_of(reading) <= c1

    def reads_into(self, diameter: Diameter, lo: float, hi: float) -> bool:
        c0, c1 = self.counts(diameter)
        first, last = self.counts_held(lo, hi)
        return max(c0, first) <= min(c1, last)

    def can_read_alike(self, d1: Diameter, d2: Diameter) -> bool:
        a, b = self.counts(d1), self.counts(d2)
        return a[0] <= b[1] and b[0] <= a[1]

    def reading_reach(self) -> float:
        return 2.0 * self.noise + self.pitch

    def nominal_reading(self, diameter: Diameter) -> float | None:
        lo, hi = span(diameter)
        return led_count(self.pitch, (lo + hi) / 2.0) * self.pitch

    def read(self, width: float) -> float | None:
        return led_count(self.pitch, width) * self.pitch

    def probe_readings(self, diameter: Diameter, inset: float) -> tuple[float, ...]:
        c0, c1 = self.counts(diameter)
        return tuple(c * self.pitch for c in range(c0, c1 + 1))

    def reading_probability(self, diameter: Diameter, lo: float | None, hi: float | None) -> float:
        if lo is None or hi is None:
            return 1.0
        # Count c means c * p < width <= (c + 1) * p; the branch holds counts first..last.
        first, last = self.counts_held(lo, hi)
        if first > last:
            return 0.0
        wlo, whi = first * self.pitch, (last + 1) * self.pitch
        e = self.noise
        d_lo, d_hi = span(diameter)
        if d_hi - d_lo + 2.0 * e <= 0.0:
            return 1.0 if wlo < d_lo <= whi else 0.0
        return _uniform_share(wlo, whi, (d_lo, d_hi), e)

    def uncovered_reading(
        self, diameter: Diameter, intervals: Sequence[tuple[float, float]]
    ) -> float | None:
        c0, c1 = self.counts(diameter)
        held = [self.counts_held(a, b) for a, b in intervals]
        for c in range(c0, c1 + 1):
            if not any(a <= c <= b for a, b in held):
                return c * self.pitch
        return None

    def split(
        self,
        diameters: Sequence[float],
        grouping: Grouping | str = Grouping.EXACT,
        labels: Labels = None,
    ) -> list[ReadingBranch]:
        """The beam-count cells (each count, the states that can block it), neighbours with
        equal states merged; each branch's interval is its counts' :meth:`window`."""
        if not diameters:
            return []
        if Grouping(grouping) is Grouping.COMPONENTS:
            return [
                ReadingBranch(*self.window(*self.counts_held(b.lo, b.hi)), b.mask)
                for b in _component_branches(self, diameters, labels)
            ]
        n = len(diameters)
        extents = [self.counts(d) for d in diameters]
        # The states that can block a count change only where an extent starts or ends:
        # one cell per run of counts between those, not one per count (a pitch of 0.1 um
        # has ten million counts per millimetre of diameters).
        bounds = sorted({c for lo, hi in extents for c in (lo, hi + 1)})
        cells = []
        for a, nxt in zip(bounds, bounds[1:], strict=False):
            members = [i for i in range(n) if extents[i][0] <= a <= extents[i][1]]
            cells.append((float(a), float(nxt - 1), _mask(members, labels)))
        return [
            ReadingBranch(*self.window(int(a), int(b)), m)
            for a, b, m in _merge_cells(cells, gap=1.0)
        ]

    def indistinguishable_sets(self, diameters: Sequence[float]) -> list[tuple[int, ...]]:
        return _components(diameters, lambda d: self.reading_interval(d), closed=True)

    def reading_windows(self, diameters: Sequence[float]) -> list[int] | None:
        return None

    def shared_reading_probability(self, diameters: Sequence[float]) -> list[float] | None:
        return None

    def narrowed(self, inset: float) -> LedSensor:
        return self

    def describe(self) -> str:
        return (
            f"LED array: beams every {self.pitch:.12g} mm, alignment noise {self.noise:.12g} mm; "
            "the reading is the blocked beams times the pitch"
        )

    def to_dict(self) -> dict[str, Any]:
        return {"model": "led", "pitch_mm": self.pitch, "noise_mm": self.noise}


SensorModel = NoSensor | ToleranceSensor | LedSensor
"""The concrete models (for type hints where a value, not the protocol, is meant)."""


def _ascending_spans(diameters: Sequence[Diameter]) -> list[tuple[float, float]] | None:
    """The diameters as intervals when both ends ascend (points, or snapped clusters,
    docs/conventions.md), else None.

    Only then are the states one reading can come from a run in this order, which the fast
    paths :meth:`Sensor.reading_windows` and :meth:`Sensor.shared_reading_probability` use.
    """
    spans = [span(d) for d in diameters]
    for (lo0, hi0), (lo1, hi1) in zip(spans, spans[1:], strict=False):
        if lo0 > lo1 or hi0 > hi1:
            return None
    return spans


def _uniform_share(lo: float, hi: float, diameter: tuple[float, float], e: float) -> float:
    """The share of ``[lo, hi]`` in a state's widths ``[d_lo - e, d_hi + e]`` (readings
    uniform over them: :meth:`Sensor.reading_probability`); the widths must not be empty."""
    d_lo, d_hi = diameter
    a, b = max(lo, d_lo - e), min(hi, d_hi + e)
    return max(0.0, min(1.0, (b - a) / (d_hi - d_lo + 2.0 * e)))


def _mask(positions: Sequence[int] | range, labels: Labels) -> int:
    """The bit mask of the states at these positions, by their labels."""
    m = 0
    for j in positions:
        m |= 1 << (j if labels is None else labels[j])
    return m


def _merge_cells(cells: list[tuple[float, float, int]], gap: float) -> list[list]:
    """Drop empty cells and join neighbours (at most ``gap`` apart) with equal members."""
    merged: list[list] = []
    for a, b, members in cells:
        if not members:
            continue
        if merged and merged[-1][2] == members and merged[-1][1] >= a - gap:
            merged[-1][1] = b
        else:
            merged.append([a, b, members])
    return merged


def _interval_branches(
    sensor: ToleranceSensor, diameters: Sequence[Diameter], labels: Labels
) -> list[ReadingBranch]:
    """Exact reading cells of states with diameter intervals (open reading sets).

    Between consecutive ends of the reading sets, the states whose set holds the cell's
    middle; neighbours with equal states merged. O(n * cells): intervals can nest, so the
    states of a cell need not be a run.
    """
    sets = [sensor.reading_interval(d) for d in diameters]
    ends = sorted({x for iv in sets if iv is not None for x in iv})
    cells = []
    for lo, hi in zip(ends, ends[1:], strict=False):
        x = (lo + hi) / 2.0
        inside = [j for j, iv in enumerate(sets) if iv is not None and iv[0] < x < iv[1]]
        cells.append((lo, hi, _mask(inside, labels)))
    return [ReadingBranch(a, b, m) for a, b, m in _merge_cells(cells, gap=0.0)]


def _components(diameters: Sequence, extent, closed: bool) -> list[tuple[int, ...]]:
    """Connected components of overlapping reading intervals, in the order of their lower
    ends (a diameter may be an interval, under a shape tolerance)."""
    spans = [extent(d) for d in diameters]
    order = sorted(range(len(diameters)), key=lambda i: spans[i])
    groups: list[list[int]] = []
    reach = -math.inf
    for i in order:
        lo, hi = spans[i]
        if groups and (lo <= reach if closed else lo < reach):
            groups[-1].append(i)
            reach = max(reach, hi)
        else:
            groups.append([i])
            reach = hi
    return [tuple(g) for g in groups]


def _component_branches(
    sensor: Sensor, diameters: Sequence[float], labels: Labels = None
) -> list[ReadingBranch]:
    """The paper's branching: one branch per indistinguishable set, over its whole extent."""
    out = []
    for comp in sensor.indistinguishable_sets(diameters):
        ivs = [sensor.reading_interval(diameters[i]) for i in comp]
        lo = min(iv[0] for iv in ivs if iv is not None)
        hi = max(iv[1] for iv in ivs if iv is not None)
        out.append(ReadingBranch(lo, hi, _mask(comp, labels)))
    return out


def make_sensor(
    *,
    sensorless: bool = False,
    tolerance: float | None = None,
    led_pitch: float | None = None,
    noise: float | None = None,
) -> SensorModel:
    """The sensor model for the given settings; impossible settings are bad input.

    >>> make_sensor(tolerance=0.2)
    ToleranceSensor(tolerance=0.2, model='tolerance')
    """
    chosen = sum([sensorless, tolerance is not None, led_pitch is not None])
    if chosen > 1:
        raise InputError("choose one of --sensorless, --tolerance and --led-pitch")
    if noise is not None and led_pitch is None:
        raise InputError("--noise goes with --led-pitch")
    if tolerance is not None:
        if not math.isfinite(tolerance) or tolerance <= 0.0:
            raise InputError(f"--tolerance must be a finite positive number of mm, got {tolerance}")
        return ToleranceSensor(float(tolerance))
    if led_pitch is not None:
        if not math.isfinite(led_pitch) or led_pitch <= 0.0:
            raise InputError(f"--led-pitch must be a finite positive number of mm, got {led_pitch}")
        e = 0.0 if noise is None else noise
        if not math.isfinite(e) or e < 0.0:
            raise InputError(f"--noise must be zero or a positive number of mm, got {noise}")
        if too_noisy(e, led_pitch):
            raise InputError(f"--noise {_noise_words(e, led_pitch)}")
        return LedSensor(float(led_pitch), float(e))
    return NoSensor()


def too_noisy(noise: float, pitch: float) -> bool:
    """Whether an LED array's alignment noise is more than :data:`LED_MAX_NOISE_PITCHES`
    pitches (the one bound, on the command line, in cell profiles and in plan files).

    >>> too_noisy(0.1, 0.5), too_noisy(600.0, 0.5)
    (False, True)
    """
    return noise > LED_MAX_NOISE_PITCHES * pitch


def _noise_words(noise: float, pitch: float) -> str:
    """Why an LED array's alignment noise is refused (:func:`too_noisy`)."""
    return (
        f"{noise:g} mm is more than {LED_MAX_NOISE_PITCHES} beam pitches of {pitch:g} mm: "
        "no LED array is that far off (check the units)"
    )


def _led_from_dict(data: dict) -> SensorModel:
    """The plan file's LED array, its noise bounded as on the command line."""
    pitch, noise = float(data["pitch_mm"]), float(data.get("noise_mm", 0.0))
    if not (math.isfinite(pitch) and pitch > 0.0 and math.isfinite(noise) and noise >= 0.0):
        return make_sensor(led_pitch=pitch, noise=noise)  # refused there, in its words
    # Past 2**53 pitches the widths are no beam counts: refused where counts are made.
    if too_noisy(noise, pitch) and noise < 2.0**53 * pitch:
        raise InputError(f"the plan's sensor noise_mm {_noise_words(noise, pitch)}")
    return LedSensor(pitch, noise)


def sensor_from_dict(data: object) -> SensorModel:
    """Read the plan file's ``sensor`` object (the inverse of ``Sensor.to_dict``)."""
    if not isinstance(data, dict) or "model" not in data:
        raise InputError("the plan's 'sensor' must be an object with a 'model'")
    model = data["model"]
    read = _FROM_DICT.get(model) if isinstance(model, str) else None
    if read is None:
        raise InputError(f"unknown sensor model {model!r}")
    try:
        return read(data)
    except (KeyError, TypeError, ValueError):
        raise InputError(f"the plan's {model!r} sensor lacks its parameters") from None


_FROM_DICT: dict[str, Any] = {
    "none": lambda data: NoSensor(),
    "tolerance": lambda data: make_sensor(tolerance=float(data["tolerance_mm"])),
    "led": _led_from_dict,
}
"""Per model name, how its ``to_dict`` object is read back: a new model adds its line."""


def sensor_warnings(sensor: Sensor, diameters: Sequence[float]) -> list[str]:
    """Settings that make the sensor useless for states of these diameters, in words.

    Not errors (a plan can still be made: it is the sensorless one), but almost always a
    mistake in units or scale: every state reads alike, or the sensor cannot tell apart two
    widths as far apart as the part is wide (an LED pitch or a tolerance larger than the
    part).

    >>> sensor_warnings(ToleranceSensor(0.01), [10.0, 12.0])
    []
    >>> sensor_warnings(LedSensor(50.0), [10.0, 12.0])  # doctest: +NORMALIZE_WHITESPACE
    ['every state reads alike (diameters 10 to 12 mm): the plan cannot use the readings',
     'states up to 50 mm apart can read alike, more than the largest diameter (12 mm)']
    """
    if not sensor.informative or not diameters:
        return []
    lo, hi = min(diameters), max(diameters)
    out = []
    if len(diameters) > 1 and sensor.can_read_alike(lo, hi):
        out.append(
            f"every state reads alike (diameters {lo:.4g} to {hi:.4g} mm): "
            "the plan cannot use the readings"
        )
    reach = sensor.reading_reach()
    if reach > hi:
        out.append(
            f"states up to {reach:.4g} mm apart can read alike, "
            f"more than the largest diameter ({hi:.4g} mm)"
        )
    if isinstance(sensor, LedSensor) and sensor.noise == 0.0 and not out:
        near = near_beam(sensor.pitch, diameters)
        if near:
            d, gap = near[0]
            out.append(
                f"with no alignment noise (--noise 0) the plan trusts each beam count; "
                f"{len(near)} diameter{' lies' if len(near) == 1 else 's lie'} within "
                f"{LED_NEAR_BEAM_REL:.0%} of the pitch of a beam (the closest: {d:.4g} mm, "
                f"{gap:.3g} mm from it): a part a little off flush or off size there blocks "
                "one beam more or less, which no branch may read (the line stops); give the "
                "array's alignment noise with --noise MM"
            )
    return out


LED_NEAR_BEAM_REL = 0.25
"""With no alignment noise, a diameter closer than this fraction of the pitch to a beam's
height (yet not on it, where both counts are read: ``LED_EDGE_REL``) is named by
:func:`sensor_warnings`: its count is trusted, though a part a little off flush or off size
flips it (a 60 mm part 0.25 degrees off flush reads 0.26 mm wider)."""


def near_beam(pitch: float, diameters: Sequence[float]) -> list[tuple[float, float]]:
    """The diameters within ``LED_NEAR_BEAM_REL * pitch`` of a beam's height ``k * pitch``
    but farther than ``LED_EDGE_REL * pitch`` (those count both ways), with their distance,
    closest first.

    >>> [(d, round(gap, 6)) for d, gap in near_beam(0.5, [40.0, 21.96, 33.25])]
    [(21.96, 0.04)]
    """
    out = []
    for d in diameters:
        gap = abs(d - round(d / pitch) * pitch)
        if LED_EDGE_REL * pitch < gap < LED_NEAR_BEAM_REL * pitch:
            out.append((d, gap))
    return sorted(out, key=lambda x: x[1])
