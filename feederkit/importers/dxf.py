"""DXF drawings (ezdxf + shapely): entities to flattened lines in millimetres, then parts.

Block references are exploded recursively in world coordinates (rotated, scaled, mirrored
and nested inserts alike). Curves are flattened within a tolerance by :mod:`.flatten` (a
bounded version of ezdxf's subdivision); text, dimensions, hatches and other annotation are
skipped. The lines become loops in :mod:`.loops` and parts in :mod:`.drawing`.
"""

from __future__ import annotations

import logging
import math
import os
import re
import warnings
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import ezdxf
import numpy as np
import shapely
from ezdxf import path as dxfpath
from ezdxf import recover
from ezdxf.document import Drawing as DxfDocument
from ezdxf.entities import DXFGraphic
from ezdxf.lldxf.const import DXFError
from ezdxf.math import Matrix44, Vec2, Vec3
from ezdxf.path import Command
from shapely.geometry import Polygon

from feederkit.errors import InputError
from feederkit.importers.budget import MAX_COORD_MM, Budget
from feederkit.importers.drawing import Counterbore, Drawing, counterbores, drawing_from_lines
from feederkit.importers.drawingnotes import edge_line_note, merged_note
from feederkit.importers.flatten import NonFiniteCurve, cubic_flattening
from feederkit.importers.loops import Region, closing_lines
from feederkit.importers.model import ImportedOutline, ImportOptions
from feederkit.importers.plausible import measurement_warnings, outline_size, size_warnings
from feederkit.outline import make_outline, unit_name, unit_scale
from feederkit.words import plural

logging.getLogger("ezdxf").addHandler(logging.NullHandler())  # a library never prints

CURVES = frozenset({"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE"})
"""Entity types that make up an outline; everything else (text, dimensions, hatches) is skipped."""

CONTINUOUS = "Continuous"
BYLAYER = "ByLayer"

HIDDEN_LINETYPE = re.compile(
    r"HIDDEN|DASH|CENT(ER|RE)|PHANTOM|DOT|DIVIDE|BORDER|ACAD_ISO(0[2-9]|1[0-5])W|JIS_0[2-9]",
    re.IGNORECASE,
)
"""Linetypes of hidden edges, centre and construction lines (HIDDEN2, DASHEDX2, CENTER,
PHANTOM, DASHDOT, the ISO dashed types ACAD_ISO02W100 to ACAD_ISO15W100, ...): never a
visible outline."""

MAX_LISTED = 8
"""Entities named at most in one warning."""

MAX_BLOCK_DEPTH = 32
"""Deeper block nesting is taken as a reference cycle."""

REL_FLATTEN = 1e-5
"""The flatten tolerance is at least this share of the drawing's size (0.002 mm at 200 mm)."""

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


SECTION_NAME = re.compile(rb"SECTION[ \t]*\r?\n[ \t]*2[ \t]*\r?\n[ \t]*(\w+)")
"""A section's name after the ``0 SECTION`` tag (a literal first: fast on a 50 MB file)."""

DRAWN_SECTIONS = frozenset({b"ENTITIES", b"BLOCKS"})
"""Sections whose entities are drawn (the others hold tables, classes and objects)."""


def prescan(path: Path, budget: Budget) -> None:
    """Count an ASCII DXF's entities and points from its raw tags, before ezdxf parses it.

    Parsing costs about a millisecond per entity, so a file with 200,000 entities or a
    million-vertex polyline is refused here, in a fraction of that time: the group codes of
    the drawn sections (entities and blocks) are tallied at C speed, ``0`` for an entity and
    ``10`` for a point. Binary DXF files are left to the parser (the file size limit bounds
    them).
    """
    with path.open("rb") as fh:
        if fh.read(22) == b"AutoCAD Binary DXF\r\n\x1a\x00":
            return
        fh.seek(0)
        data = fh.read()
    starts = []  # (offset of the section's "0" line, whether it is drawn)
    for m in SECTION_NAME.finditer(data):
        line = data.rfind(b"\n", 0, m.start()) + 1  # the "SECTION" line; its code line before
        starts.append((data.rfind(b"\n", 0, max(0, line - 1)) + 1, m.group(1) in DRAWN_SECTIONS))
    entities = points = 0
    for k, (start, drawn) in enumerate(starts):
        budget.check_time()
        if not drawn:
            continue
        end = starts[k + 1][0] if k + 1 < len(starts) else len(data)
        for code, n in Counter(data[start:end].splitlines()[0::2]).items():
            code = code.strip()
            entities += n if code == b"0" else 0
            points += n if code == b"10" else 0
        entities -= 1  # the section's own "0 SECTION" tag
    budget.need("entities", entities, "entities in the file")
    budget.need("vertices", points, "points in the file")
    budget.check_time()


def read_document(path: Path) -> DxfDocument:
    """Open a DXF file (ASCII or binary, any version), recovering damaged files when possible."""
    return open_document(path)[0]


def open_document(path: Path) -> tuple[DxfDocument, str | None]:
    """The document of a DXF file and, when ``ezdxf.readfile`` refused it and
    ``ezdxf.recover`` repaired it, why it was refused (the damage), else None.

    A repaired file may have lost entities (recover skips what it cannot parse, silently:
    a LINE whose coordinate is ``abc`` is gone), so the damage is reported with the part, or
    in the refusal when nothing readable is left.
    """
    try:
        return ezdxf.readfile(path), None
    except OSError as exc:
        if exc.errno is not None:
            raise InputError(f"{path}: cannot read the file ({exc.strerror})") from None
        raise InputError(f"{path}: not a DXF file") from None  # ezdxf's own verdict
    except Exception as exc:  # noqa: BLE001 - any parser failure: try the recover module
        damage = _reason(exc).removeprefix(f"{type(exc).__name__}: ").rstrip(".")
    try:
        doc, auditor = recover.readfile(path)
    except Exception as exc:  # noqa: BLE001 - ezdxf raises many types on broken input
        raise InputError(f"{path}: not a readable DXF file ({_reason(exc)})") from None
    if auditor.has_errors:
        raise InputError(f"{path}: damaged DXF file ({len(auditor.errors)} unrecoverable errors)")
    return doc, damage


