"""Words for counts and limits in messages: one rule each, so no line anywhere reads
"1 operations", and no stated maximum is one the user cannot use.

>>> plural(1, "operation")
'1 operation'
>>> plural(3, "vertex", "vertices")
'3 vertices'
>>> at_most(6.0274084767)
'6.02740'
"""

from __future__ import annotations

import math
from decimal import ROUND_FLOOR, Decimal


def plural(n: int, word: str, many: str | None = None) -> str:
    """``n`` and the noun in the number it takes: ``1 part``, ``2 parts``, ``0 parts``;
    ``many`` is the plural when it is not ``word + "s"`` (``1 vertex``, ``3 vertices``)."""
    return f"{n} {word if n == 1 else (many or word + 's')}"


def at_most(x: float, digits: int = 6) -> str:
    """``x`` to ``digits`` significant digits, rounded down (toward minus infinity): a
    largest value that works, printed so that the printed value works too (``{x:.6g}``
    rounds 6.0274085 up to 6.02741, past the limit). The shortest text when it reads back
    as at most ``x`` (0.3 is the float 0.3), else the digits rounded down, significant
    trailing zeros kept.

    >>> at_most(0.3)
    '0.3'
    >>> at_most(0.000123456789)
    '0.000123456'
    """
    short = f"{x:.{digits}g}"
    if x == 0.0 or not math.isfinite(x) or float(short) <= x:
        return short
    exact = Decimal(x)  # the float's exact binary value
    quantum = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    return format(exact.quantize(quantum, rounding=ROUND_FLOOR), "g")


FLOAT_NOISE_DIGITS = 9
"""Significant digits a tolerance is snapped to before it is shown (0.3 minus float noise
shows as 0.3)."""


def shown_tolerance(x: float) -> str:
    """A critical tolerance or step bound for display, the terminal's and the report's: rid
    of float noise (:data:`FLOAT_NOISE_DIGITS`), then rounded down to 6 significant digits
    (:func:`at_most`: the printed value works, 0.4552137502 shows as 0.455213, not 0.455214).
    The values themselves (``--json``) are kept exact.

    >>> shown_tolerance(0.3 - 1e-12), shown_tolerance(0.4552137502)
    ('0.3', '0.455213')
    """
    return at_most(float(f"{x:.{FLOAT_NOISE_DIGITS}g}"))
