"""CAD fixtures generated for the import tests (ezdxf drawings, trimesh solids), with hand figures.

Each ``write_*`` function writes one file and returns its path; the docstrings and the
``*_AREA`` constants give the values computed by hand that the tests check.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
import shapely
import trimesh

BULGE_90 = math.tan(math.radians(90) / 4)

# plate 60 x 40 with corner radius 5, a hole r = 5 and a slot 13 long (centres), r = 4
PLATE_W, PLATE_H, PLATE_R = 60.0, 40.0, 5.0
PLATE_AREA = (
    PLATE_W * PLATE_H
    - (4 - math.pi) * PLATE_R**2
    - math.pi * 5.0**2
    - (13.0 * 8.0 + math.pi * 4.0**2)
)


def _rounded_rect(w: float, h: float, r: float) -> list[tuple[float, float, float]]:
    """LWPOLYLINE points (x, y, bulge) of a w x h rectangle with corner radius r, CCW."""
    return [
        (r, 0, 0),
        (w - r, 0, BULGE_90),
        (w, r, 0),
        (w, h - r, BULGE_90),
        (w - r, h, 0),
        (r, h, BULGE_90),
        (0, h - r, 0),
        (0, r, BULGE_90),
    ]


def _plate_entities(msp, r12: bool = False) -> None:
    pts = _rounded_rect(PLATE_W, PLATE_H, PLATE_R)
    if r12:
        msp.add_polyline2d([(x, y, 0, 0, b) for x, y, b in pts], format="xyseb", close=True)
    else:
        msp.add_lwpolyline(pts, format="xyb", close=True)
    msp.add_circle((15, 20), 5)
    msp.add_line((35, 16), (48, 16))
    msp.add_line((48, 24), (35, 24))
    msp.add_arc((48, 20), 4, -90, 90)
    msp.add_arc((35, 20), 4, 90, 270)


def write_plate(path: Path, *, version: str = "R2010", fmt: str = "asc") -> Path:
    """Plate with bulged corners, a circular hole and a slot: area PLATE_AREA, 2 holes, mm."""
    doc = ezdxf.new(version)
    doc.header["$INSUNITS"] = 4
    _plate_entities(doc.modelspace(), r12=version == "R12")
    doc.saveas(path, fmt=fmt)
    return path


BLOCK_AREA_IN = (10 * 5 - math.pi * 1.0**2) * 2.0**2  # in square inches, scale 2


def write_rotated_block(path: Path) -> Path:
    """A 10 x 5 in rectangle with a r = 1 in hole, in a block inserted at (100, 50) in, 30 deg,
    scale 2: area BLOCK_AREA_IN * 25.4**2 mm2, edges at 30 and 120 deg."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 1
    blk = doc.blocks.new("PART")
    blk.add_lwpolyline([(0, 0), (10, 0), (10, 5), (0, 5)], close=True)
    blk.add_circle((5, 2.5), 1.0)
    doc.modelspace().add_blockref(
        "PART", (100, 50), dxfattribs={"rotation": 30, "xscale": 2, "yscale": 2}
    )
    doc.saveas(path)
    return path


def nested_mirrored_expected() -> set[tuple[float, float]]:
    """Vertices of the nested/mirrored fixture: triangle (0,0),(4,0),(0,3) mirrored in x and
    moved to (10, 0) in block OUTER, OUTER rotated 90 deg: (x, y) -> (-y, x)."""
    inner = [(0, 0), (4, 0), (0, 3)]
    mirrored = [(10 - x, y) for x, y in inner]
    return {(-y, x) for x, y in mirrored}


