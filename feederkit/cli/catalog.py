"""``feederkit catalog``: the parts catalog from the command line (init, add, import, list, ...).

No logic of its own: it parses options, calls :mod:`feederkit.catalog` and prints. The
catalog is ``--catalog PATH``, else ``$FEEDERKIT_CATALOG``, else ``./feederkit.db``.
"""

from __future__ import annotations

import sqlite3
import stat
import sys
import textwrap
import unicodedata
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from sqlite3 import Connection
from typing import Annotated, Any

import typer
from rich.box import SIMPLE_HEAD
from rich.markup import escape
from rich.progress import TextColumn
from rich.table import Table

from feederkit.catalog import (
    DEFAULT_WAIT,
    SCHEMA_VERSION,
    AddOutcome,
    PartTolerances,
    Revision,
    add_file,
    export_part,
    get_revision,
    import_directory,
    list_changeovers,
    list_parts,
    open_catalog,
    remove_part,
    resolve_catalog_path,
    revision_history,
)
from feederkit.catalog.export import export_warnings
from feederkit.catalog.model import split_revision
from feederkit.cli.catalog_analyze import analyze_command
from feederkit.cli.common import (
    DONE_WORK,
    CatalogOpt,
    JsonOpt,
    console,
    err_console,
    flag_words,
    plural,
    print_json,
    print_warnings,
    progress_bar,
)
from feederkit.cli.importopts import takes_import_options, with_com
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.jsonio import SQLITE_SIDE_SUFFIXES
from feederkit.landing.model import DEFAULT_SIDE_PROBABILITY, Landing, check_side_probability
from feederkit.part import Part
from feederkit.uncertainty import Uncertainty, check_for_part

RICH_TABLE_ROWS = 200
"""Longer tables are printed as plain columns."""

ORIENTABLE_NOTE = (
    "pushing orients the part on the ideal model (no rotation error, no vibration); "
    "plan and catalog analyze --rotation-error DEG say whether it has a strong plan "
    "under uncertainty"
)
"""What a part's stored ``orientable`` flag says: import judges it on the ideal push
function, so a part flagged orientable may still have no strong plan at the default rotation
error of 1 degree."""

ORIENT_HEADER = "orient*"
"""``catalog list``'s orientability column, marked for its footnote (the list keeps to 80
columns for names up to 24 characters, so the header stays 7 wide)."""


HULL_AREA_MARK = "+"
"""``catalog list`` marks a mesh's area with this, for its footnote (:data:`HULL_AREA_NOTE`)."""

HULL_AREA_NOTE = (
    "mm2 of a mesh: its convex hull seen from above, which is all the catalog keeps of a "
    "mesh's outline (what the fence feels), not its footprint; its holes are not known"
)
"""Why a mesh's area is its hull's: the mesh import keeps the convex hull of each resting
pose seen from above as the outline, so area and holes of its footprint are not stored."""


def area_fields(kind: str, area: float, holes: int) -> dict[str, object]:
    """The JSON fields of a part's area: ``area`` (mm2), ``area_of`` (``outline``, or
    ``convex hull`` for a mesh, whose stored outline is its hull) and ``holes`` (null for a
    mesh: not known)."""
    mesh = kind == "mesh"
    return {
        "area": area,
        "area_of": "convex hull" if mesh else "outline",
        "holes": None if mesh else holes,
    }


def _area_cells(kind: str, area: float, holes: int) -> tuple[str, str]:
    """``catalog list``'s mm2 and holes cells: a mesh's area marked as its hull's, its holes
    not known."""
    if kind == "mesh":
        return f"{area:.1f}{HULL_AREA_MARK}", "-"
    return f"{area:.1f}", str(holes)


def _area_words(kind: str, area: float, holes: int) -> str:
    """``catalog show``'s area row."""
    if kind == "mesh":
        return (
            f"{area:.3f} mm2 of its convex hull seen from above (a mesh: the catalog keeps "
            "that hull as its outline, not its footprint; holes not known)"
        )
    return f"{area:.3f} mm2, {plural(holes, 'hole')}"


