"""Mesh import never returns the wrong part without a warning: --com on a mesh, one COM for a
folder, parts in fixtures and inserts, frames under tiny tilts, export debris, bodies named,
inside-out meshes, and --pose on plan (docs/import.md, "Meshes")."""

from __future__ import annotations

import math
from pathlib import Path

import fixtures_cad as fx
import numpy as np
import pytest
import shapely
import trimesh
from shared import cli_ok, one_line_error

from feederkit.catalog import import_directory
from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts
from feederkit.importers.mesh import (
    HALF_TURN_X,
    RestingPose,
    load_mesh,
    resting_poses,
    rotation_to_down,
    solid,
    sorted_poses,
)

PLATE = [(0, 0), (60, 0), (60, 12), (14, 12), (14, 40), (0, 40)]
"""A flat L plate 3 mm thick: it lands face up or face down about 46 % of drops each."""


def one(path: Path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    return parts[0]


def plate(tmp_path: Path, name: str = "lb.stl", rotation=None) -> Path:
    mesh = fx.prism(PLATE, 3.0)
    if rotation is not None:
        mesh.apply_transform(rotation)
    return fx.write_mesh(mesh, tmp_path / name)


def extrude(poly: shapely.Polygon, height: float) -> trimesh.Trimesh:
    """A closed prism over a polygon with holes (caps from shapely's constrained Delaunay)."""
    poly = shapely.geometry.polygon.orient(poly, 1.0)
    verts: list[tuple[float, float, float]] = []
    index: dict[tuple[float, float, float], int] = {}

    def at(x: float, y: float, z: float) -> int:
        if (x, y, z) not in index:
            index[x, y, z] = len(verts)
            verts.append((x, y, z))
        return index[x, y, z]

    faces = []
    for tri in shapely.constrained_delaunay_triangles(poly).geoms:
        (ax, ay), (bx, by), (cx, cy) = list(tri.exterior.coords)[:3]
        faces.append([at(ax, ay, 0.0), at(cx, cy, 0.0), at(bx, by, 0.0)])
        faces.append([at(ax, ay, height), at(bx, by, height), at(cx, cy, height)])
    for ring in [poly.exterior, *poly.interiors]:
        pts = list(ring.coords)
        for (x1, y1), (x2, y2) in zip(pts[:-1], pts[1:], strict=True):
            a, b = at(x1, y1, 0.0), at(x2, y2, 0.0)
            c, d = at(x2, y2, height), at(x1, y1, height)
            faces += [[a, b, c], [a, c, d]]
    mesh = trimesh.Trimesh(np.array(verts), np.array(faces), process=True)
    trimesh.repair.fix_normals(mesh)
    assert mesh.is_watertight and mesh.is_volume
    return mesh


def box_at(size, centre) -> trimesh.Trimesh:
    b = trimesh.creation.box(size)
    b.apply_translation(centre)
    return b


# ---- --com on a mesh: the poses left out are named --------------------------------------


def test_com_on_a_closed_mesh_names_the_poses_and_share_left_out(tmp_path, capsys):
    path = plate(tmp_path)
    probs = [one(path, pose=k).source.pose.probability for k in range(5)]
    share = f"{100 * (1 - probs[0]):.0f} %"
    ip = one(path, com=(25.0, 13.0))
    said = [w for w in ip.warnings if "--com" in w]
    assert said == [
        "--com gives the center of mass of pose-0 only: the plan covers pose-0 only; the "
        f"other 4 poses, {share} of drops, are left out: leave out --com to plan every landing"
    ]
    assert share == "54 %"
    err = cli_ok(capsys, ["part", "analyze", str(path), "--com", "25", "13"]).err
    assert "the other 4 poses, 54 % of drops, are left out" in " ".join(err.split())
    db = str(tmp_path / "c.db")
    err = cli_ok(capsys, ["catalog", "add", str(path), "--com", "25", "13", "--catalog", db]).err
    assert "the plan covers pose-0 only" in " ".join(err.split())
    err = cli_ok(capsys, ["plan", "lb", "--catalog", db, "--tolerance", "0.2"]).err
    assert "the plan covers pose-0 only" in " ".join(err.split())


def test_com_with_pose_names_that_pose(tmp_path):
    ip = one(plate(tmp_path), com=(25.0, -13.0), pose=1)
    assert any("the plan covers pose-1 only; the other 4 poses" in w for w in ip.warnings)


def test_com_on_an_open_mesh_says_only_the_imported_pose_is_planned(tmp_path):
    mesh = fx.prism(PLATE, 3.0)
    top = np.isclose(mesh.triangles_center[:, 2], 3.0)
    mesh.update_faces(~top)
    ip = one(fx.write_mesh(mesh, tmp_path / "open.stl"), com=(21.9, 13.05))
    assert any(
        "only the imported pose (pose-0) is planned" in w and "open mesh" in w for w in ip.warnings
    )


# ---- --com and --pose describe one part ----------------------------------------------------


def _folder(tmp_path: Path) -> Path:
    d = tmp_path / "meshes"
    d.mkdir()
    plate(d, "lb.stl")
    fx.write_mesh(box_at((40, 20, 2), (20, 10, 1)), d / "bar.stl")
    return d


@pytest.mark.parametrize("option", [["--com", "20", "10"], ["--pose", "1"]])
def test_a_folder_import_refuses_com_and_pose(tmp_path, capsys, option):
    db = tmp_path / "c.db"
    args = ["catalog", "import", str(_folder(tmp_path)), "--catalog", str(db), *option]
    err = one_line_error(capsys, args)
    assert "not every file of a folder" in err and "catalog add FILE" in err
    assert not db.exists()


def test_import_directory_refuses_com_from_python(tmp_path):
    with pytest.raises(InputError, match="a folder import would give it to every file"):
        import_directory(tmp_path / "c.db", _folder(tmp_path), ImportOptions(com=(20.0, 10.0)))


def test_com_for_a_drawing_of_several_parts_is_refused(tmp_path):
    path = fx.write_two_parts(tmp_path / "two.dxf")
    with pytest.raises(InputError, match="one part's center of mass, and the file holds 2 parts"):
        import_parts(path, ImportOptions(all_parts=True, com=(1.0, 1.0)))
    assert one(path, com=(20.0, 10.0)).part.com == (20.0, 10.0)  # the largest part alone


def test_plan_refuses_pose_and_points_to_landings(tmp_path, capsys):
    path = plate(tmp_path)
    err = one_line_error(capsys, ["plan", str(path), "--pose", "2", "--tolerance", "0.2"])
    assert "--landings 2" in err


# ---- shells: fixtures, inserts, cavities ----------------------------------------------------


def nest(tmp_path: Path, side: float) -> Path:
    """A 60 x 60 x 10 fixture frame with a 20 x 20 window and a part of ``side`` in it."""
    frame = extrude(shapely.box(0, 0, 60, 60).difference(shapely.box(20, 20, 40, 40)), 10.0)
    part = box_at((side, side, 5.0), (30.0, 30.0, 2.5))
    return fx.write_mesh(trimesh.util.concatenate([frame, part]), tmp_path / "nest.stl")


@pytest.mark.parametrize(("side", "how"), [(20.0, "touches"), (19.0, "lies outside")])
def test_a_part_in_its_nest_fixture_is_refused_not_taken_as_a_void(tmp_path, side, how):
    with pytest.raises(InputError) as info:
        one(nest(tmp_path, side))
    message = str(info.value)
    assert "the file holds 2 separate bodies" in message and f"body 2 {how} body 1" in message
    assert "body 1: 32000 mm3, 60 x 60 x 10 mm at (30, 30, 5)" in message


def block_with(tmp_path: Path, inverted: bool) -> Path:
    block = box_at((40, 20, 10), (20, 10, 5))
    pin = trimesh.creation.cylinder(radius=3, height=6, sections=32)
    pin.apply_translation((32, 10, 5))
    if inverted:
        pin.invert()
    return fx.write_mesh(trimesh.util.concatenate([block, pin]), tmp_path / "block.stl")


def test_an_inner_body_facing_outward_is_an_insert_not_a_cavity(tmp_path):
    path = block_with(tmp_path, inverted=False)
    mesh, _, _ = load_mesh(path, None)
    s = solid(mesh, False, str(path))
    assert s.com == pytest.approx((20.0, 10.0, 5.0), abs=1e-6)  # the block's own
    (note,) = [w for w in s.warnings if "inner body" in w]
    assert "body 2: " in note and "6 x 6 x 6 mm at (32, 10, 5)" in note
    assert "give --com X Y if it is an insert of another material" in note
    assert not any("void" in w for w in s.warnings)


def test_an_inner_shell_facing_inward_is_a_cavity(tmp_path):
    path = block_with(tmp_path, inverted=True)
    mesh, _, _ = load_mesh(path, None)
    s = solid(mesh, False, str(path))
    v_pin = float(trimesh.creation.cylinder(radius=3, height=6, sections=32).volume)
    v_block = 8000.0
    want = (20.0 * v_block - 32.0 * v_pin) / (v_block - v_pin)
    assert s.com == pytest.approx((want, 10.0, 5.0), abs=1e-4)
    assert any("1 internal void" in w for w in s.warnings)


def test_overlapping_bodies_a_speck_and_a_paste_are_named(tmp_path):
    slab = box_at((60, 30, 4), (30, 15, 2))
    pin = trimesh.creation.cylinder(radius=2, height=20, sections=32)
    pin.apply_translation((50, 15, 8))
    path = fx.write_mesh(trimesh.util.concatenate([slab, pin]), tmp_path / "pin.stl")
    with pytest.raises(InputError, match=r"body 2 overlaps body 1 \(their surfaces cross"):
        one(path)
    speck = box_at((0.1, 0.1, 0.1), (200, 0, 0))
    path = fx.write_mesh(trimesh.util.concatenate([slab, speck]), tmp_path / "speck.stl")
    with pytest.raises(InputError, match=r"body 2: 0\.001 mm3, 0\.1 x 0\.1 x 0\.1 mm at \(200, "):
        one(path)
    path = fx.write_mesh(trimesh.util.concatenate([slab, slab.copy()]), tmp_path / "twice.stl")
    ip = one(path)
    assert any("dropped 12 duplicate triangles" in w for w in ip.warnings)


# ---- export debris and inside-out meshes ---------------------------------------------------


def test_duplicate_degenerate_and_stray_triangles_are_dropped(tmp_path):
    lb = fx.prism(PLATE, 3.0)
    want = one(plate(tmp_path)).part.com
    cases = {
        "dup": (lb.vertices, np.vstack([lb.faces, lb.faces[:4]]), "dropped 4 duplicate"),
        "degen": (lb.vertices, np.vstack([lb.faces, [[0, 1, 1], [2, 2, 2]]]), "2 degenerate"),
        "stray": (
            np.vstack([lb.vertices, [[100, 0, 0], [101, 0, 0], [100, 1, 0]]]),
            np.vstack([lb.faces, [[len(lb.vertices) + k for k in range(3)]]]),
            "left out 1 flat stray piece of no volume",
        ),
    }
    for name, (verts, faces, said) in cases.items():
        mesh = trimesh.Trimesh(verts, faces, process=False)
        ip = one(fx.write_mesh(mesh, tmp_path / f"{name}.stl"))
        assert any(said in w for w in ip.warnings), (name, ip.warnings)
        assert ip.part.com == pytest.approx(want, abs=1e-4), name


def test_bodies_touching_along_edges_are_named(tmp_path):
    a = box_at((10, 10, 10), (5, 5, 5))
    b = box_at((10, 10, 10), (15, 15, 5))  # shares one vertical edge with a
    path = fx.write_mesh(trimesh.util.concatenate([a, b]), tmp_path / "edge.stl")
    with pytest.raises(InputError, match="body 2 touches body 1"):
        one(path)


def test_stacked_bodies_not_unioned_are_non_manifold_not_open(tmp_path):
    """A plate with a hole and a pocketed layer on it, not unioned: their triangles meet in
    the plane between them, edges shared by 3 or more triangles."""
    holed = shapely.box(0, 0, 80, 40).difference(shapely.Point(20, 20).buffer(6, 16))
    base = extrude(holed, 2.0)
    top = extrude(holed.difference(shapely.box(50, 10, 70, 30)), 3.0)
    top.apply_translation((0, 0, 2))
    path = fx.write_mesh(trimesh.util.concatenate([base, top]), tmp_path / "stack.stl")
    with pytest.raises(InputError) as info:
        one(path)
    message = str(info.value)
    assert "non-manifold edges (shared by 3 or more triangles" in message, message
    assert "union touching bodies" in message and "0 border edges" not in message


def test_an_inside_out_mesh_says_its_normals_were_flipped(tmp_path):
    mesh = fx.prism(PLATE, 3.0)
    mesh.invert()
    ip = one(fx.write_mesh(mesh, tmp_path / "inverted.stl"))
    assert any("inside out" in w and "flipped" in w for w in ip.warnings)
    assert not any("holes were filled" in w for w in ip.warnings)


# ---- frames and pose numbers under tiny tilts ---------------------------------------------


def _rounded(ring) -> list[tuple[float, float]]:
    return sorted((round(x, 3) + 0.0, round(y, 3) + 0.0) for x, y in ring)


def _tilt(degrees: float, axis) -> np.ndarray:
    return trimesh.transformations.rotation_matrix(math.radians(degrees), axis)


@pytest.mark.parametrize(
    ("degrees", "axis"), [(1e-4, (0, 1, 0)), (0.01, (1, 0, 0)), (3.0, (1, 1, 0))]
)
def test_a_tilted_model_keeps_its_frames_and_pose_numbers(tmp_path, degrees, axis):
    flat = plate(tmp_path, "flat.stl")
    tilted = plate(tmp_path, "tilted.stl", _tilt(degrees, axis))
    for k in (0, 1):
        a, b = one(flat, pose=k).part, one(tilted, pose=k).part
        assert b.com == pytest.approx(a.com, abs=1e-3), k
        assert _rounded(b.hull) == _rounded(a.hull), k
    assert one(flat, pose=1).part.com == pytest.approx((21.892, -13.050), abs=1e-3)


@pytest.mark.parametrize("radians", [1e-9, 1e-6, math.radians(3), 0.9])
def test_the_face_up_frame_is_continuous(radians):
    up = np.array([0.0, 0.0, 1.0])
    for axis in ((1, 0, 0), (0, 1, 0), (1, 1, 0), (-3, 1, 0)):
        tilt = _tilt(math.degrees(radians), axis)[:3, :3]
        r = rotation_to_down(tilt @ up) @ tilt  # the tilted model, then our rotation
        assert np.allclose(r, HALF_TURN_X, atol=1e-9), axis


def test_exact_faces_keep_their_frames():
    assert np.allclose(rotation_to_down(np.array([0.0, 0.0, -1.0])), np.eye(3))
    assert np.allclose(rotation_to_down(np.array([0.0, 0.0, 1.0])), HALF_TURN_X)
    side = rotation_to_down(np.array([1.0, 0.0, 0.0]))
    assert np.allclose(side @ [0, 1, 0], [0, 1, 0])  # the smallest rotation, about y


def test_tied_poses_are_ordered_by_their_normals_not_by_noise():
    rot = np.eye(3)
    down = RestingPose(0.4641235, (1e-5, 0.0, -1.0), rot)
    up = RestingPose(0.4641235 + 4e-10, (-1e-5, 0.0, 1.0), rot)  # a tie across a rounding
    side = RestingPose(0.0329, (0.0, -1.0, 0.0), rot)
    assert sorted_poses([side, up, down]) == [down, up, side]
    assert sorted_poses([down, side, up]) == [down, up, side]


def test_resting_poses_of_a_tilted_plate_put_face_down_first(tmp_path):
    path = plate(tmp_path, "t.stl", _tilt(0.01, (1, 0, 0)))
    mesh, _, _ = load_mesh(path, None)
    poses = resting_poses(solid(mesh, False, str(path)))
    assert poses[0].normal[2] < -0.99 and poses[1].normal[2] > 0.99


@pytest.mark.parametrize("kind", ["stl", "obj"])
def test_a_nan_corner_is_named_not_dropped_with_its_triangles(tmp_path, kind):
    # Dropped silently, its triangles left a hole the import blamed on the shape ("give
    # --com"), and with --com a frustum lost a corner and was planned.
    box = trimesh.creation.box(extents=(20, 10, 4))
    vertices = np.asarray(box.vertices, dtype=float).copy()
    vertices[0, 0] = math.nan
    broken = trimesh.Trimesh(vertices, box.faces, process=False)
    path = tmp_path / f"box.{kind}"
    broken.export(path)
    with pytest.raises(InputError, match="a corner with a NaN or infinite coordinate"):
        import_parts(path, ImportOptions())
    box.export(tmp_path / f"ok.{kind}")
    (ip,) = import_parts(tmp_path / f"ok.{kind}", ImportOptions())[1]
    assert ip.part.outline.polygon().area == pytest.approx(200.0)


def test_a_ply_missing_a_coordinate_field_says_which(tmp_path):
    path = tmp_path / "x-only.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n")
    with pytest.raises(InputError, match=r"not a readable mesh \(its data lack the field 'y'\)"):
        import_parts(path, ImportOptions())