def _reason(exc: BaseException) -> str:
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def drawing_units(
    doc: DxfDocument, override: str | None, label: str
) -> tuple[str, float, list[str]]:
    """The drawing's unit name, millimetres per unit, and warnings (unitless files)."""
    if override is not None:
        return unit_name(override), unit_scale(override), []
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code in INSUNITS:
        name, scale = INSUNITS[code]
        return name, scale, []
    if code == 0:
        return "mm", 1.0, ["the drawing has no units ($INSUNITS 0): read as mm (use --units)"]
    raise InputError(f"{label}: unsupported drawing unit $INSUNITS {code}; give --units")


def space_layouts(doc: DxfDocument, space: str) -> list[object]:
    """The layouts to read: the model space, or every paper-space layout."""
    if space == "model":
        return [doc.modelspace()]
    if space == "paper":
        return [lay for lay in doc.layouts if lay.is_any_paperspace]
    raise InputError(f"--space must be model or paper, got {space!r}")


def _count_expanded(doc: DxfDocument, layouts: list[object], budget: Budget) -> int:
    """Curve entities the layouts hold once every block reference is expanded (exact count).

    Counted per block definition (memoised), so nesting depth 32 with fan-out 10 or a MINSERT
    grid of 1e9 x 1e9 is refused before anything is expanded; reference cycles, references to
    undefined blocks and nesting deeper than :data:`MAX_BLOCK_DEPTH` are bad input.
    """
    memo: dict[str, int] = {}
    active: list[str] = []

    def block(name: str) -> int:
        if name in memo:
            return memo[name]
        if name in active:
            raise InputError(f"{budget.label}: block {name!r} contains a reference to itself")
        if len(active) >= MAX_BLOCK_DEPTH:
            raise InputError(
                f"{budget.label}: block references nested deeper than {MAX_BLOCK_DEPTH}"
            )
        definition = doc.blocks.get(name)
        if definition is None:
            raise InputError(f"{budget.label}: a reference to the undefined block {name!r}")
        active.append(name)
        memo[name] = count(definition)
        active.pop()
        return memo[name]

    def count(entities: object) -> int:
        total = 0
        for entity in entities:  # type: ignore[attr-defined]
            kind = entity.dxftype()
            if kind == "INSERT":
                rows = max(1, int(entity.dxf.get("row_count", 1) or 1))
                cols = max(1, int(entity.dxf.get("column_count", 1) or 1))
                total += rows * cols * block(str(entity.dxf.get("name", "")))
            elif kind in CURVES:
                total += 1
            if total > budget.limits.entities:
                break  # already too many: the exact figure does not matter
        return total

    total = sum(count(layout) for layout in layouts)
    budget.need("entities", total, "entities after block expansion")
    return total


Unseen = tuple[str, str]
"""Why CAD does not show an entity: ``("frozen", layer)``, ``("off", layer)`` or
``("invisible", "")``."""


@dataclass(frozen=True)
class Placed:
    """A curve entity of the drawing as CAD draws it: the entity as stored (in its block's
    coordinates), its effective layer and linetype, the block-to-world ``matrix`` (None for
    an entity of the layout itself), the layout's block reference it comes from, and why
    CAD does not show it (:func:`unseen_by`; None when it does)."""

    entity: DXFGraphic
    layer: str
    linetype: str = CONTINUOUS
    matrix: Matrix44 | None = None
    ref: DXFGraphic | None = None
    unseen: Unseen | None = None


def hidden_layers(doc: DxfDocument, shown: Sequence[str] = ()) -> dict[str, str]:
    """The layers CAD does not show, by lower-case name: ``"frozen"`` or ``"off"``.

    Layers named in ``shown`` (``--layer``) are read whatever their state: the user asked
    for them.
    """
    keep = {name.lower() for name in shown}
    states = {}
    for layer in doc.layers:
        name = str(layer.dxf.name).lower()
        if name in keep:
            continue
        if layer.is_frozen():
            states[name] = "frozen"
        elif layer.is_off():
            states[name] = "off"
    return states


def unseen_by(
    entity: DXFGraphic, layer: str, states: dict[str, str], reference: bool = False
) -> Unseen | None:
    """Why CAD does not show ``entity`` drawn on its effective ``layer``: the layer is
    frozen or off, or the entity carries the invisible flag (group 60); None if it shows.

    For a block ``reference`` only a frozen layer counts: an off one hides the block's
    entities that take the reference's layer (on layer "0"), and those are told apart
    when they are read.
    """
    state = states.get(layer.lower())
    if state == "frozen" or (state == "off" and not reference):
        return state, layer
    if entity.dxf.is_supported("invisible") and entity.dxf.get("invisible", 0):
        return "invisible", ""
    return None


def effective_linetype(entity: DXFGraphic, layer: str, block_linetype: str) -> str:
    """The linetype ``entity`` is drawn with: its own, its layer's (BYLAYER, on the effective
    ``layer``) or its block reference's (BYBLOCK, ``block_linetype``)."""
    own = entity.dxf.get("linetype", BYLAYER) if entity.dxf.is_supported("linetype") else BYLAYER
    name = str(own or BYLAYER)
    if name.upper() == "BYBLOCK":
        return block_linetype
    if name.upper() != BYLAYER.upper():
        return name
    doc = entity.doc
    if doc is None or not doc.layers.has_entry(layer or "0"):
        return CONTINUOUS
    return str(doc.layers.get(layer or "0").dxf.get("linetype", CONTINUOUS) or CONTINUOUS)


def _block_references(entity: DXFGraphic, label: str) -> list[DXFGraphic]:
    """The references an INSERT stands for: itself, or each cell of a MINSERT grid."""
    if entity.mcount <= 1:
        return [entity]
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return list(entity.multi_insert())
    except Exception as exc:  # noqa: BLE001 - broken block definitions
        raise InputError(
            f"{label}: cannot explode block {entity.dxf.get('name', '?')!r} ({exc})"
        ) from None


def _reference_matrix(ref: DXFGraphic, label: str) -> Matrix44:
    """A block reference's block-to-parent matrix (``Insert.matrix44``); InputError when
    ezdxf cannot make it (a broken reference)."""
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return ref.matrix44()
    except Exception as exc:  # noqa: BLE001 - ezdxf raises many types on broken input
        raise InputError(
            f"{label}: cannot explode block {ref.dxf.get('name', '?')!r} ({_reason(exc)})"
        ) from None


