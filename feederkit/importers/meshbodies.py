"""The closed shells of a mesh and how they lie: cavities, inner bodies, bodies that touch.

A mesh file may hold several closed shells. A shell strictly inside the outer one whose
triangles face inward (as CAD programs write a void) is a cavity; one facing outward is an
inner body (an insert, a pressed pin). Shells whose surfaces cross or touch are not one
solid, and neither are shells side by side. Each shell's facing is read from the file before
any repair, since ``fix_normals`` turns every shell outward.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely

if TYPE_CHECKING:
    import trimesh

MAX_BODIES_LISTED = 4
"""Bodies described one by one in a refusal; the others are counted."""

PAIR_CHUNK = 200_000
"""Edge-triangle (or vertex-triangle) pairs tested at once: bounds the memory of a test."""

SURFACE_EPS = 1e-6
"""Distance, relative to the mesh's size, within which a point lies on a surface (float32
STL coordinates carry about 7 digits)."""

FLAT_HOLE_EPS = 1e-5
"""Distance from a plane, relative to the mesh's size or its farthest coordinate (the
larger), within which a hole's border is flat (:func:`bent_holes`): ten times
:data:`SURFACE_EPS`, so the float32 STL and 6-digit text coordinates of a flat face's hole
are flat wherever the part lies; a hole across an edge or a curved face is out of plane by
a share of its width."""

BENT_GUESS_SHARE = 1e-3
"""The share of a solid's volume up to which holes that are not flat are filled, with a
warning saying the guess (a dropout on a finely tessellated curved face guesses a
millionth); past it the mesh is refused (a box edge's dropout guesses a sixth)."""

BARYCENTRIC_EPS = 1e-6
"""Slack of the point-in-triangle test, so a point on a triangle's edge is on the surface."""


@dataclass(frozen=True)
class Shell:
    """A closed shell with outward normals, how the file wrote it (``facing`` +1 outward,
    -1 inward, 0 unknown: its winding was repaired) and the repair made (``filled`` holes,
    ``flipped`` inside out, ``rewound`` inconsistent winding, or None)."""

    mesh: trimesh.Trimesh
    facing: int
    repair: str | None


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


def close_shell(body: trimesh.Trimesh) -> Shell | None:
    """The body as a closed shell with outward normals (small holes filled), or None.

    A closed body whose consistent winding gives a negative volume faces inward: it is
    inverted, not repaired, and keeps ``facing`` -1 (a cavity, or a file written inside out).
    """
    import trimesh  # on first use: importing it costs every command about a second

    if body.is_watertight and body.is_winding_consistent:
        if body.is_volume:
            return Shell(body, 1, None)
        if float(body.volume) < 0:
            flipped = body.copy()
            flipped.invert()
            if flipped.is_volume:
                return Shell(flipped, -1, "flipped")
    fixed = body.copy()
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        trimesh.repair.fill_holes(fixed)
        known = fixed.is_watertight and fixed.is_winding_consistent
        facing = int(np.sign(float(fixed.volume))) if known else 0
        trimesh.repair.fix_normals(fixed)
    if not (fixed.is_watertight and fixed.is_volume):
        return None
    return Shell(fixed, facing, "rewound" if body.is_watertight else "filled")


def bent_holes(body: trimesh.Trimesh) -> list[tuple[float, float]]:
    """Each hole of ``body`` whose border is not flat: how far out of plane it lies (mm) and
    how much volume a fill of it guesses (mm3).

    A hole's border is a connected set of the body's edges used by one triangle (holes that
    touch at a vertex are one), read from the body as written, before any repair; it is flat
    when its vertices lie within :data:`FLAT_HOLE_EPS` of their least-squares plane, and a
    flat hole's fill is the face it lost. A bent one (across an edge of the solid, or a
    curved face) has no one fill: the two fills of a four-sided hole differ by the
    tetrahedron of its corners (what is said for it; for another, its distance out of plane
    times its area on that plane, a bound of that): a box edge's two triangles, filled
    across the other diagonal, cut off 17 % of the box.
    """
    import trimesh  # on first use: importing it costs every command about a second

    edges = trimesh.grouping.group_rows(body.edges_sorted, require_count=1)
    if len(edges) == 0:
        return []
    border = body.edges_sorted[edges]
    pts = np.asarray(body.vertices, dtype=float)
    scale = max(float(np.ptp(pts, axis=0).max()), float(np.abs(pts).max()))
    out = []
    for group in trimesh.graph.connected_components(border, min_len=3):
        ring = pts[np.asarray(group)]
        ring = ring - ring.mean(axis=0)
        axes = np.linalg.svd(ring, full_matrices=False)[2]
        off = float(np.abs(ring @ axes[2]).max())
        if off <= FLAT_HOLE_EPS * scale:
            continue
        if len(ring) == 4:  # the tetrahedron between its two fills
            guess = abs(float(np.linalg.det(ring[1:] - ring[0]))) / 6.0
        else:
            guess = off * float(shapely.convex_hull(shapely.multipoints(ring @ axes[:2].T)).area)
        out.append((off, guess))
    return out


def bent_words(bent: list[tuple[float, float]]) -> str:
    """``a hole whose border is X mm out of plane`` (or N holes, up to X mm)."""
    far = max(off for off, _ in bent)
    if len(bent) == 1:
        return f"a hole whose border is {far:.2g} mm out of plane"
    return f"{len(bent)} holes whose borders are up to {far:.2g} mm out of plane"


def is_debris(body: trimesh.Trimesh, size: float) -> bool:
    """Whether an open piece is flat (no volume: a stray triangle or sheet), so no mass."""
    pts = np.asarray(body.vertices, dtype=float)
    if len(pts) < 4:
        return True
    spread = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
    return float(spread[-1]) / np.sqrt(len(pts)) <= SURFACE_EPS * size


def edge_counts(mesh: trimesh.Trimesh) -> tuple[int, int]:
    """Edges used by one triangle (the border of holes) and by three or more (non-manifold)."""
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    return int((counts == 1).sum()), int((counts >= 3).sum())


def not_closed_reason(border: int, branching: int, pieces: int) -> str:
    """What keeps a mesh of ``pieces`` pieces, with ``border`` edges of one triangle and
    ``branching`` of three or more, from being one closed solid, in words, with a remedy."""
    where = f" in {pieces} pieces" if pieces > 1 else ""
    if branching:
        return (
            f"{branching} non-manifold edges (shared by 3 or more triangles: bodies that touch "
            f"along edges or faces, or a face written twice){where}; export it again as one "
            "closed solid (union touching bodies)"
        )
    if border:
        return f"an open surface with {border} border edges{where}"
    return f"a surface that encloses no volume{where}; export it again as one closed solid"


def _mm3(volume: float) -> str:
    return f"{volume:.0f}" if volume >= 100 else f"{volume:.2g}"


def bent_reason(bent: list[tuple[float, float]], volume: float, pieces: int) -> str:
    """Why a mesh with holes ``bent`` (:func:`bent_holes`) that guess too much of its
    ``volume`` is not a closed solid, with the remedy."""
    where = f" in {pieces} pieces" if pieces > 1 else ""
    guess = sum(g for _, g in bent)
    return (
        f"{bent_words(bent)}{where}, across an edge or a curved face: filling it would guess "
        f"up to {_mm3(guess)} mm3, {100.0 * guess / volume:.2g} % of the volume; repair the mesh "
        "or export it again"
    )


def bent_note(bent: list[tuple[float, float]], volume: float, reach: float) -> str:
    """The warning of a mesh whose bent holes (:func:`bent_holes`) were filled: the volume
    guessed, its share of ``volume``, and how far it may move the center of mass (the guess
    times ``reach``, the solid's diagonal, over its volume)."""
    guess = sum(g for _, g in bent)
    return (
        f"the mesh was not closed: holes were filled to compute its center of mass, "
        f"{bent_words(bent)} (across a curved face or an edge) by a guess of up to "
        f"{_mm3(guess)} mm3 ({100.0 * guess / volume:.2g} % of the volume), which may move "
        f"the center of mass by up to {guess * reach / volume:.2g} mm"
    )


def _in_box(points: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return ((points >= lo) & (points <= hi)).all(axis=-1)


def _near(mesh: trimesh.Trimesh, other: trimesh.Trimesh, eps: float) -> np.ndarray:
    """The triangles of ``mesh`` whose bounding boxes meet ``other``'s, grown by ``eps``."""
    lo, hi = other.bounds[0] - eps, other.bounds[1] + eps
    tri = np.asarray(mesh.triangles, dtype=float)
    return tri[(tri.max(axis=1) >= lo).all(axis=1) & (tri.min(axis=1) <= hi).all(axis=1)]


def _planes(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    return tri[keep], normal[keep] / length[keep, None]


def _in_triangles(
    x: np.ndarray, tri: np.ndarray, unit: np.ndarray, slack: float = BARYCENTRIC_EPS
) -> np.ndarray:
    """Whether points ``x`` (pairs, n x 3), in their triangles' planes, lie in the triangles
    (``slack`` > 0: or on their edges; < 0: strictly inside)."""
    area = np.einsum("ij,ij->i", np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), unit)
    inside = np.ones(len(x), dtype=bool)
    for i in range(3):
        a, b = tri[:, (i + 1) % 3], tri[:, (i + 2) % 3]
        w = np.einsum("ij,ij->i", np.cross(a - x, b - x), unit) / area
        inside &= w >= -slack
    return inside


def _pairs(n: int, m: int):
    """Index pairs (i < n, j < m) in chunks of about :data:`PAIR_CHUNK`."""
    rows = max(1, PAIR_CHUNK // max(m, 1))
    for start in range(0, n, rows):
        i = np.arange(start, min(n, start + rows))
        yield np.repeat(i, m), np.tile(np.arange(m), len(i))


def _edges_cross(a: trimesh.Trimesh, b: trimesh.Trimesh, eps: float) -> bool:
    """Whether an edge of ``a`` passes through the inside of a triangle of ``b`` (its ends
    strictly on either side): the surfaces cross. Through a triangle's edge is left to
    :func:`_vertices_on` (a part whose edge rests along its fixture's edge touches it)."""
    tri, unit = _planes(_near(b, a, eps))
    seg = np.asarray(a.vertices, dtype=float)[a.edges_unique]
    lo, hi = b.bounds[0] - eps, b.bounds[1] + eps
    seg = seg[(seg.max(axis=1) >= lo).all(axis=1) & (seg.min(axis=1) <= hi).all(axis=1)]
    for i, j in _pairs(len(seg), len(tri)):
        p0, p1, t, u = seg[i, 0], seg[i, 1], tri[j], unit[j]
        d0 = np.einsum("ij,ij->i", p0 - t[:, 0], u)
        d1 = np.einsum("ij,ij->i", p1 - t[:, 0], u)
        cross = ((d0 > eps) & (d1 < -eps)) | ((d0 < -eps) & (d1 > eps))
        if not cross.any():
            continue
        k = np.flatnonzero(cross)
        x = p0[k] + (p1[k] - p0[k]) * (d0[k] / (d0[k] - d1[k]))[:, None]
        if _in_triangles(x, t[k], u[k], -BARYCENTRIC_EPS).any():
            return True
    return False


def _vertices_on(a: trimesh.Trimesh, b: trimesh.Trimesh, eps: float) -> bool:
    """Whether a vertex of ``a`` lies on the surface of ``b`` (within ``eps``)."""
    tri, unit = _planes(_near(b, a, eps))
    pts = np.asarray(a.vertices, dtype=float)
    pts = pts[_in_box(pts, b.bounds[0] - eps, b.bounds[1] + eps)]
    for i, j in _pairs(len(pts), len(tri)):
        d = np.einsum("ij,ij->i", pts[i] - tri[j, 0], unit[j])
        on = np.abs(d) <= eps
        if on.any():
            k = np.flatnonzero(on)
            x = pts[i][k] - d[k, None] * unit[j][k]
            if _in_triangles(x, tri[j][k], unit[j][k]).any():
                return True
    return False


def surfaces_meet(a: trimesh.Trimesh, b: trimesh.Trimesh, eps: float) -> str | None:
    """``"overlap"`` when the surfaces of two closed shells cross, ``"touch"`` when a vertex
    of one lies on the other, None when they are apart (then one is wholly inside the other
    or outside it, as any of its points says)."""
    lo = np.maximum(a.bounds[0], b.bounds[0]) - eps
    hi = np.minimum(a.bounds[1], b.bounds[1]) + eps
    if (lo > hi).any():
        return None
    if _edges_cross(a, b, eps) or _edges_cross(b, a, eps):
        return "overlap"
    if _vertices_on(a, b, eps) or _vertices_on(b, a, eps):
        return "touch"
    return None


def describe_body(k: int, mesh: trimesh.Trimesh) -> str:
    """``body K: V mm3, W x D x H mm at (x, y, z)`` (K from 1; the box's size and centre)."""
    lo, hi = mesh.bounds
    size = " x ".join(f"{v:.3g}" for v in hi - lo)
    centre = ", ".join(f"{v:.4g}" for v in (lo + hi) / 2 + 0.0)
    volume = abs(float(mesh.volume))
    said = f"{volume:.0f}" if volume >= 1000 else f"{volume:.4g}"
    return f"body {k + 1}: {said} mm3, {size} mm at ({centre})"


def bodies_listed(shells: list[trimesh.Trimesh]) -> str:
    """The first :data:`MAX_BODIES_LISTED` bodies described, the others counted."""
    listed = [describe_body(k, m) for k, m in enumerate(shells[:MAX_BODIES_LISTED])]
    if len(shells) > MAX_BODIES_LISTED:
        listed.append(f"and {len(shells) - MAX_BODIES_LISTED} more")
    return "; ".join(listed)


RELATION_WORDS = {
    "overlap": "overlaps {j} (their surfaces cross: union them into one solid)",
    "touch": "touches {j} (a part in its fixture, or bodies not unioned)",
    "apart": "lies outside {j}",
}
"""How body k lies against body j, for the refusal of a file of separate bodies."""


def separate_bodies_message(shells: list[trimesh.Trimesh], k: int, j: int, how: str) -> str:
    """The refusal of a file whose body ``k`` is not inside body ``j`` (``how``: overlap,
    touch or apart), each body named by volume and box as the DXF importer names areas."""
    relation = RELATION_WORDS[how].format(j=f"body {j + 1}")
    return (
        f"the file holds {len(shells)} separate bodies ({bodies_listed(shells)}); "
        f"body {k + 1} {relation}; import one body per file"
    )
