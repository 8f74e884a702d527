"""The catalog's SQLite schema, its version (``PRAGMA user_version``) and migrations.

Every connection runs in WAL mode with foreign keys on. Each migration runs in its own
transaction and bumps ``user_version``, so a catalog is always at one known version.
"""

from __future__ import annotations

import os
import sqlite3
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

from feederkit.errors import InputError

SCHEMA_V1 = """
CREATE TABLE parts (
    id          INTEGER PRIMARY KEY,
    name        TEXT NOT NULL UNIQUE,
    created_at  TEXT NOT NULL,
    created_by  TEXT NOT NULL
);
CREATE TABLE revisions (
    id                    INTEGER PRIMARY KEY,
    part_id               INTEGER NOT NULL REFERENCES parts(id) ON DELETE CASCADE,
    revision              INTEGER NOT NULL CHECK (revision >= 1),
    source_path           TEXT NOT NULL,
    source_sha256         TEXT NOT NULL,
    source_kind           TEXT NOT NULL CHECK (source_kind IN ('outline', 'dxf', 'mesh')),
    source_units          TEXT NOT NULL,
    options_json          TEXT NOT NULL,
    outline_json          TEXT NOT NULL,
    hull_json             TEXT NOT NULL,
    com_x                 REAL NOT NULL,
    com_y                 REAL NOT NULL,
    hull_tolerance        REAL,
    mesh_pose_json        TEXT,
    orientable            INTEGER NOT NULL CHECK (orientable IN (0, 1)),
    not_orientable_reason TEXT,
    warnings_json         TEXT NOT NULL,
    area                  REAL NOT NULL,
    n_holes               INTEGER NOT NULL,
    n_hull                INTEGER NOT NULL,
    created_at            TEXT NOT NULL,
    created_by            TEXT NOT NULL,
    UNIQUE (part_id, revision)
);
CREATE TABLE changeovers (
    id          INTEGER PRIMARY KEY,
    name        TEXT NOT NULL UNIQUE,
    created_at  TEXT NOT NULL,
    created_by  TEXT NOT NULL,
    sensor_json TEXT NOT NULL,
    plan_json   TEXT NOT NULL
);
CREATE TABLE changeover_parts (
    changeover_id INTEGER NOT NULL REFERENCES changeovers(id) ON DELETE CASCADE,
    position      INTEGER NOT NULL,
    revision_id   INTEGER NOT NULL REFERENCES revisions(id) ON DELETE RESTRICT,
    PRIMARY KEY (changeover_id, position)
);
CREATE INDEX changeover_parts_revision ON changeover_parts(revision_id);
"""


def _v1(conn: sqlite3.Connection) -> None:
    for statement in SCHEMA_V1.split(";"):
        if statement.strip():
            conn.execute(statement)


SCHEMA_V2 = """
CREATE TABLE landings (
    revision_id  INTEGER NOT NULL REFERENCES revisions(id) ON DELETE CASCADE,
    position     INTEGER NOT NULL CHECK (position >= 0),
    name         TEXT NOT NULL,
    probability  REAL NOT NULL CHECK (probability > 0),
    outline_json TEXT NOT NULL,
    hull_json    TEXT NOT NULL,
    com_x        REAL NOT NULL,
    com_y        REAL NOT NULL,
    merged_json  TEXT NOT NULL,
    PRIMARY KEY (revision_id, position),
    UNIQUE (revision_id, name)
);
"""


def _v2(conn: sqlite3.Connection) -> None:
    """Landings (docs/landings.md): each revision's ways to land, one row each.

    Revisions stored before this version have no rows; reading them computes their landings
    and says so (:func:`feederkit.catalog.store.get_revision`), so old catalogs stay readable
    without the source files.
    """
    for statement in SCHEMA_V2.split(";"):
        if statement.strip():
            conn.execute(statement)


SCHEMA_V3 = """
ALTER TABLE revisions ADD COLUMN shape_tolerance_mm REAL
    CHECK (shape_tolerance_mm IS NULL OR shape_tolerance_mm >= 0);
ALTER TABLE revisions ADD COLUMN com_tolerance_mm REAL
    CHECK (com_tolerance_mm IS NULL OR com_tolerance_mm >= 0);
"""