def explode(
    entities: object,
    layer: str,
    depth: int,
    skipped: Counter[str],
    budget: Budget,
    matrix: Matrix44 | None = None,
    linetype: str = CONTINUOUS,
    ref: DXFGraphic | None = None,
    states: dict[str, str] | None = None,
    unseen: Unseen | None = None,
) -> Iterator[Placed]:
    """Curve entities with their effective layer, linetype, block-to-world matrix and
    whether CAD shows them (the layers' ``states``, :func:`hidden_layers`).

    A block reference's matrix (``Insert.matrix44``) is composed with its parents', and each
    curve is later transformed as a curve (:func:`curve_path`): ezdxf's ``virtual_entities``
    re-derives a nested reference's rotation and scale, which turns a rotation inside a
    non-uniform scale into the wrong shape, and re-interpolates a fit-point spline through
    transformed fit points. Annotation inside blocks (dimensions, leaders, text) is
    skipped. Entities of a block on layer "0" take the layer of the reference, as CAD
    programs draw them: so a reference on an off layer hides them, and one on a frozen
    layer, or with the invisible flag, hides its whole block (``unseen``).
    """
    states = {} if states is None else states
    for entity in entities:  # type: ignore[attr-defined]
        kind = entity.dxftype()
        if kind != "INSERT" and kind not in CURVES:
            skipped[kind] += 1
            continue
        own = entity.dxf.get("layer", "0") if entity.dxf.is_supported("layer") else "0"
        eff = layer if (own == "0" and layer) else own
        drawn = effective_linetype(entity, eff, linetype)
        hidden = unseen or unseen_by(entity, eff, states, reference=kind == "INSERT")
        if kind != "INSERT":
            budget.entities()
            yield Placed(entity, eff, drawn, matrix, ref, hidden)
            continue
        if depth >= MAX_BLOCK_DEPTH:
            raise InputError(
                f"{budget.label}: block references nested deeper than {MAX_BLOCK_DEPTH}"
            )
        check_finite(entity, budget.label, ref)
        block = entity.doc.blocks.get(entity.dxf.get("name", "")) if entity.doc else None
        if block is None:
            raise InputError(
                f"{budget.label}: a reference to the undefined block {entity.dxf.get('name')!r}"
            )
        for cell in _block_references(entity, budget.label):
            own = _reference_matrix(cell, budget.label)
            placed = own if matrix is None else own @ matrix
            yield from explode(
                block, eff, depth + 1, skipped, budget, placed, drawn, ref or entity, states, hidden
            )


def _point_count(entity: DXFGraphic) -> int:
    """Defining points of an entity, counted without building geometry (for the budget)."""
    kind = entity.dxftype()
    if kind == "LWPOLYLINE":
        return len(entity)
    if kind == "POLYLINE":
        return len(entity.vertices)
    if kind == "SPLINE":
        return entity.control_point_count() + entity.fit_point_count()
    return 2


def curve_path(entity: DXFGraphic, matrix: Matrix44 | None = None) -> dxfpath.Path | None:
    """The entity as an ezdxf path (cubic Bezier pieces) in world coordinates, transformed
    as a curve by its block ``matrix``; None for surfaces (polyface meshes)."""
    if entity.dxftype() == "POLYLINE" and not (entity.is_2d_polyline or entity.is_3d_polyline):
        return None  # polyface and polygon meshes are surfaces, not outlines
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        path = dxfpath.make_path(entity)
        return path if matrix is None else path.transform(matrix)


FLATTEN_CHUNK = 4096
"""Path commands read between two checks of the deadline."""


def flatten_paths(
    paths: Sequence[dxfpath.Path], distance: float, budget: Budget | None = None
) -> list[list[np.ndarray]]:
    """Each path as polylines (drawing units, x y), curves within ``distance`` of their chords.

    Not ezdxf's ``Path.flattening``, which never returns for a curve with a NaN or infinite
    coordinate (docs/import.md, curves): the Bezier pieces of all the paths are flattened
    together, in the x-y plane, by :func:`.flatten.cubic_flattening`, the same subdivision
    with its levels capped and the vertices counted against ``budget`` as they are made.
    Quadratic pieces are raised to cubic ones (the same curve). Raises
    :class:`.flatten.NonFiniteCurve` whose ``piece`` is the index of the path.
    """
    owner: list[int] = []
    cubics: list[tuple[float, ...]] = []
    plans: list[list[list[tuple[float, float] | int]]] = []
    for k, path in enumerate(paths):
        subs: list[list[tuple[float, float] | int]] = []
        for sub in path.sub_paths():
            if not len(sub):
                continue  # a lone start point: ezdxf flattens it to nothing
            prev = sub.start
            items: list[tuple[float, float] | int] = [(prev.x, prev.y)]
            lines = 1
            for n, cmd in enumerate(sub.commands()):
                if budget is not None and n % FLATTEN_CHUNK == FLATTEN_CHUNK - 1:
                    budget.check_time()
                end = cmd.end
                if cmd.type == Command.CURVE4_TO:
                    c1, c2 = cmd.ctrl1, cmd.ctrl2
                elif cmd.type == Command.CURVE3_TO:
                    c1 = prev + (cmd.ctrl - prev) * (2.0 / 3.0)
                    c2 = end + (cmd.ctrl - end) * (2.0 / 3.0)
                else:
                    items.append((end.x, end.y))
                    lines += 1
                    prev = end
                    continue
                cubics.append((prev.x, prev.y, c1.x, c1.y, c2.x, c2.y, end.x, end.y))
                owner.append(k)
                items.append(len(cubics) - 1)
                prev = end
            if budget is not None:
                budget.vertices(lines)
            subs.append(items)
        plans.append(subs)
    try:
        piece, points = cubic_flattening(np.array(cubics, dtype=float), distance, budget)
    except NonFiniteCurve as exc:
        raise NonFiniteCurve(owner[exc.piece]) from None
    bounds = np.searchsorted(piece, np.arange(len(cubics) + 1))
    out: list[list[np.ndarray]] = []
    for subs in plans:
        polylines = []
        for items in subs:
            chunks: list[np.ndarray] = []
            run: list[tuple[float, float]] = []
            for item in items:
                if isinstance(item, tuple):
                    run.append(item)
                    continue
                if run:
                    chunks.append(np.array(run, dtype=float))
                    run = []
                chunks.append(points[bounds[item] : bounds[item + 1]])
            if run:
                chunks.append(np.array(run, dtype=float))
            pts = np.concatenate(chunks)
            if len(pts) >= 2:
                polylines.append(pts)
        out.append(polylines)
    return out


