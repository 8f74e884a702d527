"""Parts in the catalog: add (with revisions by SHA-256), read, list, remove, export.

Functions take a catalog as an open connection (from :func:`open_catalog`) or a path. Every
write is one transaction: a killed process leaves the catalog as it was.
"""

from __future__ import annotations

import dataclasses
import getpass
import hashlib
import json
import os
import sqlite3
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from feederkit.catalog.model import AddOutcome, PartSummary, Revision, check_name
from feederkit.catalog.schema import connect, transaction
from feederkit.errors import InputError
from feederkit.importers import (
    ImportedOutline,
    ImportedPart,
    ImportOptions,
    build_part,
    import_parts,
)
from feederkit.outline import Outline, outline_from_dict, outline_to_dict, write_text_atomic
from feederkit.part import Part

CatalogLike = sqlite3.Connection | str | os.PathLike[str]

DEFAULT_CATALOG = "feederkit.db"
CATALOG_ENV = "FEEDERKIT_CATALOG"


def default_catalog_path() -> Path:
    """``$FEEDERKIT_CATALOG`` if set, else ``./feederkit.db``."""
    return Path(os.environ.get(CATALOG_ENV) or DEFAULT_CATALOG)


def open_catalog(
    path: str | os.PathLike[str] | None = None, *, create: bool = False
) -> sqlite3.Connection:
    """Open the catalog at ``path`` (default :func:`default_catalog_path`), migrated."""
    return connect(Path(path) if path is not None else default_catalog_path(), create=create)


@contextmanager
def _conn(catalog: CatalogLike, create: bool = False) -> Iterator[sqlite3.Connection]:
    if isinstance(catalog, sqlite3.Connection):
        yield catalog
        return
    conn = connect(Path(catalog), create=create)
    try:
        yield conn
    finally:
        conn.close()


def now_utc() -> str:
    """The current time, UTC, ISO 8601 to the second."""
    return datetime.now(UTC).isoformat(timespec="seconds")


def current_user() -> str:
    """Who is writing: the login name, or ``unknown``."""
    try:
        return getpass.getuser()
    except Exception:  # noqa: BLE001 - no login name in some containers
        return "unknown"


def _dumps(data: Any) -> str:
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _part_id(conn: sqlite3.Connection, name: str) -> int | None:
    row = conn.execute("SELECT id FROM parts WHERE name = ?", (name,)).fetchone()
    return None if row is None else int(row[0])


def _latest(conn: sqlite3.Connection, part_id: int) -> tuple[int, str, str, str]:
    return conn.execute(
        "SELECT revision, source_path, source_sha256, options_json FROM revisions "
        "WHERE part_id = ? ORDER BY revision DESC LIMIT 1",
        (part_id,),
    ).fetchone()


def write_revision(
    conn: sqlite3.Connection,
    imported: ImportedPart,
    *,
    source_path: str,
    sha256: str,
    options_key: dict[str, Any],
    revise: bool = False,
    created_by: str | None = None,
) -> AddOutcome:
    """Store one imported part inside the caller's transaction.

    A new name is added as revision 1. For an existing name, the same source path (or
    ``revise``) with the same SHA-256 and options is a no-op; with a changed file or options
    it becomes the next revision. Another source file under an existing name is refused.
    """
    part = imported.part
    name = check_name(part.name)
    who = created_by or current_user()
    when = now_utc()
    options_json = _dumps(options_key)
    pid = _part_id(conn, name)
    if pid is None:
        cur = conn.execute(
            "INSERT INTO parts (name, created_at, created_by) VALUES (?, ?, ?)", (name, when, who)
        )
        pid = int(cur.lastrowid)
        revision, status = 1, "added"
    else:
        rev, old_path, old_sha, old_options = _latest(conn, pid)
        if old_path != source_path and not revise:
            raise InputError(
                f"duplicate name: part {name!r} already exists from {old_path}; choose another "
                "--name, or use --revise to make this file its next revision"
            )
        if old_sha == sha256 and old_options == options_json:
            return AddOutcome(
                name,
                int(rev),
                "unchanged",
                source_path,
                imported.orientability.orientable,
                imported.warnings,
            )
        revision, status = int(rev) + 1, "revised"
    src = imported.source
    pose = None
    if src.pose is not None:
        pose = {
            "index": src.pose.index,
            "probability": src.pose.probability,
            "count": src.pose.count,
            "transform": [list(r) for r in src.pose.transform],
        }
    outline = part.outline
    conn.execute(
        "INSERT INTO revisions (part_id, revision, source_path, source_sha256, source_kind, "
        "source_units, options_json, outline_json, hull_json, com_x, com_y, hull_tolerance, "
        "mesh_pose_json, orientable, not_orientable_reason, warnings_json, area, n_holes, "
        "n_hull, created_at, created_by) VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
        (
            pid,
            revision,
            source_path,
            sha256,
            src.kind,
            src.source_units,
            options_json,
            _dumps(outline_to_dict(outline)),
            _dumps([list(p) for p in part.hull]),
            part.com[0],
            part.com[1],
            imported.hull_tolerance,
            None if pose is None else _dumps(pose),
            int(imported.orientability.orientable),
            imported.orientability.reason,
            _dumps(list(imported.warnings)),
            float(outline.polygon().area),
            len(outline.holes),
            len(part.hull),
            when,
            who,
        ),
    )
    return AddOutcome(
        name, revision, status, source_path, imported.orientability.orientable, imported.warnings
    )


