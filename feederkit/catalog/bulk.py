"""Import a directory of source files into the catalog: all files or none.

Every file is read and checked first; only then are all parts written, in one transaction.
A bad file, a duplicate name or a killed process leaves the catalog as it was.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from feederkit.catalog.model import AddOutcome, check_name
from feederkit.catalog.schema import transaction
from feederkit.catalog.store import CatalogLike, _conn, write_revision
from feederkit.errors import InputError
from feederkit.importers import SUPPORTED_SUFFIXES, ImportedPart, ImportOptions, import_parts

Progress = Callable[[str, int, int, str], None]
"""Called as ``progress(phase, done, total, item)``; phase is ``read`` or ``write``."""


@dataclass(frozen=True)
class DirectoryImport:
    """The outcome of a directory import: one outcome per part, and files that were not sources."""

    outcomes: tuple[AddOutcome, ...]
    ignored: tuple[str, ...]


def source_files(directory: Path) -> tuple[list[Path], list[Path]]:
    """Supported source files under ``directory`` (recursive, sorted) and the other files."""
    if not directory.exists():
        raise InputError(f"{directory}: no such directory")
    if not directory.is_dir():
        raise InputError(f"{directory}: not a directory")
    found, ignored = [], []
    for root, dirs, files in os.walk(directory):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for f in sorted(files):
            p = Path(root) / f
            if f.startswith("."):
                continue
            (found if p.suffix.lower() in SUPPORTED_SUFFIXES else ignored).append(p)
    return found, ignored


def import_directory(
    catalog: CatalogLike,
    directory: str | os.PathLike[str],
    options: ImportOptions = ImportOptions(),
    *,
    revise: bool = False,
    created_by: str | None = None,
    progress: Progress | None = None,
) -> DirectoryImport:
    """Import every source file under ``directory`` in one transaction (all files or none).

    Part names come from the files (outline name or file stem); two files giving the same
    name are refused. Raises InputError naming the first bad file; nothing is written then.
    """
    root = Path(directory)
    files, ignored = source_files(root)
    if not files:
        raise InputError(f"{root}: no source files (.json, .dxf, .stl, .obj, .ply) in it")
    batch: list[tuple[Path, str, ImportedPart]] = []
    seen: dict[str, Path] = {}
    for k, path in enumerate(files):
        if progress:
            progress("read", k, len(files), str(path))
        result, parts = import_parts(path, options)
        for p in parts:
            name = check_name(p.part.name)
            if name in seen:
                raise InputError(f"duplicate name {name!r}: from {seen[name]} and {path}")
            seen[name] = path
            batch.append((path, result.sha256, p))
    if progress:
        progress("read", len(files), len(files), "")
    outcomes = []
    with _conn(catalog, create=True) as conn, transaction(conn):
        for k, (path, sha, p) in enumerate(batch):
            if progress:
                progress("write", k, len(batch), p.part.name)
            outcomes.append(
                write_revision(
                    conn,
                    p,
                    source_path=str(path.resolve()),
                    sha256=sha,
                    options_key=options.as_key(),
                    revise=revise,
                    created_by=created_by,
                )
            )
        if progress:
            progress("write", len(batch), len(batch), "")
    return DirectoryImport(outcomes=tuple(outcomes), ignored=tuple(str(p) for p in ignored))