def _label(entity: DXFGraphic, ref: DXFGraphic | None = None) -> str:
    """``ARC 47``; an entity of a block: ``ARC 3A in block 'B' (INSERT 2F)``, with the
    layout's reference ``ref`` it is drawn by."""
    kind = entity.dxftype()
    handle = entity.dxf.get("handle")
    own = f"{kind} {handle}" if handle else kind
    if ref is None:
        return own
    return f"{own} in block {ref.dxf.get('name', '?')!r} (INSERT {ref.dxf.get('handle', '?')})"


def _first_non_finite(entity: DXFGraphic) -> str | None:
    """The name of an attribute of ``entity`` holding NaN or infinity, else None.

    Every number the curve is made of: its DXF attributes (centre, radius, angles, ratio,
    extrusion, elevation, scale factors), LWPOLYLINE points with their widths and bulges,
    POLYLINE vertices, SPLINE control and fit points, knots and weights. A NaN angle or
    radius could otherwise drop a curve without a word, and an infinite z would send the
    flattening into a loop (fuzz seed 2, input 73: an ARC centre's z of inf).
    """
    for name, value in entity.dxf.all_existing_dxf_attribs().items():
        if isinstance(value, float):
            if not math.isfinite(value):
                return name
        elif isinstance(value, tuple | Vec3 | Vec2) and not all(
            isinstance(v, int | float) and math.isfinite(v) for v in value
        ):
            return name
    kind = entity.dxftype()
    arrays: dict[str, object] = {}
    if kind == "LWPOLYLINE":
        arrays["points"] = entity.lwpoints.values
    elif kind == "SPLINE":
        arrays = {
            "control points": entity.control_points.values,
            "fit points": entity.fit_points.values,
            "knots": entity.knots,
            "weights": entity.weights,
        }
    for name, values in arrays.items():
        if not np.isfinite(np.asarray(values, dtype=float)).all():
            return name
    if kind == "POLYLINE":
        for vertex in entity.vertices:
            found = _first_non_finite(vertex)
            if found is not None:
                return f"vertex {found}"
    return None


def check_finite(entity: DXFGraphic, label: str, ref: DXFGraphic | None = None) -> None:
    """Refuse an entity with a NaN or infinite number in one line naming it and the value."""
    found = _first_non_finite(entity)
    if found is not None:
        what = found.replace("_", " ")
        raise InputError(f"{label}: {_label(entity, ref)} has a NaN or infinite value ({what})")


@dataclass(frozen=True)
class DrawnLines:
    """Flattened polylines (mm) and, for each, its entity (with layer), layer and linetype."""

    lines: list[np.ndarray]
    names: list[str]
    layers: list[str]
    linetypes: list[str]

    def without(self, drop: set[int]) -> DrawnLines:
        """These lines but those whose index is in ``drop``."""
        keep = [k for k in range(len(self.lines)) if k not in drop]
        return DrawnLines(
            [self.lines[k] for k in keep],
            [self.names[k] for k in keep],
            [self.layers[k] for k in keep],
            [self.linetypes[k] for k in keep],
        )


def top_view_loss(points: Sequence[np.ndarray], end_on: float) -> tuple[float, float]:
    """How much the top view (the projection onto XY) shortens the drawing: the largest
    length a segment of the entities' control polygons (``points``, one array per entity)
    loses, over all segments and over those not seen end-on (a top view no longer than
    ``end_on``: a wireframe's vertical edge draws nothing there, so it loses nothing)."""
    pts = np.concatenate(points)
    seg = np.diff(pts, axis=0)
    inside = np.ones(len(seg), dtype=bool)
    inside[np.cumsum([len(cv) for cv in points])[:-1] - 1] = False  # one entity to the next
    seg = seg[inside]
    if not len(seg):
        return 0.0, 0.0
    flat = np.hypot(seg[:, 0], seg[:, 1])
    loss = np.linalg.norm(seg, axis=1) - flat
    shown = loss[flat > end_on]
    return float(loss.max()), float(shown.max()) if len(shown) else 0.0


def best_plane(pts: np.ndarray) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, float]:
    """The plane that fits points (n, 3) best: its unit normal (None when the points lie
    on a line, which no plane fixes), a point of it (their mean), each point's distance
    from it, and the largest distance of a point from the line that fits them best."""
    mean = pts.mean(axis=0)
    centred = pts - mean
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    along = centred @ axes[0]
    off_line = float(np.linalg.norm(centred - along[:, None] * axes[0], axis=1).max())
    if len(axes) < 3:  # two points
        return None, mean, np.zeros(len(pts)), off_line
    return axes[2], mean, centred @ axes[2], off_line


def upward(normal: np.ndarray) -> np.ndarray:
    """The plane's normal seen from above: z up; in a vertical plane, toward -y (CAD's
    front view), in the YZ plane toward +x (its right view)."""
    nx, ny, nz = normal
    key = nz if abs(nz) > 1e-9 else (-ny if abs(ny) > 1e-9 else nx)
    return normal if key > 0 else -normal


def plane_words(normal: np.ndarray, point: np.ndarray, scale: float) -> str:
    """A plane by name (``the XZ plane (y = 0 mm)``) or by tilt, normal and a point."""
    for k, (axis, name) in enumerate((("x", "YZ"), ("y", "XZ"))):
        if abs(abs(normal[k]) - 1.0) < 1e-9:
            return f"the {name} plane ({axis} = {point[k] * scale:.4g} mm)"
    tilt = math.degrees(math.acos(min(1.0, abs(float(normal[2])))))
    n = ", ".join(f"{v:.3g}" for v in normal + 0.0)
    at = ", ".join(f"{v * scale:.4g}" for v in point + 0.0)
    return f"a plane tilted {tilt:.3g} degrees to the XY plane (normal ({n}), through ({at}) mm)"


