"""Rows of the catalog as frozen values, and the rules for part names."""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from feederkit.catalog.tolerances import RevisionTolerances
from feederkit.errors import InputError
from feederkit.landing.model import Landing
from feederkit.outline import Outline

Point = tuple[float, float]

NAME_RE = re.compile(r"^[^\s@/\\\-\x00-\x1f][^@/\\\x00-\x1f]{0,199}$")
"""Part and changeover names: 1-200 characters, no '@', '/', '\\' or control characters,
not starting with '-' or a space ('@' separates a revision: ``bracket@2``)."""

MAX_NAME_BYTES = 240
"""A name's UTF-8 bytes: names become file names (``NAME.json``, ``NAME.plan.json``) and file
systems hold 255 bytes per name, so 240 leaves room for the suffix."""

_INVISIBLE_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})
"""Control, format (bidi overrides, zero-width), surrogate, private, unassigned, line and
paragraph separators: characters that hide or reorder what a name shows."""


def _name_problem(name: object) -> str | None:
    """Why ``name`` is not a valid catalog name, or None."""
    if not isinstance(name, str):
        return "not text"
    if name in (".", ".."):
        return "'.' and '..' name folders"
    if name != name.strip():
        return "surrounding spaces"
    for ch in name:
        category = unicodedata.category(ch)
        if category in _INVISIBLE_CATEGORIES:
            return f"the invisible or control character U+{ord(ch):04X} ({category})"
        if category == "Zs" and ch != " ":
            return f"the space character U+{ord(ch):04X} (only plain spaces are allowed)"
    if not NAME_RE.match(name):
        return "1-200 characters, no '@', '/', '\\', no leading '-'"
    size = len(name.encode("utf-8"))
    if size > MAX_NAME_BYTES:
        return (
            f"{size} bytes in UTF-8, more than the {MAX_NAME_BYTES} a file name can hold "
            "(file systems allow 255 bytes)"
        )
    return None


def name_key(name: str) -> str:
    """``name`` in Unicode normal form NFC: the form the catalog stores and compares names in.

    'Ü' typed on Linux is one code point, a macOS file name spells it 'U' and a combining
    diaeresis (NFD); both look the same, so they must name the same part, not two.
    """
    return unicodedata.normalize("NFC", name)


def check_name(name: str, what: str = "part") -> str:
    """Return ``name`` in NFC (:func:`name_key`) when it is a valid catalog name, else raise
    InputError.

    Valid: 1-200 characters and at most 240 UTF-8 bytes (names are used as file names), no
    '@', '/', '\\', no leading '-', no surrounding spaces, not '.' or '..', and no control,
    bidi-override or zero-width characters; the NFC form is what is checked, and stored.
    """
    if isinstance(name, str):
        name = name_key(name)
    problem = _name_problem(name)
    if problem is not None:
        shown = repr(_clip(name)) if isinstance(name, str) else type(name).__name__
        raise InputError(f"invalid {what} name {shown}: {problem}")
    return name


MIX_SEPARATORS = {
    ",": "separates the parts of --mix (A,B)",
    ":": "separates a part's share in --mix (NAME:SHARE)",
}
"""The characters ``--mix`` reads as syntax: a part name holding one could not be put in a mix
(``t-clip:0.5`` would be the part ``t-clip`` at 50 %)."""

PART_NAME_ADVICE = "give the part a name without ',' or ':' (catalog add FILE --name NAME)"
"""How to name a part whose name holds a mix separator, when the name came from a file."""


def mix_separator(name: str) -> str | None:
    """The first character of ``name`` that ``--mix`` reads as syntax, or None."""
    return next((ch for ch in name if ch in MIX_SEPARATORS), None)


def check_part_name(name: str, advice: str = PART_NAME_ADVICE) -> str:
    """Return ``name`` when it may name a new part, else raise InputError (one line).

    A catalog name (:func:`check_name`) without ',' or ':', which ``--mix`` reads as syntax.
    Parts stored before this rule keep their names (they list, show and plan by name);
    ``advice`` says how to give the part another name where it was made. Returns the name in
    NFC, as :func:`check_name`.
    """
    name = check_name(name)
    ch = mix_separator(name)
    if ch is not None:
        raise InputError(
            f"invalid part name {_clip(name)!r}: {ch!r} {MIX_SEPARATORS[ch]}, so no mix could "
            f"name this part; {advice}"
        )
    return name


