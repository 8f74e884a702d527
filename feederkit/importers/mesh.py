"""Meshes (STL, OBJ, PLY) with trimesh: the resting poses of the solid and its outline from above.

The outline of a pose is the convex hull of the mesh seen from above (what the fence feels);
its COM is the mesh's center of mass projected. The rotation about the vertical axis is free;
feederkit takes the smallest rotation that turns the resting face's outward normal straight
down, so a part modelled lying on its base keeps the drawing's x and y (the identity), and a
face pointing up is turned over about the x axis.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from feederkit.errors import InputError
from feederkit.hull import convex_hull
from feederkit.importers.model import ImportedOutline, ImportOptions, MeshPose
from feederkit.outline import make_outline, unit_scale

DOWN = np.array([0.0, 0.0, -1.0])


@dataclass(frozen=True)
class Solid:
    """A mesh ready for pose analysis (mm): the mesh, its COM (3-D or None) and warnings."""

    mesh: trimesh.Trimesh
    com: np.ndarray | None
    warnings: tuple[str, ...]


def load_mesh(path: Path, units: str | None) -> tuple[trimesh.Trimesh, str, list[str]]:
    """Read one mesh file, scaled to mm; refuse files with no triangles or several bodies."""
    notes: list[str] = []
    unit_name = units or "mm"
    if units is None:
        notes.append("mesh files carry no units: read as mm (use --units)")
    scale = unit_scale(unit_name)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            mesh = trimesh.load_mesh(path, file_type=path.suffix.lower().lstrip("."), process=True)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types on broken files
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"{path}: not a readable mesh ({reason})") from None
    if isinstance(mesh, trimesh.Scene):
        geoms = [g for g in mesh.dump() if isinstance(g, trimesh.Trimesh)]
        mesh = trimesh.util.concatenate(geoms) if geoms else None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError(f"{path}: the file holds no triangles")
    if not np.isfinite(mesh.vertices).all():
        raise InputError(f"{path}: the mesh has NaN or infinite coordinates")
    bodies = mesh.split(only_watertight=False)
    if len(bodies) > 1:
        raise InputError(
            f"{path}: the file holds {len(bodies)} separate bodies; import one body per file"
        )
    extent = mesh.extents
    if float(extent.min()) <= 1e-9 * float(extent.max()):
        raise InputError(f"{path}: the mesh is flat (zero volume)")
    if scale != 1.0:
        mesh.apply_scale(scale)
    return mesh, unit_name, notes


def solid(mesh: trimesh.Trimesh, com_given: bool, label: str) -> Solid:
    """Make sure the mesh is a closed volume for its COM: fill small holes, else need ``--com``."""
    if mesh.is_watertight and mesh.is_volume:
        return Solid(mesh, np.asarray(mesh.center_mass, dtype=float), ())
    fixed = mesh.copy()
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        trimesh.repair.fill_holes(fixed)
        trimesh.repair.fix_normals(fixed)
    if fixed.is_watertight and fixed.is_volume:
        note = "the mesh was not closed: small holes were filled to compute its center of mass"
        return Solid(fixed, np.asarray(fixed.center_mass, dtype=float), (note,))
    if not com_given:
        raise InputError(
            f"{label}: the mesh is not a closed volume (not watertight), so its center of mass "
            "is unknown; give --com X Y"
        )
    note = "the mesh is not closed: resting poses use its convex hull's centroid, COM from --com"
    return Solid(mesh, None, (note,))


def rotation_to_down(normal: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the unit vector ``normal`` to straight down (-z)."""
    n = normal / np.linalg.norm(normal)
    c = float(n @ DOWN)
    if c > 1.0 - 1e-12:
        return np.eye(3)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])  # half turn about x
    axis = np.cross(n, DOWN)
    s = float(np.linalg.norm(axis))
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)


@dataclass(frozen=True)
class RestingPose:
    """A resting pose: its probability, the resting face's outward normal, and our rotation."""

    probability: float
    normal: tuple[float, float, float]
    rotation: np.ndarray


def resting_poses(s: Solid) -> list[RestingPose]:
    """Stable resting poses of the solid on a plane, most probable first (ties by normal)."""
    hull = s.mesh.convex_hull
    com = s.com if s.com is not None else np.asarray(hull.center_mass, dtype=float)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            transforms, probs = trimesh.poses.compute_stable_poses(s.mesh, center_mass=com)
        except Exception as exc:  # noqa: BLE001 - degenerate solids in third-party files
            raise InputError(f"cannot compute the mesh's resting poses ({exc})") from None
    poses = []
    for t, p in zip(transforms, probs, strict=True):
        normal = np.asarray(t)[:3, :3].T @ DOWN
        normal = normal / np.linalg.norm(normal)
        poses.append(
            RestingPose(float(p), tuple(float(v) for v in normal), rotation_to_down(normal))
        )
    poses.sort(key=lambda q: (-round(q.probability, 9), tuple(round(v, 9) for v in q.normal)))
    return poses


def pose_outline(
    s: Solid, pose: RestingPose, com2d: tuple[float, float] | None
) -> tuple[list[tuple[float, float]], tuple[float, float], np.ndarray]:
    """Outline (convex hull seen from above), COM (projected or given) and 4x4 transform."""
    pts = np.asarray(s.mesh.convex_hull.vertices, dtype=float) @ pose.rotation.T
    ring = convex_hull(pts[:, :2])
    if com2d is None:
        assert s.com is not None
        c = pose.rotation @ s.com
        com2d = (float(c[0]), float(c[1]))
    transform = np.eye(4)
    transform[:3, :3] = pose.rotation
    transform[2, 3] = -float(pts[:, 2].min())
    return ring, com2d, transform


def read_mesh(path: Path, options: ImportOptions, name: str) -> ImportedOutline:
    """The outline of a mesh in its resting pose ``options.pose`` (default: the most probable)."""
    mesh, unit_name, notes = load_mesh(path, options.units)
    s = solid(mesh, options.com is not None, str(path))
    try:
        poses = resting_poses(s)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    if not poses:
        raise InputError(f"{path}: no resting pose found for the mesh")
    k = 0 if options.pose is None else options.pose
    if not 0 <= k < len(poses):
        raise InputError(
            f"{path}: no pose {k}: the mesh has {len(poses)} resting poses (0-{len(poses) - 1})"
        )
    ring, com2d, transform = pose_outline(s, poses[k], options.com)
    outline = make_outline(name, ring, (), com2d, "mm")
    pose = MeshPose(
        index=k,
        probability=poses[k].probability,
        count=len(poses),
        transform=tuple(tuple(float(v) for v in row) for row in transform),
    )
    return ImportedOutline(
        outline=outline,
        kind="mesh",
        source_units=unit_name,
        pose=pose,
        warnings=tuple(notes) + s.warnings,
    )