def plane_turn(normal: np.ndarray) -> Matrix44:
    """The smallest rotation that turns a plane's (upward) ``normal`` onto +z."""
    axis = np.cross(normal, (0.0, 0.0, 1.0))
    angle = math.acos(max(-1.0, min(1.0, float(normal[2]))))
    return Matrix44.axis_rotate(Vec3(*(axis / np.linalg.norm(axis))), angle)


def turned(points: np.ndarray, matrix: Matrix44) -> np.ndarray:
    """Points (n, 3) transformed by an ezdxf matrix (row vectors, as ``Matrix44``)."""
    m = np.array([matrix.get_row(k) for k in range(4)], dtype=float)
    return points @ m[:3, :3] + m[3, :3]


def drawing_plane(
    points: Sequence[np.ndarray],
    names: Sequence[str],
    scale: float,
    tolerance: float,
    label: str,
) -> tuple[Matrix44 | None, str]:
    """The rotation that lays a drawing drawn in a plane not parallel to XY flat, true to
    shape, and the warning saying so; (None, "") for a drawing read in its top view.

    ``points`` are the entities' control points (drawing units), ``names`` the entities.
    The top view is read when it shortens no segment of the entities' control polygons by
    more than ``tolerance`` (mm, at least :data:`REL_FLATTEN` of the drawing's size): the
    drawing lies in XY, or in planes parallel to it (a wireframe's edges seen end-on
    aside). Otherwise geometry in one plane (within the tolerance; an entity drawn in a
    UCS, LINEs whose z varies with y) is turned onto XY, by the smallest rotation that
    keeps it seen from above: read as its top view it came in foreshortened, and in the XZ
    plane as a line. Geometry in no one plane is refused, naming the entity farthest off.
    """
    pts = np.concatenate(points)
    size = float((pts.max(axis=0) - pts.min(axis=0)).max())
    tol = max(tolerance / scale, REL_FLATTEN * size)
    loss, loss_seen = top_view_loss(points, tol)
    if loss <= tol:
        return None, ""
    normal, mean, dist, off_line = best_plane(pts)
    if normal is None or off_line <= tol:
        return None, ""  # on a line: refused later as having no area
    normal = upward(normal)
    if size * math.hypot(float(normal[0]), float(normal[1])) <= tol:
        # The plane is horizontal within the tolerance across the drawing: what the top view
        # shortens are short steps out of it (or edges seen end-on), nothing to turn.
        return None, ""
    if float(np.abs(dist).max()) <= tol:
        tilt = math.degrees(math.acos(min(1.0, float(normal[2]))))
        turn = plane_turn(normal)
        axis = np.cross(normal, (0.0, 0.0, 1.0))
        axis = ", ".join(f"{v:.3g}" for v in axis / np.linalg.norm(axis) + 0.0)
        short = 1.0 - float(normal[2])
        top = "a line" if short > 0.999 else f"{short:.0%} short across the tilt"
        return turn, (
            f"the drawing lies in {plane_words(normal, mean, scale)}: imported true to shape, "
            f"turned {tilt:.3g} degrees onto the XY plane about the axis ({axis}), so the "
            f"part's coordinates are the turned plane's, not the drawing's (its top view is "
            f"{top}); draw it in the XY plane to keep the drawing's coordinates"
        )
    if loss_seen <= tol:
        return None, ""  # in planes parallel to XY: a wireframe's top view
    owner = np.repeat(np.arange(len(points)), [len(cv) for cv in points])
    worst = int(np.argmax(np.abs(dist)))
    raise InputError(
        f"{label}: the geometry lies in no one plane: {names[owner[worst]]} lies "
        f"{abs(float(dist[worst])) * scale:.3g} mm off the plane that fits the drawing best "
        f"({plane_words(normal, mean, scale)}), and the top view would shorten lines by up "
        f"to {loss_seen * scale:.3g} mm; draw the part's outline in one plane, or leave the "
        "other geometry out with --layer"
    )