def orientable_fields(orientable: bool) -> dict[str, bool]:
    """The JSON fields of a part's orientability: ``orientable_ideal``, and ``orientable``,
    the same value under its older name."""
    return {"orientable": orientable, "orientable_ideal": orientable}


def orientable_footnote(width: int = 80) -> str:
    """``catalog list``'s footnote on its :data:`ORIENT_HEADER` column, ``width`` wide."""
    text = f"* {ORIENT_HEADER.rstrip('*')}: {ORIENTABLE_NOTE}"
    return textwrap.fill(text, width=width, subsequent_indent="  ") + "\n"


catalog_app = typer.Typer(
    rich_markup_mode="markdown",
    name="catalog",
    help="The parts catalog (SQLite): import CAD files, list, show, remove and export parts.",
    no_args_is_help=True,
)

ComOpt = Annotated[
    tuple[float, float] | None,
    typer.Option("--com", metavar="X Y", help="Center of mass X Y (mm) in the outline's frame."),
]
ReviseOpt = Annotated[
    bool,
    typer.Option(
        "--revise", help="Make this file the next revision of an existing part of the same name."
    ),
]

SideOpt = Annotated[
    float,
    typer.Option(
        "--side-probability",
        metavar="P",
        help="Probability (0 < P < 1) that a flat part lands up, as drawn; down gets 1 - P.",
    ),
]

StoredShapeToleranceOpt = Annotated[
    float | None,
    typer.Option(
        "--shape-tolerance",
        metavar="MM",
        help="Store with the new revision: its hull vertices lie within MM of their drawn "
        "positions (below half its smallest hull edge in every landing); plans declare the "
        "largest their parts store unless given. Not given, the previous revision's is kept.",
    ),
]
StoredComToleranceOpt = Annotated[
    float | None,
    typer.Option(
        "--com-tolerance",
        metavar="MM",
        help="Store with the new revision: its centre of mass lies within MM of its nominal "
        "position (below its distance to the hull's edges), as --shape-tolerance.",
    ),
]


def stored_tolerances(shape: float | None, com: float | None) -> PartTolerances:
    """The tolerances ``add`` and ``import`` store (finite, at least 0; errors name the flags)."""
    with flag_words():
        return PartTolerances(shape, com)


def check_tolerances(part: Part, tolerances: PartTolerances) -> None:
    """The part's own bounds on the tolerances its new revision stores (half its smallest
    hull edge, its COM's distance to the hull: :func:`feederkit.uncertainty.check_for_part`),
    checked before anything is written; errors name the flags."""
    shape, com = tolerances.shape_tolerance_mm, tolerances.com_tolerance_mm
    with flag_words():
        check_for_part(Uncertainty(0.0, shape or 0.0, com or 0.0), part)


def _tolerance_words(o: AddOutcome) -> str:
    """``; stores shape tolerance 0.05 mm`` for an outcome whose revision stores tolerances."""
    stored = [
        f"{what} {value:g} mm"
        for what, value in (
            ("shape tolerance", o.shape_tolerance_mm),
            ("COM tolerance", o.com_tolerance_mm),
        )
        if value is not None
    ]
    return f"; stores {' and '.join(stored)}" if stored else ""


RevisionOpt = Annotated[
    int | None,
    typer.Option("--revision", min=1, metavar="N", help="Revision (default latest)."),
]
WaitOpt = Annotated[
    float,
    typer.Option(
        "--wait",
        metavar="S",
        min=0.0,
        max=86400.0,
        help=f"Seconds to wait while another process writes the catalog ({DEFAULT_WAIT:g}).",
    ),
]


def catalog_path(option: Path | None) -> Path:
    """The catalog file: the option, else ``$FEEDERKIT_CATALOG``, else ./feederkit.db."""
    return resolve_catalog_path(option)


@contextmanager
def opened(option: Path | None, wait: float, *, create: bool = False) -> Iterator[Connection]:
    """The catalog connection of a command, waiting up to ``wait`` s for a busy catalog."""
    conn = open_catalog(catalog_path(option), create=create, wait=wait)
    try:
        yield conn
    finally:
        conn.close()


