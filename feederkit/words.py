"""Words for counts in messages: one rule, so no line anywhere reads "1 operations".

>>> plural(1, "operation")
'1 operation'
>>> plural(3, "vertex", "vertices")
'3 vertices'
"""

from __future__ import annotations


def plural(n: int, word: str, many: str | None = None) -> str:
    """``n`` and the noun in the number it takes: ``1 part``, ``2 parts``, ``0 parts``;
    ``many`` is the plural when it is not ``word + "s"`` (``1 vertex``, ``3 vertices``)."""
    return f"{n} {word if n == 1 else (many or word + 's')}"
