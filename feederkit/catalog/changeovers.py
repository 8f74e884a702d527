"""Changeovers: a named plan for a product mix, stored against the exact part revisions."""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from feederkit.catalog.model import (
    Changeover,
    ChangeoverInfo,
    check_name,
    is_valid_name,
    is_valid_text,
    name_key,
    shown_name,
)
from feederkit.catalog.schema import transaction
from feederkit.catalog.store import (
    CatalogLike,
    _conn,
    _similar,
    current_user,
    did_you_mean,
    now_utc,
)
from feederkit.errors import InputError
from feederkit.jsonio import parse_json


def _revision_id(conn: sqlite3.Connection, name: str, revision: int) -> int:
    row = conn.execute(
        "SELECT r.id FROM revisions r JOIN parts p ON p.id = r.part_id "
        "WHERE p.name = ? AND r.revision = ?",
        (name, int(revision)),
    ).fetchone()
    if row is None:
        raise InputError(f"no part {name!r} revision {revision} in the catalog")
    return int(row[0])


RevisionStamp = tuple[Any, ...]
"""What a stored revision is (source file, options, hull, COM, when it was added), so that a
revision removed and added again under its number is not taken for the one a plan was made
from."""

_STAMP_SQL = (
    "SELECT source_sha256, options_json, outline_json, hull_json, com_x, com_y, created_at "
    "FROM revisions WHERE id = ?"
)


def _stamp(conn: sqlite3.Connection, rid: int) -> RevisionStamp:
    return tuple(conn.execute(_STAMP_SQL, (rid,)).fetchone())


def revision_stamps(catalog: CatalogLike, mix: Sequence[tuple[str, int]]) -> list[RevisionStamp]:
    """The :data:`RevisionStamp` of each ``(name, revision)``, read now (InputError for one
    the catalog does not have); :func:`save_changeover` compares them with the stored ones."""
    with _conn(catalog) as conn:
        return [_stamp(conn, _revision_id(conn, str(n), int(r))) for n, r in mix]


def save_changeover(
    catalog: CatalogLike,
    name: str,
    part_revisions: Sequence[tuple[str, int]],
    sensor: Mapping[str, Any],
    plan_json: str,
    *,
    replace: bool = False,
    created_by: str | None = None,
    before_commit: Callable[[], None] | None = None,
    stamps: Sequence[RevisionStamp] | None = None,
) -> ChangeoverInfo:
    """Store a changeover in one transaction: the mix's exact revisions, sensor, and plan JSON.

    ``stamps`` are the revisions' :func:`revision_stamps` as the plan was made from them: a
    revision removed and added again meanwhile has the same number and other contents, and
    is refused rather than stored against a plan not made for it.

    ``before_commit`` runs inside that transaction once the rows are written: write the plan
    and report files there, so that the changeover is committed only when they were written
    and nothing is stored when writing them raises. An existing name is refused unless
    ``replace``. Raises InputError for unknown parts or revisions, an empty mix, a part listed
    twice, a plan that is not JSON, or a catalog error (busy, read-only, disk full).
    """
    name = check_name(name, "changeover")  # in NFC, as part names are
    mix = [(str(n), int(r)) for n, r in part_revisions]
    if not mix:
        raise InputError(f"changeover {name!r}: the mix has no parts")
    names = [n for n, _ in mix]
    if len(set(names)) != len(names):
        raise InputError(f"changeover {name!r}: a part is listed twice in the mix")
    try:
        json.loads(plan_json)
        sensor_text = json.dumps(dict(sensor), sort_keys=True, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"changeover {name!r}: the sensor or plan is not valid JSON ({exc})"
        ) from None
    who, when = created_by or current_user(), now_utc()
    with _conn(catalog) as conn, transaction(conn, before_commit=before_commit):
        ids = [_revision_id(conn, n, r) for n, r in mix]
        gone = [] if stamps is None else [
            f"{n}@{r}" for (n, r), i, was in zip(mix, ids, stamps, strict=True)
            if _stamp(conn, i) != was
        ]  # fmt: skip
        if gone:
            raise InputError(
                f"{', '.join(gone)} replaced in the catalog while the plan was made (removed and "
                "added again under the same number): nothing stored; compile the changeover again"
            )
        old = conn.execute(
            "SELECT id FROM changeovers WHERE name IN (?, ?)", _spellings(name)
        ).fetchone()
        if old is not None:
            if not replace:
                raise InputError(f"a changeover named {name!r} already exists")
            conn.execute("DELETE FROM changeovers WHERE id = ?", (old[0],))
        cur = conn.execute(
            "INSERT INTO changeovers (name, created_at, created_by, sensor_json, plan_json) "
            "VALUES (?, ?, ?, ?, ?)",
            (name, when, who, sensor_text, plan_json),
        )
        cid = int(cur.lastrowid)
        conn.executemany(
            "INSERT INTO changeover_parts (changeover_id, position, revision_id) VALUES (?, ?, ?)",
            [(cid, k, rid) for k, rid in enumerate(ids)],
        )
    return ChangeoverInfo(name, when, who, tuple(mix), json.loads(sensor_text))


