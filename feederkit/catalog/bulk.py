"""Import a directory of source files into the catalog: all files or none (or, asked, the good).

Every file is read and checked first; only then are all parts written, in one transaction.
A bad file, a duplicate name or a killed process leaves the catalog as it was; every bad
file is named with its path and reason. With ``skip_bad`` the good files are imported (one
transaction) and the bad ones, and parts whose name the catalog has from another source,
reported.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from feederkit.catalog.model import AddOutcome, check_part_name
from feederkit.catalog.schema import transaction
from feederkit.catalog.store import (
    CatalogLike,
    DuplicateNameError,
    _conn,
    landings_for,
    options_key,
    write_revision,
)
from feederkit.catalog.tolerances import PartCheck, PartTolerances
from feederkit.errors import InputError
from feederkit.importers import SUPPORTED_SUFFIXES, ImportedPart, ImportOptions, import_parts
from feederkit.landing.model import DEFAULT_SIDE_PROBABILITY, Landing, check_side_probability

Progress = Callable[[str, int, int, str], None]
"""Called as ``progress(phase, done, total, item)``; phase is ``read`` or ``write``."""


@dataclass(frozen=True)
class DirectoryImport:
    """The outcome of a directory import: one outcome per part, files that were not sources,
    and (with ``skip_bad``) the bad files skipped, each ``path: reason``."""

    outcomes: tuple[AddOutcome, ...]
    ignored: tuple[str, ...]
    bad: tuple[str, ...] = ()


SKIP_BAD_ADVICE = "--skip-bad imports the rest"
"""What :class:`BadFilesError` advises by default (``catalog import`` has ``--skip-bad``)."""


class BadFilesError(InputError):
    """Some files of a directory import are bad and nothing was imported.

    Keeps the parts of the message, so a command without ``--skip-bad`` (``demo``) can give
    advice that works for it: :meth:`with_advice`.
    """

    def __init__(self, bad: tuple[str, ...], total: int, root: Path) -> None:
        self.bad, self.total, self.root = bad, total, root
        super().__init__(self.with_advice(SKIP_BAD_ADVICE))

    def with_advice(self, advice: str) -> str:
        """The one-line message with ``advice`` in parentheses, every bad file named."""
        return (
            f"{len(self.bad)} of {self.total} files in {self.root} are bad, nothing imported "
            f"({advice}): {'; '.join(self.bad)}"
        )


OUTLINE_PEEK_BYTES = 1 << 20
"""An outline file is recognised from at most its first megabyte (it must parse as one)."""


def is_outline_file(path: Path) -> bool:
    """Whether a ``.json`` file is read as an outline file (design.md) by a folder import.

    A folder of parts often holds other JSON (plans, settings, a package.json): a file that
    parses as JSON and is not an object with "vertices" is not a part and is left alone
    (ignored) instead of being refused as a broken outline. A file that does not parse (not
    JSON, not UTF-8, truncated, empty) cannot be told to be something else, so it is read as
    an outline and reported as a bad file with the reason. Beyond the first megabyte the file
    is an outline when that megabyte holds the text ``"vertices"``.
    """
    try:
        with path.open("rb") as fh:
            head = fh.read(OUTLINE_PEEK_BYTES + 1)
    except OSError:
        return True  # unreadable: let the import name the reason
    if len(head) > OUTLINE_PEEK_BYTES:
        return b'"vertices"' in head
    try:
        data = json.loads(head.decode("utf-8-sig"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return True  # broken JSON: reported as a bad file, not silently ignored
    return isinstance(data, dict) and "vertices" in data


def source_files(directory: Path) -> tuple[list[Path], list[Path]]:
    """Supported source files under ``directory`` (recursive, sorted) and the other files.

    Only supported extensions count; a ``.json`` file counts when it is an outline file
    (:func:`is_outline_file`).
    """
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
            suffix = p.suffix.lower()
            source = suffix in SUPPORTED_SUFFIXES and (suffix != ".json" or is_outline_file(p))
            (found if source else ignored).append(p)
    return found, ignored


FOLDER_NAME_ADVICE = (
    "--revise makes this file the part's next revision; or rename the file, or change an "
    'outline file\'s "name"'
)
"""What a folder import advises for a name the catalog has from another source: the options
``catalog import`` has (it has no ``--name``; a part's name is the outline's "name", else the
file's stem)."""


FOLDER_RENAME_ADVICE = (
    "rename the file, or change an outline file's \"name\", to a name without ',' or ':'"
)
"""How a folder import (no ``--name``) gives a part another name: its name is the outline's
"name", else the file's stem."""


def _bad_line(path: Path, exc: InputError) -> str:
    """One skipped file: ``path: reason``, a name clash with advice that works for a folder
    import (it has no ``--name``)."""
    if isinstance(exc, DuplicateNameError):
        return (
            f"{path}: duplicate name: part {exc.name!r} already exists from {exc.old_path} "
            f"({FOLDER_NAME_ADVICE})"
        )
    reason = str(exc)
    return reason if str(path) in reason else f"{path}: {reason}"


def check_one_file_options(options: ImportOptions) -> None:
    """Refuse a center of mass or a mesh pose for a folder: each belongs to one part, and
    every file of the folder would get it (InputError)."""
    given = [
        o for o, v in (("--pose K", options.pose), ("--com X Y", options.com)) if v is not None
    ]
    if given:
        said = " and ".join(given)
        raise InputError(
            f"{said}: a folder import would give {'them' if len(given) > 1 else 'it'} to every "
            f"file; add that part's file alone with catalog add FILE {said}"
        )


def import_directory(
    catalog: CatalogLike,
    directory: str | os.PathLike[str],
    options: ImportOptions = ImportOptions(),
    *,
    revise: bool = False,
    created_by: str | None = None,
    progress: Progress | None = None,
    skip_bad: bool = False,
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
    tolerances: PartTolerances = PartTolerances(),
    check_part: PartCheck | None = None,
) -> DirectoryImport:
    """Import every source file under ``directory`` in one transaction (all files or none).

    Part names come from the files (outline name or file stem); two files giving the same
    name are refused, and so is a name the catalog has from another source (unless
    ``revise``). Every file is read; a bad one raises :class:`BadFilesError` naming every bad
    file with its path and reason, and nothing is written; with ``skip_bad`` the good files
    are written and the bad ones, and the parts whose name is taken, are listed in
    :attr:`DirectoryImport.bad`. Every new revision stores ``tolerances``, checked against
    its part by ``check_part`` (:func:`~feederkit.catalog.store.write_revision`; a refusal
    is a bad file).
    """
    check_side_probability(side_probability)
    check_one_file_options(options)
    root = Path(directory)
    files, ignored = source_files(root)
    if not files:
        raise InputError(f"{root}: no source files (.json, .dxf, .stl, .obj, .ply) in it")
    batch: list[tuple[Path, str, ImportedPart, tuple[Landing, ...]]] = []
    seen: dict[str, Path] = {}
    bad: list[str] = []
    for k, path in enumerate(files):
        if progress:
            progress("read", k, len(files), str(path))
        try:
            timed = options.counting_from()  # the file's reading and its landings: one limit
            result, parts = import_parts(path, timed)
            names = [check_part_name(p.part.name, FOLDER_RENAME_ADVICE) for p in parts]
            landings = [landings_for(p, timed, path, side_probability) for p in parts]
        except InputError as exc:
            bad.append(_bad_line(path, exc))
            continue
        for name, p, lands in zip(names, parts, landings, strict=True):
            if name in seen:
                bad.append(f"{path}: duplicate name {name!r} (also from {seen[name]})")
                continue
            seen[name] = path
            batch.append((path, result.sha256, p, lands))
    if progress:
        progress("read", len(files), len(files), "")
    if bad and not skip_bad:
        raise BadFilesError(tuple(bad), len(files), root)
    outcomes = []
    with _conn(catalog, create=True) as conn, transaction(conn):
        for k, (path, sha, p, lands) in enumerate(batch):
            if progress:
                progress("write", k, len(batch), p.part.name)
            # A part the catalog refuses (a name taken by another source) is, with
            # skip_bad, skipped and named like a bad file; its savepoint undoes its writes.
            conn.execute("SAVEPOINT import_part")
            try:
                outcomes.append(
                    write_revision(
                        conn,
                        p,
                        source_path=str(path.resolve()),
                        sha256=sha,
                        options_key=options_key(options, side_probability, p.source.kind),
                        revise=revise,
                        created_by=created_by,
                        landings=lands,
                        tolerances=tolerances,
                        check_part=check_part,
                    )
                )
            except DuplicateNameError as exc:
                if not skip_bad:
                    # The single-file wording advises --name, which a folder import has not.
                    raise InputError(
                        f"{path}: duplicate name: part {exc.name!r} already exists from "
                        f"{exc.old_path}; nothing imported ({FOLDER_NAME_ADVICE}; "
                        "--skip-bad imports the rest)"
                    ) from None
                conn.execute("ROLLBACK TO import_part")
                bad.append(_bad_line(path, exc))
            except InputError as exc:
                if not skip_bad:
                    raise
                conn.execute("ROLLBACK TO import_part")
                bad.append(_bad_line(path, exc))
            conn.execute("RELEASE import_part")
        if progress:
            progress("write", len(batch), len(batch), "")
    return DirectoryImport(
        outcomes=tuple(outcomes), ignored=tuple(str(p) for p in ignored), bad=tuple(bad)
    )
