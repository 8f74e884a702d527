"""Resolve a SOURCE argument (design.md): an outline file, a CAD file, or a catalog part name."""

from __future__ import annotations

from pathlib import Path

from feederkit.errors import InputError
from feederkit.outline import load_outline_json
from feederkit.part import Part, make_part

Point = tuple[float, float]


def load_part(source: str, *, com: Point | None = None, catalog: str | None = None) -> Part:
    """Load one part from a SOURCE: an outline ``.json`` file (catalog and CAD files: see below).

    Raises InputError naming the source when it cannot be read or is not a valid part.
    """
    path = Path(source)
    if path.suffix.lower() == ".json":
        return make_part(load_outline_json(path), com)
    if path.exists():
        raise InputError(f"{source}: unsupported file type {path.suffix!r}")
    raise InputError(f"{source}: no such file or catalog part")