def write_nested_mirrored(path: Path) -> Path:
    """Nested and mirrored inserts (see :func:`nested_mirrored_expected`), area 6."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    inner = doc.blocks.new("INNER")
    inner.add_lwpolyline([(0, 0), (4, 0), (0, 3)], close=True)
    outer = doc.blocks.new("OUTER")
    outer.add_blockref("INNER", (10, 0), dxfattribs={"xscale": -1})
    doc.modelspace().add_blockref("OUTER", (0, 0), dxfattribs={"rotation": 90})
    doc.saveas(path)
    return path


SPLINE_AREA = 40 * 10 + 200 - 2 * 20**3 / 3 / 80  # box 40x10 + parabola cap 5 - (x-20)^2/80


def write_fit_spline(path: Path) -> Path:
    """A 40 x 10 box whose top is a fit-point spline through the parabola y = 15 - (x-20)^2/80:
    area SPLINE_AREA = 533.33 mm2."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_line((0, 10), (0, 0))
    msp.add_line((0, 0), (40, 0))
    msp.add_line((40, 0), (40, 10))
    xs = [40, 35, 30, 25, 20, 15, 10, 5, 0]
    msp.add_spline([(x, 15 - (x - 20) ** 2 / 80) for x in xs])
    doc.saveas(path)
    return path


ELLIPSE_AREA = 50 * 30 - math.pi * 10 * 5


def write_ellipse_hole(path: Path) -> Path:
    """A 50 x 30 rectangle with a rotated elliptic hole (semi-axes 10 and 5): ELLIPSE_AREA."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (50, 0), (50, 30), (0, 30)], close=True)
    msp.add_ellipse((25, 15), major_axis=(6, 8), ratio=0.5)
    doc.saveas(path)
    return path


FRAME_PART_AREA = 50 * 50 - math.pi * 10**2


def write_framed(path: Path) -> Path:
    """An A4 drawing frame with a title block around a 50 x 50 square with a r = 10 hole."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (297, 0), (297, 210), (0, 210)], close=True)
    msp.add_line((200, 0), (200, 30))
    msp.add_line((200, 30), (297, 30))
    msp.add_line((200, 15), (297, 15))
    msp.add_text("TITLE", dxfattribs={"height": 5}).set_placement((210, 20))
    msp.add_lwpolyline([(100, 80), (150, 80), (150, 130), (100, 130)], close=True)
    msp.add_circle((125, 105), 10)
    doc.saveas(path)
    return path


def write_two_parts(path: Path) -> Path:
    """Two separate parts: a 40 x 20 rectangle (the largest) and a 10 x 10 square."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (40, 0), (40, 20), (0, 20)], close=True)
    msp.add_lwpolyline([(60, 0), (70, 0), (70, 10), (60, 10)], close=True)
    doc.saveas(path)
    return path


def write_gear(path: Path, teeth: int = 12, tip: float = 30.0, root: float = 24.0) -> Path:
    """A gear drawn with LINE and ARC entities: tip arcs of +-3 deg at radius ``tip``, root arcs
    at ``root``, straight flanks. Tooth k is centred on angle k * 360 / teeth."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    pitch = 360.0 / teeth
    half_tip, half_base = 3.0, 7.0

    def at(r: float, a: float) -> tuple[float, float]:
        return (r * math.cos(math.radians(a)), r * math.sin(math.radians(a)))

    for k in range(teeth):
        c = k * pitch
        msp.add_arc((0, 0), tip, c - half_tip, c + half_tip)
        msp.add_line(at(tip, c + half_tip), at(root, c + half_base))
        msp.add_arc((0, 0), root, c + half_base, c + pitch - half_base)
        msp.add_line(at(root, c + pitch - half_base), at(tip, c + pitch - half_tip))
    doc.saveas(path)
    return path


def write_disk(path: Path, radius: float = 10.0) -> Path:
    """A plain disk (CIRCLE): not orientable by pushing."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_circle((0, 0), radius)
    doc.saveas(path)
    return path


def write_slot(path: Path) -> Path:
    """A plain slot, 60 x 20 mm: two long flat sides (normals 90 and 270 degrees) and two
    semicircular ends, the left one an ARC in an OCS with extrusion -Z (its centre (-10, 10)
    there is (10, 10) in the drawing). Its tip states' normals come out 0 and 180 degrees up to
    rounding (359.9999999999996 and 180.00000000000006)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_line((10, 0), (50, 0))
    msp.add_line((50, 20), (10, 20))
    msp.add_arc((50, 10), 10, -90, 90)
    msp.add_arc((-10, 10), 10, -90, 90, dxfattribs={"extrusion": (0, 0, -1)})
    doc.saveas(path)
    return path


