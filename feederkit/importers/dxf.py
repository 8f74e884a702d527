"""DXF drawings (ezdxf + shapely): entities to flattened lines in millimetres, then parts.

Block references are exploded recursively in world coordinates (rotated, scaled, mirrored
and nested inserts alike). Curves are flattened within a tolerance; text, dimensions,
hatches and other annotation are skipped. The loops are built in :mod:`.loops`.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import ezdxf
import numpy as np
from ezdxf import path as dxfpath
from ezdxf import recover
from ezdxf.document import Drawing as DxfDocument
from ezdxf.entities import DXFGraphic
from ezdxf.lldxf.const import DXFError

from feederkit.errors import InputError
from feederkit.importers.loops import Region, drawing_from_lines
from feederkit.importers.model import ImportedOutline, ImportOptions
from feederkit.outline import make_outline, unit_scale

logging.getLogger("ezdxf").addHandler(logging.NullHandler())  # a library never prints

CURVES = frozenset({"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE"})
"""Entity types that make up an outline; everything else (text, dimensions, hatches) is skipped."""

MAX_BLOCK_DEPTH = 32
"""Deeper block nesting is taken as a reference cycle."""

INSUNITS: dict[int, tuple[str, float]] = {
    1: ("in", 25.4),
    2: ("ft", 304.8),
    3: ("mi", 1_609_344.0),
    4: ("mm", 1.0),
    5: ("cm", 10.0),
    6: ("m", 1000.0),
    7: ("km", 1_000_000.0),
    8: ("microinch", 25.4e-6),
    9: ("mil", 0.0254),
    10: ("yd", 914.4),
    13: ("um", 0.001),
    14: ("dm", 100.0),
}
"""``$INSUNITS`` codes and millimetres per unit (0, unitless, is read as mm with a warning)."""


def read_document(path: Path) -> DxfDocument:
    """Open a DXF file (ASCII or binary, any version), recovering damaged files when possible."""
    try:
        return ezdxf.readfile(path)
    except OSError as exc:
        if exc.errno is not None:
            raise InputError(f"{path}: cannot read the file ({exc.strerror})") from None
        raise InputError(f"{path}: not a DXF file") from None  # ezdxf's own verdict
    except Exception:  # noqa: BLE001 - any parser failure: try the recover module
        pass
    try:
        doc, auditor = recover.readfile(path)
    except Exception as exc:  # noqa: BLE001 - ezdxf raises many types on broken input
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"{path}: not a readable DXF file ({reason})") from None
    if auditor.has_errors:
        raise InputError(f"{path}: damaged DXF file ({len(auditor.errors)} unrecoverable errors)")
    return doc


def drawing_units(
    doc: DxfDocument, override: str | None, label: str
) -> tuple[str, float, list[str]]:
    """The drawing's unit name, millimetres per unit, and warnings (unitless files)."""
    if override is not None:
        return override, unit_scale(override), []
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code in INSUNITS:
        name, scale = INSUNITS[code]
        return name, scale, []
    if code == 0:
        return "mm", 1.0, ["the drawing has no units ($INSUNITS 0): read as mm (use --units)"]
    raise InputError(f"{label}: unsupported drawing unit $INSUNITS {code}; give --units")


def explode(
    entities: object, layer: str, depth: int, skipped: Counter[str]
) -> Iterator[tuple[DXFGraphic, str]]:
    """Curve entities in world coordinates with their effective layer, block references exploded.

    Like ``ezdxf.disassemble.recursive_decompose`` but annotation inside blocks (dimensions,
    leaders, text) is skipped instead of decomposed into lines. Entities of a block on layer
    "0" take the layer of the reference, as CAD programs draw them.
    """
    for entity in entities:  # type: ignore[attr-defined]
        kind = entity.dxftype()
        if kind != "INSERT" and kind not in CURVES:
            skipped[kind] += 1
            continue
        own = entity.dxf.get("layer", "0") if entity.dxf.is_supported("layer") else "0"
        eff = layer if (own == "0" and layer) else own
        if kind == "INSERT":
            if depth >= MAX_BLOCK_DEPTH:
                raise InputError(f"block references nested deeper than {MAX_BLOCK_DEPTH}")
            try:
                subs = (
                    list(entity.multi_insert())
                    if entity.mcount > 1
                    else list(entity.virtual_entities())
                )
            except Exception as exc:  # noqa: BLE001 - broken block definitions
                raise InputError(
                    f"cannot explode block {entity.dxf.get('name', '?')!r} ({exc})"
                ) from None
            yield from explode(subs, eff, depth + 1, skipped)
        else:
            yield entity, eff


