"""Resolve a SOURCE argument (design.md): an outline file, a CAD file, or a catalog part name.

A SOURCE that names an existing file is read as a file (``.json``, ``.dxf``, ``.stl``,
``.obj``, ``.ply``); otherwise it is a catalog part name, ``NAME`` (latest revision) or
``NAME@REV``, looked up in ``catalog`` (default ``$FEEDERKIT_CATALOG`` or ``./feederkit.db``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from feederkit.catalog import (
    RevisionTolerances,
    could_be_part_name,
    default_catalog_path,
    get_revision,
    landings_for,
    part_from_revision,
)
from feederkit.catalog.model import bad_revision, split_revision
from feederkit.catalog.store import NoSuchPartError
from feederkit.errors import InputError
from feederkit.importers import (
    NOT_ORIENTABLE,
    ImportOptions,
    Orientability,
    import_parts,
    orientability,
)
from feederkit.outline import unit_scale
from feederkit.part import Part, make_part

Point = tuple[float, float]


@dataclass(frozen=True)
class LoadedPart:
    """A part resolved from a SOURCE, with the import's warnings and its orientability;
    ``tolerances``: what its catalog revision stores (None: a part read from a file)."""

    part: Part
    warnings: tuple[str, ...]
    orientability: Orientability
    origin: str
    tolerances: RevisionTolerances | None = None


def _from_catalog(source: str, com: Point | None, catalog: str | None) -> LoadedPart:
    db = Path(catalog) if catalog is not None else default_catalog_path()
    if not db.is_file():
        raise InputError(f"{source}: no such file or catalog part (no catalog at {db})")
    name, rev = split_revision(source)
    try:
        revision = get_revision(db, name, rev)
    except NoSuchPartError as exc:  # a damaged row or catalog says so in its own line
        raise InputError(f"{source}: no such file or catalog part ({exc})") from None
    part = part_from_revision(revision)
    if com is not None:
        part = make_part(
            part.outline, com, hull_tolerance=revision.hull_tolerance, revision=part.revision
        )
    verdict = orientability(part, revision.hull_tolerance)
    notes = [w for w in revision.warnings if not w.startswith(NOT_ORIENTABLE)]
    if not verdict.orientable:
        notes.append(f"{NOT_ORIENTABLE}: {verdict.reason}")
    loaded = LoadedPart(part, tuple(notes), verdict, f"catalog {db}", revision.tolerances)
    if not verdict.orientable and revision.source_kind == "mesh":
        lands = [(x.name, x.part) for x in revision.landings]
        return _by_landings(loaded, lands, revision.hull_tolerance)
    return loaded


def _by_landings(
    loaded: LoadedPart, landings: Sequence[tuple[str, Part]], hull_tolerance: float | None
) -> LoadedPart:
    """A mesh part whose imported pose pushing cannot orient (a cylinder standing on its
    round end) is still a part to plan when another of its landings can: that landing's
    verdict, with a warning naming the pose that cannot (plans over landings check each
    selected one: ``--landings`` leaves it out). ``landings``: (name, part) of each;
    ``loaded`` itself when none can."""
    for name, part in landings:
        verdict = orientability(part, hull_tolerance)
        if verdict.orientable:
            notes = [w for w in loaded.warnings if not w.startswith(NOT_ORIENTABLE)]
            notes.append(
                f"the imported pose is {NOT_ORIENTABLE} ({loaded.orientability.reason}); "
                f"landing {name} is: leave the others out with --landings"
            )
            return dataclasses.replace(loaded, warnings=tuple(notes), orientability=verdict)
    return loaded


def load_parts_with_warnings(
    source: str,
    *,
    com: Point | None = None,
    catalog: str | None = None,
    options: ImportOptions | None = None,
) -> tuple[LoadedPart, ...]:
    """Every part a SOURCE holds, with the warnings of its import (unitless drawing, ...).

    A file gives one part, or every separate part of a drawing with ``options.all_parts``
    (named ``NAME``, ``NAME-2``, ...); a catalog name gives its revision. ``options`` sets the
    CAD import (units, layers, tolerances, mesh pose); ``com`` overrides the center of mass.
    Raises InputError naming the source when it is not a valid part.
    """
    opts = options or ImportOptions()
    if com is not None:
        opts = dataclasses.replace(opts, com=(float(com[0]), float(com[1])))
    path = Path(source)
    try:
        is_file, exists = path.is_file(), path.exists()
    except OSError as exc:  # e.g. a name longer than the file system holds
        raise InputError(f"{source[:80]}: cannot be a file ({exc.strerror or exc})") from None
    if is_file:
        _, parts = import_parts(path, opts)
        out = []
        for p in parts:
            loaded = LoadedPart(p.part, p.warnings, p.orientability, str(path))
            if not p.orientability.orientable and p.source.kind == "mesh":
                lands = [(x.name, x.part) for x in landings_for(p, opts, path)]
                loaded = _by_landings(loaded, lands, p.hull_tolerance)
            out.append(loaded)
        return tuple(out)
    if exists:
        raise InputError(f"{source}: not a file")
    if not could_be_part_name(source):
        name, at, rev = source.rpartition("@")
        if at and could_be_part_name(name):  # NAME@REV with a revision that is no number
            raise InputError(
                f"{source}: no such file, nor a catalog part: {bad_revision(name, rev)}"
            )
        raise InputError(f"{source}: no such file")
    found = _from_catalog(source, opts.com, catalog)  # a mistyped name says so first
    if opts.units is not None:
        unit_scale(opts.units)  # then an unknown unit
        raise InputError(
            f"{source}: --units applies to drawing files; a catalog part is stored in mm"
        )
    return (found,)


def labelled_warnings(
    source: str, parts: Sequence[LoadedPart], several: bool | None = None
) -> list[str]:
    """The import warnings of ``parts`` (those a SOURCE holds) as lines ``SOURCE: ...``.

    When the SOURCE holds several parts (``several``, default: more than one given), a
    warning every part carries (the drawing's own: its units, a frame, parts in holes) is
    said once under the SOURCE, and one of only some parts names them, ``SOURCE (NAME):
    ...``: a 6 mm square cut from a plate's hole is no '60 x 30 mm rectangle'."""
    if not (len(parts) > 1 if several is None else several):
        return [f"{source}: {w}" for p in parts for w in p.warnings]
    common = [w for w in parts[0].warnings if all(w in p.warnings for p in parts)] if parts else []
    lines = [f"{source}: {w}" for w in common]
    for p in parts:
        lines += [f"{source} ({p.part.name}): {w}" for w in p.warnings if w not in common]
    return lines


def load_part_with_warnings(
    source: str,
    *,
    com: Point | None = None,
    catalog: str | None = None,
    options: ImportOptions | None = None,
) -> LoadedPart:
    """The one part a SOURCE holds (:func:`load_parts_with_warnings`), for the commands that
    take a single outline: InputError when ``options.all_parts`` finds several, so that no
    part is silently left out."""
    loaded = load_parts_with_warnings(source, com=com, catalog=catalog, options=options)
    if len(loaded) > 1:
        names = ", ".join(x.part.name for x in loaded)
        raise InputError(
            f"{source}: holds {len(loaded)} separate parts ({names}) and this command takes "
            "one: leave out --all-parts to take the largest"
        )
    return loaded[0]


def load_part(
    source: str,
    *,
    com: Point | None = None,
    catalog: str | None = None,
    options: ImportOptions | None = None,
) -> Part:
    """Load one part from a SOURCE: an outline or CAD file, or a catalog name (``NAME[@REV]``).

    Raises InputError naming the source when it cannot be read or is not a valid part.
    """
    return load_part_with_warnings(source, com=com, catalog=catalog, options=options).part
