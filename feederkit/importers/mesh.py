"""Meshes (STL, OBJ, PLY) with trimesh: the resting poses of the solid and its outline from above.

The outline of a pose is the convex hull of the mesh seen from above (what the fence feels);
its COM is the mesh's center of mass projected. The rotation about the vertical axis is free;
feederkit takes the smallest rotation that turns the resting face's outward normal straight
down, so a part modelled lying on its base keeps the drawing's x and y (the identity), and a
face pointing up is turned over about the x axis.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import shapely

from feederkit.errors import InputError
from feederkit.hull import convex_hull
from feederkit.importers.budget import MAX_COORD_MM, Budget, ImportLimits
from feederkit.importers.meshbodies import (
    BENT_GUESS_SHARE,
    SURFACE_EPS,
    Shell,
    bent_holes,
    bent_note,
    bent_reason,
    close_shell,
    describe_body,
    edge_counts,
    is_debris,
    not_closed_reason,
    separate_bodies_message,
    surfaces_meet,
    winding_number,
)
from feederkit.importers.model import ImportedOutline, ImportOptions, MeshPose
from feederkit.importers.plausible import outline_size, size_warnings, unitless_warnings
from feederkit.outline import make_outline, unit_name, unit_scale
from feederkit.words import plural

if TYPE_CHECKING:
    import trimesh

DOWN = np.array([0.0, 0.0, -1.0])

CHECK_EVERY = 65_536
"""Lines of a mesh file read between two checks of the import deadline."""

PROBABILITY_TIE = 1e-6
"""Probabilities of resting poses this close are a tie, ordered by the resting face's normal
(:func:`pose_key`); real differences between poses are far larger."""

NORMAL_GRID = 8
"""Steps per unit of the grid on which tied poses' normals are compared (:func:`pose_key`):
its cells' edges (odd sixteenths) lie away from the components of axis-aligned faces and of
faces at 30, 45 and 60 degrees to them."""


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


def _refuse_non_finite(path: Path, geoms: Sequence[trimesh.Trimesh]) -> None:
    """Refuse a mesh whose triangles use a vertex with a NaN or infinite coordinate (a
    damaged export): processing would drop those triangles without a word, and the solid
    that is left has a hole or a corner missing, which the import would blame on the mesh's
    shape (a frustum lost a corner this way and was planned)."""
    bad = 0
    for geom in geoms:
        if len(geom.faces):
            wrong = ~np.isfinite(np.asarray(geom.vertices, dtype=float)).all(axis=1)
            bad += int(np.count_nonzero(wrong[np.asarray(geom.faces)].any(axis=1)))
    if bad:
        raise InputError(
            f"{path}: {plural(bad, 'triangle')} of the mesh {'has' if bad == 1 else 'have'} a "
            "corner with a NaN or infinite coordinate (a damaged export): export the mesh again"
        )


def load_mesh(
    path: Path, units: str | None, budget: Budget | None = None
) -> tuple[trimesh.Trimesh, str, list[str]]:
    """Read one mesh file, scaled to mm; refuse files with no triangles or broken coordinates."""
    import trimesh  # on first use: importing it costs every command about a second

    budget = budget or Budget(ImportLimits(), str(path))
    notes: list[str] = []
    name = unit_name(units or "mm")
    scale = unit_scale(name)
    _precount_faces(path, budget)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            mesh = trimesh.load_mesh(path, file_type=path.suffix.lower().lstrip("."), process=False)
            # A scene's bodies as placed (``dump`` makes transformed copies), each checked and
            # processed on its own, as trimesh's own load does: NaN faces out, vertices merged.
            loaded = mesh.dump() if isinstance(mesh, trimesh.Scene) else [mesh]
            geoms = [g for g in loaded if isinstance(g, trimesh.Trimesh)]
            _refuse_non_finite(path, geoms)
            for geom in geoms:
                geom.process()
    except InputError:
        raise
    except ImportError as exc:  # an optional module trimesh wanted for this file's content
        raise _needs_module(path, exc) from None
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types on broken files
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if isinstance(exc, KeyError) and exc.args:  # a field the format needs is missing
            reason = f"its data lack the field {exc.args[0]!r}"
        raise InputError(f"{path}: not a readable mesh ({reason})") from None
    if isinstance(mesh, trimesh.Scene):
        mesh = trimesh.util.concatenate(geoms) if geoms else None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError(
            f"{path}: the file holds no triangles (none left once those with no area or with "
            "NaN or infinite coordinates are dropped)"
        )
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
    notes += drop_bad_faces(mesh)
    if scale != 1.0:
        mesh.apply_scale(scale)
    return mesh, name, notes


def drop_bad_faces(mesh: trimesh.Trimesh) -> list[str]:
    """Drop, in place, triangles written twice and degenerate ones (no area): exporters leave
    them, and they hold no volume but make a closed solid look open or non-manifold. The
    trimesh masks ``unique_faces`` and ``nondegenerate_faces`` (what its ``validate`` drops,
    without its ``fix_normals``: the file's own facing tells a cavity from an inner body)."""
    unique = mesh.unique_faces()
    proper = mesh.nondegenerate_faces()
    if unique.all() and proper.all():
        return []
    mesh.update_faces(unique & proper)
    mesh.remove_unreferenced_vertices()
    said = [
        plural(n, what)
        for n, what in (
            (int((~unique).sum()), "duplicate triangle"),
            (int((unique & ~proper).sum()), "degenerate (zero-area) triangle"),
        )
        if n
    ]
    return [f"dropped {' and '.join(said)}: they hold no volume"]


def open_edges(mesh: trimesh.Trimesh) -> int:
    """Edges of the surface that only one triangle uses: the border of its holes."""
    return edge_counts(mesh)[0]


OPEN_WITH_COM = (
    "the mesh is not closed: resting poses use its convex hull's centroid, COM from --com"
)
"""The note of an open mesh imported with ``--com`` (its own center of mass is unknown)."""

REPAIR_NOTES = {
    "filled": "the mesh was not closed: small holes were filled to compute its center of mass",
    "rewound": "the mesh's triangles were not wound consistently: they were turned to face "
    "outward to compute its center of mass",
}
"""The warning of each repair a shell may need (:class:`Shell`); ``flipped`` is said of the
outer shell only (an inner one facing inward is a cavity)."""

INSIDE_OUT = "the mesh is inside out (its triangles face inward): its normals were flipped"


def _pieces(
    mesh: trimesh.Trimesh, size: float, budget: Budget | None
) -> tuple[list[Shell], list[trimesh.Trimesh], list[trimesh.Trimesh], list[tuple[float, float]]]:
    """The mesh's connected pieces: closed shells, open pieces, flat debris (no volume), and
    the holes a shell had filled whose borders are not flat, each as far out of plane as it
    lies and the volume its fill guesses (:func:`.meshbodies.bent_holes`, read from the
    piece as written).

    Each piece's one-triangle and four-sided holes are filled as trimesh's ``split`` fills
    them (its ``repair``), after its holes are read.
    """
    shells, open_bodies, debris, bent = [], [], [], []
    for raw in list(mesh.split(only_watertight=False, repair=False)) or [mesh]:
        if budget is not None:
            budget.check_time()
        body = raw.copy()
        if len(body.faces) >= 4:
            body.fill_holes()
        shell = close_shell(body)
        if shell is not None:
            shells.append(shell)
            bent += bent_holes(raw)
        elif is_debris(body, size):
            debris.append(body)
        else:
            open_bodies.append(body)
    return shells, open_bodies, debris, bent


def _debris_note(debris: list[trimesh.Trimesh]) -> str:
    area = sum(float(d.area) for d in debris)
    return (
        f"left out {plural(len(debris), 'flat stray piece')} of no volume "
        f"({plural(sum(len(d.faces) for d in debris), 'triangle')}, {area:.3g} mm2): "
        "they carry no mass"
    )


def _open_edges(mesh: trimesh.Trimesh, debris: list[trimesh.Trimesh]) -> tuple[int, int]:
    """Edges of the mesh, debris left out, that one triangle uses and that three or more do."""
    border, branching = edge_counts(mesh)
    return border - sum(edge_counts(d)[0] for d in debris), branching


def _refuse_open(
    mesh: trimesh.Trimesh, label: str, debris: list[trimesh.Trimesh], pieces: int
) -> InputError:
    """The refusal of a mesh that is not closed, saying what is wrong (holes or edges that
    more than two triangles share) and the remedy."""
    border, branching = _open_edges(mesh, debris)
    reason = not_closed_reason(border, branching, pieces)
    hint = "; give --com X Y" if pieces == 1 and not branching else ""
    return InputError(
        f"{label}: not a closed solid ({reason}), so its center of mass is unknown{hint}"
    )


def solid(
    mesh: trimesh.Trimesh, com_given: bool, label: str, budget: Budget | None = None
) -> Solid:
    """The mesh as one solid for its COM: a closed volume, possibly with internal voids.

    Small holes are filled, an inside-out mesh is turned outward, flat stray pieces (no
    volume) are left out, each with a warning. Shells strictly inside the outer shell that
    the file writes facing inward are cavities (and shells inside a cavity material again):
    one physical part, whose COM is that of the solid with its cavities; an inner shell
    facing outward is an inner body, taken as the solid's own material with a warning.
    Shells side by side, touching or overlapping are separate parts and refused; a surface
    that is not closed, or whose holes' borders are not flat (across an edge: any fill is a
    guess) and guess more than :data:`.meshbodies.BENT_GUESS_SHARE` of its volume, is
    refused as "not a closed solid" unless ``--com`` is given (a smaller guess is filled
    and said). A mesh of many bodies costs a repair per body and a test per pair of shells:
    the deadline of ``budget`` is checked between them.
    """
    size = float(mesh.extents.max())
    shells, open_bodies, debris, bent = _pieces(mesh, size, budget)
    notes = [_debris_note(debris)] if debris else []
    if open_bodies:
        if com_given and len(open_bodies) == 1 and not shells:
            return Solid(open_bodies[0], None, (OPEN_WITH_COM, *notes))
        raise _refuse_open(mesh, label, debris, len(open_bodies) + len(shells))
    volume = max((float(sh.mesh.volume) for sh in shells), default=0.0)
    if bent and sum(g for _, g in bent) > BENT_GUESS_SHARE * volume:  # a fill across an edge
        if com_given and len(shells) == 1:  # guesses the solid: its COM is unknown
            return Solid(shells[0].mesh, None, (OPEN_WITH_COM, *notes))
        hint = "; give --com X Y" if len(shells) == 1 else ""
        reason = bent_reason(bent, volume, len(shells))
        raise InputError(
            f"{label}: not a closed solid ({reason}), so its center of mass is unknown{hint}"
        )
    shells.sort(key=lambda sh: -float(sh.mesh.volume))
    repairs = {sh.repair for sh in shells}
    if _open_edges(mesh, debris)[0]:  # split() itself fills single-triangle holes
        repairs.add("filled")
    if bent:
        repairs.discard("filled")
        notes.append(bent_note(bent, volume, float(np.linalg.norm(mesh.extents))))
    notes += [REPAIR_NOTES[r] for r in REPAIR_NOTES if r in repairs]
    if shells[0].facing < 0:
        notes.append(INSIDE_OUT)
    if len(shells) == 1:
        return Solid(
            shells[0].mesh, np.asarray(shells[0].mesh.center_mass, dtype=float), tuple(notes)
        )
    inside = _nesting([sh.mesh for sh in shells], SURFACE_EPS * size, label, budget)
    signs, inner_notes = _material_signs(shells, inside)
    volumes = np.array([float(sh.mesh.volume) for sh in shells]) * signs
    centres = np.array([sh.mesh.center_mass for sh in shells], dtype=float)
    com = (volumes[:, None] * centres).sum(axis=0) / volumes.sum()
    voids = int((signs < 0).sum())
    if voids:
        notes.append(
            f"the solid has {voids} internal void(s) (cavities): one part, its center of mass "
            "computed with the cavities"
        )
    return Solid(shells[0].mesh, com, tuple(notes + inner_notes))


def _nesting(
    meshes: list[trimesh.Trimesh], eps: float, label: str, budget: Budget | None
) -> dict[tuple[int, int], bool]:
    """Whether shell k lies wholly inside shell j (j < k, shells by decreasing volume).

    Every shell must lie inside the first (the outer one); shells whose surfaces cross or
    touch are refused, naming the bodies. Two shells whose surfaces do not meet are nested
    or apart as a whole, so one vertex's winding number decides which (a vertex on the
    other's surface would not: a part tight in its nest fixture has every vertex on it).
    """
    inside: dict[tuple[int, int], bool] = {}
    for k in range(1, len(meshes)):
        for j in range(k):
            if budget is not None:
                budget.check_time()
            how = surfaces_meet(meshes[k], meshes[j], eps)
            if how is None:
                nested = abs(winding_number(meshes[j], meshes[k].vertices[0])) >= 0.5
                how = "inside" if nested else "apart"
            if how != "inside" and (j == 0 or how != "apart"):
                raise InputError(f"{label}: {separate_bodies_message(meshes, k, j, how)}")
            inside[k, j] = how == "inside"
    return inside


def _material_signs(
    shells: list[Shell], inside: dict[tuple[int, int], bool]
) -> tuple[np.ndarray, list[str]]:
    """+1 for material, -1 for a void, 0 for a shell left out, per shell; and the warnings.

    A shell's depth (the kept shells around it) says what it should be: material at even
    depth, a void at odd. The file's facing, relative to the outer shell's, says what it is
    written as; where the two disagree (an inner body facing outward inside the material: an
    insert, a pressed pin) the shell is taken as the material (or void) around it and named.
    """
    ref = shells[0].facing
    signs = np.ones(len(shells))
    notes = []
    for k in range(1, len(shells)):
        depth = sum(1 for j in range(k) if inside[k, j] and signs[j] != 0)
        expected = -1 if depth % 2 else 1
        written = shells[k].facing * ref
        if written == 0 or written == expected:
            signs[k] = expected
            continue
        signs[k] = 0
        body = describe_body(k, shells[k].mesh)
        notes.append(
            f"an inner body ({body}) lies inside the solid, written as a body of its own, "
            "not a cavity: taken as the solid's own material; give --com X Y if it is an "
            "insert of another material"
            if expected < 0
            else f"an inner shell ({body}) inside a cavity faces inward: taken as part of "
            "the cavity"
        )
    return signs, notes


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


HALF_TURN_X = np.diag([1.0, -1.0, -1.0])
"""The half turn about the x axis: how a face pointing straight up is turned over."""

TURN_OVER_CONE_DEG = float(np.degrees(1.0))
"""Resting faces whose outward normal lies within this angle (1 radian) of straight up are
turned over about x once their tilt is removed; the others take the smallest rotation. No
rule can be continuous for every normal (a rotation chosen continuously for each direction
does not exist); this one puts the seam at an angle CAD models seldom draw a face at, far
from straight up, down and sideways."""


EXACT_SINE = 1e-12
"""A normal this close (sine of the angle) to straight down or up is taken as exactly so."""


def _smallest_rotation(n: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the unit vector ``n`` to straight down: Rodrigues' formula
    ``I + [v] + [v]^2 / (1 + c)`` with ``v = n x down``, ``c = n . down`` (exact for tiny
    angles too). A normal within :data:`EXACT_SINE` of straight down gives the identity
    exactly, and one of straight up (which has no smallest rotation) the half turn about x:
    float noise in a normal must not tilt an axis-aligned model's outline by 1e-17."""
    c = float(n @ DOWN)
    v = np.cross(n, DOWN)
    if float(np.linalg.norm(v)) < EXACT_SINE:
        return np.eye(3) if c > 0 else HALF_TURN_X.copy()
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + (vx @ vx) / (1.0 + c)


def rotation_to_down(normal: np.ndarray) -> np.ndarray:
    """Our rotation taking the resting face's outward ``normal`` straight down (-z).

    A face pointing down or sideways takes the smallest rotation (a part modelled on its base
    keeps the model's x and y). A face pointing up, within :data:`TURN_OVER_CONE_DEG`, is
    turned over about x after the smallest rotation that removes its tilt: so the frame of
    a face-up pose varies continuously with the model (a face tilted by 1e-4 degrees or by 3
    degrees gets the frame of the face straight up, which is turned over about x).
    """
    n = normal / np.linalg.norm(normal)
    if float(-n @ DOWN) >= np.cos(np.radians(TURN_OVER_CONE_DEG)):
        return _smallest_rotation(HALF_TURN_X @ n) @ HALF_TURN_X
    return _smallest_rotation(n)


@dataclass(frozen=True)
class RestingPose:
    """A resting pose: its probability, the resting face's outward normal, and our rotation."""

    probability: float
    normal: tuple[float, float, float]
    rotation: np.ndarray


def resting_poses(s: Solid) -> list[RestingPose]:
    """Stable resting poses of the solid on a plane, most probable first (ties by normal,
    :func:`sorted_poses`)."""
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
    return sorted_poses(poses)


def sorted_poses(poses: list[RestingPose]) -> list[RestingPose]:
    """The poses most probable first; poses whose probabilities tie (within
    :data:`PROBABILITY_TIE`: opposite faces of a plate differ in the last digits, in an order
    trimesh versions and tiny tilts of the model change) in the order of :func:`pose_key`."""
    groups: list[list[RestingPose]] = []
    for pose in sorted(poses, key=lambda p: -p.probability):
        if groups and groups[-1][-1].probability - pose.probability <= PROBABILITY_TIE:
            groups[-1].append(pose)
        else:
            groups.append([pose])
    return [pose for group in groups for pose in sorted(group, key=pose_key)]


def pose_key(pose: RestingPose) -> tuple[float, ...]:
    """The order of tied poses: the normal on a grid of 1/:data:`NORMAL_GRID`, then exact.

    On the grid a normal tilted by up to 3.5 degrees from an axis keeps its place: a plate's
    face-down pose stays pose 0 before its face-up twin however slightly the model is tilted,
    and exactly axis-aligned models keep the order of their exact normals.
    """
    grid = (round(v * NORMAL_GRID) / NORMAL_GRID + 0.0 for v in pose.normal)
    return (*grid, *(float(v) for v in pose.normal))


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


def com_pose_note(s: Solid, poses: list[RestingPose], k: int) -> str:
    """The warning of a mesh imported with ``--com``: only pose ``k`` is planned.

    ``--com X Y`` is a point in pose k's plane; the other poses' outlines, edge poses and
    probabilities need the solid's 3-D center of mass (Akella and Mason's stable poses),
    which it does not give: their landings are left out, never silently (design.md: plans
    cover every landing unless told otherwise).
    """
    name = f"pose-{k}"
    if s.com is None:
        return (
            f"only the imported pose ({name}) is planned, with the COM from --com: the other "
            "resting poses need the solid's center of mass, which an open mesh does not give "
            "(close the mesh to plan every landing)"
        )
    others = len(poses) - 1
    share = 100.0 * (1.0 - poses[k].probability)
    return (
        f"--com gives the center of mass of {name} only: the plan covers {name} only; the "
        f"other {plural(others, 'pose')}, {share:.0f} % of drops, are left out: leave out "
        "--com to plan every landing"
    )


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
    said = (com_pose_note(s, poses, k),) if options.com is not None else ()
    ring, com2d, transform = pose_outline(s, poses[k], options.com)
    outline = make_outline(name, ring, (), com2d, "mm")
    # The part's size as the plan has it (its resting outline's hull diameter, Part.size),
    # not the solid's largest extent: one size per part in what the import says.
    size = outline_size(outline)
    unitless = options.units is None
    notes += size_warnings(size, unit_name, not unitless, unitless)
    if unitless:
        notes += unitless_warnings(size)
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
        warnings=tuple(notes) + s.warnings + said,
    )