@contextmanager
def opened_for_import(option: Path | None, wait: float) -> Iterator[Connection]:
    """The catalog connection of ``add`` and ``import``, which create a missing catalog.

    When the command fails (any exception, an interrupt too) and the catalog file did not
    exist before, or was an empty file, it is put back: removed (with the ``-wal``,
    ``-shm`` and ``-journal`` files the command made), or emptied again. A failed command
    leaves no new catalog behind, and an existing catalog is left as it was by its own
    rolled-back transaction. A catalog that holds parts by then (another process wrote it
    meanwhile) is kept.
    """
    path = catalog_path(option)
    before = _file_state(path)
    sides_before = {s for s in SQLITE_SIDE_SUFFIXES if _file_state(Path(f"{path}{s}")) is not None}
    try:
        conn = open_catalog(path, create=True, wait=wait)
    except BaseException:
        if before in (None, 0) and not _holds_data(path):
            _put_back(path, before, sides_before)
        raise
    try:
        yield conn
    except BaseException:
        conn.close()
        if before in (None, 0) and not _holds_data(path):
            _put_back(path, before, sides_before)
        raise
    conn.close()


def _holds_data(path: Path) -> bool:
    """Whether the catalog at ``path`` holds a part or a changeover (read-only look; a file
    that cannot be read as a catalog holds none)."""
    if not path.is_file():
        return False
    try:
        look = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
    except sqlite3.Error:
        return False
    try:
        row = look.execute(
            "SELECT (SELECT count(*) FROM parts) + (SELECT count(*) FROM changeovers)"
        ).fetchone()
        return bool(row and row[0])
    except sqlite3.Error:
        return False
    finally:
        look.close()


def _file_state(path: Path) -> int | None:
    """The size of the file at ``path``: None when there is none, -1 when it is no regular
    file (a folder is never put back)."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_size if stat.S_ISREG(st.st_mode) else -1


def _put_back(path: Path, before: int | None, sides_before: set[str]) -> None:
    """Remove (``before`` None) or empty (``before`` 0) the catalog a failed command made,
    and the SQLite side files it made; best effort, the command's error is what is said."""
    try:
        if before is None:
            path.unlink(missing_ok=True)
        else:
            with path.open("r+b") as fh:
                fh.truncate(0)
        for side in SQLITE_SIDE_SUFFIXES:
            if side not in sides_before:
                Path(f"{path}{side}").unlink(missing_ok=True)
    except OSError:
        pass


def _outcome_dict(o: AddOutcome) -> dict[str, Any]:
    return {
        "name": o.name,
        "revision": o.revision,
        "status": o.status,
        "source": o.source_path,
        **orientable_fields(o.orientable),
        "warnings": list(o.warnings),
        "changes": list(o.changes),
        "shape_tolerance_mm": o.shape_tolerance_mm,
        "com_tolerance_mm": o.com_tolerance_mm,
    }


def _stored_words(outcomes: list[AddOutcome] | tuple[AddOutcome, ...]) -> str:
    """What an import stored, in words: "3 parts in the catalog" (unchanged ones too)."""
    return f"{len(outcomes)} part{'s' if len(outcomes) != 1 else ''} in the catalog"


def _warn(outcomes: list[AddOutcome] | tuple[AddOutcome, ...]) -> None:
    for o in outcomes:
        for w in o.warnings:
            err_console.print(
                f"[yellow]warning:[/] {escape(o.name)}: {escape(w)}",
                highlight=False,
                soft_wrap=True,
            )


def _relative(path: str, root: Path) -> str:
    try:
        return str(Path(path).relative_to(root.resolve()))
    except ValueError:
        return path


IMPORT_HEADERS = ("part", "rev", "status", "orientable (ideal)", "warnings", "file")
"""The import summary's columns."""

WHOLE_COLUMNS = (0, 2, 5)
"""The summary's columns never broken: part, status and file (the headers of the others
wrap at their words)."""