def _info(conn: sqlite3.Connection, row: Sequence[Any]) -> ChangeoverInfo:
    """A stored changeover's info, checked: a damaged row is one InputError naming it."""
    parts = conn.execute(
        "SELECT p.name, r.revision FROM changeover_parts cp JOIN revisions r "
        "ON r.id = cp.revision_id JOIN parts p ON p.id = r.part_id "
        "WHERE cp.changeover_id = ? ORDER BY cp.position",
        (row[0],),
    ).fetchall()
    name = row[1]
    try:
        if not is_valid_name(name):
            raise InputError("the name is not a valid changeover name")
        for text in (row[2], row[3]):
            if not isinstance(text, str) or not is_valid_text(text):
                raise InputError("created_at or created_by is not UTF-8 text")
        if not all(is_valid_name(n) and isinstance(r, int) for n, r in parts):
            raise InputError("a part of its mix has a damaged name or revision")
        if not isinstance(row[4], str) or not is_valid_text(row[4]):
            raise InputError("sensor_json is not UTF-8 text")
        sensor = parse_json(row[4], "sensor_json")
        if not isinstance(sensor, dict):
            raise InputError("sensor_json is not a JSON object")
    except InputError as exc:
        raise InputError(
            f"changeover {shown_name(name)}: the stored data is damaged ({exc}); remove it "
            "with 'feederkit changeover remove NAME' and compile it again"
        ) from None
    return ChangeoverInfo(
        name=name,
        created_at=row[2],
        created_by=row[3],
        parts=tuple((n, int(r)) for n, r in parts),
        sensor=sensor,
    )


def _spellings(name: str) -> tuple[str, str]:
    """A changeover name as typed and in NFC (:func:`~feederkit.catalog.model.name_key`):
    names are stored in NFC, and older versions stored them as typed."""
    return name, name_key(name)


def get_changeover(catalog: CatalogLike, name: str) -> Changeover:
    """The changeover ``name`` with its plan JSON text; InputError when there is none."""
    with _conn(catalog) as conn:
        row = conn.execute(
            "SELECT id, name, created_at, created_by, sensor_json, plan_json FROM changeovers "
            "WHERE name IN (?, ?)",
            _spellings(name),
        ).fetchone()
        if row is None:
            names = [r[0] for r in conn.execute("SELECT name FROM changeovers")]
            hint = did_you_mean(_similar([n for n in names if is_valid_name(n)], name))
            raise InputError(f"no changeover named {name!r} in the catalog{hint}")
        info = _info(conn, row)
        if not isinstance(row[5], str) or not is_valid_text(row[5]):
            raise InputError(
                f"changeover {name!r}: the stored plan is not UTF-8 text; remove it with "
                "'feederkit changeover remove NAME' and compile it again"
            )
        return Changeover(info=info, plan_json=row[5])


def list_changeovers(catalog: CatalogLike) -> list[ChangeoverInfo]:
    """All changeovers (without their plans), sorted by name."""
    with _conn(catalog) as conn:
        rows = conn.execute(
            "SELECT id, name, created_at, created_by, sensor_json FROM changeovers ORDER BY name"
        ).fetchall()
        return [_info(conn, row) for row in rows]


UNREADABLE = object()
"""The value :func:`declared_uncertainties` gives a changeover whose stored plan is not JSON."""


def declared_uncertainties(catalog: CatalogLike) -> dict[str, object]:
    """Each changeover's declared uncertainty: its plan file's ``"uncertainty"`` value
    (design.md), None when the plan declares none (a version-1 plan, the ideal model), or
    :data:`UNREADABLE` when the stored plan is not JSON. SQLite reads the one value, so a
    listing does not load every plan (a plan may hold megabytes)."""
    with _conn(catalog) as conn:
        try:
            rows = conn.execute(
                "SELECT name, json_valid(plan_json), CASE WHEN json_valid(plan_json) THEN "
                "json_extract(plan_json, '$.uncertainty') END FROM changeovers"
            ).fetchall()
        except sqlite3.OperationalError:  # an SQLite without JSON functions: Python reads
            rows = [(n, *_uncertainty_of(t)) for n, t in conn.execute(_ALL_PLANS).fetchall()]
    out: dict[str, object] = {}
    for name, valid, raw in rows:
        if not valid:
            out[name] = UNREADABLE
            continue
        try:
            out[name] = None if raw is None else parse_json(str(raw), "uncertainty")
        except InputError:
            out[name] = UNREADABLE
    return out


_ALL_PLANS = "SELECT name, plan_json FROM changeovers"


def _uncertainty_of(plan_json: object) -> tuple[int, str | None]:
    """``(valid, the "uncertainty" value as JSON text)`` of a stored plan, read in Python."""
    try:
        plan = json.loads(plan_json) if isinstance(plan_json, str) else None
    except ValueError:
        plan = None
    if not isinstance(plan, dict):
        return 0, None
    value = plan.get("uncertainty")
    return 1, None if value is None else json.dumps(value)


def remove_changeover(catalog: CatalogLike, name: str) -> None:
    """Delete a changeover (its parts stay); InputError when there is none."""
    with _conn(catalog) as conn, transaction(conn):
        cur = conn.execute("DELETE FROM changeovers WHERE name IN (?, ?)", _spellings(name))
        if cur.rowcount == 0:
            raise InputError(f"no changeover named {name!r} in the catalog")
