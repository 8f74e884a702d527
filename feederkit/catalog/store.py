"""Parts in the catalog: add (with revisions by SHA-256), read, list, remove, export.

Functions take a catalog as an open connection (from :func:`open_catalog`) or a path. Every
write is one transaction: a killed process leaves the catalog as it was.
"""

from __future__ import annotations

import dataclasses
import difflib
import getpass
import hashlib
import json
import math
import os
import sqlite3
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from feederkit.catalog.model import (
    AddOutcome,
    PartSummary,
    Revision,
    check_part_name,
    is_mix_name,
    is_valid_name,
    is_valid_text,
    name_key,
    shown_name,
)
from feederkit.catalog.schema import (
    DEFAULT_WAIT,
    catalog_error,
    catalog_file_of,
    connect,
    transaction,
)
from feederkit.catalog.tolerances import TOLERANCE_WORDS, PartCheck, PartTolerances
from feederkit.errors import InputError
from feederkit.importers import (
    ImportedOutline,
    ImportedPart,
    ImportOptions,
    build_part,
    import_parts,
)
from feederkit.importers.budget import Budget
from feederkit.jsonio import parse_json
from feederkit.landing.mesh import judged_by_landings, landings_of_mesh, pose_name
from feederkit.landing.model import (
    DEFAULT_SIDE_PROBABILITY,
    Landing,
    check_landing_name,
    check_side_probability,
    landings_of_outline,
)
from feederkit.outline import (
    MAX_COORD_MM,
    Outline,
    outline_from_dict,
    outline_to_dict,
    write_text_atomic,
)
from feederkit.part import Part

CatalogLike = sqlite3.Connection | str | os.PathLike[str]

DEFAULT_CATALOG = "feederkit.db"
CATALOG_ENV = "FEEDERKIT_CATALOG"


def resolve_catalog_path(path: str | os.PathLike[str] | None = None) -> Path:
    """The catalog file: ``path`` when given, else ``$FEEDERKIT_CATALOG``, else ``./feederkit.db``.

    The one rule every command uses (docs/catalog.md); an empty string counts as not given.
    """
    if path is not None and str(path):
        return Path(path)
    return Path(os.environ.get(CATALOG_ENV) or DEFAULT_CATALOG)


def default_catalog_path() -> Path:
    """``$FEEDERKIT_CATALOG`` if set, else ``./feederkit.db`` (:func:`resolve_catalog_path`)."""
    return resolve_catalog_path(None)


def open_catalog(
    path: str | os.PathLike[str] | None = None,
    *,
    create: bool = False,
    wait: float = DEFAULT_WAIT,
) -> sqlite3.Connection:
    """Open the catalog at ``path`` (default :func:`resolve_catalog_path`), migrated.

    ``wait``: seconds a write waits for another process's transaction before giving up.
    """
    return connect(resolve_catalog_path(path), create=create, wait=wait)


@contextmanager
def _conn(catalog: CatalogLike, create: bool = False) -> Iterator[sqlite3.Connection]:
    """The connection for a catalog argument; SQLite errors become one-line InputErrors."""
    if isinstance(catalog, sqlite3.Connection):
        try:
            yield catalog
        except sqlite3.Error as exc:
            raise catalog_error(exc, catalog_file_of(catalog)) from None
        return
    path = Path(catalog)
    conn = connect(path, create=create)
    try:
        yield conn
    except sqlite3.Error as exc:
        raise catalog_error(exc, path) from None
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
    """The id of the part ``name`` names (:func:`_find_part`), or None."""
    found = _find_part(conn, name)
    return None if found is None else found[0]


def _stored_name(conn: sqlite3.Connection, name: str) -> str:
    """The name the catalog stores the part ``name`` under (:func:`_find_part`); ``name``
    itself when no part has it, for the caller's "no part named" line."""
    found = _find_part(conn, name)
    return name if found is None else found[1]


def _find_part(conn: sqlite3.Connection, name: str) -> tuple[int, str] | None:
    """(id, stored name) of the part ``name`` names, however its letters are composed.

    Names are stored in NFC (:func:`~feederkit.catalog.model.name_key`), but older versions
    stored them as typed, so a macOS (NFD) name may be stored as such. The name exactly as
    stored wins (two parts that an older version stored in both forms each keep theirs); else
    its NFC form; else a stored name whose NFC form is ``name``'s, the first by name. Only the
    last looks beyond the index, at the names holding non-ASCII characters (ASCII names have
    one form), and only for a name that is not stored as typed or in NFC.
    """
    row = conn.execute("SELECT id, name FROM parts WHERE name = ?", (name,)).fetchone()
    if row is not None or not isinstance(name, str) or name.isascii():
        return None if row is None else (int(row[0]), row[1])
    key = name_key(name)
    if key != name:
        row = conn.execute("SELECT id, name FROM parts WHERE name = ?", (key,)).fetchone()
        if row is not None:
            return int(row[0]), row[1]
    rows = conn.execute(
        "SELECT id, name FROM parts WHERE length(CAST(name AS BLOB)) > length(name) ORDER BY name"
    )
    for pid, stored in rows:
        if isinstance(stored, str) and is_valid_text(stored) and name_key(stored) == key:
            return int(pid), stored
    return None