def add_file(
    catalog: CatalogLike,
    path: str | os.PathLike[str],
    options: ImportOptions = ImportOptions(),
    *,
    name: str | None = None,
    revise: bool = False,
    created_by: str | None = None,
) -> list[AddOutcome]:
    """Import one file and store its part(s) in one transaction (several with ``all_parts``)."""
    if name is not None:
        check_name(name)
    result, parts = import_parts(path, options, name)
    source = str(Path(path).resolve())
    with _conn(catalog, create=True) as conn, transaction(conn):
        return [
            write_revision(
                conn,
                p,
                source_path=source,
                sha256=result.sha256,
                options_key=options.as_key(),
                revise=revise,
                created_by=created_by,
            )
            for p in parts
        ]


def add_outline(
    catalog: CatalogLike,
    outline: Outline,
    *,
    name: str | None = None,
    hull_tolerance: float | None = None,
    source_path: str | None = None,
    revise: bool = False,
    created_by: str | None = None,
) -> AddOutcome:
    """Store an outline made in Python; its SHA-256 is that of its outline-file JSON."""
    if name is not None:
        outline = dataclasses.replace(outline, name=check_name(name))
    text = _dumps(outline_to_dict(outline))
    sha = hashlib.sha256(text.encode()).hexdigest()
    options = ImportOptions(hull_tolerance=hull_tolerance)
    imported = build_part(
        ImportedOutline(outline=outline, kind="outline", source_units="mm"), options
    )
    with _conn(catalog, create=True) as conn, transaction(conn):
        return write_revision(
            conn,
            imported,
            source_path=source_path or f"<python:{outline.name}>",
            sha256=sha,
            options_key=options.as_key(),
            revise=revise,
            created_by=created_by,
        )


_SUMMARY_SQL = """
SELECT p.name, r.revision, (SELECT count(*) FROM revisions c WHERE c.part_id = p.id),
       r.source_kind, r.source_units, r.area, r.n_holes, r.n_hull, r.orientable, r.created_at
FROM parts p JOIN revisions r ON r.part_id = p.id
WHERE r.revision = (SELECT max(m.revision) FROM revisions m WHERE m.part_id = p.id)
"""


def list_parts(catalog: CatalogLike) -> list[PartSummary]:
    """Every part with its latest revision, sorted by name."""
    with _conn(catalog) as conn:
        rows = conn.execute(_SUMMARY_SQL + " ORDER BY p.name").fetchall()
    return [
        PartSummary(
            name=r[0],
            revision=int(r[1]),
            revisions=int(r[2]),
            source_kind=r[3],
            source_units=r[4],
            area=float(r[5]),
            n_holes=int(r[6]),
            n_hull=int(r[7]),
            orientable=bool(r[8]),
            updated_at=r[9],
        )
        for r in rows
    ]


def part_names(catalog: CatalogLike) -> list[str]:
    """Names of all parts, sorted."""
    with _conn(catalog) as conn:
        return [r[0] for r in conn.execute("SELECT name FROM parts ORDER BY name")]


_REVISION_SQL = """
SELECT p.name, r.revision, r.source_path, r.source_sha256, r.source_kind, r.source_units,
       r.options_json, r.outline_json, r.hull_json, r.com_x, r.com_y, r.hull_tolerance,
       r.mesh_pose_json, r.orientable, r.not_orientable_reason, r.warnings_json, r.area,
       r.created_at, r.created_by
FROM parts p JOIN revisions r ON r.part_id = p.id WHERE p.name = ?
"""