def dxf_lines(
    doc: DxfDocument,
    options: ImportOptions,
    scale: float,
    label: str,
    budget: Budget,
) -> tuple[DrawnLines, Counter[str], list[str], float, str]:
    """Outline polylines of the chosen space (mm) with their entities, layers and linetypes,
    skipped types, warnings, flatten tolerance, and what was left out as not shown in CAD
    (:func:`unseen_note`; "" for nothing).

    With ``options.layers``, only entities on those layers (case-insensitive; block contents
    on layer "0" count on their reference's layer) are read. Entities CAD does not show (on
    a frozen or off layer not named with ``--layer``, or invisible) are left out, with a
    warning; when nothing else is left the drawing is refused. Every coordinate is checked
    as it is read: NaN, infinity or a magnitude beyond :data:`MAX_COORD_MM` is refused
    before any geometry runs. A drawing in one plane not parallel to XY is turned onto it
    (:func:`drawing_plane`). The flatten tolerance is at least :data:`REL_FLATTEN` of the
    drawing's size, so a huge circle cannot ask for millions of segments.
    """
    layers = options.layers
    skipped: Counter[str] = Counter()
    wanted = {name.lower() for name in layers}
    seen: set[str] = set()
    layouts = space_layouts(doc, options.space)
    _count_expanded(doc, layouts, budget)
    states = hidden_layers(doc, layers)
    unseen: list[tuple[Unseen, str]] = []
    paths: list[tuple[str, dxfpath.Path]] = []
    points: list[np.ndarray] = []
    owners: list[str] = []
    owner_layers: list[str] = []
    owner_linetypes: list[str] = []
    for layout in layouts:
        for placed in explode(layout, "", 0, skipped, budget, states=states):
            entity, layer = placed.entity, placed.layer
            seen.add(layer)
            if wanted and layer.lower() not in wanted:
                continue
            name = _label(entity, placed.ref)
            if placed.unseen is not None:
                unseen.append((placed.unseen, f"{name} on layer {layer!r}"))
                continue
            budget.need("vertices", _point_count(entity), "points in one entity")
            budget.check_time()
            check_finite(entity, label, placed.ref)
            try:
                path = curve_path(entity, placed.matrix)
                if path is None:
                    continue
                cv = np.array([v.xyz for v in path.control_vertices()], dtype=float)
            except Exception as exc:  # noqa: BLE001 - degenerate curves in third-party files
                raise InputError(f"{label}: cannot read {name} ({exc})") from None
            if len(cv) == 0:
                continue
            if not np.isfinite(cv).all():  # finite numbers whose curve overflows (radius 1e300)
                raise InputError(
                    f"{label}: {name} has coordinates too large to compute, beyond "
                    "any part a feeder can hold (check the units)"
                )
            far = float(np.abs(cv).max()) * scale
            if far > MAX_COORD_MM:
                raise InputError(
                    f"{label}: {name} has a coordinate of {far:.3g} mm, beyond any "
                    f"part a feeder can hold ({MAX_COORD_MM:g} mm; check the units)"
                )
            paths.append((name, path))
            points.append(cv)
            owners.append(f"{name} on layer {layer!r}")
            owner_layers.append(layer)
            owner_linetypes.append(placed.linetype)
    notes: list[str] = []
    left_out = unseen_note(unseen)
    if unseen and not paths:
        raise InputError(
            f"{label}: the drawing shows no outline geometry: every line, arc and curve is "
            f"hidden in CAD ({left_out}){_unseen_hint(unseen)}"
        )
    if unseen:
        notes.append(
            f"left out {plural(len(unseen), 'entity', 'entities')} CAD does not show: "
            f"{left_out}{_unseen_hint(unseen)}"
        )
    if wanted and not paths and seen:
        names = ", ".join(sorted(seen))
        raise InputError(
            f"{label}: no geometry on layer {', '.join(sorted(layers))} (layers: {names})"
        )
    if not paths:
        return DrawnLines([], [], [], []), skipped, notes, options.flatten_tolerance, left_out
    turn, plane_note = drawing_plane(points, owners, scale, options.flatten_tolerance, label)
    if turn is not None:
        paths = [(name, path.transform(turn)) for name, path in paths]
        points = [turned(cv, turn) for cv in points]
        notes.append(plane_note)
    xy = np.concatenate(points)[:, :2]
    size_mm = float((xy.max(axis=0) - xy.min(axis=0)).max()) * scale
    flatten_mm = options.flatten_tolerance
    if REL_FLATTEN * size_mm > flatten_mm:
        flatten_mm = REL_FLATTEN * size_mm
        notes.append(
            f"flatten tolerance raised to {flatten_mm:.3g} mm ({REL_FLATTEN:g} of the "
            f"drawing's size, {size_mm:.4g} mm)"
        )
    distance = flatten_mm / scale
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            flat = flatten_paths([p for _, p in paths], distance, budget)  # counts vertices
    except NonFiniteCurve as exc:
        raise InputError(
            f"{label}: {paths[exc.piece][0]} has NaN or infinite coordinates"
        ) from None
    lines = [pts * scale for pieces in flat for pts in pieces]
    per_line = [
        [value for value, pieces in zip(values, flat, strict=True) for _ in pieces]
        for values in (owners, owner_layers, owner_linetypes)
    ]
    return DrawnLines(lines, *per_line), skipped, notes, flatten_mm, left_out


def unseen_note(unseen: Sequence[tuple[Unseen, str]]) -> str:
    """What was left out as not shown in CAD: how many entities on each frozen or off
    layer, and the invisible entities by name (``2 on frozen layer 'C'; CIRCLE 2F on layer
    '0', invisible``); "" for nothing."""
    by_layer = Counter((state, layer) for (state, layer), _ in unseen if state != "invisible")
    parts = [f"{n} on {state} layer {layer!r}" for (state, layer), n in by_layer.items()]
    invisible = [name for (state, _), name in unseen if state == "invisible"]
    if invisible:
        more = f" and {len(invisible) - MAX_LISTED} more" if len(invisible) > MAX_LISTED else ""
        parts.append(f"{', '.join(invisible[:MAX_LISTED])}{more}, invisible")
    return "; ".join(parts)


def _unseen_hint(unseen: Sequence[tuple[Unseen, str]]) -> str:
    """How to read entities left out as not shown in CAD: thaw or turn on their layer,
    or name it with ``--layer`` (invisible entities only in CAD)."""
    layers = sorted({layer for (state, layer), _ in unseen if state != "invisible"})
    options = " ".join(f"--layer {layer}" for layer in layers)
    if not layers:
        return "; if they are outline, make them visible in CAD"
    return (
        f"; if they are outline, thaw or turn on their layer in CAD, or name it with {options} "
        "(and the part's other layers)"
    )


def is_hidden_linetype(name: str, kept: tuple[str, ...] = ()) -> bool:
    """Whether a linetype draws hidden edges or centre lines (:data:`HIDDEN_LINETYPE`), and
    is not one of the ``kept`` names (case-insensitive)."""
    if name.lower() in {k.lower() for k in kept}:
        return False
    return HIDDEN_LINETYPE.search(name) is not None


def hidden_loops(drawn: DrawnLines, gap: float, kept: tuple[str, ...]) -> set[int]:
    """The lines drawn in a hidden or centre linetype that close loops among themselves
    (:func:`.loops.closing_lines`): hidden edges of pockets and far-side features, bolt
    circles (the other lines in those linetypes, centre lines, are left out quietly)."""
    hidden = [k for k, lt in enumerate(drawn.linetypes) if is_hidden_linetype(lt, kept)]
    closing = closing_lines([drawn.lines[k] for k in hidden], gap)
    return {hidden[k] for k in closing}


def hidden_note(drawn: DrawnLines, dropped: set[int]) -> tuple[str, str]:
    """What was left out as hidden or centre lines (entities with layer and linetype) and
    the ``--keep-linetype`` options that keep them."""
    seen: dict[str, str] = {}
    for k in sorted(dropped):
        seen.setdefault(drawn.names[k], drawn.linetypes[k])
    listed = [f"{name} (linetype {lt})" for name, lt in list(seen.items())[:MAX_LISTED]]
    more = f" and {len(seen) - MAX_LISTED} more" if len(seen) > MAX_LISTED else ""
    keep = " ".join(f"--keep-linetype {lt}" for lt in sorted(set(seen.values()), key=str.lower))
    return "; ".join(listed) + more, keep