def write_entities(path: Path, build, units: int = 4) -> Path:
    """A drawing made by ``build(modelspace)``."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = units
    build(doc.modelspace())
    doc.saveas(path)
    return path


# ---- meshes -------------------------------------------------------------------------------


def prism(vertices: list[tuple[float, float]], height: float) -> trimesh.Trimesh:
    """A closed prism over a simple polygon (z from 0 to ``height``), built without a
    triangulation engine: caps from shapely's constrained Delaunay triangles."""
    poly = shapely.Polygon(vertices)
    if not poly.exterior.is_ccw:
        vertices = vertices[::-1]
    n = len(vertices)
    xy = np.asarray(vertices, dtype=float)
    verts = np.vstack([np.c_[xy, np.zeros(n)], np.c_[xy, np.full(n, height)]])
    index = {tuple(p): i for i, p in enumerate(map(tuple, xy))}
    faces = []
    for tri in shapely.get_parts(shapely.constrained_delaunay_triangles(poly)):
        a, b, c = (index[tuple(p)] for p in np.asarray(tri.exterior.coords)[:3])
        if shapely.Polygon(xy[[a, b, c]]).exterior.is_ccw:
            a, b = b, a
        faces.append([a, b, c])  # bottom faces point down
        faces.append([n + b, n + a, n + c])  # top faces point up
    for i in range(n):
        j = (i + 1) % n
        faces.append([i, j, n + j])
        faces.append([i, n + j, n + i])
    mesh = trimesh.Trimesh(verts, np.asarray(faces), process=True)
    trimesh.repair.fix_normals(mesh)
    return mesh


L_VERTICES = [(0, 0), (40, 0), (40, 5), (5, 5), (5, 30), (0, 30)]
L_DEPTH = 20.0
L_HULL = [(0, 0), (40, 0), (40, 5), (5, 30), (0, 30)]
L_HULL_AREA = 40 * 30 - 0.5 * 35 * 25  # 762.5
L_COM = ((200 * 20 + 125 * 2.5) / 325, (200 * 2.5 + 125 * 17.5) / 325)
L_SIDE_AREAS = (40 * L_DEPTH, 30 * L_DEPTH, 2150 / math.sqrt(1850) * L_DEPTH)
"""Outlines of the three side poses: the L's stable hull edges (bottom, left, diagonal);
the width of the L's hull along each edge times the depth."""


def write_mesh(mesh: trimesh.Trimesh, path: Path) -> Path:
    """Export a mesh (the format follows the suffix)."""
    mesh.export(path)
    return path


def box_solid_angle_fraction(a: float, b: float, d: float) -> float:
    """Solid angle of an a x b rectangle seen from distance d on its axis, over 4 pi."""
    omega = 4 * math.asin(a * b / math.sqrt((a * a + 4 * d * d) * (b * b + 4 * d * d)))
    return omega / (4 * math.pi)


# ---- real-drawing patterns: frames and cut sheets, gaps, units, paper space ----------------


def _rect(msp, x0: float, y0: float, x1: float, y1: float, **attribs) -> None:
    msp.add_lwpolyline([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], close=True, dxfattribs=attribs)


def _title_block(msp, x1: float, y0: float) -> None:
    """A title block in the lower right corner of a frame, its lines touching the frame."""
    msp.add_line((x1 - 120, y0), (x1 - 120, y0 + 40))
    msp.add_line((x1 - 120, y0 + 40), (x1, y0 + 40))
    msp.add_line((x1 - 120, y0 + 20), (x1, y0 + 20))
    msp.add_line((x1 - 60, y0), (x1 - 60, y0 + 20))
    msp.add_text("FRAME PLATE", dxfattribs={"height": 5}).set_placement((x1 - 110, y0 + 28))