def _revision_from_row(row: Sequence[Any]) -> Revision:
    outline = outline_from_dict(json.loads(row[7]), default_name=row[0])
    return Revision(
        name=row[0],
        revision=int(row[1]),
        source_path=row[2],
        source_sha256=row[3],
        source_kind=row[4],
        source_units=row[5],
        options=json.loads(row[6]),
        outline=outline,
        hull=tuple((float(x), float(y)) for x, y in json.loads(row[8])),
        com=(float(row[9]), float(row[10])),
        hull_tolerance=row[11],
        mesh_pose=None if row[12] is None else json.loads(row[12]),
        orientable=bool(row[13]),
        not_orientable_reason=row[14],
        warnings=tuple(json.loads(row[15])),
        area=float(row[16]),
        created_at=row[17],
        created_by=row[18],
    )


def _unknown(name: str) -> InputError:
    return InputError(f"no part named {name!r} in the catalog")


def get_revision(catalog: CatalogLike, name: str, revision: int | None = None) -> Revision:
    """A stored revision of a part (default: the latest); InputError when there is none."""
    with _conn(catalog) as conn:
        if revision is None:
            row = conn.execute(
                _REVISION_SQL + " ORDER BY r.revision DESC LIMIT 1", (name,)
            ).fetchone()
        else:
            row = conn.execute(
                _REVISION_SQL + " AND r.revision = ?", (name, int(revision))
            ).fetchone()
        if row is None:
            if revision is not None and _part_id(conn, name) is not None:
                raise InputError(f"part {name!r} has no revision {revision}")
            raise _unknown(name)
    return _revision_from_row(row)


def revision_history(catalog: CatalogLike, name: str) -> list[tuple[int, str, str, str]]:
    """(revision, created_at, created_by, sha256) of each revision of a part, oldest first."""
    with _conn(catalog) as conn:
        rows = conn.execute(
            "SELECT r.revision, r.created_at, r.created_by, r.source_sha256 FROM revisions r "
            "JOIN parts p ON p.id = r.part_id WHERE p.name = ? ORDER BY r.revision",
            (name,),
        ).fetchall()
    if not rows:
        raise InputError(f"no part named {name!r} in the catalog")
    return [(int(r[0]), r[1], r[2], r[3]) for r in rows]


def part_from_revision(rev: Revision) -> Part:
    """The :class:`Part` of a stored revision, exactly as imported (``revision`` as a string)."""
    return Part(
        name=rev.name, outline=rev.outline, com=rev.com, hull=rev.hull, revision=str(rev.revision)
    )


def get_part(catalog: CatalogLike, name: str, revision: int | None = None) -> Part:
    """The part ``name`` (latest revision unless given) with ``Part.revision`` set, e.g. ``"3"``."""
    return part_from_revision(get_revision(catalog, name, revision))


def remove_part(catalog: CatalogLike, name: str, *, force: bool = False) -> list[str]:
    """Delete a part with all its revisions; returns the changeovers removed with it.

    A part used by a changeover is refused unless ``force``, which removes those changeovers too.
    """
    with _conn(catalog) as conn, transaction(conn):
        pid = _part_id(conn, name)
        if pid is None:
            raise _unknown(name)
        users = [
            r[0]
            for r in conn.execute(
                "SELECT DISTINCT c.name FROM changeovers c JOIN changeover_parts cp "
                "ON cp.changeover_id = c.id JOIN revisions r ON r.id = cp.revision_id "
                "WHERE r.part_id = ? ORDER BY c.name",
                (pid,),
            )
        ]
        if users and not force:
            raise InputError(
                f"part {name!r} is used by changeover(s) {', '.join(users)}; "
                "use --force to remove them too"
            )
        for changeover in users:
            conn.execute("DELETE FROM changeovers WHERE name = ?", (changeover,))
        conn.execute("DELETE FROM parts WHERE id = ?", (pid,))
    return users


def export_part(
    catalog: CatalogLike, name: str, out: str | os.PathLike[str], revision: int | None = None
) -> Revision:
    """Write a part's outline file (design.md format) atomically; returns the revision written."""
    rev = get_revision(catalog, name, revision)
    target = Path(out)
    if target.parent and not target.parent.exists():
        raise InputError(f"{target}: the folder {target.parent} does not exist")
    write_text_atomic(target, json.dumps(outline_to_dict(rev.outline), indent=2) + "\n")
    return rev