def _latest(
    conn: sqlite3.Connection, part_id: int
) -> tuple[int, str, str, str, int, float | None, float | None]:
    return conn.execute(
        "SELECT revision, source_path, source_sha256, options_json, id, shape_tolerance_mm, "
        "com_tolerance_mm FROM revisions WHERE part_id = ? ORDER BY revision DESC LIMIT 1",
        (part_id,),
    ).fetchone()


def options_key(
    options: ImportOptions,
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
    kind: str = "outline",
) -> dict[str, Any]:
    """The import options that make a revision: ``options.as_key()`` and, for a flat part
    (``kind`` not ``mesh``) when not the default 0.5, ``side_probability`` (so older
    revisions compare equal, and a mesh, which has no sides, is not revised by it)."""
    key = dict(options.as_key())
    p = check_side_probability(side_probability)
    if p != DEFAULT_SIDE_PROBABILITY and kind != "mesh":
        key["side_probability"] = p
    return key


def _imported_pose(imported: ImportedPart) -> tuple[Landing, ...]:
    """The one landing known without the mesh file: the imported pose."""
    part = imported.part
    pose = imported.source.pose
    k = 0 if pose is None else pose.index
    prob = 1.0 if pose is None else float(pose.probability)
    named = Part(part.name + f"/{pose_name(k)}", part.outline, part.com, part.hull, part.revision)
    return (Landing(part.name, pose_name(k), prob, named),)


def landings_for(
    imported: ImportedPart,
    options: ImportOptions = ImportOptions(),
    source: str | os.PathLike[str] | None = None,
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
) -> tuple[Landing, ...]:
    """The landings to store with an imported part (docs/landings.md).

    A flat part: ``up`` and ``down`` (one when mirror-symmetric), ``up`` with
    ``side_probability``. A mesh: every resting pose of the ``source`` file, congruent ones
    merged (without the file, only the imported pose).
    """
    if imported.source.kind != "mesh":
        budget = Budget(options.limits, str(source or imported.part.name))
        return landings_of_outline(imported.part, side_probability, budget.check_time)
    if source is None:
        return _imported_pose(imported)
    return landings_of_mesh(
        Path(source), options, name=imported.part.name, hull_tolerance=imported.hull_tolerance
    )


def _has_landings(conn: sqlite3.Connection, revision_id: int) -> bool:
    row = conn.execute("SELECT 1 FROM landings WHERE revision_id = ? LIMIT 1", (revision_id,))
    return row.fetchone() is not None


def _write_landings(
    conn: sqlite3.Connection, revision_id: int, landings: Sequence[Landing]
) -> None:
    for position, x in enumerate(landings):
        conn.execute(
            "INSERT INTO landings (revision_id, position, name, probability, outline_json, "
            "hull_json, com_x, com_y, merged_json) VALUES (?,?,?,?,?,?,?,?,?)",
            (
                revision_id,
                position,
                check_landing_name(x.name),
                float(x.probability),
                _dumps(outline_to_dict(x.part.outline)),
                _dumps([list(p) for p in x.part.hull]),
                x.part.com[0],
                x.part.com[1],
                _dumps(list(x.merged)),
            ),
        )


class NoSuchPartError(InputError):
    """The catalog holds no part of the name, or not the revision asked for: kept apart from
    a damaged row or catalog, which a SOURCE looked up in the catalog reports in the catalog's
    own words (the part is there)."""


class DuplicateNameError(InputError):
    """A part name the catalog already has from another source file (``name``, ``old_path``),
    kept apart so a folder import can skip and name the clash in its own words."""

    def __init__(self, name: str, old_path: str) -> None:
        self.name, self.old_path = name, old_path
        super().__init__(
            f"duplicate name: part {name!r} already exists from {old_path}; choose another "
            "--name, or use --revise to make this file its next revision"
        )