def _print_summary(outcomes: list[AddOutcome] | tuple[AddOutcome, ...], root: Path) -> None:
    """The import summary: a rich table, or plain columns when it is long (rich is slow there)
    or when the terminal is too narrow for its names whole (a part or file name cut in two
    reads as another name).

    Sources are shown relative to the imported folder ``root``.
    """
    rows = [
        (
            o.name,
            str(o.revision),
            o.status,
            "yes" if o.orientable else "no",
            str(len(o.warnings)),
            _relative(o.source_path, root),
        )
        for o in outcomes
    ]
    if len(rows) > RICH_TABLE_ROWS or _table_width(rows) > console.width:
        sys.stdout.write(plain_table(IMPORT_HEADERS, rows, right=(1, 4)))
        return
    table = Table(
        title="catalog import",
        box=SIMPLE_HEAD,
        show_edge=False,
        pad_edge=False,
        collapse_padding=True,
    )
    for k, col in enumerate(IMPORT_HEADERS):
        if k in WHOLE_COLUMNS:
            table.add_column(col, no_wrap=True, min_width=max(display_width(r[k]) for r in rows))
        else:
            table.add_column(col, justify="right" if k in (1, 4) else "left")
    for row in rows:
        cells = [escape(c) for c in row]
        table.add_row(*cells[:3], cells[3] if row[3] == "yes" else "[red]no[/]", *cells[4:])
    console.print(table)


def _table_width(rows: list[tuple[str, ...]]) -> int:
    """The narrowest the summary table can be with every cell whole and each header broken
    only between words: its columns and the two spaces between them."""
    widths = [
        max([display_width(r[k]) for r in rows] + [len(w) for w in header.split()])
        for k, header in enumerate(IMPORT_HEADERS)
    ]
    return sum(widths) + 2 * (len(widths) - 1)


def cmd_init(
    catalog: CatalogOpt = None, wait: WaitOpt = DEFAULT_WAIT, json_out: JsonOpt = False
) -> None:
    """Create the catalog (or bring an existing one to the current schema)."""
    path = catalog_path(catalog)
    existed = _has_content(path)
    with opened(catalog, wait, create=True):
        pass
    if json_out:
        print_json({"catalog": str(path), "created": not existed, "schema_version": SCHEMA_VERSION})
    else:
        verb = "ready" if existed else "created"
        console.print(
            f"catalog {path} {verb} (schema version {SCHEMA_VERSION})",
            highlight=False,
            markup=False,
        )


def _has_content(path: Path) -> bool:
    """Whether ``path`` is a file with bytes in it: an empty file becomes a catalog only now,
    so ``init`` says it was created."""
    try:
        return path.stat().st_size > 0
    except OSError:
        return False


@takes_import_options
def cmd_add(
    file: Annotated[Path, typer.Argument(help="Outline .json, .dxf, .stl, .obj or .ply file.")],
    name: Annotated[
        str | None,
        typer.Option("--name", metavar="NAME", help="Part name (default: from the file)."),
    ] = None,
    revise: ReviseOpt = False,
    import_opts: ImportOptions = ImportOptions(),
    com: ComOpt = None,
    side_probability: SideOpt = DEFAULT_SIDE_PROBABILITY,
    shape_tolerance: StoredShapeToleranceOpt = None,
    com_tolerance: StoredComToleranceOpt = None,
    catalog: CatalogOpt = None,
    wait: WaitOpt = DEFAULT_WAIT,
    json_out: JsonOpt = False,
) -> None:
    """Import one file as a part with its landings; a changed file, changed options or a new
    shape or COM tolerance make a new revision (and say what changed), an unchanged one
    nothing."""
    opts = with_com(import_opts, com)
    check_side_probability(side_probability)
    tolerances = stored_tolerances(shape_tolerance, com_tolerance)
    _check_source_file(file)
    with opened_for_import(catalog, wait) as conn:
        outcomes = add_file(
            conn,
            file,
            opts,
            name=name,
            revise=revise,
            side_probability=side_probability,
            tolerances=tolerances,
            check_part=check_tolerances,
        )
    DONE_WORK.note(f"stored {_stored_words(outcomes)}")
    _warn(outcomes)
    if json_out:
        print_json([_outcome_dict(o) for o in outcomes])
        return
    for o in outcomes:
        changed = f": {'; '.join(o.changes)}" if o.changes else ""
        console.print(
            f"{o.name}: revision {o.revision} ({o.status}{changed}){_tolerance_words(o)}",
            highlight=False,
            markup=False,
        )


