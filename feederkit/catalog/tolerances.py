"""A revision's own shape and COM tolerances, and the one rule that makes them a plan's.

design.md, "Uncertainty": a catalog revision may store its own shape tolerance ``t`` and COM
tolerance ``c``. A plan file declares one uncertainty, so the parts planned together get one
``t`` and one ``c``: a value given on the command line wins; else the largest value stored
over the planned parts, where a revision storing none and a part read from a file count as
0 (docs/uncertainty.md). :func:`declared_tolerances` is that rule, pure: every command that
plans catalog parts calls it with what it loaded.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from feederkit.errors import InputError
from feederkit.part import Part

MAX_TOLERANCE_MM = 1e9
"""No tolerance is larger than a coordinate may be (``feederkit.outline.MAX_COORD_MM``)."""

DEFAULT = "default"
"""Where a tolerance came from when nothing was given and no planned revision stores one."""
GIVEN = "given"
"""Where a tolerance came from when the caller gave it (the command line's flag)."""
CATALOG = "catalog"
"""The start of where a tolerance came from when a revision stores it: ``catalog: NAME rREV``."""


def check_tolerance(value: float | None, what: str) -> float | None:
    """``value`` (mm) when it may be stored as ``what`` (finite, at least 0), None when not
    given; InputError otherwise. The part's own bound is the caller's to check
    (``feederkit.uncertainty.check_for_part``)."""
    if value is None:
        return None
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number of mm, got {value!r}") from None
    if not math.isfinite(x) or x < 0.0 or x > MAX_TOLERANCE_MM:
        raise InputError(f"{what} must be a finite nonnegative number of mm, got {value!r}")
    return x + 0.0  # no -0.0


@dataclass(frozen=True)
class PartTolerances:
    """The tolerances (mm) to store with a new revision; None: not stored. Checked on
    construction (:func:`check_tolerance`)."""

    shape_tolerance_mm: float | None = None
    com_tolerance_mm: float | None = None

    def __post_init__(self) -> None:
        shape = check_tolerance(self.shape_tolerance_mm, "shape tolerance")
        com = check_tolerance(self.com_tolerance_mm, "COM tolerance")
        object.__setattr__(self, "shape_tolerance_mm", shape)
        object.__setattr__(self, "com_tolerance_mm", com)

    def over(self, previous: PartTolerances) -> PartTolerances:
        """These tolerances where given, ``previous`` (the latest revision's) where not: a
        new revision keeps a tolerance it is not given."""
        shape, com = self.shape_tolerance_mm, self.com_tolerance_mm
        return PartTolerances(
            previous.shape_tolerance_mm if shape is None else shape,
            previous.com_tolerance_mm if com is None else com,
        )

    def kept(self, previous: PartTolerances) -> dict[str, str]:
        """The tolerances :meth:`over` keeps from ``previous`` (stored there, not given here):
        field to words, as :data:`TOLERANCE_WORDS`."""
        return {
            field: what
            for field, what in TOLERANCE_WORDS
            if getattr(self, field) is None and getattr(previous, field) is not None
        }


TOLERANCE_WORDS = (("shape_tolerance_mm", "shape tolerance"), ("com_tolerance_mm", "COM tolerance"))
"""Each tolerance's field (the catalog's column, the plan file's key) and its name in words."""

PartCheck = Callable[[Part, PartTolerances], None]
"""The caller's check of the tolerances a new revision will store against its part (the part's
own bounds, ``feederkit.uncertainty.check_for_part``): its InputError refuses the revision."""


@dataclass(frozen=True)
class RevisionTolerances:
    """What one planned part's revision stores (mm; None: nothing stored)."""

    name: str
    revision: int
    shape_tolerance_mm: float | None = None
    com_tolerance_mm: float | None = None

    @property
    def label(self) -> str:
        """The revision in words: ``bracket r2``."""
        return f"{self.name} r{self.revision}"


@dataclass(frozen=True)
class DeclaredTolerances:
    """The shape and COM tolerance a plan declares (mm), where each came from, and the
    warnings of a given value below a stored one.

    ``shape_from`` and ``com_from``: ``"default"`` (nothing given, nothing stored),
    ``"given"``, or ``"catalog: NAME rREV"`` (the revision storing the largest)."""

    shape_tolerance_mm: float = 0.0
    com_tolerance_mm: float = 0.0
    shape_from: str = DEFAULT
    com_from: str = DEFAULT
    warnings: tuple[str, ...] = ()

    def sources(self) -> dict[str, str]:
        """Where each tolerance came from, keyed as the plan file's ``"uncertainty"``."""
        return {"shape_tolerance_mm": self.shape_from, "com_tolerance_mm": self.com_from}

    def note(self, key: str) -> str:
        """`` (catalog: bracket r2)`` after a value taken from the catalog, else nothing;
        ``key`` as in :meth:`sources`."""
        source = self.sources()[key]
        return f" ({source})" if source.startswith(CATALOG) else ""


def _mm(x: float) -> str:
    return f"{x:g} mm"


def _one(
    stored: list[tuple[str, float | None]], given: float | None, what: str
) -> tuple[float, str, str | None]:
    """One tolerance: (value, where from, warning or None)."""
    if given is not None:
        above = [(label, x) for label, x in stored if x is not None and x > given]
        if not above:
            return given, GIVEN, None
        named = ", ".join(f"{label} stores {_mm(x)}" for label, x in above)
        return (
            given,
            GIVEN,
            f"the {what} given, {_mm(given)}, is below the one stored in the catalog "
            f"({named}): the plan declares {_mm(given)}, as given",
        )
    best: tuple[str, float] | None = None
    for label, x in stored:
        if x is not None and (best is None or x > best[1]):
            best = (label, x)
    if best is None:
        return 0.0, DEFAULT, None
    return best[1], f"{CATALOG}: {best[0]}", None


def declared_tolerances(
    stored: Iterable[RevisionTolerances],
    shape_tolerance: float | None = None,
    com_tolerance: float | None = None,
) -> DeclaredTolerances:
    """The one shape and COM tolerance of a plan of the parts whose revisions store
    ``stored`` (parts read from files have none), given the command line's values (None:
    not given).

    A given value wins, with a warning when a planned revision stores a larger one (the user
    overrides the catalog knowingly); else the largest stored, named (ties: the first part);
    nothing stored anywhere is 0, the default. Values are checked by the caller
    (``feederkit.uncertainty.Uncertainty``).

    >>> stored = [RevisionTolerances("a", 1, 0.02), RevisionTolerances("b", 2, 0.05)]
    >>> d = declared_tolerances(stored)
    >>> d.shape_tolerance_mm, d.shape_from, d.com_tolerance_mm, d.com_from
    (0.05, 'catalog: b r2', 0.0, 'default')
    """
    revisions = list(stored)
    shape, shape_from, shape_warning = _one(
        [(r.label, r.shape_tolerance_mm) for r in revisions],
        shape_tolerance,
        "shape tolerance",
    )
    com, com_from, com_warning = _one(
        [(r.label, r.com_tolerance_mm) for r in revisions],
        com_tolerance,
        "COM tolerance",
    )
    return DeclaredTolerances(
        shape,
        com,
        shape_from,
        com_from,
        tuple(w for w in (shape_warning, com_warning) if w is not None),
    )
