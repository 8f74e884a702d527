"""Sets a plan was found for, indexed for superset queries: a set inside one is as easy.

Without a margin floor a plan that orients a set orients every subset of it (section 6.1: at
the set's rotation a subset's image lies inside the set's image, and each of its reading
branches inside one of the image's), and its margins hold for the subset too, whose
overlap range around that rotation is as wide or wider (docs/planning.md, "Which plan among
the shortest"). So a set lying inside a set that some plan within ``k`` orients keeping a
margin of ``x`` has such a plan too. The margin stage's probes (``Refiner.keeps``) ask
"keeps ``x`` within ``k``?" of many sets that are new but lie inside a set a probe already
answered: on a 50-part mix at 1 % of 60 mm, half of the probes' searches. The length search
and the beams ask "within ``k``?" the same way (``WorstCase.inside_solved``, a set then
taking the larger set's action, whose node in a plan is the smaller set's own).
:class:`SolvedSets` answers "which kept set holds ``mask``?" by a bitmap of the kept sets
per state, the dual of :class:`~feederkit.planning.refuted.RefutedSets` (a set holding a
refuted set is refuted).
"""

from __future__ import annotations

from collections.abc import Callable

from feederkit.machine import members

MAX_ROWS = 32768
"""Sets kept at most: each state's bitmap has a bit per set, so a query costs a few
operations on integers of this many bits; past it nothing more is kept."""

MAX_TRIES = 8
"""A query tries at most this many of the sets holding ``mask``, the latest first (what was
found for one may not be enough: too small a margin)."""


class SolvedSets:
    """Sets a plan was found for, as a bitmap per state of the sets that hold it.

    >>> s = SolvedSets(4)
    >>> s.add(0b0111)
    >>> s.add(0b1100)
    >>> s.holder(0b0101, lambda m: True), s.holder(0b0100, lambda m: True)
    (7, 12)
    >>> s.holder(0b1001, lambda m: True) is None
    True
    >>> s.holder(0b0100, lambda m: m != 0b1100)
    7
    """

    def __init__(self, n: int) -> None:
        self._by_state = [0] * n
        self._rows: list[int] = []
        self._kept: set[int] = set()

    def __len__(self) -> int:
        return len(self._rows)

    def add(self, mask: int) -> None:
        """Keep ``mask`` (once; past ``MAX_ROWS`` sets nothing more)."""
        if mask in self._kept or len(self._rows) >= MAX_ROWS:
            return
        bit = 1 << len(self._rows)
        self._rows.append(mask)
        self._kept.add(mask)
        by_state = self._by_state
        for i in members(mask):
            by_state[i] |= bit

    def holder(self, mask: int, fits: Callable[[int], bool]) -> int | None:
        """A kept set holding ``mask`` for which ``fits`` is true (the latest of the first
        ``MAX_TRIES`` holding it), or None."""
        if not self._rows or not mask:
            return None
        by_state = self._by_state
        rest = mask
        low = rest & -rest
        found = by_state[low.bit_length() - 1]
        rest ^= low
        while rest and found:
            low = rest & -rest
            found &= by_state[low.bit_length() - 1]
            rest ^= low
        tries = 0
        while found and tries < MAX_TRIES:
            top = found.bit_length() - 1
            row = self._rows[top]
            if fits(row):
                return row
            found ^= 1 << top
            tries += 1
        return None