def _check_source_file(file: Path) -> None:
    """A FILE argument that is missing or not a file is named as such, before the catalog."""
    try:
        if not file.exists():
            raise InputError(f"{file}: no such file")
        if not file.is_file():
            raise InputError(f"{file}: not a file")
    except OSError as exc:
        raise InputError(f"{file}: cannot read the file ({exc.strerror})") from None


@takes_import_options
def cmd_import(
    directory: Annotated[
        Path, typer.Argument(help="Folder searched recursively for source files.")
    ],
    revise: ReviseOpt = False,
    import_opts: ImportOptions = ImportOptions(),
    com: ComOpt = None,
    side_probability: SideOpt = DEFAULT_SIDE_PROBABILITY,
    skip_bad: Annotated[
        bool,
        typer.Option("--skip-bad", help="Import the good files and name each bad one."),
    ] = False,
    shape_tolerance: StoredShapeToleranceOpt = None,
    com_tolerance: StoredComToleranceOpt = None,
    catalog: CatalogOpt = None,
    wait: WaitOpt = DEFAULT_WAIT,
    json_out: JsonOpt = False,
) -> None:
    """Import every source file of a folder, with landings, in one transaction: all files or
    none (with --skip-bad: every good file, and each bad one named). A shape or COM tolerance
    is stored with every new revision; a part it is too large for is a bad file."""
    opts = with_com(import_opts, com)
    check_side_probability(side_probability)
    tolerances = stored_tolerances(shape_tolerance, com_tolerance)
    if not directory.is_dir():  # before the catalog is created: bad input leaves no file
        what = "not a directory" if directory.exists() else "no such directory"
        raise InputError(f"{directory}: {what}")
    item_column = TextColumn("{task.fields[item]}")
    with progress_bar(item_column, disable=not err_console.is_terminal) as bar:
        tasks: dict[str, Any] = {}

        def progress(phase: str, done: int, total: int, item: str) -> None:
            if phase not in tasks:
                label = "reading" if phase == "read" else "writing"
                tasks[phase] = bar.add_task(label, total=total, item="")
            bar.update(tasks[phase], completed=done, item=Path(item).name if item else "")

        with opened_for_import(catalog, wait) as conn:
            result = import_directory(
                conn,
                directory,
                opts,
                revise=revise,
                progress=progress,
                skip_bad=skip_bad,
                side_probability=side_probability,
                tolerances=tolerances,
                check_part=check_tolerances,
            )
    DONE_WORK.note(f"stored {_stored_words(result.outcomes)}")
    _warn(result.outcomes)
    for line in result.bad:
        err_console.print(f"[yellow]skipped:[/] {escape(line)}", highlight=False, soft_wrap=True)
    if json_out:
        print_json(
            {
                "parts": [_outcome_dict(o) for o in result.outcomes],
                "ignored": list(result.ignored),
                "skipped": list(result.bad),
            }
        )
        return
    _print_summary(result.outcomes, directory)
    counts = {
        s: sum(o.status == s for o in result.outcomes) for s in ("added", "revised", "unchanged")
    }
    console.print(
        f"{counts['added']} added, {counts['revised']} revised, {counts['unchanged']} unchanged; "
        f"{plural(len(result.ignored), 'other file')} ignored"
        + (f"; {plural(len(result.bad), 'bad file')} skipped" if result.bad else ""),
        highlight=False,
    )