def flatten(entity: DXFGraphic, distance: float) -> list[np.ndarray]:
    """The entity as polylines (drawing units, x y), curves within ``distance`` of their chords."""
    kind = entity.dxftype()
    if kind == "LINE":
        s, e = entity.dxf.start, entity.dxf.end
        return [np.array([[s.x, s.y], [e.x, e.y]])]
    if kind == "POLYLINE" and not (entity.is_2d_polyline or entity.is_3d_polyline):
        return []  # polyface and polygon meshes are surfaces, not outlines
    out = []
    for sub in dxfpath.make_path(entity).sub_paths():
        pts = np.array([(v.x, v.y) for v in sub.flattening(distance)], dtype=float)
        if len(pts) >= 2:
            out.append(pts)
    return out


def dxf_lines(
    doc: DxfDocument, layers: tuple[str, ...], scale: float, flatten_mm: float, label: str
) -> tuple[list[np.ndarray], Counter[str]]:
    """All outline polylines of the model space in millimetres, and the skipped entity types.

    With ``layers``, only entities on those layers (case-insensitive; block contents on
    layer "0" count on their reference's layer) are read.
    """
    skipped: Counter[str] = Counter()
    wanted = {name.lower() for name in layers}
    seen: set[str] = set()
    distance = flatten_mm / scale
    lines: list[np.ndarray] = []
    for entity, layer in explode(doc.modelspace(), "", 0, skipped):
        seen.add(layer)
        if wanted and layer.lower() not in wanted:
            continue
        try:
            pieces = flatten(entity, distance)
        except Exception as exc:  # noqa: BLE001 - degenerate curves in third-party files
            kind, handle = entity.dxftype(), entity.dxf.handle
            raise InputError(f"{label}: cannot flatten {kind} {handle} ({exc})") from None
        for pts in pieces:
            if not np.isfinite(pts).all():
                kind, handle = entity.dxftype(), entity.dxf.handle
                raise InputError(f"{label}: {kind} {handle} has NaN or infinite coordinates")
            lines.append(pts * scale)
    if wanted and not lines and seen:
        names = ", ".join(sorted(seen))
        raise InputError(
            f"{label}: no geometry on layer {', '.join(sorted(layers))} (layers: {names})"
        )
    return lines, skipped


def _describe(region: Region) -> str:
    xs = [p[0] for p in region.shell]
    ys = [p[1] for p in region.shell]
    cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    return f"area {region.area:.1f} mm2 at ({cx:.1f}, {cy:.1f})"


def read_dxf(
    path: Path, options: ImportOptions, name: str
) -> tuple[list[ImportedOutline], list[str], list[str]]:
    """Parts of a DXF file: (imported outlines, descriptions of parts left out, warnings).

    The part is the largest closed loop with the loops inside it as holes; with
    ``options.all_parts`` every separate part is returned, named ``name``, ``name-2``, ...
    """
    doc = read_document(path)
    try:
        return _read_doc(doc, path, options, name)
    except DXFError as exc:  # malformed entities that ezdxf loaded but cannot interpret
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"{path}: malformed DXF ({reason})") from None


def _read_doc(
    doc: DxfDocument, path: Path, options: ImportOptions, name: str
) -> tuple[list[ImportedOutline], list[str], list[str]]:
    unit_name, scale, warnings = drawing_units(doc, options.units, str(path))
    lines, skipped = dxf_lines(doc, options.layers, scale, options.flatten_tolerance, str(path))
    if not lines:
        what = ", ".join(f"{k} x{v}" for k, v in sorted(skipped.items())) or "nothing"
        raise InputError(
            f"{path}: no outline geometry (lines, arcs, curves) in the drawing: {what}"
        )
    drawing = drawing_from_lines(lines, options.flatten_tolerance, str(path))
    if drawing.frames:
        warnings.append(f"skipped {drawing.frames} drawing frame(s) around the part")
    regions = list(drawing.regions)
    chosen = regions if options.all_parts else regions[:1]
    others = (
        []
        if options.all_parts
        else [f"{name}-{k + 2}: {_describe(r)}" for k, r in enumerate(regions[1:])]
    )
    if others:
        warnings.append(
            f"the drawing holds {len(regions)} separate parts; imported the largest "
            "(use --all-parts for all)"
        )
    outlines = []
    for k, region in enumerate(chosen):
        label = name if k == 0 else f"{name}-{k + 1}"
        outline = make_outline(label, region.shell, region.holes, options.com, "mm")
        outlines.append(
            ImportedOutline(outline=outline, kind="dxf", source_units=unit_name, warnings=())
        )
    return outlines, others, warnings
