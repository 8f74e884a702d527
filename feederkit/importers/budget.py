"""Import budgets: how large an input may grow while it is read, and a wall-clock deadline.

A hostile or broken file (blocks nested a thousand-fold, a MINSERT grid of a billion cells,
a million-vertex polyline, coordinates of 1e300) must be refused in one line, not hang the
tool. The limits are counted while reading, before the expensive geometry runs, and each
names the option that raises it (docs/import.md, budgets). The defaults are far above any
real part: a laser-cut plate with a thousand holes uses a few percent of them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from feederkit.errors import InputError

DEFAULT_MAX_ENTITIES = 10_000
DEFAULT_MAX_VERTICES = 1_000_000
DEFAULT_MAX_LOOPS = 5_000
DEFAULT_MAX_FACES = 1_000_000
DEFAULT_MAX_HULL_FACES = 4_000
DEFAULT_MAX_CROSSINGS = 50_000
DEFAULT_TIME_LIMIT_S = 30.0

MAX_PART_MM = 10_000.0
"""No feeder holds a part larger than 10 m: coordinates beyond this (after units) are refused."""

MAX_COORD_MM = 1e7
"""Coordinates farther than 10 km from the origin (after units) are a broken file."""


OPTION = {
    "entities": "--max-entities",
    "vertices": "--max-vertices",
    "loops": "--max-loops",
    "crossings": "--max-crossings",
    "faces": "--max-faces",
    "hull_faces": "--max-hull-faces",
}
"""The command-line option that raises each count budget."""


@dataclass(frozen=True)
class ImportLimits:
    """Budgets of one import (counts after block expansion and flattening; seconds of wall time).

    ``entities``: curve entities after block references are expanded; ``vertices``: points
    after flattening (and mesh vertices); ``loops``: closed loops (each hole is one);
    ``crossings``: pairs of drawn lines whose bounding boxes overlap (noding them costs
    about 0.5 s per 50,000); ``faces``: mesh triangles; ``hull_faces``: faces of a mesh's
    convex hull (the resting pose search grows with their square: 4,000 take about 3 s);
    ``seconds``: wall time of the whole import (from ``started`` when given); ``seconds_option``:
    the option that allows more (a command whose own ``--time-limit`` is shorter names that
    one).
    """

    entities: int = DEFAULT_MAX_ENTITIES
    vertices: int = DEFAULT_MAX_VERTICES
    loops: int = DEFAULT_MAX_LOOPS
    crossings: int = DEFAULT_MAX_CROSSINGS
    faces: int = DEFAULT_MAX_FACES
    hull_faces: int = DEFAULT_MAX_HULL_FACES
    seconds: float = DEFAULT_TIME_LIMIT_S
    seconds_option: str = "--import-time-limit"
    started: float | None = None
    """The ``time.monotonic()`` instant the seconds count from (None: each budget's start):
    the files' reading and their landings then share one limit."""

    def __post_init__(self) -> None:
        for what, option in OPTION.items():
            if not int(getattr(self, what)) >= 1:
                raise InputError(f"{option} must be at least 1, got {getattr(self, what)}")
        if not self.seconds > 0.0:
            raise InputError(f"--import-time-limit must be > 0 s, got {self.seconds:g}")


class Budget:
    """The running counts of one import against its :class:`ImportLimits` (not a value).

    Every ``add``-style call raises InputError naming the file, what was too large and the
    option to raise it, as soon as a count passes its limit or the deadline has passed.
    """

    def __init__(self, limits: ImportLimits, label: str) -> None:
        self.limits = limits
        self.label = label
        start = time.monotonic() if limits.started is None else limits.started
        self.deadline = start + limits.seconds
        self.counts = dict.fromkeys(OPTION, 0)

    def _add(self, what: str, n: int, noun: str) -> None:
        self.counts[what] += n
        limit = int(getattr(self.limits, what))
        if self.counts[what] > limit:
            raise InputError(
                f"{self.label}: more than {limit:,} {noun} (the import budget; "
                f"use {OPTION[what]} to raise it)"
            )
        self.check_time()

    def need(self, what: str, n: int, noun: str) -> None:
        """Refuse in advance when ``n`` more of ``what`` would pass the limit (no count kept)."""
        limit = int(getattr(self.limits, what))
        if self.counts[what] + n > limit:
            raise InputError(
                f"{self.label}: more than {limit:,} {noun} (the import budget; "
                f"use {OPTION[what]} to raise it)"
            )

    def entities(self, n: int = 1) -> None:
        """Count curve entities after block expansion."""
        self._add("entities", n, "entities after block expansion")

    def vertices(self, n: int, noun: str = "vertices after flattening") -> None:
        """Count points after flattening (or mesh vertices, or an outline file's ``noun``)."""
        self._add("vertices", n, noun)

    def segments(self, n: int) -> None:
        """Refuse more line pieces after noding (crossing lines multiply them) than vertices."""
        if n > self.limits.vertices:
            raise InputError(
                f"{self.label}: crossing lines make {n:,} line pieces, more than the "
                f"{self.limits.vertices:,} vertices of the import budget (use --max-vertices "
                "to raise it)"
            )
        self.check_time()

    def crossings(self, n: int) -> None:
        """Refuse drawings whose lines overlap in more pairs than the budget, before noding."""
        self.need("crossings", n, "pairs of lines that may cross")

    def loops(self, n: int) -> None:
        """Count closed loops (parts and holes)."""
        self._add("loops", n, "closed loops (parts and holes)")

    def faces(self, n: int) -> None:
        """Count mesh triangles."""
        self._add("faces", n, "mesh faces")

    def check_time(self) -> None:
        """Refuse once the wall-time budget has run out."""
        if time.monotonic() > self.deadline:
            raise InputError(
                f"{self.label}: the import took longer than {self.limits.seconds:g} s "
                f"(use {self.limits.seconds_option} to allow more)"
            )