def cmd_list(catalog: CatalogOpt = None, json_out: JsonOpt = False) -> None:
    """List the parts with their latest revision."""
    with opened(catalog, DEFAULT_WAIT) as conn:
        parts = list_parts(conn)
    if json_out:
        print_json(
            [
                {
                    "name": p.name,
                    "revision": p.revision,
                    "revisions": p.revisions,
                    "kind": p.source_kind,
                    "source_units": p.source_units,
                    **area_fields(p.source_kind, p.area, p.n_holes),
                    "hull_vertices": p.n_hull,
                    **orientable_fields(p.orientable),
                    "updated_at": p.updated_at,
                    "shape_tolerance_mm": p.shape_tolerance_mm,
                    "com_tolerance_mm": p.com_tolerance_mm,
                }
                for p in parts
            ]
        )
        return
    # Fits 80 columns for names up to 24 characters: units are in --json and catalog show.
    headers = ("part", "rev", "kind", "mm2", "holes", "hull", ORIENT_HEADER, "updated")
    rows = [
        (
            p.name,
            str(p.revision),
            p.source_kind,
            *_area_cells(p.source_kind, p.area, p.n_holes),
            str(p.n_hull),
            "yes" if p.orientable else "no",
            _date(p.updated_at),
        )
        for p in parts
    ]
    sys.stdout.write(plain_table(headers, rows, right=(1, 3, 4, 5)))
    if parts:
        sys.stdout.write(orientable_footnote())
    if any(p.source_kind == "mesh" for p in parts):
        note = f"{HULL_AREA_MARK} {HULL_AREA_NOTE}"
        sys.stdout.write(textwrap.fill(note, width=80, subsequent_indent="  ") + "\n")
    sys.stdout.write(f"{plural(len(parts), 'part')}\n")
    sys.stdout.flush()


def _date(stamp: str) -> str:
    """An ISO time stamp as the date it was written (the list is read at 80 columns; the
    full stamp is in --json and in catalog show)."""
    return stamp[:10]


def display_width(text: str) -> int:
    """The columns ``text`` takes on a terminal: 2 for a wide or full-width character (East
    Asian width W or F: CJK, full-width Latin), 0 for a combining mark (Unicode Mn, Me: the
    accents of an NFD name) and a conjoining Hangul vowel or final consonant (U+1160-U+11FF),
    1 for any other. ``len`` counts code points, which misaligns columns holding such names
    (wcwidth's rules, without the dependency; names hold no control or format characters).
    """
    if text.isascii():
        return len(text)
    width = 0
    for ch in text:
        if unicodedata.category(ch) in ("Mn", "Me") or "\u1160" <= ch <= "\u11ff":
            continue
        width += 2 if unicodedata.east_asian_width(ch) in ("W", "F") else 1
    return width


def _pad(text: str, width: int, right: bool) -> str:
    """``text`` padded with spaces to ``width`` terminal columns (:func:`display_width`)."""
    fill = " " * (width - display_width(text))
    return fill + text if right else text + fill


