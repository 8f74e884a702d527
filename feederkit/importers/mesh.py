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
from typing import TYPE_CHECKING

import numpy as np
import shapely

from feederkit.errors import InputError
from feederkit.hull import convex_hull
from feederkit.importers.budget import MAX_COORD_MM, Budget, ImportLimits
from feederkit.importers.model import ImportedOutline, ImportOptions, MeshPose
from feederkit.importers.plausible import size_warnings
from feederkit.outline import make_outline, unit_scale

if TYPE_CHECKING:
    import trimesh

DOWN = np.array([0.0, 0.0, -1.0])

CHECK_EVERY = 65_536
"""Lines of a mesh file read between two checks of the import deadline."""

POSE_KEY_DIGITS = 6
"""Decimals of a pose's probability and normal compared when sorting poses."""


@dataclass(frozen=True)
class Solid:
    """A mesh ready for pose analysis (mm): the mesh, its COM (3-D or None) and warnings."""

    mesh: trimesh.Trimesh
    com: np.ndarray | None
    warnings: tuple[str, ...]


def _precount_faces(path: Path, budget: Budget) -> None:
    """Refuse, from the file's own counts and before trimesh builds anything, too many faces.

    Binary STL states its triangle count; an OBJ face of n vertices becomes n - 2 triangles
    (a face with a vertex list repeated a million times is a million triangles); PLY states
    its face count in the header.
    """
    suffix = path.suffix.lower()
    noun = "mesh faces in the file"
    with path.open("rb") as fh:
        head = fh.read(84)
        if suffix == ".stl" and len(head) == 84:
            count = int.from_bytes(head[80:84], "little")
            if 84 + 50 * count == path.stat().st_size:  # a consistent binary STL
                budget.need("faces", count, noun)
            return
        if suffix == ".ply":
            fh.seek(0)
            for _ in range(64):
                line = fh.readline()
                parts = line.split()
                if parts[:2] == [b"element", b"face"] and len(parts) == 3 and parts[2].isdigit():
                    budget.need("faces", int(parts[2]), noun)
                if not line or line.strip() == b"end_header":
                    break
            return
        if suffix == ".obj":
            fh.seek(0)
            total = 0
            for n, line in enumerate(fh):
                if line.startswith(b"f ") or line.startswith(b"f\t"):
                    total += max(1, len(line.split()) - 3)
                if n % CHECK_EVERY == CHECK_EVERY - 1:
                    budget.check_time()
            budget.need("faces", total, noun)


NOT_THE_FORMAT = {
    "stl": "not an STL file (neither binary nor ASCII STL)",
    "obj": "not an OBJ file (not text with vertex lines)",
    "ply": "not a PLY file (no 'ply' header)",
}
"""What a file that is not of its extension's format is called, by extension."""

SNIFF_BYTES = 65_536
"""Bytes read from a file's start to tell whether it looks like its mesh format."""


def looks_like_format(head: bytes, kind: str) -> bool:
    """Whether a file's first bytes look like a text STL, an OBJ or a PLY file.

    Used only once trimesh failed, to tell a broken file from a readable one.
    """
    text = head.lstrip()
    if kind == "stl":
        return text[:5].lower() == b"solid" and b"facet" in text.lower()
    if kind == "ply":
        return text[:3] == b"ply"
    if kind == "obj":
        return any(ln.lstrip().startswith((b"v ", b"v\t")) for ln in text.splitlines())
    return False


def _needs_module(path: Path, exc: ImportError) -> InputError:
    """The error for a file whose reading made trimesh import a module that is missing.

    trimesh imports optional modules while it reads: ``charset_normalizer`` to guess the
    encoding of text that is not UTF-8, which is how random bytes in an ``.stl`` end. A file
    that does not look like its format is named as such (the module is trimesh's business);
    one that does is readable with the module, which is then named so it can be installed.
    """
    kind = path.suffix.lower().lstrip(".")
    try:
        with path.open("rb") as fh:
            head = fh.read(SNIFF_BYTES)
    except OSError as err:
        return InputError(f"{path}: cannot read the file ({err.strerror})")
    if not looks_like_format(head, kind):
        return InputError(f"{path}: {NOT_THE_FORMAT.get(kind, 'not a readable mesh')}")
    module = exc.name or "an optional module"
    return InputError(
        f"{path}: reading this {kind.upper()} file needs the Python package {module!r}, "
        "which is not installed (its text is not UTF-8)"
    )


