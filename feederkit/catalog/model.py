"""Rows of the catalog as frozen values, and the rules for part names."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from feederkit.errors import InputError
from feederkit.outline import Outline

Point = tuple[float, float]

NAME_RE = re.compile(r"^[^\s@/\\\-\x00-\x1f][^@/\\\x00-\x1f]{0,199}$")
"""Part and changeover names: 1-200 characters, no '@', '/', '\\' or control characters,
not starting with '-' or a space ('@' separates a revision: ``bracket@2``)."""


def check_name(name: str, what: str = "part") -> str:
    """Return ``name`` when it is a valid catalog name, else raise InputError."""
    if not isinstance(name, str) or not NAME_RE.match(name) or name != name.strip():
        raise InputError(
            f"invalid {what} name {name!r}: 1-200 characters, no '@', '/', '\\', "
            "no leading '-' or surrounding spaces"
        )
    return name


@dataclass(frozen=True)
class PartSummary:
    """One line of ``catalog list``: a part and its latest revision."""

    name: str
    revision: int
    revisions: int
    source_kind: str
    source_units: str
    area: float
    n_holes: int
    n_hull: int
    orientable: bool
    updated_at: str


@dataclass(frozen=True)
class Revision:
    """A stored part revision with everything needed to rebuild the part exactly."""

    name: str
    revision: int
    source_path: str
    source_sha256: str
    source_kind: str
    source_units: str
    options: Mapping[str, Any]
    outline: Outline
    hull: tuple[Point, ...]
    com: Point
    hull_tolerance: float | None
    mesh_pose: Mapping[str, Any] | None
    orientable: bool
    not_orientable_reason: str | None
    warnings: tuple[str, ...]
    area: float
    created_at: str
    created_by: str


@dataclass(frozen=True)
class AddOutcome:
    """What an add did to one part: ``status`` is ``added``, ``revised`` or ``unchanged``."""

    name: str
    revision: int
    status: str
    source_path: str
    orientable: bool
    warnings: tuple[str, ...]


@dataclass(frozen=True)
class ChangeoverInfo:
    """A changeover without its plan: name, who and when, the exact part revisions, the sensor."""

    name: str
    created_at: str
    created_by: str
    parts: tuple[tuple[str, int], ...]
    sensor: Mapping[str, Any]


@dataclass(frozen=True)
class Changeover:
    """A stored changeover: its info and the plan file's JSON text (design.md, feederkit-plan)."""

    info: ChangeoverInfo
    plan_json: str

    @property
    def name(self) -> str:
        """The changeover's unique name."""
        return self.info.name