def plain_table(
    headers: tuple[str, ...], rows: list[tuple[str, ...]], right: tuple[int, ...]
) -> str:
    """Columns padded to their widest cell: fast for catalogs of thousands of parts (rich's
    Table takes seconds there) and never truncated, so it can be piped and grepped. Widths
    are terminal columns (:func:`display_width`), so rows of CJK, full-width or NFD names
    line up with the others."""
    widths = [
        max([display_width(h)] + [display_width(r[k]) for r in rows]) for k, h in enumerate(headers)
    ]

    def line(cells: tuple[str, ...]) -> str:
        return "  ".join(
            _pad(c, w, k in right) for k, (c, w) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([line(headers), rule, *(line(r) for r in rows)]) + "\n"


def revision_dict(
    rev: Revision, history: list[tuple[int, str, str, str]], changeovers: list[str]
) -> dict[str, Any]:
    """``catalog show --json``: everything stored about a revision."""
    from feederkit.outline import outline_to_dict

    return {
        "name": rev.name,
        "revision": rev.revision,
        "units": "mm",
        "source": {
            "path": rev.source_path,
            "sha256": rev.source_sha256,
            "kind": rev.source_kind,
            "units": rev.source_units,
        },
        "options": dict(rev.options),
        "outline": outline_to_dict(rev.outline),
        **area_fields(rev.source_kind, rev.area, len(rev.outline.holes)),
        "com": list(rev.com),
        "hull": [list(p) for p in rev.hull],
        "hull_tolerance": rev.hull_tolerance,
        "shape_tolerance_mm": rev.shape_tolerance_mm,
        "com_tolerance_mm": rev.com_tolerance_mm,
        "mesh_pose": None if rev.mesh_pose is None else dict(rev.mesh_pose),
        **orientable_fields(rev.orientable),
        "not_orientable_reason": rev.not_orientable_reason,
        "warnings": list(rev.warnings),
        "landings": [landing_dict(x) for x in rev.landings],
        "landings_note": rev.landings_note,
        "created_at": rev.created_at,
        "created_by": rev.created_by,
        "revisions": [
            {"revision": r, "created_at": at, "created_by": by, "sha256": sha}
            for r, at, by, sha in history
        ],
        "changeovers": changeovers,
    }


def landing_dict(x: Landing) -> dict[str, Any]:
    """One landing of ``catalog show --json``: name, probability, outline, hull, COM."""
    from feederkit.outline import outline_to_dict

    return {
        "landing": x.name,
        "probability": x.probability,
        "merged": list(x.merged),
        "outline": outline_to_dict(x.part.outline),
        "com": list(x.part.com),
        "hull": [list(p) for p in x.part.hull],
    }


def _landing_line(x: Landing) -> str:
    same = f", same shape as {', '.join(x.merged)}" if x.merged else ""
    return (
        f"{x.name}: probability {x.probability:.3f}, "
        f"{plural(len(x.part.hull), 'hull vertex', 'hull vertices')}, "
        f"com ({x.part.com[0]:.4f}, {x.part.com[1]:.4f}) mm{same}"
    )


def _stored_tolerance_rows(rev: Revision) -> list[tuple[str, str]]:
    """``catalog show``'s rows of the tolerances the revision stores (none when not stored)."""
    rows = [
        (what, f"{value:g} mm ({meaning})")
        for what, value, meaning in (
            ("shape tolerance", rev.shape_tolerance_mm, "every hull vertex within it"),
            ("COM tolerance", rev.com_tolerance_mm, "the centre of mass within it"),
        )
        if value is not None
    ]
    return rows


def _tol(value: float | None) -> str:
    return "exact" if value is None else f"{value:g} mm"


def cmd_show(
    name: Annotated[str, typer.Argument(help="Part name (NAME@REV for one revision).")],
    revision: RevisionOpt = None,
    catalog: CatalogOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Show a part: source, units, outline, hull, COM, mesh pose, landings, orientability,
    revisions."""
    part, which = asked_revision(name, revision)
    with opened(catalog, DEFAULT_WAIT) as conn:
        rev = get_revision(conn, part, which)
        history = revision_history(conn, part)
        users = [c.name for c in list_changeovers(conn) if any(n == rev.name for n, _ in c.parts)]
    data = revision_dict(rev, history, users)
    if json_out:
        print_json(data)
        return
    table = Table(show_header=False, title=f"{escape(rev.name)} revision {rev.revision}")
    table.add_column("field")
    table.add_column("value", overflow="fold")
    pose = rev.mesh_pose
    rows = [
        ("source", f"{rev.source_path} ({rev.source_kind}, {rev.source_units})"),
        ("sha256", rev.source_sha256),
        ("area", _area_words(rev.source_kind, rev.area, len(rev.outline.holes))),
        (
            "outline",
            plural(len(rev.outline.vertices), "vertex", "vertices")
            + (" (the convex hull seen from above)" if rev.source_kind == "mesh" else ""),
        ),
        (
            "hull",
            f"{plural(len(rev.hull), 'vertex', 'vertices')} (tolerance {_tol(rev.hull_tolerance)})",
        ),
        ("com", f"({rev.com[0]:.4f}, {rev.com[1]:.4f}) mm"),
        *_stored_tolerance_rows(rev),
        (
            "mesh pose",
            "-"
            if pose is None
            else f"{pose['index']} of {pose['count']} (probability {pose['probability']:.3f})",
        ),
        *[("landing", _landing_line(x)) for x in rev.landings],
        *([("landings", rev.landings_note)] if rev.landings_note else []),
        (
            "orientable (ideal)",
            "yes" if rev.orientable else f"no: {rev.not_orientable_reason}",
        ),
        ("created", f"{rev.created_at} by {rev.created_by}"),
        ("revisions", ", ".join(f"{r} ({at})" for r, at, _, _ in history)),
        ("changeovers", ", ".join(users) or "-"),
    ]
    rows += [("warning", w) for w in rev.warnings]
    for k, v in rows:
        table.add_row(k, escape(v))
    console.print(table)


def asked_revision(text: str, revision: int | None) -> tuple[str, int | None]:
    """The part and revision (None: the latest) of ``NAME`` or ``NAME@REV`` with
    ``--revision``; InputError when both name a revision and they differ.

    >>> asked_revision("clip@2", None), asked_revision("clip", 3), asked_revision("clip@2", 2)
    (('clip', 2), ('clip', 3), ('clip', 2))
    """
    part, at = split_revision(text)
    if at is not None and revision is not None and at != revision:
        raise InputError(f"{text}: the revision is given twice ({at} and --revision {revision})")
    return part, at if at is not None else revision


def cmd_remove(
    name: Annotated[str, typer.Argument(help="Part name, or NAME@REV for one revision.")],
    force: Annotated[
        bool, typer.Option("--force", help="Also remove changeovers that use the part.")
    ] = False,
    catalog: CatalogOpt = None,
    wait: WaitOpt = DEFAULT_WAIT,
    json_out: JsonOpt = False,
) -> None:
    """Remove a part and all its revisions, or one revision (NAME@REV)."""
    part, revision = split_revision(name)
    with opened(catalog, wait) as conn:
        removed = remove_part(conn, part, force=force, revision=revision)
    if json_out:
        print_json({"removed": part, "revision": revision, "changeovers_removed": removed})
        return
    extra = ""
    if removed:
        extra = f" and {'changeover' if len(removed) == 1 else 'changeovers'} {', '.join(removed)}"
    what = part if revision is None else f"{part} revision {revision}"
    console.print(f"removed {what}{extra}", highlight=False, markup=False)


def cmd_export(
    name: Annotated[str, typer.Argument(help="Part name.")],
    output: Annotated[
        Path,
        typer.Option("-o", "--output", metavar="OUT.json", help="Outline file to write (.json)."),
    ],
    revision: RevisionOpt = None,
    catalog: CatalogOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Write a part's outline file (design.md outline format); warn of what the file has
    no field for (a mesh's other landings, a side probability, stored tolerances)."""
    if output.suffix.lower() != ".json":
        raise InputError(f"{output}: the outline file must end in .json")
    part, which = asked_revision(name, revision)
    with opened(catalog, DEFAULT_WAIT) as conn:
        rev = export_part(conn, part, output, which)
    warnings = export_warnings(rev)
    if json_out:
        print_json(
            {
                "name": rev.name,
                "revision": rev.revision,
                "output": str(output),
                "warnings": warnings,
            }
        )
        return
    print_warnings(warnings)
    console.print(
        f"wrote {output} ({rev.name} revision {rev.revision})",
        highlight=False,
        markup=False,
        soft_wrap=True,
    )


catalog_app.command("init")(cmd_init)
catalog_app.command("add")(cmd_add)
catalog_app.command("import")(cmd_import)
catalog_app.command("list")(cmd_list)
catalog_app.command("show")(cmd_show)
catalog_app.command("remove")(cmd_remove)
catalog_app.command("export")(cmd_export)


def register(app: typer.Typer) -> None:
    """Add the ``catalog`` command group to the app."""
    catalog_app.command("analyze")(analyze_command)
    app.add_typer(catalog_app, name="catalog")