def is_mix_name(name: str) -> bool:
    """Whether ``name`` can be typed in ``--mix`` (holds no ',' or ':'): only such names are
    suggested ("did you mean ...?")."""
    return mix_separator(name) is None


def is_valid_name(name: object) -> bool:
    """Whether ``name`` could name a catalog part or changeover (see :func:`check_name`)."""
    return _name_problem(name) is None


FILE_SUFFIXES = (".json", ".dxf", ".stl", ".obj", ".ply")
"""Suffixes of source files (docs/import.md): a SOURCE ending so names a file."""


def could_be_part_name(source: str) -> bool:
    """Whether a SOURCE that is not an existing file could be a catalog name (``NAME`` or
    ``NAME@REV``); when not (a path with '/', a file suffix, an invalid name) it is a missing
    file and should be reported as one."""
    name = re.sub(r"@[0-9]+$", "", source)
    return is_valid_name(name) and not name.lower().endswith(FILE_SUFFIXES)


def split_revision(text: str) -> tuple[str, int | None]:
    """A part argument ``NAME@REV`` as (name, revision), a plain ``NAME`` as (name, None).

    The one reading of ``NAME@REV`` for the catalog commands and a catalog SOURCE: a name holds
    no '@', so a valid name before the last '@' is a part and what follows must be a revision
    number; anything else (``abc``, ``-1``) is one InputError in the words every command uses,
    not "no part named 'NAME@abc'" (:func:`bad_revision`). Text whose part before the last '@'
    is no valid name is returned whole, to be answered as an unknown name.

    >>> split_revision("clip@2"), split_revision("clip")
    (('clip', 2), ('clip', None))
    """
    name, at, rev = text.rpartition("@")
    if not at or not is_valid_name(name):
        return text, None
    if not (rev.isascii() and rev.isdigit()):
        raise InputError(bad_revision(name, rev))
    if int(rev) < 1:
        raise InputError(f"{text}: revisions are numbered from 1")
    return name, int(rev)


def bad_revision(name: str, rev: str) -> str:
    """What is wrong with ``NAME@REV`` whose ``rev`` is no number (``part 'clip' has no
    revision 'abc' (NAME@REV takes a revision number)``)."""
    return f"part {name!r} has no revision {rev!r} (NAME@REV takes a revision number)"


def is_valid_text(text: str) -> bool:
    """Whether ``text`` read from the catalog is UTF-8 (bad bytes come back as surrogates)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def shown_name(name: object) -> str:
    """A name as it is safe to print on one line: itself when valid, else its ``repr``."""
    return name if isinstance(name, str) and is_valid_name(name) else repr(name)


def _clip(text: str, n: int = 40) -> str:
    return text if len(text) <= n else text[:n] + "..."


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
    shape_tolerance_mm: float | None = None
    com_tolerance_mm: float | None = None
    """The latest revision's own tolerances (mm; None: not stored)."""


@dataclass(frozen=True)
class Revision:
    """A stored part revision with everything needed to rebuild the part exactly.

    ``landings`` are the ways the part lands (docs/landings.md), each with its own outline,
    hull and COM; ``landings_note`` says when they were not stored but computed on read (a
    revision stored before catalog schema 2), and what that means. ``shape_tolerance_mm``
    and ``com_tolerance_mm`` are the revision's own tolerances (design.md, "Uncertainty"; None:
    not stored, which plans count as 0).
    """

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
    landings: tuple[Landing, ...] = ()
    landings_note: str | None = None
    shape_tolerance_mm: float | None = None
    com_tolerance_mm: float | None = None

    @property
    def tolerances(self) -> RevisionTolerances:
        """What this revision stores, for :func:`~feederkit.catalog.declared_tolerances`."""
        return RevisionTolerances(
            self.name, self.revision, self.shape_tolerance_mm, self.com_tolerance_mm
        )


@dataclass(frozen=True)
class AddOutcome:
    """What an add did to one part: ``status`` is ``added``, ``revised`` or ``unchanged``."""

    name: str
    revision: int
    status: str
    source_path: str
    orientable: bool
    warnings: tuple[str, ...]
    changes: tuple[str, ...] = ()
    """For ``revised``: what changed against the previous latest revision (file, options,
    tolerances)."""
    shape_tolerance_mm: float | None = None
    com_tolerance_mm: float | None = None
    """The tolerances the revision stores (mm; None: not stored)."""


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