def _v3(conn: sqlite3.Connection) -> None:
    """A revision's own shape and COM tolerances (mm; design.md, "Uncertainty"): NULL where
    none is stored, which the plan commands count as 0 (docs/uncertainty.md). Existing
    revisions keep every field and store none."""
    for statement in SCHEMA_V3.split(";"):
        if statement.strip():
            conn.execute(statement)


MIGRATIONS: tuple[Callable[[sqlite3.Connection], None], ...] = (_v1, _v2, _v3)
"""Migration ``k`` brings a catalog from version ``k`` to ``k + 1``."""

SCHEMA_VERSION = len(MIGRATIONS)


DEFAULT_WAIT = 10.0
"""Seconds a command waits for another process's write transaction (``--wait``)."""

_FIRST_TRY_MS = 200
"""A busy catalog is retried silently this long (at most a quarter of the wait) before the
wait is announced."""

_busy_notifier: Callable[[str], None] | None = None


def set_busy_notifier(notify: Callable[[str], None] | None) -> None:
    """Who hears "the catalog is busy, waiting": the command line prints it on stderr.

    The library itself never prints; without a notifier the wait is silent.
    """
    global _busy_notifier
    _busy_notifier = notify


class CatalogConnection(sqlite3.Connection):
    """A catalog connection that knows its file and how long to wait for a busy catalog."""

    path: Path = Path("?")
    wait: float = DEFAULT_WAIT


def catalog_file_of(conn: sqlite3.Connection) -> Path:
    """The file behind a connection (for messages)."""
    if isinstance(conn, CatalogConnection):
        return conn.path
    try:
        return Path(conn.execute("PRAGMA database_list").fetchone()[2] or "?")
    except sqlite3.Error:
        return Path("?")


def _writable_dir(p: Path) -> bool:
    return os.access(p.parent if str(p.parent) else Path("."), os.W_OK)


def describe_sqlite_error(exc: sqlite3.Error, path: Path) -> str:
    """One line for an SQLite error on the catalog ``path``: what happened and what to do.

    Classified by SQLite's result code (busy, read-only, full, damaged, cannot open).
    """
    code = getattr(exc, "sqlite_errorname", "") or ""
    folder = path.parent if str(path.parent) else Path(".")
    if code.startswith(("SQLITE_BUSY", "SQLITE_LOCKED")):
        return (
            f"{path}: the catalog is busy (another process is writing it); try again when it "
            "is done, or wait longer with --wait SECONDS"
        )
    if code.startswith("SQLITE_FULL") or "disk is full" in str(exc):
        return (
            f"{path}: the disk is full; nothing was written and the catalog is as it was; "
            "free some space and try again"
        )
    if code.startswith(("SQLITE_READONLY", "SQLITE_CANTOPEN", "SQLITE_PERM", "SQLITE_AUTH")):
        if path.exists() and not os.access(path, os.R_OK):
            return f"{path}: cannot read the catalog (permission denied)"
        if not folder.is_dir():
            return f"{path}: cannot open the catalog (the folder {folder} does not exist)"
        if not _writable_dir(path):
            return (
                f"{path}: the catalog's folder {folder} is not writable (SQLite keeps its "
                "-wal and -shm files beside the catalog); use a writable folder or a copy"
            )
        if path.exists() and not os.access(path, os.W_OK) or code.startswith("SQLITE_READONLY"):
            return (
                f"{path}: the catalog is read-only; ask for write permission or work on a "
                "writable copy"
            )
        return f"{path}: cannot open the catalog ({exc})"
    if code.startswith(("SQLITE_CORRUPT", "SQLITE_NOTADB")):
        return (
            f"{path}: the catalog file is damaged ({exc}); restore it from a backup (or "
            "salvage it with: sqlite3 CATALOG .recover)"
        )
    if code.startswith("SQLITE_IOERR"):
        return f"{path}: input/output error on the catalog ({exc}); check the disk and try again"
    return f"{path}: catalog error ({exc})"


def catalog_error(exc: sqlite3.Error, path: Path) -> InputError:
    """The :class:`InputError` for an SQLite error on the catalog ``path``."""
    return InputError(describe_sqlite_error(exc, path))