def write_revision(
    conn: sqlite3.Connection,
    imported: ImportedPart,
    *,
    source_path: str,
    sha256: str,
    options_key: dict[str, Any],
    revise: bool = False,
    created_by: str | None = None,
    landings: Sequence[Landing] | None = None,
    tolerances: PartTolerances = PartTolerances(),
    check_part: PartCheck | None = None,
) -> AddOutcome:
    """Store one imported part and its landings inside the caller's transaction.

    A new name is added as revision 1. For an existing name, the same source path (or
    ``revise``) with the same SHA-256 and options is a no-op; with a changed file or options
    it becomes the next revision, and so does a mesh whose latest revision was stored before
    landings (to store all its resting poses), and a tolerance given that the latest
    revision does not store. Another source file under an existing name is refused.
    ``landings`` default to :func:`landings_for` without the source file. A new revision
    stores ``tolerances`` where given and keeps the latest revision's where not
    (:meth:`PartTolerances.over`); ``check_part`` checks them against the part first.
    """
    if landings is None:
        landings = landings_for(imported)
    imported = judged_by_landings(imported, landings)  # a mesh: orientable by its landings
    part = imported.part
    name = check_part_name(part.name)
    who = created_by or current_user()
    when = now_utc()
    options_json = _dumps(options_key)
    pid = _part_id(conn, name)
    changes: tuple[str, ...] = ()
    stored, kept, rev = tolerances, {}, 0
    if pid is None:
        cur = conn.execute(
            "INSERT INTO parts (name, created_at, created_by) VALUES (?, ?, ?)", (name, when, who)
        )
        pid = int(cur.lastrowid)
        revision, status = 1, "added"
    else:
        rev, old_path, old_sha, old_options, old_id, old_shape, old_com = _latest(conn, pid)
        if old_path != source_path and not revise:
            raise DuplicateNameError(name, old_path)
        poses_missing = (
            imported.source.kind == "mesh" and len(landings) > 1 and not _has_landings(conn, old_id)
        )
        old = _stored_tolerances(name, int(rev), old_shape, old_com)
        stored, kept = tolerances.over(old), tolerances.kept(old)
        same = old_sha == sha256 and old_options == options_json and not poses_missing
        if same and stored == old:
            return AddOutcome(
                name,
                int(rev),
                "unchanged",
                source_path,
                imported.orientability.orientable,
                imported.warnings,
                shape_tolerance_mm=old.shape_tolerance_mm,
                com_tolerance_mm=old.com_tolerance_mm,
            )
        revision, status = int(rev) + 1, "revised"
        changes = _changes(int(rev), old_sha, sha256, old_options, options_key)
        changes += _tolerance_changes(old, stored)
        if poses_missing:
            changes += (
                f"landings: all {len(landings)} resting poses stored (revision {rev} was "
                "stored before landings)",
            )
    if check_part is not None:  # plans cover every landing: a mesh's poses have other hulls
        for checked in (part, *(landing.part for landing in landings)):
            _check_tolerances(check_part, checked, stored, kept, int(rev))
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
    cur = conn.execute(
        "INSERT INTO revisions (part_id, revision, source_path, source_sha256, source_kind, "
        "source_units, options_json, outline_json, hull_json, com_x, com_y, hull_tolerance, "
        "mesh_pose_json, orientable, not_orientable_reason, warnings_json, area, n_holes, "
        "n_hull, created_at, created_by, shape_tolerance_mm, com_tolerance_mm) "
        "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
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
            stored.shape_tolerance_mm,
            stored.com_tolerance_mm,
        ),
    )
    _write_landings(conn, int(cur.lastrowid), landings)
    return AddOutcome(
        name,
        revision,
        status,
        source_path,
        imported.orientability.orientable,
        imported.warnings,
        changes,
        stored.shape_tolerance_mm,
        stored.com_tolerance_mm,
    )


def _stored_tolerances(
    name: str, revision: int, shape: float | None, com: float | None
) -> PartTolerances:
    """The latest revision's tolerances, read for a write; a damaged value says so."""
    try:
        return PartTolerances(shape, com)
    except InputError as exc:
        raise _damaged(name, revision, str(exc)) from None


def _check_tolerances(
    check: PartCheck, part: Part, stored: PartTolerances, kept: dict[str, str], previous: int
) -> None:
    """``check`` the tolerances to store against the part; the refusal of a tolerance kept
    from revision ``previous`` says so (the user did not give it this time). The check's
    error names the tolerance it refuses in ``field`` when it can
    (``feederkit.uncertainty.ToleranceTooLarge``)."""
    try:
        check(part, stored)
    except InputError as exc:
        field = getattr(exc, "field", None)
        what = kept.get(field) if field is not None else " and ".join(kept.values())
        if what:
            verb = "are" if " and " in what else "is"
            exc.args = (
                f"{exc}; the {what} {verb} revision {previous}'s, kept because not given: give "
                "a smaller one",
            )
        raise