CUT_PLATE_HOLE_R = 3.0
CUT_PLATE_AREA = 200 * 150 - 120 * 80 - 4 * math.pi * CUT_PLATE_HOLE_R**2
"""The plate of :func:`write_cut_sheet`: 200 x 150, a 120 x 80 window, four r = 3 holes."""
CUT_PIECE_AREAS = (50 * 30 - math.pi * 4.0**2, 30 * 30)


def _cut_sheet(msp, ox: float, oy: float) -> None:
    """A 200 x 150 printer frame plate with a 120 x 80 window and four mounting holes; two
    pieces cut from the window lie in it (a 50 x 30 bar with a r = 4 hole, a 30 x 30 square)."""
    _rect(msp, ox, oy, ox + 200, oy + 150)
    _rect(msp, ox + 40, oy + 35, ox + 160, oy + 115)
    for dx, dy in ((15, 15), (185, 15), (185, 135), (15, 135)):
        msp.add_circle((ox + dx, oy + dy), CUT_PLATE_HOLE_R)
    _rect(msp, ox + 50, oy + 45, ox + 100, oy + 75)
    msp.add_circle((ox + 75, oy + 60), 4.0)
    _rect(msp, ox + 120, oy + 70, ox + 150, oy + 100)


def write_cut_sheet(path: Path, *, frame: str | None = "title") -> Path:
    """The cut sheet of :func:`_cut_sheet`, alone (``frame=None``), inside an A3 drawing frame
    with a title block (``"title"``), or inside a double-line frame border (``"double"``)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    if frame == "title":
        _rect(msp, 0, 0, 420, 297)
        _title_block(msp, 420, 0)
    elif frame == "double":
        _rect(msp, 0, 0, 420, 297)
        _rect(msp, 10, 10, 410, 287)
    _cut_sheet(msp, 60, 70)
    doc.saveas(path)
    return path


def gap_spline_points(gap: float) -> list[tuple[float, float]]:
    """Fit points of a 100 x 60 oval sketched as one open spline whose end stops ``gap`` short
    of its start (the start at (50, 0), the end at (50 - gap, 0))."""
    pts = []
    for k in range(33):
        t = 2 * math.pi * k / 32
        pts.append((50 * math.cos(t), 30 * math.sin(t)))
    pts[0] = (50.0, 0.0)
    pts[-1] = (50.0 - gap * math.cos(0.05), -gap * math.sin(0.05))
    return pts


GAP_HOLE_AREA = math.pi * 15 * 8


def write_gap_spline(path: Path, gap: float) -> Path:
    """An oval outline drawn as an open fit-point spline missing closing by ``gap`` mm, with a
    15 x 8 elliptical hole: the part is the oval minus the hole, never the hole."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_spline(gap_spline_points(gap))
    msp.add_ellipse((0, 0), major_axis=(15, 0), ratio=8 / 15)
    doc.saveas(path)
    return path


def write_wrong_header(path: Path, insunits: int = 6, measurement: int | None = 0) -> Path:
    """An 8 x 5 inch plate with a r = 0.5 in hole, drawn in inch numbers, whose header says
    ``$INSUNITS`` ``insunits`` (6: metres) and ``$MEASUREMENT`` ``measurement`` (0: imperial)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = insunits
    if measurement is not None:
        doc.header["$MEASUREMENT"] = measurement
    msp = doc.modelspace()
    _rect(msp, 0, 0, 8, 5)
    msp.add_circle((2, 2.5), 0.5)
    doc.saveas(path)
    return path


WRONG_HEADER_AREA_IN2 = 8 * 5 - math.pi * 0.25


def write_paper_space(path: Path) -> Path:
    """A 40 x 20 rectangle with a r = 5 hole drawn in paper space only (model space empty)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    paper = doc.paperspace()
    _rect(paper, 0, 0, 40, 20)
    paper.add_circle((10, 10), 5)
    doc.saveas(path)
    return path


