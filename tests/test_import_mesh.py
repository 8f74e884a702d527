"""Mesh import (trimesh): resting poses and their outlines, checked against hand computation."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import fixtures_cad as fx
import numpy as np
import pytest
import shapely
import trimesh

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts
from feederkit.importers.mesh import rotation_to_down


def one(path: Path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    return parts[0]


def extents(ring) -> tuple[float, float]:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    return max(xs) - min(xs), max(ys) - min(ys)


def side_lengths(ring) -> list[float]:
    return [math.dist(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]


@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj"])
def test_box_poses_probabilities_and_outlines(tmp_path, suffix):
    path = fx.write_mesh(trimesh.creation.box((10, 20, 30)), tmp_path / f"box{suffix}")
    ip = one(path)
    pose = ip.source.pose
    assert pose.count == 6 and pose.index == 0
    # most probable: a 20 x 30 face; probability = its solid angle seen from the COM / 4 pi
    assert pose.probability == pytest.approx(fx.box_solid_angle_fraction(20, 30, 5), rel=1e-6)
    # resting on the -x face: the smallest rotation turns it down about the y axis
    assert sorted(extents(ip.part.hull)) == pytest.approx([20.0, 30.0])
    assert extents(ip.part.hull) == pytest.approx((30.0, 20.0))
    assert ip.part.com == pytest.approx((0.0, 0.0), abs=1e-9)
    areas = sorted(
        round(shapely.Polygon(one(path, pose=k).part.outline.vertices).area, 6) for k in range(6)
    )
    assert areas == [200, 200, 300, 300, 600, 600]
    probs = [one(path, pose=k).source.pose.probability for k in range(6)]
    assert all(a >= b - 1e-12 for a, b in zip(probs[:-1], probs[1:], strict=True))  # decreasing
    # opposite faces come in pairs of equal probability, whatever order trimesh gives them
    for k in (0, 2, 4):
        assert probs[k] == pytest.approx(probs[k + 1], rel=1e-9)
    assert sum(probs) == pytest.approx(1.0, abs=1e-9)
    assert probs[4] == pytest.approx(fx.box_solid_angle_fraction(10, 20, 15), rel=1e-6)


def test_pose_out_of_range(tmp_path):
    path = fx.write_mesh(trimesh.creation.box((10, 20, 30)), tmp_path / "box.stl")
    with pytest.raises(InputError, match=r"no pose 6: the mesh has 6 resting poses \(0-5\)"):
        one(path, pose=6)


def test_dodecagonal_prism(tmp_path):
    r, h = 20.0, 4.0
    path = fx.write_mesh(
        trimesh.creation.cylinder(radius=r, height=h, sections=12), tmp_path / "p12.stl"
    )
    ip = one(path)
    assert ip.source.pose.count == 14  # two caps, twelve sides
    assert len(ip.part.hull) == 12
    area = shapely.Polygon(ip.part.outline.vertices).area
    assert area == pytest.approx(3 * r * r, rel=1e-6)  # float32 STL
    assert ip.part.com == pytest.approx((0.0, 0.0), abs=1e-9)
    side = one(path, pose=2)
    w = 2 * r * math.cos(math.radians(15))  # width of the 12-gon along a side
    assert len(side.part.hull) == 4
    assert sorted(side_lengths(side.part.hull)) == pytest.approx([h, h, w, w], rel=1e-6)
    assert shapely.Polygon(side.part.outline.vertices).area == pytest.approx(h * w, rel=1e-6)


def test_l_bracket_poses(tmp_path):
    mesh = fx.prism(fx.L_VERTICES, fx.L_DEPTH)
    assert mesh.is_watertight and mesh.volume == pytest.approx(325 * fx.L_DEPTH)
    path = fx.write_mesh(mesh, tmp_path / "bracket.stl")
    first = one(path)
    count = first.source.pose.count
    assert count == 5  # two L faces, three stable sides of the L's hull (hand count)
    outlines = [one(path, pose=k) for k in range(count)]
    areas = sorted(shapely.Polygon(o.part.outline.vertices).area for o in outlines)
    expected = sorted([fx.L_HULL_AREA, fx.L_HULL_AREA, *fx.L_SIDE_AREAS])
    assert areas == pytest.approx(expected, rel=1e-9)
    # lying on its z = 0 face (normal straight down) the outline is the drawing's hull of the L
    flat = [o for o in outlines if np.allclose(o.source.pose.transform[2][:3], [0, 0, 1])]
    assert len(flat) == 1
    hull = {(round(x, 9) + 0.0, round(y, 9) + 0.0) for x, y in flat[0].part.hull}
    assert hull == {(float(x), float(y)) for x, y in fx.L_HULL}
    assert flat[0].part.com == pytest.approx(fx.L_COM, abs=1e-9)


def test_rotation_to_down_is_the_smallest():
    assert np.allclose(rotation_to_down(np.array([0.0, 0.0, -1.0])), np.eye(3))
    r = rotation_to_down(np.array([0.0, 0.0, 1.0]))
    assert np.allclose(r @ [0, 0, 1], [0, 0, -1]) and np.allclose(r @ [1, 0, 0], [1, 0, 0])
    n = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    r = rotation_to_down(n)
    assert np.allclose(r @ n, [0, 0, -1]) and np.allclose(r @ r.T, np.eye(3))
    axis = np.cross(n, [0, 0, -1])
    assert np.allclose(r @ axis, axis)  # rotates about n x down only


def test_mesh_with_a_missing_face_is_filled(tmp_path):
    box = trimesh.creation.box((10, 20, 30))
    # the two triangles of one face (faces 0 and 1 meet across an edge: a bent hole, refused
    # in test_mesh_bent_holes.py)
    face = [k for k, n in enumerate(box.face_normals) if n[0] < -0.5]
    keep = np.ones(len(box.faces), dtype=bool)
    keep[face] = False
    holed = trimesh.Trimesh(box.vertices, box.faces[keep], process=False)
    ip = one(fx.write_mesh(holed, tmp_path / "holed.stl"))
    assert any("holes were filled" in w for w in ip.warnings)
    assert sorted(extents(ip.part.hull)) == pytest.approx([20.0, 30.0])
    assert ip.part.com == pytest.approx((0.0, 0.0), abs=1e-9)


def test_open_mesh_needs_com(tmp_path):
    box = trimesh.creation.box((10, 20, 30))
    open_mesh = trimesh.Trimesh(box.vertices, box.faces[3:], process=False)
    path = fx.write_mesh(open_mesh, tmp_path / "open.stl")
    with pytest.raises(InputError, match="not a closed solid.*--com") as info:
        one(path)
    assert "\n" not in str(info.value)
    ip = one(path, com=(1.0, 2.0))
    assert ip.part.com == (1.0, 2.0)
    assert any("convex hull" in w for w in ip.warnings)


def test_two_bodies_refused(tmp_path):
    a = trimesh.creation.box((10, 10, 10))
    b = trimesh.creation.box((10, 10, 10))
    b.apply_translation((30, 0, 0))
    path = fx.write_mesh(trimesh.util.concatenate([a, b]), tmp_path / "two.stl")
    with pytest.raises(InputError, match="2 separate bodies"):
        one(path)


def test_mesh_units(tmp_path):
    path = fx.write_mesh(trimesh.creation.box((1, 2, 3)), tmp_path / "inch.stl")
    ip = one(path, units="in")
    assert sorted(extents(ip.part.hull)) == pytest.approx([2 * 25.4, 3 * 25.4])
    assert not any("no units" in w for w in ip.warnings)
    assert any("no units" in w for w in one(path).warnings)


@pytest.mark.parametrize(
    ("content", "match"),
    [
        (b"", "empty"),
        (b"solid x\nendsolid x\n", "no triangles|not a readable mesh"),
        (b"\x00\x01garbage" * 50, "not a readable mesh|no triangles"),
    ],
)
def test_bad_mesh_files(tmp_path, content, match):
    path = tmp_path / "bad.stl"
    path.write_bytes(content)
    with pytest.raises(InputError, match=match) as info:
        one(path)
    assert "\n" not in str(info.value)


@pytest.fixture
def no_charset_module(monkeypatch: pytest.MonkeyPatch) -> None:
    """trimesh's optional text-encoding guesser is not installed (as in a plain install)."""
    monkeypatch.setitem(sys.modules, "charset_normalizer", None)