def ring_owners(ring: Sequence[tuple[float, float]], drawn: DrawnLines, gap: float) -> str:
    """The entities drawing a loop, each with its layer and linetype (or "a loop")."""
    poly = Polygon(ring)
    tol = max(2.0 * gap, 1e-9 * float(np.sqrt(poly.area)))
    names: dict[str, str] = {}
    for k, line in enumerate(drawn.lines):
        if shapely.dwithin(shapely.points(line), poly.exterior, tol).all():
            names.setdefault(drawn.names[k], drawn.linetypes[k])
    listed = [f"{name}, linetype {lt}" for name, lt in list(names.items())[:MAX_LISTED]]
    return " + ".join(listed) or "a loop"


def counterbore_note(bore: Counterbore, drawing: Drawing, drawn: DrawnLines, gap: float) -> str:
    """The warning for a hole drawn as concentric loops: which loops (entities, layers,
    linetypes), the one taken as the through hole and where the COM may lie."""
    outer = Polygon(bore.outer)
    loops = "; ".join(
        f"{ring_owners(r, drawn, gap)}, {_across(Polygon(r)):.4g} mm across" for r in bore.rings
    )
    where = f"({outer.centroid.x:.1f}, {outer.centroid.y:.1f})"
    if bore.crosses:
        return (
            f"the hole at {where} is drawn as concentric loops ({loops}), the outer one "
            "crossing other holes: taken for a construction circle (a bolt circle) around a "
            "through hole, the innermost loop; check the part, or leave the construction "
            "circle's layer out with --layer"
        )
    note = (
        f"the hole at {where} is drawn as concentric loops ({loops}): taken for a "
        "counterbore, countersink, chamfer or construction circle around a through hole, "
        "not a part in the hole; the through hole is the innermost loop"
    )
    region = next((r for r in drawing.regions if bore.inner in r.holes), None)
    if region is None:
        return note
    with_inner = Polygon(region.shell, region.holes)
    holes = [bore.outer if h == bore.inner else h for h in region.holes]
    with_outer = Polygon(region.shell, holes)
    a, b = with_inner.centroid, with_outer.centroid
    return (
        f"{note}, so the part keeps the material under the counterbore: COM ({a.x:.2f}, "
        f"{a.y:.2f}); with the outer loop cut through it would be ({b.x:.2f}, {b.y:.2f}), "
        f"{a.distance(b):.2g} mm away: the true COM lies between, by the counterbore's depth "
        "(give it with --com)"
    )


def _across(poly: Polygon) -> float:
    """A loop's largest extent along x or y (a circle's diameter)."""
    x0, y0, x1, y1 = poly.bounds
    return max(x1 - x0, y1 - y0)


def region_fault(region: Region, drawn: DrawnLines, gap: float) -> str | None:
    """Which loop of a part crosses others (entities, layers, linetypes, where), the one
    crossing the most named first; None when its outline and holes make a valid polygon."""
    if Polygon(region.shell, region.holes).is_valid:
        return None
    rings = [region.shell, *region.holes]
    rims = [Polygon(r).exterior for r in rings]
    pairs = [
        (i, j)
        for j in range(len(rims))
        for i in range(j)
        if rims[i].crosses(rims[j]) or rims[i].overlaps(rims[j])
    ]
    if not pairs:
        return None
    counts = Counter(k for pair in pairs for k in pair)
    worst = max(counts, key=lambda k: (counts[k], -k))
    others = [j if i == worst else i for i, j in pairs if worst in (i, j)]
    where = rims[worst].intersection(rims[others[0]]).representative_point()
    crossed = "; ".join(ring_owners(rings[k], drawn, gap) for k in others[:MAX_LISTED])
    return (
        f"{ring_owners(rings[worst], drawn, gap)} crosses {plural(len(others), 'other loop')} "
        f"({crossed}), first near ({where.x:.4g}, {where.y:.4g})"
    )


AREA_TIE_REL = 1e-9
"""Separate parts of a drawing whose areas differ by less than this share are equally large."""


def _describe(region: Region) -> str:
    xs = [p[0] for p in region.shell]
    ys = [p[1] for p in region.shell]
    cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    # Parts are chosen by their outline's area; a part with holes has less material.
    inside = f" ({region.loop_area:.1f} inside its outline)" if region.holes else ""
    return f"area {region.area:.1f} mm2{inside} at ({cx:.1f}, {cy:.1f})"


def read_dxf(
    path: Path, options: ImportOptions, name: str, budget: Budget | None = None
) -> tuple[list[ImportedOutline], list[str], list[str]]:
    """Parts of a DXF file: (imported outlines, descriptions of parts left out, warnings).

    The part is the largest closed loop with the loops inside it as holes; with
    ``options.all_parts`` every separate part is returned, named ``name``, ``name-2``, ...
    """
    budget = budget or Budget(options.limits, str(path))
    prescan(path, budget)
    doc, damage = open_document(path)
    budget.check_time()
    try:
        return _read_doc(doc, path, options, name, budget, damage)
    except DXFError as exc:  # malformed entities that ezdxf loaded but cannot interpret
        reason = _reason(exc)
        raise InputError(f"{path}: malformed DXF ({reason})") from None
    except (AttributeError, KeyError, TypeError) as exc:
        # A structure ezdxf loaded from a broken file but cannot walk (e.g. a block record
        # without its attributes): malformed input when ezdxf itself raised it, our bug if not.
        if not _raised_in_ezdxf(exc):
            raise
        reason = _reason(exc)
        raise InputError(f"{path}: malformed DXF ({reason})") from None


def _raised_in_ezdxf(exc: BaseException) -> bool:
    """Whether the innermost frame of ``exc``'s traceback is in the ezdxf package."""
    tb = exc.__traceback__
    if tb is None:
        return False
    while tb.tb_next is not None:
        tb = tb.tb_next
    return f"{os.sep}ezdxf{os.sep}" in tb.tb_frame.f_code.co_filename


