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
MAX_ROWS = 32768
"""Sets kept at most: a query scans every row (about 0.03 ms per thousand rows of one word),
and a search opens a set for about a millisecond, so more would cost more than it saves."""


class RefutedSets:
    """Sets with proven lower bounds (on their lengths; or minus a margin no plan keeps), as
    rows of 64-bit words.

    >>> r = RefutedSets(70)
    >>> r.add(0b0110, 3)
    >>> r.bound(0b1110, 2), r.bound(0b1110, 4), r.bound(0b1010, 2)
    (3.0, None, None)
    >>> r.add(1 << 69 | 1, 4)
    >>> r.bound((1 << 69) | 0b111, 4)
    4.0
    """

    def __init__(self, n: int) -> None:
        self._words = max(1, -(-n // 64))
        self._rows = np.zeros((_START, self._words), dtype=np.uint64)
        self._lb = np.zeros(_START, dtype=np.float64)
        self._count = 0

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
            self._rows = np.concatenate([self._rows, np.zeros_like(self._rows)])
            self._lb = np.concatenate([self._lb, np.zeros_like(self._lb)])
        self._rows[self._count] = self._split(mask)
        self._lb[self._count] = lb
        self._count += 1

    def bound(self, mask: int, need: float) -> float | None:
        """The largest bound of at least ``need`` among the kept sets inside ``mask`` (None:
        none)."""
        n = self._count
        if n == 0:
            return None
        lbs = self._lb[:n]
        hard = lbs >= need
        if not hard.any():
            return None
        rows = self._rows[:n]
        words = self._split(mask)
        inside = ((rows & words) == rows).all(axis=1) & hard
        if not inside.any():
            return None
        return float(lbs[inside].max())