@pytest.mark.parametrize(
    ("suffix", "said"),
    [(".stl", "not an STL file (neither binary nor ASCII STL)"), (".obj", "not an OBJ file")],
)
def test_random_bytes_are_named_as_the_file_not_a_module(tmp_path, no_charset_module, suffix, said):
    """Bytes that are no mesh make trimesh reach for an encoding guesser: the file is named."""
    path = tmp_path / f"garbage{suffix}"
    path.write_bytes(bytes(range(256)) * 2)
    with pytest.raises(InputError) as info:
        one(path)
    message = str(info.value)
    assert message == f"{path}: {said}" or message.startswith(f"{path}: {said} (")
    assert "module" not in message and "charset" not in message


def test_a_text_stl_that_is_not_utf8_names_the_package_it_needs(tmp_path, no_charset_module):
    """A text STL in Latin-1 is readable with the guesser: the missing package is named."""
    path = tmp_path / "latin.stl"
    path.write_bytes(
        b"solid caf\xe9\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
        b"   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid\n"
    )
    with pytest.raises(InputError, match="needs the Python package 'charset_normalizer'"):
        one(path)


def test_flat_mesh_refused(tmp_path):
    sheet = trimesh.Trimesh(
        [[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]], [[0, 1, 2], [1, 3, 2]]
    )
    path = fx.write_mesh(sheet, tmp_path / "sheet.stl")
    with pytest.raises(InputError, match="flat"):
        one(path)
