"""A mesh hole whose border is not flat (across an edge or a curved face) has no one fill.

A flat hole's fill is the face it lost; a bent one's fill is a guess: two triangles missing
along a box edge, filled across the other diagonal, cut a sixth off the box. Such a hole is
refused as "not a closed solid" when its guess is more than a thousandth of the volume, and
filled with a warning saying the guess otherwise (a rev93 review).
"""

from __future__ import annotations

import re
from pathlib import Path

import fixtures_cad as fx
import numpy as np
import pytest
import trimesh

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts


def one(path: Path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    return parts[0]


def _box() -> trimesh.Trimesh:
    box = trimesh.creation.box((40, 20, 6))
    box.apply_translation((20, 10, 3))
    return box


def _without(mesh: trimesh.Trimesh, drop: list[int]) -> trimesh.Trimesh:
    keep = np.ones(len(mesh.faces), dtype=bool)
    keep[drop] = False
    return trimesh.Trimesh(mesh.vertices, mesh.faces[keep], process=False)


def _edge_pair(mesh: trimesh.Trimesh, curved: bool) -> list[int]:
    """Two triangles sharing an edge, not coplanar (on a box: across its edge)."""
    for (i, j), angle in zip(mesh.face_adjacency, mesh.face_adjacency_angles, strict=True):
        if angle > 1e-6 and (not curved or angle < 0.2):
            return [int(i), int(j)]
    raise AssertionError("no bent pair")


def _face_pair(mesh: trimesh.Trimesh) -> list[int]:
    """The two triangles of one face of a box (coplanar, sharing an edge)."""
    for (i, j), angle in zip(mesh.face_adjacency, mesh.face_adjacency_angles, strict=True):
        if angle < 1e-9:
            return [int(i), int(j)]
    raise AssertionError("no coplanar pair")


@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_two_triangles_missing_along_a_box_edge_are_refused(tmp_path, suffix):
    path = fx.write_mesh(_without(_box(), _edge_pair(_box(), False)), tmp_path / f"b{suffix}")
    with pytest.raises(InputError) as info:
        one(path)
    message = str(info.value)
    assert "\n" not in message
    assert "not a closed solid (a hole whose border is 3 mm out of plane" in message, message
    # the tetrahedron between the two fills: 17 % of the box, 20 % of the box cut by it
    assert re.search(r"would guess up to 800 mm3, (17|20) % of the volume", message), message
    assert message.endswith("so its center of mass is unknown; give --com X Y"), message
    ip = one(path, com=(20.0, 10.0))  # the remedy named: the imported pose, COM given
    assert ip.part.com == (20.0, 10.0)
    assert any("not closed" in w and "--com" in w for w in ip.warnings)


def test_a_whole_missing_face_is_filled_exactly(tmp_path):
    box = _box()
    ip = one(fx.write_mesh(_without(box, _face_pair(box)), tmp_path / "face.stl"))
    assert any("small holes were filled" in w for w in ip.warnings)
    assert ip.part.com == pytest.approx((20.0, 10.0), abs=1e-9)
    assert ip.source.pose.count == 6


def test_a_dropout_on_a_curved_face_is_filled_and_the_guess_said(tmp_path):
    cyl = trimesh.creation.cylinder(radius=10, height=5, sections=64)
    path = fx.write_mesh(_without(cyl, _edge_pair(cyl, True)), tmp_path / "cyl.stl")
    ip = one(path)
    said = [w for w in ip.warnings if "out of plane" in w]
    assert len(said) == 1 and "small holes were filled" not in " ".join(ip.warnings)
    assert "% of the volume" in said[0] and "center of mass by up to" in said[0], said
    assert ip.part.com == pytest.approx((0.0, 0.0), abs=1e-6)


def test_the_two_bent_holes_of_a_mesh_are_counted(tmp_path):
    box = _box()
    first = _edge_pair(box, False)
    shared = set(box.faces[first[0]]) | set(box.faces[first[1]])
    second = next(
        [int(i), int(j)]
        for (i, j), a in zip(box.face_adjacency, box.face_adjacency_angles, strict=True)
        if a > 1e-6 and not (set(box.faces[i]) | set(box.faces[j])) & shared
    )
    path = fx.write_mesh(_without(box, first + second), tmp_path / "two.stl")
    with pytest.raises(InputError, match=r"not a closed solid \(2 holes whose borders are"):
        one(path)