def _is_busy(exc: sqlite3.Error) -> bool:
    code = getattr(exc, "sqlite_errorname", "") or ""
    return code.startswith(("SQLITE_BUSY", "SQLITE_LOCKED"))


def _begin(conn: sqlite3.Connection, path: Path) -> None:
    """``BEGIN IMMEDIATE``; a busy catalog is announced, then waited for up to ``conn.wait``."""
    wait = conn.wait if isinstance(conn, CatalogConnection) else DEFAULT_WAIT
    first = min(_FIRST_TRY_MS, int(wait * 250))
    conn.execute(f"PRAGMA busy_timeout = {first}")
    try:
        conn.execute("BEGIN IMMEDIATE")
        return
    except sqlite3.OperationalError as exc:
        if not _is_busy(exc):
            raise catalog_error(exc, path) from None
        if first == 0:
            raise InputError(
                f"{path}: the catalog is busy (another process is writing it); try again when "
                "it is done, or wait longer with --wait SECONDS"
            ) from None
    finally:
        conn.execute(f"PRAGMA busy_timeout = {int(wait * 1000)}")
    if _busy_notifier is not None:
        _busy_notifier(
            f"{path}: the catalog is busy (another process is writing it); waiting up to {wait:g} s"
        )
    try:
        conn.execute("BEGIN IMMEDIATE")
    except sqlite3.OperationalError as exc:
        if _is_busy(exc):
            raise InputError(
                f"{path}: the catalog is still busy after {wait:g} s (another process is "
                "writing it); try again when it is done, or wait longer with --wait SECONDS"
            ) from None
        raise catalog_error(exc, path) from None


def _rollback(conn: sqlite3.Connection) -> None:
    if conn.in_transaction:
        # SQLite may have rolled back already (e.g. after a full disk); nothing is committed.
        with suppress(sqlite3.Error):
            conn.execute("ROLLBACK")


@contextmanager
def transaction(
    conn: sqlite3.Connection, *, before_commit: Callable[[], None] | None = None
) -> Iterator[sqlite3.Connection]:
    """One write transaction: all of it is committed, or (on any exception or kill) none.

    ``before_commit`` runs after the body, inside the transaction: when it raises, nothing is
    committed (used to write a changeover's files only together with its row). SQLite errors
    (busy, read-only, full disk at ``COMMIT``, damaged file) become one-line InputErrors.
    """
    path = catalog_file_of(conn)
    _begin(conn, path)
    try:
        yield conn
        if before_commit is not None:
            before_commit()
        conn.execute("COMMIT")
    except sqlite3.Error as exc:
        _rollback(conn)
        raise catalog_error(exc, path) from None
    except BaseException:
        _rollback(conn)
        raise


def schema_version(conn: sqlite3.Connection) -> int:
    """The catalog's ``PRAGMA user_version``."""
    return int(conn.execute("PRAGMA user_version").fetchone()[0])


def migrate(conn: sqlite3.Connection) -> int:
    """Bring the schema to :data:`SCHEMA_VERSION`, one transaction per step; return the version."""
    version = schema_version(conn)
    if version > SCHEMA_VERSION:
        raise InputError(
            f"the catalog has schema version {version}, newer than this feederkit "
            f"({SCHEMA_VERSION}); upgrade feederkit"
        )
    while version < SCHEMA_VERSION:
        with transaction(conn):
            MIGRATIONS[version](conn)
            conn.execute(f"PRAGMA user_version = {version + 1}")
        version += 1
    return version


def _readable_as_is(conn: sqlite3.Connection, p: Path) -> None:
    """Refuse a catalog in a read-only folder whose schema this feederkit cannot read as it is
    (an older one would need its migration written first)."""
    version = schema_version(conn)
    if version > SCHEMA_VERSION:
        migrate(conn)  # the newer-schema error
    if version < SCHEMA_VERSION:
        folder = p.parent if str(p.parent) else Path(".")
        raise InputError(
            f"{p}: the catalog has schema version {version} and this feederkit reads "
            f"{SCHEMA_VERSION}; upgrading it writes, and its folder {folder} is not writable: "
            "open a copy in a writable folder"
        )


