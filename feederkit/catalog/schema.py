"""The catalog's SQLite schema, its version (``PRAGMA user_version``) and migrations.

Every connection runs in WAL mode with foreign keys on. Each migration runs in its own
transaction and bumps ``user_version``, so a catalog is always at one known version.
"""

from __future__ import annotations

import sqlite3
from collections.abc import Callable, Iterator
from contextlib import contextmanager
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


MIGRATIONS: tuple[Callable[[sqlite3.Connection], None], ...] = (_v1,)
"""Migration ``k`` brings a catalog from version ``k`` to ``k + 1``."""

SCHEMA_VERSION = len(MIGRATIONS)


@contextmanager
def transaction(conn: sqlite3.Connection) -> Iterator[sqlite3.Connection]:
    """One write transaction: all of it is committed, or (on any exception or kill) none."""
    conn.execute("BEGIN IMMEDIATE")
    try:
        yield conn
    except BaseException:
        conn.execute("ROLLBACK")
        raise
    conn.execute("COMMIT")


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


def connect(path: str | Path, *, create: bool = False) -> sqlite3.Connection:
    """Open (and with ``create`` make) a catalog, migrated to the current schema.

    Raises InputError when the file is missing (without ``create``) or not a catalog.
    """
    p = Path(path)
    if not create and not p.exists():
        raise InputError(f"{p}: no catalog there (create one with 'feederkit catalog init')")
    if p.exists() and p.is_dir():
        raise InputError(f"{p}: is a directory, not a catalog file")
    try:
        conn = sqlite3.connect(p, isolation_level=None, timeout=10.0)
    except sqlite3.Error as exc:
        raise InputError(f"{p}: cannot open the catalog ({exc})") from None
    try:
        conn.execute("PRAGMA foreign_keys = ON")
        conn.execute("PRAGMA busy_timeout = 10000")
        mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
        if str(mode).lower() != "wal":
            raise InputError(f"{p}: the catalog cannot use WAL journaling (got {mode})")
        conn.execute("PRAGMA synchronous = FULL")
        if schema_version(conn) == 0:
            tables = conn.execute("SELECT count(*) FROM sqlite_master").fetchone()[0]
            if tables:
                raise InputError(f"{p}: an SQLite file but not a feederkit catalog")
        migrate(conn)
    except sqlite3.DatabaseError as exc:
        conn.close()
        raise InputError(f"{p}: not a feederkit catalog ({exc})") from None
    except BaseException:
        conn.close()
        raise
    return conn