def load_mesh(
    path: Path, units: str | None, budget: Budget | None = None
) -> tuple[trimesh.Trimesh, str, list[str]]:
    """Read one mesh file, scaled to mm; refuse files with no triangles or broken coordinates."""
    import trimesh  # on first use: importing it costs every command about a second

    budget = budget or Budget(ImportLimits(), str(path))
    notes: list[str] = []
    unit_name = units or "mm"
    if units is None:
        notes.append("mesh files carry no units: read as mm (use --units)")
    scale = unit_scale(unit_name)
    _precount_faces(path, budget)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            mesh = trimesh.load_mesh(path, file_type=path.suffix.lower().lstrip("."), process=True)
    except InputError:
        raise
    except ImportError as exc:  # an optional module trimesh wanted for this file's content
        raise _needs_module(path, exc) from None
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types on broken files
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputError(f"{path}: not a readable mesh ({reason})") from None
    if isinstance(mesh, trimesh.Scene):
        geoms = [g for g in mesh.dump() if isinstance(g, trimesh.Trimesh)]
        mesh = trimesh.util.concatenate(geoms) if geoms else None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError(f"{path}: the file holds no triangles")
    budget.faces(len(mesh.faces))
    budget.vertices(len(mesh.vertices))
    if not np.isfinite(mesh.vertices).all():
        raise InputError(f"{path}: the mesh has NaN or infinite coordinates")
    far = float(np.abs(mesh.vertices).max()) * scale
    if far > MAX_COORD_MM:
        raise InputError(
            f"{path}: the mesh has a coordinate of {far:.3g} mm, beyond any part a feeder can "
            f"hold ({MAX_COORD_MM:g} mm; check the units)"
        )
    extent = mesh.extents
    if float(extent.min()) <= 1e-9 * float(extent.max()):
        raise InputError(f"{path}: the mesh is flat (zero volume)")
    if scale != 1.0:
        mesh.apply_scale(scale)
    return mesh, unit_name, notes


def open_edges(mesh: trimesh.Trimesh) -> int:
    """Edges of the surface that only one triangle uses: the border of its holes."""
    import trimesh  # on first use: importing it costs every command about a second

    return len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))


def winding_number(mesh: trimesh.Trimesh, point: np.ndarray) -> float:
    """How many times the closed surface winds around ``point`` (1 inside, 0 outside).

    The sum of the triangles' solid angles seen from the point over 4 pi (Van Oosterom and
    Strackee's formula), exact for any closed surface, with no ray casting.
    """
    tri = np.asarray(mesh.triangles, dtype=float) - point
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = (
        la * lb * lc
        + np.einsum("ij,ij->i", a, b) * lc
        + np.einsum("ij,ij->i", a, c) * lb
        + np.einsum("ij,ij->i", b, c) * la
    )
    return float(np.arctan2(num, den).sum() * 2.0 / (4.0 * np.pi))


def _closed(body: trimesh.Trimesh) -> trimesh.Trimesh | None:
    """The body as a closed volume with outward normals (small holes filled), or None."""
    import trimesh  # on first use: importing it costs every command about a second

    if body.is_watertight and body.is_volume:
        return body
    fixed = body.copy()
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        trimesh.repair.fill_holes(fixed)
        trimesh.repair.fix_normals(fixed)
    return fixed if fixed.is_watertight and fixed.is_volume else None