def _text(raw: bytes) -> str:
    """Text that is not UTF-8 is read with surrogate escapes, so each row's check can name it."""
    return raw.decode("utf-8", "surrogateescape")


def no_catalog(p: Path, what: str = "") -> InputError:
    """The error for a catalog that is not there: a missing file, or ``what`` is there instead."""
    where = f"{what}; " if what else ""
    return InputError(f"{p}: no catalog there ({where}create one with 'feederkit catalog init')")


def connect(
    path: str | Path, *, create: bool = False, wait: float = DEFAULT_WAIT
) -> CatalogConnection:
    """Open (and with ``create`` make) a catalog, migrated to the current schema.

    ``wait`` is how many seconds a write waits for another process's transaction. Raises
    InputError, one line naming the file, when it is missing (without ``create``), cannot be
    created or opened, is read-only where a write is needed, or is not a catalog. An empty
    (0-byte) file or an SQLite file without tables is made a catalog only with ``create``;
    without, it is no catalog, as a missing file is, and is left as it was: SQLite would take
    it for an empty database and migrating it would write the schema on a mere read.
    """
    p = Path(path)
    if not wait >= 0.0 or wait > 86400.0:
        raise InputError(f"--wait must be between 0 and 86400 seconds, got {wait}")
    try:
        exists = p.exists()
        if exists and p.is_dir():
            raise InputError(f"{p}: is a directory, not a catalog file")
        empty = exists and p.stat().st_size == 0 and os.access(p, os.R_OK)
    except OSError as exc:
        raise InputError(f"{p}: cannot open the catalog ({exc.strerror})") from None
    if empty and not create:
        raise no_catalog(p, "an empty file")
    if not exists:
        if not create:
            raise no_catalog(p)
        folder = p.parent if str(p.parent) else Path(".")
        if not folder.is_dir():
            raise InputError(f"{p}: cannot create the catalog: the folder {folder} does not exist")
        if not _writable_dir(p):
            raise InputError(f"{p}: cannot create the catalog: the folder {folder} is not writable")
    # In a folder we cannot write, SQLite cannot make the -wal and -shm files a WAL
    # catalog's reader needs: the catalog is opened read-only, and immutable when no
    # write-ahead log is beside it (a closed catalog has none: its content is all in the
    # file, and nobody writes it through this folder).
    read_only = exists and not _writable_dir(p)
    try:
        if read_only:
            log = p.with_name(p.name + "-wal")
            flags = "mode=ro" if log.exists() and log.stat().st_size > 0 else "mode=ro&immutable=1"
            uri = f"{p.resolve().as_uri()}?{flags}"
            conn = sqlite3.connect(
                uri, uri=True, isolation_level=None, timeout=wait, factory=CatalogConnection
            )
        else:
            conn = sqlite3.connect(p, isolation_level=None, timeout=wait, factory=CatalogConnection)
    except (sqlite3.Error, OSError) as exc:
        if isinstance(exc, OSError):
            raise InputError(f"{p}: cannot open the catalog ({exc.strerror})") from None
        raise catalog_error(exc, p) from None
    conn.path, conn.wait = p, wait
    conn.text_factory = _text
    try:
        conn.execute("PRAGMA foreign_keys = ON")
        conn.execute(f"PRAGMA busy_timeout = {int(wait * 1000)}")
        if schema_version(conn) == 0:  # checked before WAL mode, which writes the header
            tables = conn.execute("SELECT count(*) FROM sqlite_master").fetchone()[0]
            if tables:
                raise InputError(f"{p}: an SQLite file but not a feederkit catalog")
            if not create:
                raise no_catalog(p, "an SQLite file without tables")
        if read_only:
            _readable_as_is(conn, p)
            return conn
        mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
        if str(mode).lower() != "wal":
            raise InputError(f"{p}: the catalog cannot use WAL journaling (got {mode})")
        conn.execute("PRAGMA synchronous = FULL")
        migrate(conn)
    except sqlite3.DatabaseError as exc:
        conn.close()
        code = getattr(exc, "sqlite_errorname", "") or ""
        if code.startswith("SQLITE_NOTADB"):
            raise InputError(f"{p}: not a feederkit catalog ({exc})") from None
        raise catalog_error(exc, p) from None
    except BaseException:
        conn.close()
        raise
    return conn
