"""Values shared by the importers: the options a user sets and what an import returns."""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

from feederkit.errors import InputError
from feederkit.importers.budget import ImportLimits
from feederkit.outline import Outline

Point = tuple[float, float]

DEFAULT_FLATTEN_TOLERANCE = 0.01
"""Largest distance (mm) between a curve and the chords that replace it."""

DEFAULT_HULL_TOLERANCE = 0.05
"""Hull simplification (mm) for CAD files: flattened arcs give the edges a fence feels.

It is a cap: the tolerance used is :data:`REL_HULL_TOLERANCE` of the part's size when that
is smaller, so a 3 mm part's hull is not shrunk by 2 %."""

REL_HULL_TOLERANCE = 0.002
"""Default hull simplification as a share of the part's size (0.05 mm from 25 mm up)."""

DEFAULT_MAX_FILE_MB = 50.0
"""Files larger than this are refused unless the user allows them."""

CAD_SUFFIXES = (".dxf",)
MESH_SUFFIXES = (".stl", ".obj", ".ply")
OUTLINE_SUFFIXES = (".json",)
SUPPORTED_SUFFIXES = OUTLINE_SUFFIXES + CAD_SUFFIXES + MESH_SUFFIXES


@dataclass(frozen=True)
class ImportOptions:
    """How to read a source file. Lengths are millimetres.

    ``units`` overrides the file's units; ``layers`` keeps only those DXF layers (empty: all);
    ``all_parts`` imports every separate part of a drawing, not only the largest; ``pose``
    chooses a mesh's resting pose (index into the poses sorted by probability; default the
    most probable); ``com`` gives the center of mass in the outline frame; ``hull_tolerance``
    ``None`` means :data:`REL_HULL_TOLERANCE` of the part's size, at most
    :data:`DEFAULT_HULL_TOLERANCE`, for CAD and mesh files and an exact hull for outline
    files; ``space`` is the DXF space read (``model`` or ``paper``); ``keep_linetypes``
    names hidden or centre linetypes whose closed loops are part of the outline (by default
    they are left out: hidden edges, construction lines); ``limits`` are the import budgets
    (:mod:`.budget`).
    """

    units: str | None = None
    layers: tuple[str, ...] = ()
    flatten_tolerance: float = DEFAULT_FLATTEN_TOLERANCE
    hull_tolerance: float | None = None
    all_parts: bool = False
    pose: int | None = None
    com: Point | None = None
    max_file_mb: float = DEFAULT_MAX_FILE_MB
    allow_large: bool = False
    space: str = "model"
    keep_linetypes: tuple[str, ...] = ()
    limits: ImportLimits = field(default_factory=ImportLimits)

    def __post_init__(self) -> None:
        if self.space not in ("model", "paper"):
            raise InputError(f"--space must be model or paper, got {self.space!r}")
        if not self.flatten_tolerance > 0.0:
            raise InputError(f"--flatten-tolerance must be > 0, got {self.flatten_tolerance:g}")

    def counting_from(self, instant: float | None = None) -> ImportOptions:
        """These options with the import's time limit counted from ``instant`` (a
        ``time.monotonic()`` value; default now): a file's reading and its landings then
        share one limit (:attr:`ImportLimits.started`)."""
        started = time.monotonic() if instant is None else instant
        return replace(self, limits=replace(self.limits, started=started))

    def as_key(self) -> dict[str, object]:
        """The options that change the imported part (stored with a revision, compared later)."""
        return (
            {
                "units": self.units,
                "layers": sorted(self.layers),
                "flatten_tolerance": self.flatten_tolerance,
                "hull_tolerance": self.hull_tolerance,
                "pose": self.pose,
                "com": list(self.com) if self.com is not None else None,
            }
            | ({"space": self.space} if self.space != "model" else {})
            | ({"keep_linetypes": sorted(self.keep_linetypes)} if self.keep_linetypes else {})
        )


@dataclass(frozen=True)
class MeshPose:
    """A resting pose of a solid on the belt.

    ``index`` counts poses by decreasing ``probability``; ``transform`` is the 4x4 rigid motion
    (row-major) from the mesh's own frame to the belt frame: the resting face at z = 0, z up.
    """

    index: int
    probability: float
    count: int
    transform: tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class ImportedOutline:
    """One part read from a file: its outline (mm) and how it was obtained.

    ``source_units`` is the unit the file's coordinates were read in; ``pose`` is set for meshes.
    """

    outline: Outline
    kind: str
    source_units: str
    pose: MeshPose | None = None
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class ImportResult:
    """Everything read from one file: the parts (largest first), warnings, and the file's hash.

    ``others`` names the parts of a drawing that were left out (without ``all_parts``).
    """

    path: str
    sha256: str
    parts: tuple[ImportedOutline, ...]
    others: tuple[str, ...] = ()
    warnings: tuple[str, ...] = field(default=())