def hollow_box(outer: float, inner: float, offset: tuple[float, float, float]) -> trimesh.Trimesh:
    """A cube of side ``outer`` with a cubic cavity of side ``inner`` centred at ``offset``:
    the cavity's shell faces inward, as CAD programs export a solid with a void."""
    shell = trimesh.creation.box((outer,) * 3)
    void = trimesh.creation.box((inner,) * 3)
    void.apply_translation(offset)
    void.invert()
    return trimesh.util.concatenate([shell, void])


# ---- hostile files: each must be answered (imported or refused) within its budget ---------


def write_nested_blocks(path: Path, depth: int, fanout: int) -> Path:
    """Blocks nested ``depth`` deep, each inserting the next ``fanout`` times: fanout**depth
    squares after expansion."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    leaf = doc.blocks.new("B0")
    leaf.add_lwpolyline([(0, 0), (1, 0), (1, 1), (0, 1)], close=True)
    for d in range(1, depth + 1):
        blk = doc.blocks.new(f"B{d}")
        for k in range(fanout):
            blk.add_blockref(f"B{d - 1}", (k * 2.0 * (2.0 * fanout) ** (d - 1), 0))
    doc.modelspace().add_blockref(f"B{depth}", (0, 0))
    doc.saveas(path)
    return path


def write_block_cycle(path: Path) -> Path:
    """Block A inserts B, B inserts A: a reference cycle."""
    doc = ezdxf.new("R2010")
    a, b = doc.blocks.new("A"), doc.blocks.new("B")
    a.add_lwpolyline([(0, 0), (1, 0), (1, 1)], close=True)
    a.add_blockref("B", (2, 0))
    b.add_blockref("A", (2, 0))
    doc.modelspace().add_blockref("A", (0, 0))
    doc.saveas(path)
    return path


def write_minsert(path: Path, rows: int, cols: int, block: str = "CELL") -> Path:
    """A MINSERT grid of ``rows`` x ``cols`` unit squares (``block`` may be left undefined)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    cell = doc.blocks.new("CELL")
    cell.add_lwpolyline([(0, 0), (1, 0), (1, 1), (0, 1)], close=True)
    ref = doc.modelspace().add_blockref("CELL", (0, 0))
    ref.grid(size=(rows, cols), spacing=(2, 2))
    if block != "CELL":
        ref.dxf.name = block
    doc.saveas(path)
    return path


def write_holes_plate(path: Path, n: int) -> Path:
    """A plate with an n x n grid of r = 0.3 holes (n * n holes)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    _rect(msp, 0, 0, n + 1, n + 1)
    for i in range(n):
        for j in range(n):
            msp.add_circle((i + 1, j + 1), 0.3)
    doc.saveas(path)
    return path


def write_crossing_lines(path: Path, n: int, seed: int = 0) -> Path:
    """``n`` random lines across a 100 mm square: about n * n / 4 crossings."""
    rng = np.random.default_rng(seed)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    for a, b in rng.uniform(0, 100, size=(n, 2, 2)):
        msp.add_line(tuple(a), tuple(b))
    doc.saveas(path)
    return path


def write_big_polyline(path: Path, n: int) -> Path:
    """A closed LWPOLYLINE with ``n`` vertices on a circle of radius 50.

    The points are written into the DXF text directly: ezdxf appends them one array copy
    at a time, which takes minutes for a million.
    """
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(1.5, 0), (0, 2.5), (-3.5, 0)], close=True)
    doc.saveas(path)
    text = path.read_text()
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    points = "".join(
        f" 10\n{x:.6f}\n 20\n{y:.6f}\n" for x, y in zip(50 * np.cos(t), 50 * np.sin(t), strict=True)
    )
    head, rest = text.split(" 90\n3\n", 1)
    start = rest.index(" 10\n1.5\n")
    end = rest.index(" 20\n0.0\n", rest.index(" 10\n-3.5\n")) + len(" 20\n0.0\n")
    path.write_text(head + f" 90\n{n}\n" + rest[:start] + points + rest[end:])
    return path


def write_circle(path: Path, radius: float, insunits: int = 6) -> Path:
    """One circle of ``radius`` drawing units (default in metres)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = insunits
    doc.modelspace().add_circle((0, 0), radius)
    doc.saveas(path)
    return path