def _tolerance_changes(old: PartTolerances, new: PartTolerances) -> tuple[str, ...]:
    """The tolerances of a new revision that differ from the previous one's, in words."""
    out = []
    for key, what in TOLERANCE_WORDS:
        before, after = getattr(old, key), getattr(new, key)
        if before != after:
            out.append(f"{what}: {_tolerance_words(before)} -> {_tolerance_words(after)}")
    return tuple(out)


def _tolerance_words(value: float | None) -> str:
    return "not stored" if value is None else f"{value:g} mm"


def _changes(
    old_rev: int, old_sha: str, new_sha: str, old_options: str, new_options: dict[str, Any]
) -> tuple[str, ...]:
    """What differs from revision ``old_rev``: the file's SHA-256 and each import option."""
    out = []
    if old_sha != new_sha:
        out.append(
            f"file changed since revision {old_rev} (sha256 {old_sha[:12]} -> {new_sha[:12]})"
        )
    try:
        before = json.loads(old_options)
    except ValueError:
        before = {}
    before = before if isinstance(before, dict) else {}
    after = json.loads(_dumps(new_options))
    for key in sorted(set(before) | set(after)):
        if before.get(key) != after.get(key):
            out.append(f"{key}: {_opt(before.get(key))} -> {_opt(after.get(key))}")
    return tuple(out)


def _opt(value: Any) -> str:
    return "default" if value is None or value == [] else json.dumps(value)


def add_file(
    catalog: CatalogLike,
    path: str | os.PathLike[str],
    options: ImportOptions = ImportOptions(),
    *,
    name: str | None = None,
    revise: bool = False,
    created_by: str | None = None,
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
    tolerances: PartTolerances = PartTolerances(),
    check_part: PartCheck | None = None,
) -> list[AddOutcome]:
    """Import one file and store its part(s) with their landings in one transaction (several
    parts with ``all_parts``); ``side_probability`` is a flat part's probability of ``up``,
    ``tolerances`` the new revisions' own, checked against each part by ``check_part``
    (:func:`write_revision`; a refusal writes nothing)."""
    if name is not None:
        check_part_name(name, "give --name a name without ',' or ':'")
    check_side_probability(side_probability)
    options = options.counting_from()  # the file's reading and its landings: one limit
    result, parts = import_parts(path, options, name)
    for p in parts:
        check_part_name(p.part.name)  # a name from the file, before anything is written
    landings = [landings_for(p, options, path, side_probability) for p in parts]
    source = str(Path(path).resolve())
    with _conn(catalog, create=True) as conn, transaction(conn):
        return [
            write_revision(
                conn,
                p,
                source_path=source,
                sha256=result.sha256,
                options_key=options_key(options, side_probability, p.source.kind),
                revise=revise,
                created_by=created_by,
                landings=lands,
                tolerances=tolerances,
                check_part=check_part,
            )
            for p, lands in zip(parts, landings, strict=True)
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
    side_probability: float = DEFAULT_SIDE_PROBABILITY,
    tolerances: PartTolerances = PartTolerances(),
) -> AddOutcome:
    """Store an outline made in Python with its landings (``up`` with ``side_probability``)
    and its own ``tolerances``; its SHA-256 is that of its outline-file JSON."""
    if name is not None:
        outline = dataclasses.replace(outline, name=check_part_name(name))
    text = _dumps(outline_to_dict(outline))
    sha = hashlib.sha256(text.encode()).hexdigest()
    options = ImportOptions(hull_tolerance=hull_tolerance)
    key = options_key(options, side_probability)
    imported = build_part(
        ImportedOutline(outline=outline, kind="outline", source_units="mm"), options
    )
    landings = landings_of_outline(imported.part, side_probability)
    with _conn(catalog, create=True) as conn, transaction(conn):
        return write_revision(
            conn,
            imported,
            source_path=source_path or f"<python:{outline.name}>",
            sha256=sha,
            options_key=key,
            revise=revise,
            created_by=created_by,
            landings=landings,
            tolerances=tolerances,
        )


_SUMMARY_SQL = """
SELECT p.name, r.revision, (SELECT count(*) FROM revisions c WHERE c.part_id = p.id),
       r.source_kind, r.source_units, r.area, r.n_holes, r.n_hull, r.orientable, r.created_at,
       r.shape_tolerance_mm, r.com_tolerance_mm
FROM parts p JOIN revisions r ON r.part_id = p.id
WHERE r.revision = (SELECT max(m.revision) FROM revisions m WHERE m.part_id = p.id)
"""


class _Damaged(Exception):
    """A stored value fails its check; turned into one InputError naming the part revision."""


