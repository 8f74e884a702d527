"""What an exported outline file leaves behind: the warnings of ``catalog export``.

The outline file (design.md) holds a name, units, vertices, holes and a COM. A revision may
store more: a mesh's other resting poses, a flat part's side probability, its own shape and
COM tolerances. A part imported from the file has none of them, so a plan of it covers other
landings, shares or uncertainty than the catalog part's; export says so, and how to get them
back, instead of losing them silently.
"""

from __future__ import annotations

from feederkit.catalog.model import Revision
from feederkit.landing.model import DEFAULT_SIDE_PROBABILITY


def export_warnings(rev: Revision) -> list[str]:
    """The warnings of exporting ``rev`` as an outline file: the mesh landings the file
    leaves to the catalog, and the stored values it has no field for (with the flags that
    store them again on import)."""
    return [w for w in (_landings_left_out(rev), _values_left_out(rev)) if w]


def _landings_left_out(rev: Revision) -> str | None:
    """A mesh's other resting poses: the file holds the imported pose's outline alone, and a
    file made from it plans that pose alone."""
    if rev.source_kind != "mesh" or len(rev.landings) < 2:
        return None
    names = ", ".join(x.name for x in rev.landings)
    return (
        f"{rev.name} is a mesh part of {len(rev.landings)} landings ({names}): the outline "
        "file holds the imported pose's outline alone, so a plan of the file covers that pose "
        "only (plan the catalog part, or the mesh file, for every landing)"
    )


def left_out_flags(rev: Revision) -> list[tuple[str, str, float]]:
    """(words, flag, value) of each value ``rev`` stores that the outline file has no field
    for: a flat part's side probability when not the default 0.5, and a shape or COM
    tolerance above 0 (0 counts as none). Importing the file with the flags stores them
    again."""
    out = []
    side = rev.options.get("side_probability") if rev.source_kind != "mesh" else None
    if isinstance(side, int | float) and float(side) != DEFAULT_SIDE_PROBABILITY:
        out.append(("side probability", "--side-probability", float(side)))
    for words, flag, value in (
        ("shape tolerance", "--shape-tolerance", rev.shape_tolerance_mm),
        ("COM tolerance", "--com-tolerance", rev.com_tolerance_mm),
    ):
        if value:
            out.append((words, flag, value))
    return out


def _values_left_out(rev: Revision) -> str | None:
    """The stored values the file cannot hold, named with what a part imported from it gets
    instead (landings up and down at 0.5 each, tolerance 0 in its plans) and the flags to
    give again on import."""
    left = left_out_flags(rev)
    if not left:
        return None
    units = {"side probability": ""}
    said = ", ".join(f"{words} {_number(v)}{units.get(words, ' mm')}" for words, _, v in left)
    instead = []
    if left[0][0] == "side probability":
        instead.append("lands up and down at 0.5 each")
    if any(words != "side probability" for words, _, _ in left):
        instead.append("stores no tolerance (its plans declare 0 unless given)")
    flags = " ".join(f"{flag} {_number(v)}" for _, flag, v in left)
    return (
        f"{rev.name} revision {rev.revision} stores {said}, which the outline file has no field "
        f"for: a part imported from the file {' and '.join(instead)}; give {flags} when "
        "importing it (catalog add or import)"
    )


def _number(x: float) -> str:
    """``x`` as typed on the command line: its shortest exact form, without a trailing .0."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text