def write_with_coordinate(path: Path, value: str) -> Path:
    """The plate of :func:`write_plate` with one line whose end x is the text ``value``
    (``1e20``, ``1e300``, ``inf``, ``nan``, ``1e400``), written into the DXF as is."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    _plate_entities(doc.modelspace())
    doc.modelspace().add_line((0, 0), (123456.789, 0))
    doc.saveas(path)
    text = path.read_text().replace("123456.789", value)
    path.write_text(text)
    return path


def write_obj_repeated_face(path: Path, repeats: int) -> Path:
    """A tetrahedron OBJ whose last face lists its vertices ``repeats`` times."""
    lines = ["v 0 0 0", "v 10 0 0", "v 0 10 0", "v 0 0 10", "f 1 3 2", "f 1 2 4", "f 2 3 4"]
    lines.append("f " + " ".join(["1", "4", "3"] * repeats))
    path.write_text("\n".join(lines) + "\n")
    return path


def with_units(path: Path, insunits: int) -> Path:
    """The drawing at ``path`` with its ``$INSUNITS`` changed to ``insunits`` (in place)."""
    doc = ezdxf.readfile(path)
    doc.header["$INSUNITS"] = insunits
    doc.saveas(path)
    return path


HOSTILE_CURVES = ("arc_z", "circle_z", "spline_z", "spline_knot", "ellipse_ratio", "bulge")
"""Curves :func:`write_hostile_curve` can break (which number of which entity)."""


def write_hostile_curve(path: Path, kind: str, value: str) -> Path:
    """A 100 x 60 rectangle and one curve whose number ``kind`` is the text ``value``.

    ``arc_z``: an ARC centre's z (``inf`` there is fuzz seed 2, input 73, which sent ezdxf's
    flattening into 2**1000 calls); ``circle_z``, ``spline_z`` (a control point's z),
    ``spline_knot``, ``ellipse_ratio``, ``bulge`` (an LWPOLYLINE bulge).
    """
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 60), (0, 60)], close=True)
    s = 777.125  # written as "777.125" (a ratio as "0.777125"), then replaced by the value
    if kind == "arc_z":
        msp.add_arc((50, 30, s), 10, 0, 219.9)
    elif kind == "circle_z":
        msp.add_circle((50, 30, s), 5)
    elif kind == "spline_z":
        msp.add_open_spline([(10, 10), (20, 40, s), (40, 10), (60, 30)])
    elif kind == "spline_knot":
        msp.add_open_spline(
            [(10, 10), (20, 40), (40, 10), (60, 30), (70, 20)], knots=[0, 0, 0, 0, s, 2, 2, 2, 2]
        )
    elif kind == "ellipse_ratio":
        s = 0.777125
        msp.add_ellipse((50, 30), (10, 0), s, 0, math.pi)
    elif kind == "bulge":
        msp.add_lwpolyline([(20, 20, 0, 0, s), (30, 20), (30, 30)], format="xyseb")
    else:
        raise ValueError(f"unknown hostile curve {kind!r}")
    doc.saveas(path)
    text = path.read_text()
    assert str(s) in text
    path.write_text(text.replace(str(s), value))
    return path


def d_shape_outline():
    """A 30 x 20 mm rectangle with an R10 half disc on its right, the arc drawn with 63
    points: 40 mm across the arc, which a simplified contact hull cuts."""
    from feederkit.outline import make_outline

    arc = [
        (
            30.0 + 10.0 * math.cos(math.pi * k / 64 - math.pi / 2),
            10.0 + 10.0 * math.sin(math.pi * k / 64 - math.pi / 2),
        )
        for k in range(1, 64)
    ]
    return make_outline("d", [(0.0, 0.0), (30.0, 0.0), *arc, (30.0, 20.0), (0.0, 20.0)])
