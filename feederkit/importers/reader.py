"""Read any supported source file into outlines, then into parts with their orientability."""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

from feederkit.errors import InputError
from feederkit.importers.budget import Budget
from feederkit.importers.model import (
    CAD_SUFFIXES,
    DEFAULT_HULL_TOLERANCE,
    MESH_SUFFIXES,
    OUTLINE_SUFFIXES,
    REL_HULL_TOLERANCE,
    SUPPORTED_SUFFIXES,
    ImportedOutline,
    ImportOptions,
    ImportResult,
)
from feederkit.importers.orientable import Orientability, orientability
from feederkit.importers.plausible import named_unit_warnings, outline_size, size_warnings
from feederkit.mechanics.modelerror import KeptTolerance, kept_part
from feederkit.outline import read_outline_file, unit_scale
from feederkit.part import Part, make_part

NOT_ORIENTABLE = "not orientable by pushing"


@dataclass(frozen=True)
class ImportedPart:
    """A part built from an imported outline, with its orientability and all warnings."""

    part: Part
    source: ImportedOutline
    orientability: Orientability
    hull_tolerance: float | None
    warnings: tuple[str, ...]


def file_sha256(path: Path, chunk: int = 1 << 20) -> str:
    """SHA-256 of a file's bytes, hex."""
    h = hashlib.sha256()
    with path.open("rb") as fh:
        while block := fh.read(chunk):
            h.update(block)
    return h.hexdigest()


def check_file(path: Path, options: ImportOptions) -> None:
    """Refuse missing, empty, unsupported and (unless allowed) oversized files."""
    suffix = path.suffix.lower()
    if not path.exists():
        raise InputError(f"{path}: no such file")
    if not path.is_file():
        raise InputError(f"{path}: not a file")
    if suffix not in SUPPORTED_SUFFIXES:
        known = ", ".join(SUPPORTED_SUFFIXES)
        raise InputError(f"{path}: unsupported file type {path.suffix!r} (known: {known})")
    size = path.stat().st_size
    if size == 0:
        raise InputError(f"{path}: the file is empty")
    limit = options.max_file_mb * 1e6
    if size > limit and not options.allow_large:
        raise InputError(
            f"{path}: the file is {size / 1e6:.1f} MB, over the {options.max_file_mb:g} MB limit "
            "(use --allow-large to read it)"
        )


def read_source(path: str | Path, options: ImportOptions, name: str | None = None) -> ImportResult:
    """Read an outline ``.json``, ``.dxf``, ``.stl``, ``.obj`` or ``.ply`` file.

    ``name`` names the part (default: the outline file's name, else the file's stem).
    Raises InputError, one line naming the file, for anything that is not a valid part.
    """
    p = Path(path)
    check_file(p, options)
    budget = Budget(options.limits, str(p))
    digest = file_sha256(p)
    suffix = p.suffix.lower()
    label = name or p.stem
    others: list[str] = []
    warnings: list[str] = []
    if suffix in OUTLINE_SUFFIXES:
        outline, unit, named = read_outline_file(
            p, options.units, lambda n: budget.vertices(n, "points listed")
        )
        budget.loops(1 + len(outline.holes))
        # A file that names no units is read as mm: at a size no feeder part has, a unit
        # mistake is likelier (an outline in metres), said as for drawings and meshes. A
        # file that says "mm" is taken at its word (the paper's figures are 1 mm across)
        # but for sizes no part has at all (1 nm, 1000 km).
        size = outline_size(outline)
        if not named:
            warnings += size_warnings(size, unit, False, True)
        else:
            warnings += named_unit_warnings(size, unit)
        if name:
            outline = dataclasses.replace(outline, name=name)
        if options.com is not None:
            outline = dataclasses.replace(outline, com=options.com)
        parts = [ImportedOutline(outline=outline, kind="outline", source_units=unit)]
    elif suffix in CAD_SUFFIXES:
        from feederkit.importers.dxf import read_dxf  # ezdxf loads slowly: only when needed

        found, others, warnings = read_dxf(p, options, label, budget)
        parts = found
    elif suffix in MESH_SUFFIXES:
        from feederkit.importers.mesh import read_mesh  # trimesh loads slowly: only when needed

        parts = [read_mesh(p, options, label, budget)]
    else:  # pragma: no cover - check_file refused it
        raise InputError(f"{p}: unsupported file type")
    return ImportResult(
        path=str(p),
        sha256=digest,
        parts=tuple(parts),
        others=tuple(others),
        warnings=tuple(warnings),
    )


HULL_TOLERANCE_MAX_SHARE = 0.25
"""A ``--hull-tolerance`` of this share of the part's size or more is refused: chords that far
from the outline leave no hull of the part (the review's 1000 mm on a 60 mm plate ended in
"the center of mass lies on the boundary of the contact hull")."""