def solid(
    mesh: trimesh.Trimesh, com_given: bool, label: str, budget: Budget | None = None
) -> Solid:
    """The mesh as one solid for its COM: a closed volume, possibly with internal voids.

    Small holes are filled (with a warning). Shells inside the outer shell are cavities
    (and shells inside a cavity material again): one physical part, whose COM is that of
    the solid with its cavities. Shells side by side are separate parts and refused; a
    surface that is not closed is refused as "not a closed solid" unless ``--com`` is given.
    A mesh of many bodies costs a repair per body and a winding number per pair of shells:
    the deadline of ``budget`` is checked between them.
    """
    bodies = list(mesh.split(only_watertight=False)) or [mesh]
    closed = []
    for body in bodies:
        if budget is not None:
            budget.check_time()
        closed.append(_closed(body))
    if any(c is None for c in closed):
        if com_given and len(bodies) == 1:
            note = (
                "the mesh is not closed: resting poses use its convex hull's centroid, "
                "COM from --com"
            )
            return Solid(mesh, None, (note,))
        pieces = f" in {len(bodies)} pieces" if len(bodies) > 1 else ""
        raise InputError(
            f"{label}: not a closed solid (an open surface with {open_edges(mesh)} border "
            f"edges{pieces}), so its center of mass is unknown"
            + ("; give --com X Y" if len(bodies) == 1 else "")
        )
    shells = [c for c in closed if c is not None]
    filled = not (mesh.is_watertight and mesh.is_volume)  # split() itself may fill small holes
    notes = (
        ["the mesh was not closed: small holes were filled to compute its center of mass"]
        if filled
        else []
    )
    if len(shells) == 1:
        return Solid(shells[0], np.asarray(shells[0].center_mass, dtype=float), tuple(notes))
    shells.sort(key=lambda m: -float(m.volume))
    outer = shells[0]
    lo, hi = outer.bounds
    depth = [0] * len(shells)
    for k, shell in enumerate(shells[1:], start=1):
        if budget is not None:
            budget.check_time()
        inside_box = bool((shell.bounds[0] >= lo).all() and (shell.bounds[1] <= hi).all())
        if not inside_box or abs(winding_number(outer, shell.vertices[0])) < 0.5:
            raise InputError(
                f"{label}: the file holds {len(shells)} separate bodies; import one body per file"
            )
        depth[k] = sum(
            abs(winding_number(shells[j], shell.vertices[0])) >= 0.5
            for j in range(k)
            if float(shells[j].volume) > float(shell.volume)
        )
    signs = np.array([(-1.0) ** d for d in depth])
    volumes = np.array([float(s.volume) for s in shells]) * signs
    centres = np.array([s.center_mass for s in shells], dtype=float)
    com = (volumes[:, None] * centres).sum(axis=0) / volumes.sum()
    voids = int((signs < 0).sum())
    notes.append(
        f"the solid has {voids} internal void(s) (cavities): one part, its center of mass "
        "computed with the cavities"
    )
    return Solid(outer, com, tuple(notes))


def hull_face_count(mesh: trimesh.Trimesh, limit: int) -> int:
    """Triangles of the mesh's convex hull, or a count above ``limit`` found without it.

    A convex polytope with V extreme vertices has 2 V - 4 triangles, and every extreme
    vertex of a projection is one: so the 2-D hulls of the three axis projections (cheap)
    refuse a 20,000-section cylinder before qhull, whose time on many cocircular points,
    and trimesh's hull post-processing (quadratic in the faces), would run for minutes.
    """
    from scipy.spatial import ConvexHull  # on first use, as trimesh

    pts = np.asarray(mesh.vertices, dtype=float)
    for a, b in ((0, 1), (1, 2), (0, 2)):
        ring = shapely.convex_hull(shapely.multipoints(pts[:, [a, b]]))
        extreme = shapely.get_num_coordinates(ring) - 1
        if 2 * extreme - 4 > limit:
            return 2 * extreme - 4
    try:
        return len(ConvexHull(pts).simplices)
    except Exception as exc:  # noqa: BLE001 - qhull refuses degenerate point sets
        raise InputError(f"the mesh has no convex hull ({str(exc).splitlines()[0]})") from None


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
    import trimesh  # on first use: importing it costs every command about a second

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
    poses.sort(key=pose_key)
    return poses


def pose_key(pose: RestingPose) -> tuple[float, ...]:
    """Sort key: decreasing probability, ties by the normal, both rounded (``POSE_KEY_DIGITS``).

    Opposite faces of a box have equal probabilities up to the last digit, which trimesh
    versions order differently; rounding makes the order a function of the solid alone.
    """
    prob = round(pose.probability, POSE_KEY_DIGITS) + 0.0
    return (-prob, *(round(v, POSE_KEY_DIGITS) + 0.0 for v in pose.normal))


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


def read_mesh(
    path: Path, options: ImportOptions, name: str, budget: Budget | None = None
) -> ImportedOutline:
    """The outline of a mesh in its resting pose ``options.pose`` (default: the most probable)."""
    budget = budget or Budget(options.limits, str(path))
    mesh, unit_name, notes = load_mesh(path, options.units, budget)
    budget.check_time()
    try:  # before the solid is split into shells and repaired: a hull of 40,000 faces is
        hull_faces = hull_face_count(mesh, options.limits.hull_faces)  # refused in a moment
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    budget.need("hull_faces", hull_faces, "faces of the mesh's convex hull")
    budget.check_time()
    s = solid(mesh, options.com is not None, str(path), budget)
    budget.check_time()
    notes += size_warnings(float(s.mesh.extents.max()), unit_name, options.units is not None)
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