def _damaged(name: Any, revision: Any, why: str) -> InputError:
    label = f"{shown_name(name)}@{revision}"
    if isinstance(name, str) and is_valid_name(name) and isinstance(revision, int):
        fix = (
            f"remove it with 'feederkit catalog remove {label}' or re-import its file with --revise"
        )
    else:
        fix = "restore the catalog from a backup or fix the row with sqlite3"
    return InputError(f"catalog part {label}: the stored data is damaged ({why}); {fix}")


def _text(value: Any, what: str, *, optional: bool = False) -> str | None:
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise _Damaged(f"{what} is {type(value).__name__}, not text")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise _Damaged(f"{what} is not UTF-8 text") from None
    return value


def _int(value: Any, what: str, lo: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < lo:
        raise _Damaged(f"{what} is {value!r}, not a whole number of at least {lo}")
    return value


def _real(value: Any, what: str, *, optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Damaged(f"{what} is {type(value).__name__}, not a number")
    x = float(value)
    if not math.isfinite(x) or abs(x) > MAX_COORD_MM:
        raise _Damaged(f"{what} is {value!r}, not a finite number within 1e9")
    return x


def _tolerance(value: Any, what: str) -> float | None:
    """A stored tolerance: None (not stored) or a finite number of mm, at least 0."""
    x = _real(value, what, optional=True)
    if x is not None and x < 0.0:
        raise _Damaged(f"{what} is {x}, negative")
    return x


def _json(value: Any, what: str, kind: type | tuple[type, ...], *, optional: bool = False) -> Any:
    text = _text(value, what, optional=optional)
    if text is None:
        return None
    try:
        data = parse_json(text, what)
    except InputError as exc:
        raise _Damaged(str(exc)) from None
    if not isinstance(data, kind):
        raise _Damaged(f"{what} is not a JSON {getattr(kind, '__name__', 'value')}")
    return data


def _hull(raw: list[Any]) -> tuple[tuple[float, float], ...]:
    """The stored contact hull: at least 3 finite points, convex, counter-clockwise."""
    pts = []
    for q in raw:
        if not isinstance(q, list) or len(q) != 2:
            raise _Damaged("hull_json is not a list of [x, y] points")
        pts.append((_real(q[0], "a hull_json coordinate"), _real(q[1], "a hull_json coordinate")))
    if len(pts) < 3:
        raise _Damaged(f"hull_json has {len(pts)} vertices, fewer than 3")
    scale = max(max(abs(x), abs(y)) for x, y in pts) or 1.0
    n = len(pts)
    for k in range(n):
        (ax, ay), (bx, by), (cx, cy) = pts[k], pts[(k + 1) % n], pts[(k + 2) % n]
        if (bx - ax) * (cy - by) - (by - ay) * (cx - bx) < -1e-9 * scale * scale:
            raise _Damaged("hull_json is not convex and counter-clockwise")
    return tuple(pts)  # type: ignore[arg-type]


def _inside(com: tuple[float, float], hull: tuple[tuple[float, float], ...]) -> bool:
    """Whether ``com`` lies strictly inside the convex CCW ``hull`` (pushing needs it there)."""
    scale = max(max(abs(x), abs(y)) for x, y in hull) or 1.0
    n = len(hull)
    for k in range(n):
        (ax, ay), (bx, by) = hull[k], hull[(k + 1) % n]
        if (bx - ax) * (com[1] - ay) - (by - ay) * (com[0] - ax) <= 1e-12 * scale * scale:
            return False
    return True


def _summary_from_row(r: Sequence[Any]) -> PartSummary:
    """A ``catalog list`` row, checked: a damaged row is one InputError naming the part."""
    try:
        name = _text(r[0], "the name")
        if not is_valid_name(name):
            raise _Damaged("the name is not a valid part name")
        return PartSummary(
            name=name,  # type: ignore[arg-type]
            revision=_int(r[1], "revision", 1),
            revisions=_int(r[2], "the revision count", 1),
            source_kind=_text(r[3], "source_kind"),  # type: ignore[arg-type]
            source_units=_text(r[4], "source_units"),  # type: ignore[arg-type]
            area=_real(r[5], "area"),  # type: ignore[arg-type]
            n_holes=_int(r[6], "n_holes"),
            n_hull=_int(r[7], "n_hull", 3),
            orientable=bool(_int(r[8], "orientable")),
            updated_at=_text(r[9], "created_at"),  # type: ignore[arg-type]
            shape_tolerance_mm=_tolerance(r[10], "shape_tolerance_mm"),
            com_tolerance_mm=_tolerance(r[11], "com_tolerance_mm"),
        )
    except _Damaged as exc:
        raise _damaged(r[0], r[1], str(exc)) from None


def list_parts(catalog: CatalogLike) -> list[PartSummary]:
    """Every part with its latest revision, sorted by name; each row checked."""
    with _conn(catalog) as conn:
        rows = conn.execute(_SUMMARY_SQL + " ORDER BY p.name").fetchall()
    return [_summary_from_row(r) for r in rows]


def part_names(catalog: CatalogLike) -> list[str]:
    """Names of all parts, sorted (names that are not valid text are left out)."""
    with _conn(catalog) as conn:
        names = [r[0] for r in conn.execute("SELECT name FROM parts ORDER BY name")]
    return [n for n in names if isinstance(n, str) and is_valid_name(n)]


def similar_names(catalog: CatalogLike, name: str, n: int = 3) -> list[str]:
    """Up to ``n`` catalog part names closest to ``name`` (for "did you mean ...?")."""
    return _similar(_suggestable(part_names(catalog)), name, n)


def _suggestable(names: Sequence[object]) -> list[str]:
    """The part names a hint may suggest: valid, and typeable in ``--mix`` (no ',' or ':',
    :func:`~feederkit.catalog.model.is_mix_name`; older parts may hold them)."""
    return [n for n in names if isinstance(n, str) and is_valid_name(n) and is_mix_name(n)]


def _similar(names: list[str], name: str, n: int = 3) -> list[str]:
    folded = {k.casefold(): k for k in names}
    close = difflib.get_close_matches(name.casefold(), list(folded), n=n, cutoff=0.6)
    return [folded[c] for c in close]


def did_you_mean(names: list[str]) -> str:
    """`` (did you mean 'a' or 'b'?)`` for the suggestions, or nothing when there are none."""
    if not names:
        return ""
    return " (did you mean " + " or ".join(repr(x) for x in names) + "?)"


_REVISION_SQL = """
SELECT p.name, r.revision, r.source_path, r.source_sha256, r.source_kind, r.source_units,
       r.options_json, r.outline_json, r.hull_json, r.com_x, r.com_y, r.hull_tolerance,
       r.mesh_pose_json, r.orientable, r.not_orientable_reason, r.warnings_json, r.area,
       r.created_at, r.created_by, r.id, r.shape_tolerance_mm, r.com_tolerance_mm
FROM parts p JOIN revisions r ON r.part_id = p.id WHERE p.name = ?
"""

_LANDINGS_SQL = """
SELECT position, name, probability, outline_json, hull_json, com_x, com_y, merged_json
FROM landings WHERE revision_id = ? ORDER BY position
"""

NOTE_FLAT = (
    "landings computed on read: this revision was stored before landings (catalog schema 1), "
    "so up and down have probability 0.5 each"
)
NOTE_MESH = (
    "only the imported pose is known: this revision was stored before landings (catalog "
    "schema 1); add the mesh file again to store all its resting poses"
)


def _stored_landing(name: str, revision: int, row: Sequence[Any]) -> Landing:
    """One stored landing, checked like the revision (name, probability, outline, hull, COM)."""
    lname = _text(row[1], "a landing's name")
    try:
        check_landing_name(lname)  # type: ignore[arg-type]
    except InputError as exc:
        raise _Damaged(str(exc)) from None
    prob = _real(row[2], f"landing {lname}'s probability")
    if not 0.0 < prob <= 1.0 + 1e-9:  # type: ignore[operator]
        raise _Damaged(f"landing {lname}'s probability is {prob}, not in (0, 1]")
    data = _json(row[3], f"landing {lname}'s outline_json", dict)
    try:
        outline = outline_from_dict(data, default_name=name)
    except InputError as exc:
        raise _Damaged(f"landing {lname}'s outline_json: {exc}") from None
    hull = _hull(_json(row[4], f"landing {lname}'s hull_json", list))
    com = (_real(row[5], f"landing {lname}'s com_x"), _real(row[6], f"landing {lname}'s com_y"))
    if not _inside(com, hull):  # type: ignore[arg-type]
        raise _Damaged(f"landing {lname}'s center of mass {com} is not inside its hull")
    merged = _json(row[7], f"landing {lname}'s merged_json", list)
    if not all(isinstance(m, str) for m in merged):
        raise _Damaged(f"landing {lname}'s merged_json is not a list of text")
    part = Part(f"{name}/{lname}", outline, com, hull, str(revision))  # type: ignore[arg-type]
    return Landing(name, lname, prob, part, tuple(merged))  # type: ignore[arg-type]


def _computed_landings(
    name: str, revision: int, kind: str, part: Part, pose: Any
) -> tuple[tuple[Landing, ...], str]:
    """The landings of a revision stored before landings, and the note saying so."""
    if kind != "mesh":
        return landings_of_outline(part), NOTE_FLAT
    k, prob = 0, 1.0
    if isinstance(pose, dict):
        k = _int(pose.get("index", 0), "mesh_pose_json's index")
        p = _real(pose.get("probability", 1.0), "mesh_pose_json's probability")
        prob = p if 0.0 < p <= 1.0 else 1.0  # type: ignore[operator]
    named = Part(f"{name}/{pose_name(k)}", part.outline, part.com, part.hull, str(revision))
    return (Landing(name, pose_name(k), prob, named),), NOTE_MESH


def _revision_from_row(row: Sequence[Any], landing_rows: Sequence[Sequence[Any]] = ()) -> Revision:
    """A stored revision, every field checked (types, UTF-8, JSON, hull convex, COM inside),
    with its landings (computed, and noted, for a revision stored before landings).

    Anything wrong (an edited or corrupted row) is one InputError naming the part and
    revision and saying how to get rid of it.
    """
    try:
        name = _text(row[0], "the name")
        revision = _int(row[1], "revision", 1)
        data = _json(row[7], "outline_json", dict)
        try:
            outline = outline_from_dict(data, default_name=name)  # type: ignore[arg-type]
        except InputError as exc:
            raise _Damaged(f"outline_json: {exc}") from None
        hull = _hull(_json(row[8], "hull_json", list))
        com = (_real(row[9], "com_x"), _real(row[10], "com_y"))
        if not _inside(com, hull):  # type: ignore[arg-type]
            raise _Damaged(f"the center of mass {com} is not inside the hull")
        warnings = _json(row[15], "warnings_json", list)
        if not all(isinstance(w, str) for w in warnings):
            raise _Damaged("warnings_json is not a list of text")
        orientable = _int(row[13], "orientable")
        if orientable > 1:
            raise _Damaged(f"orientable is {orientable}, not 0 or 1")
        hull_tolerance = _real(row[11], "hull_tolerance", optional=True)
        if hull_tolerance is not None and hull_tolerance < 0:
            raise _Damaged(f"hull_tolerance is {hull_tolerance}, negative")
        kind = _text(row[4], "source_kind")
        mesh_pose = _json(row[12], "mesh_pose_json", dict, optional=True)
        note = None
        if landing_rows:
            landings = tuple(_stored_landing(name, revision, r) for r in landing_rows)  # type: ignore[arg-type]
        else:
            part = Part(name, outline, com, hull, str(revision))  # type: ignore[arg-type]
            landings, note = _computed_landings(name, revision, kind, part, mesh_pose)  # type: ignore[arg-type]
        return Revision(
            name=name,  # type: ignore[arg-type]
            revision=revision,
            source_path=_text(row[2], "source_path"),  # type: ignore[arg-type]
            source_sha256=_text(row[3], "source_sha256"),  # type: ignore[arg-type]
            source_kind=kind,  # type: ignore[arg-type]
            source_units=_text(row[5], "source_units"),  # type: ignore[arg-type]
            options=_json(row[6], "options_json", dict),
            outline=outline,
            hull=hull,
            com=com,  # type: ignore[arg-type]
            hull_tolerance=hull_tolerance,
            mesh_pose=mesh_pose,
            orientable=bool(orientable),
            not_orientable_reason=_text(row[14], "not_orientable_reason", optional=True),
            warnings=tuple(warnings),
            area=_real(row[16], "area"),  # type: ignore[arg-type]
            created_at=_text(row[17], "created_at"),  # type: ignore[arg-type]
            created_by=_text(row[18], "created_by"),  # type: ignore[arg-type]
            landings=landings,
            landings_note=note,
            shape_tolerance_mm=_tolerance(row[20], "shape_tolerance_mm"),
            com_tolerance_mm=_tolerance(row[21], "com_tolerance_mm"),
        )
    except _Damaged as exc:
        raise _damaged(row[0], row[1], str(exc)) from None


def _unknown(conn: sqlite3.Connection, name: str) -> NoSuchPartError:
    """The error naming an unknown part, the catalog file it was looked up in (a default
    catalog or ``$FEEDERKIT_CATALOG`` may not be the one meant) and the names like it."""
    valid = _suggestable([r[0] for r in conn.execute("SELECT name FROM parts")])
    shown = shown_name(name) if not is_valid_name(name) else repr(name)
    file = next((row[2] for row in conn.execute("PRAGMA database_list") if row[1] == "main"), "")
    where = f" {file}" if file else ""
    return NoSuchPartError(
        f"no part named {shown!s} in the catalog{where}{did_you_mean(_similar(valid, name))}"
    )


def get_revision(catalog: CatalogLike, name: str, revision: int | None = None) -> Revision:
    """A stored revision of a part (default: the latest), checked; InputError when there is
    none (suggesting the nearest names) or when its row is damaged. ``name`` finds the part
    in any Unicode normal form (:func:`_find_part`); ``Revision.name`` is the stored one."""
    with _conn(catalog) as conn:
        name = _stored_name(conn, name)
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
                raise NoSuchPartError(f"part {name!r} has no revision {revision}")
            raise _unknown(conn, name)
        landing_rows = conn.execute(_LANDINGS_SQL, (row[19],)).fetchall()
    return _revision_from_row(row, landing_rows)


def revision_history(catalog: CatalogLike, name: str) -> list[tuple[int, str, str, str]]:
    """(revision, created_at, created_by, sha256) of each revision of a part, oldest first."""
    with _conn(catalog) as conn:
        name = _stored_name(conn, name)
        rows = conn.execute(
            "SELECT r.revision, r.created_at, r.created_by, r.source_sha256 FROM revisions r "
            "JOIN parts p ON p.id = r.part_id WHERE p.name = ? ORDER BY r.revision",
            (name,),
        ).fetchall()
        if not rows:
            raise _unknown(conn, name)
    out = []
    for r in rows:
        try:
            out.append(
                (
                    _int(r[0], "revision", 1),
                    _text(r[1], "created_at"),
                    _text(r[2], "created_by"),
                    _text(r[3], "source_sha256"),
                )
            )
        except _Damaged as exc:
            raise _damaged(name, r[0], str(exc)) from None
    return out  # type: ignore[return-value]


def part_from_revision(rev: Revision) -> Part:
    """The :class:`Part` of a stored revision, exactly as imported (``revision`` as a string)."""
    return Part(
        name=rev.name, outline=rev.outline, com=rev.com, hull=rev.hull, revision=str(rev.revision)
    )


def get_part(catalog: CatalogLike, name: str, revision: int | None = None) -> Part:
    """The part ``name`` (latest revision unless given) with ``Part.revision`` set, e.g. ``"3"``."""
    return part_from_revision(get_revision(catalog, name, revision))


def _users(conn: sqlite3.Connection, where: str, arg: int) -> list[str]:
    return [
        r[0]
        for r in conn.execute(
            "SELECT DISTINCT c.name FROM changeovers c JOIN changeover_parts cp "
            "ON cp.changeover_id = c.id JOIN revisions r ON r.id = cp.revision_id "
            f"WHERE {where} = ? ORDER BY c.name",
            (arg,),
        )
    ]


def remove_part(
    catalog: CatalogLike, name: str, *, force: bool = False, revision: int | None = None
) -> list[str]:
    """Delete a part with all its revisions, or only ``revision``; returns the changeovers
    removed with it.

    A revision used by a changeover is refused unless ``force``, which removes those
    changeovers too. Removing a part's only revision removes the part.
    """
    with _conn(catalog) as conn, transaction(conn):
        pid = _part_id(conn, name)
        if pid is None:
            raise _unknown(conn, name)
        rid = None
        if revision is not None:
            row = conn.execute(
                "SELECT id FROM revisions WHERE part_id = ? AND revision = ?", (pid, int(revision))
            ).fetchone()
            if row is None:
                raise InputError(f"part {name!r} has no revision {revision}")
            rid = int(row[0])
        users = _users(conn, "r.part_id", pid) if rid is None else _users(conn, "r.id", rid)
        label = name if revision is None else f"{name}@{revision}"
        if users and not force:
            raise InputError(
                f"part {label!r} is used by changeover(s) {', '.join(users)}; "
                "use --force to remove them too"
            )
        for changeover in users:
            conn.execute("DELETE FROM changeovers WHERE name = ?", (changeover,))
        left = conn.execute("SELECT count(*) FROM revisions WHERE part_id = ?", (pid,)).fetchone()
        if rid is None or int(left[0]) <= 1:
            conn.execute("DELETE FROM parts WHERE id = ?", (pid,))
        else:
            conn.execute("DELETE FROM revisions WHERE id = ?", (rid,))
    return users


def export_part(
    catalog: CatalogLike, name: str, out: str | os.PathLike[str], revision: int | None = None
) -> Revision:
    """Write a part's outline file (design.md format) atomically; returns the revision written."""
    rev = get_revision(catalog, name, revision)
    target = Path(out)
    try:
        missing = bool(str(target.parent)) and not target.parent.is_dir()
    except OSError as exc:
        raise InputError(f"{target}: cannot write the file ({exc.strerror})") from None
    if missing:
        raise InputError(f"{target}: the folder {target.parent} does not exist")
    write_text_atomic(target, json.dumps(outline_to_dict(rev.outline), indent=2) + "\n")
    return rev
