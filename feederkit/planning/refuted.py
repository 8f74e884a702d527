"""Refuted sets indexed for subset queries: a set holding a hard set is at least as hard.

Without a margin floor a plan that orients a set orients every subset of it (section 6.1: a
subset's overlap ranges are unions of the set's, its images and reading branches inside the
set's), so lengths are monotone under subsets. The AND/OR search memoises each set it
refutes, but a new set is seldom one met before; it often *holds* one: on a random
200-point outline at 1 % (20 states, length 5) nine in ten of the sets the search refuted
held a smaller set refuted at the same depth. :class:`RefutedSets` answers "does ``mask``
hold a set known to need more than ``k`` operations?" with one vectorised test over every
refuted set kept, before the search opens ``mask`` (which costs its overlap ranges and their
reading branches). The hardest pair (``WorstCase.pair_bound``) is the two-state case of the
same fact. Margins are monotone the same way (docs/planning.md, "Which plan among the
shortest"): a set holding a set that no plan within ``k`` keeps a margin of ``x`` for keeps
none either, so the margin probes (``Refiner.keeps``) keep an index per budget, each set
valued ``-x``.
"""

from __future__ import annotations

import numpy as np

_START = 256
"""Rows the index starts with (doubled as it fills)."""
_PYTHON_ROWS = 48
"""A query with at most this many rows to scan scans them in pure Python."""
MAX_ROWS = 32768
"""Sets kept at most: a query scans every row (about 0.03 ms per thousand rows of one word),
and a search opens a set for about a millisecond, so more would cost more than it saves."""


class RefutedSets:
    """Sets with proven lower bounds (on their lengths; or minus a margin no plan keeps), as
    columns of 64-bit words.

    A search asks about the same set again and again (a margin probe per margin, a length
    per budget) while the index grows by appending, so each set asked remembers the bound
    and the rows it was found to hold nothing for: the next query at that bound or above
    scans only the rows added since.

    >>> r = RefutedSets(70)
    >>> r.add(0b0110, 3)
    >>> r.bound(0b1110, 2), r.bound(0b1110, 4), r.bound(0b1010, 2)
    (3.0, None, None)
    >>> r.add(1 << 69 | 1, 4)
    >>> r.bound((1 << 69) | 0b111, 4)
    4.0
    >>> r.add(0b1000, 5)
    >>> r.bound(0b1010, 2)
    5.0
    """

    def __init__(self, n: int) -> None:
        self._words = max(1, -(-n // 64))
        self._cols = np.zeros((self._words, _START), dtype=np.uint64)
        self._lb = np.zeros(_START, dtype=np.float64)
        self._count = 0
        self._masks: list[int] = []
        self._bounds: list[float] = []
        # mask -> (need, rows): no set among the first ``rows`` inside ``mask`` has a bound
        # of at least ``need``.
        self._clear: dict[int, tuple[float, int]] = {}

    def __len__(self) -> int:
        return self._count

    def _split(self, mask: int) -> np.ndarray:
        """``mask`` as little-endian 64-bit words."""
        return np.frombuffer(mask.to_bytes(8 * self._words, "little"), dtype="<u8")

    def add(self, mask: int, lb: float) -> None:
        """Keep ``mask`` with its bound ``lb`` (it needs at least ``lb`` operations); past
        ``MAX_ROWS`` sets nothing more is kept."""
        if self._count >= MAX_ROWS:
            return
        if self._count == len(self._lb):
            self._cols = np.concatenate([self._cols, np.zeros_like(self._cols)], axis=1)
            self._lb = np.concatenate([self._lb, np.zeros_like(self._lb)])
        self._cols[:, self._count] = self._split(mask)
        self._lb[self._count] = lb
        self._masks.append(mask)
        self._bounds.append(float(self._lb[self._count]))
        self._count += 1

    def bound(self, mask: int, need: float) -> float | None:
        """The largest bound of at least ``need`` among the kept sets inside ``mask`` (None:
        none)."""
        n = self._count
        start, floor = 0, need
        clear = self._clear.get(mask)
        if clear is not None and need >= clear[0]:
            if clear[1] == n:
                return None
            # The rows before hold nothing of at least clear[0] <= need: scan the new ones
            # at clear[0], so that what is remembered stays as strong.
            start, floor = clear[1], clear[0]
        if n - start <= _PYTHON_ROWS:
            return self._scan(mask, need, start, floor)
        lbs = self._lb[start:n]
        hard = lbs >= floor
        if hard.any():
            outside = np.zeros(n - start, dtype=np.uint64)
            for col, word in zip(self._cols, self._split(mask), strict=True):
                outside |= col[start:n] & ~word
            inside = (outside == 0) & hard
            if inside.any():
                found = lbs[inside].max()
                if found >= need:
                    return float(found)
                floor = need  # held below ``need`` only: remember the weaker fact
        self._clear[mask] = (floor, n)
        return None

    def _scan(self, mask: int, need: float, start: int, floor: float) -> float | None:
        """:meth:`bound` over the rows from ``start`` on, one at a time (few rows: numpy's
        fixed cost per call would be most of the work)."""
        found = None
        for row, lb in zip(self._masks[start:], self._bounds[start:], strict=True):
            if lb >= floor and not row & ~mask and (found is None or lb > found):
                found = lb
        if found is not None:
            if found >= need:
                return found
            floor = need  # held below ``need`` only: remember the weaker fact
        self._clear[mask] = (floor, self._count)
        return None