def effective_hull_tolerance(
    kind: str, options: ImportOptions, size_mm: float | None = None
) -> float | None:
    """The user's hull tolerance; else, for CAD files and meshes, a share of the part's size.

    The default is :data:`REL_HULL_TOLERANCE` of ``size_mm`` capped by
    :data:`DEFAULT_HULL_TOLERANCE` (0.05 mm from 25 mm up; 0.006 mm for a 3 mm part), and
    exact (``None``) for outline files.
    """
    if options.hull_tolerance is not None:
        t = options.hull_tolerance
        if not (t >= 0 and math.isfinite(t)):
            raise InputError(f"--hull-tolerance must be a finite number of mm >= 0, got {t:g}")
        if size_mm is not None and t >= HULL_TOLERANCE_MAX_SHARE * size_mm:
            # Simplified that far the hull is no longer the part's (its COM ends on it).
            raise InputError(
                f"--hull-tolerance {t:g} mm is not small against the part ({size_mm:.4g} mm "
                f"across): a hull simplified that far is not the part's"
            )
        return t
    if kind == "outline":
        return None
    if size_mm is None:
        return DEFAULT_HULL_TOLERANCE
    return min(DEFAULT_HULL_TOLERANCE, REL_HULL_TOLERANCE * size_mm)


def lowered_warning(kept: KeptTolerance) -> str:
    """The import's note that it simplified the contact hull less than asked, and why."""
    return (
        f"hull tolerance {kept.tolerance:.3g} mm, not {kept.asked:.3g}: at {kept.asked:.3g} mm"
        " the simplified hull rests in two states where the outline rests in one (chords"
        " across its arcs hold the part where it rolls; resting states in all: simplified"
        f" {kept.model}, outline {kept.outline})"
    )


def com_units_note(com: tuple[float, float], units: str) -> str:
    """The warning that ``--com`` is read in mm while the file's coordinates are in ``units``:
    a COM given in the drawing's units may still lie inside the part, wrong without a word."""
    scale = unit_scale(units)
    x, y = com
    return (
        f"--com ({x:g}, {y:g}) is read in mm, the file's coordinates in {units}: it lies at "
        f"({x / scale:.4g}, {y / scale:.4g}) in the file's units; check that it was given in mm"
    )


def build_part(
    imported: ImportedOutline,
    options: ImportOptions,
    extra_warnings: tuple[str, ...] = (),
    label: str | None = None,
) -> ImportedPart:
    """The part of an imported outline: simplified hull, COM check, and its orientability.

    When the part cannot be built and its size was found implausible (a unit mistake is the
    likely cause), the error says so.
    """
    size = outline_size(imported.outline)
    tol = effective_hull_tolerance(imported.kind, options, size)
    notes = list(extra_warnings) + list(imported.warnings)
    if options.com is not None and imported.source_units != "mm":
        notes.append(com_units_note(options.com, imported.source_units))
    # The import's time limit, between steps (``label``: the file, which errors name).
    check = Budget(options.limits, label or imported.outline.name).check_time
    try:
        exact = make_part(imported.outline, options.com)
        check()
        part, kept = kept_part(exact, tol)
        check()
        if kept is not None and kept.lowered:
            tol = kept.tolerance
            notes.append(lowered_warning(kept))
    except InputError as exc:
        doubts = [w for w in imported.warnings if "check the units" in w]
        if not doubts:
            raise
        raise InputError(f"{exc} ({doubts[0]})") from None
    verdict = orientability(part, tol)
    if not verdict.orientable:
        notes.append(f"{NOT_ORIENTABLE}: {verdict.reason}")
    return ImportedPart(
        part=part,
        source=imported,
        orientability=verdict,
        hull_tolerance=tol,
        warnings=tuple(notes),
    )


def import_parts(
    path: str | Path, options: ImportOptions, name: str | None = None
) -> tuple[ImportResult, list[ImportedPart]]:
    """Read a source file and build its part(s) (several only with ``options.all_parts``),
    the reading and the building under one import time limit."""
    if options.limits.started is None:
        options = options.counting_from()
    result = read_source(path, options, name)
    if options.com is not None and len(result.parts) > 1:
        raise InputError(
            f"{path}: --com X Y is one part's center of mass, and the file holds "
            f"{len(result.parts)} parts: import each alone (leave out --all-parts) to give it"
        )
    shared = result.warnings + tuple(f"left out: {o}" for o in result.others)
    try:
        built = [build_part(imp, options, shared, str(path)) for imp in result.parts]
    except InputError as exc:  # name the file, as every error reading it does
        if str(exc).startswith(f"{path}:"):
            raise
        raise InputError(f"{path}: {exc}") from None
    return result, built