def _paper_space_hint(doc: DxfDocument, options: ImportOptions) -> str:
    """Why a model space without outline geometry may still hold a part: it is in paper space."""
    if options.space != "model":
        return ""
    names = [
        lay.name
        for lay in doc.layouts
        if lay.is_any_paperspace and any(e.dxftype() in CURVES | {"INSERT"} for e in lay)
    ]
    if not names:
        return ""
    return (
        f"; the drawing's geometry is in paper space (layout {', '.join(map(repr, names))}): "
        "use --space paper"
    )


def _drawing(
    drawn: DrawnLines,
    gap: float,
    label: str,
    options: ImportOptions,
    budget: Budget,
    warnings_: list[str],
) -> tuple[Drawing, DrawnLines]:
    """The drawing's loops and parts, lines drawn in hidden or centre linetypes left out
    (the loops among them, :func:`hidden_loops`, with a warning naming them in
    ``warnings_``), and the lines kept."""
    dropped = hidden_loops(drawn, gap, options.keep_linetypes)
    # Open lines in those linetypes (centre lines, a pocket's hidden step) are never outline
    # either: left to the loop search, a centre line across a plate cut it into a "drawing
    # frame" and a hole came in as the part.
    lines_ = {
        k
        for k, lt in enumerate(drawn.linetypes)
        if k not in dropped and is_hidden_linetype(lt, options.keep_linetypes)
    }
    if not dropped and not lines_:
        drawing = drawing_from_lines(drawn.lines, gap, label, budget, drawn.names, drawn.layers)
        return drawing, drawn
    listed, keep = hidden_note(drawn, dropped | lines_)
    kept = drawn.without(dropped | lines_)
    if not kept.lines:
        raise InputError(
            f"{label}: every closed loop is drawn in a hidden, dashed or centre linetype "
            f"({listed}): if they are the part, keep them with {keep}"
        )
    try:
        drawing = drawing_from_lines(kept.lines, gap, label, budget, kept.names, kept.layers)
    except InputError as exc:
        raise InputError(
            f"{exc}; left out as hidden or centre lines: {listed} (keep them with {keep})"
        ) from None
    if dropped:
        loops, keep = hidden_note(drawn, dropped)
        warnings_.append(
            f"left out loops drawn in a hidden, dashed or centre linetype, taken for hidden "
            f"edges (pockets, far-side features) or construction lines, not through holes: "
            f"{loops}; if they are holes or outline, keep them with {keep}"
        )
    return drawing, kept


def _read_doc(
    doc: DxfDocument,
    path: Path,
    options: ImportOptions,
    name: str,
    budget: Budget,
    damage: str | None = None,
) -> tuple[list[ImportedOutline], list[str], list[str]]:
    unit_name, scale, warnings_ = drawing_units(doc, options.units, str(path))
    drawn, skipped, notes, flatten_mm, unseen = dxf_lines(doc, options, scale, str(path), budget)
    warnings_ += notes
    if not drawn.lines:
        found = ", ".join(f"{k} x{v}" for k, v in sorted(skipped.items()))
        what = f"only {found}" if found else "it is empty"
        if damage is not None:
            raise InputError(
                f"{path}: damaged DXF file ({damage}): what ezdxf could recover holds no "
                f"outline geometry (lines, arcs, curves) in the {options.space} space: {what}"
            )
        raise InputError(
            f"{path}: no outline geometry (lines, arcs, curves) in the "
            f"{options.space} space: {what}{_paper_space_hint(doc, options)}"
        )
    try:
        drawing, drawn = _drawing(drawn, flatten_mm, str(path), options, budget, warnings_)
    except InputError as exc:
        if not unseen:
            raise
        raise InputError(f"{exc}; left out as not shown in CAD: {unseen}") from None
    drawing, bores = counterbores(drawing, flatten_mm)
    if damage is not None:
        warnings_.append(
            f"damaged DXF file ({damage}): read what ezdxf could recover; entities it could "
            "not parse are lost, so check the part"
        )
    warnings_ += list(drawing.warnings)
    warnings_ += [counterbore_note(b, drawing, drawn, flatten_mm) for b in bores]
    if drawing.frames:
        warnings_.append(f"skipped {drawing.frames} drawing frame(s) around the part")
    warnings_ += [edge_line_note(e.box, e.band) for e in drawing.edges]
    regions = list(drawing.regions)
    chosen = regions if options.all_parts else regions[:1]
    others = (
        []
        if options.all_parts
        else [f"{name}-{k + 2}: {_describe(r)}" for k, r in enumerate(regions[1:])]
    )
    if drawing.nested:
        warnings_.append(
            f"the part's holes hold {drawing.nested} other part(s), as in a cut sheet: imported "
            + ("them as parts of their own" if options.all_parts else "the outer part")
            + " (if the outer loop is a drawing frame, leave its layer out with --layer)"
        )
    if others:
        # Parts equal in area (within the area's rounding) leave no largest: say which.
        top = regions[0].loop_area
        ties = sum(1 for r in regions if r.loop_area >= top * (1.0 - AREA_TIE_REL))
        which = (
            f"the one of the largest outline, {_describe(regions[0])}"
            if ties == 1
            else f"one of the {ties} largest, equal in size: {_describe(regions[0])}"
        )
        warnings_.append(
            f"the drawing holds {len(regions)} separate parts; imported {which} "
            "(use --all-parts for all)"
        )
    if options.units is None:
        warnings_ += measurement_warnings(doc, unit_name)
    outlines = []
    for k, region in enumerate(chosen):
        label = name if k == 0 else f"{name}-{k + 1}"
        fault = region_fault(region, drawn, flatten_mm)
        if fault is not None:
            raise InputError(
                f"{path}: loops of the part cross: {fault}; leave construction geometry out "
                "with --layer"
            )
        outline = make_outline(label, region.shell, region.holes, options.com, "mm")
        size_notes = size_warnings(outline_size(outline), unit_name, options.units is not None)
        if region.enclosed:
            size_notes.append(merged_note(region.enclosed))
        outlines.append(
            ImportedOutline(
                outline=outline, kind="dxf", source_units=unit_name, warnings=tuple(size_notes)
            )
        )
    return outlines, others, warnings_
