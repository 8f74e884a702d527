"""Landings of a mesh: its resting poses with their probabilities, congruent ones merged.

The poses, their probabilities (trimesh's stable poses: the share of random drops that end
on each face) and each pose's outline seen from above come from
:mod:`feederkit.importers.mesh` unchanged; ``pose-K`` is its K-th pose (0 the most probable).
Poses whose outlines are congruent (:func:`feederkit.landing.model.congruent`: the same
outline and COM up to a rotation, such as opposite faces of a box) are one landing whose
probability is their sum, named after its most probable pose.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from pathlib import Path

from feederkit.errors import InputError
from feederkit.importers.budget import Budget
from feederkit.importers.mesh import load_mesh, pose_outline, resting_poses, solid
from feederkit.importers.model import ImportOptions
from feederkit.importers.orientable import orientability
from feederkit.importers.reader import NOT_ORIENTABLE, ImportedPart
from feederkit.landing.model import Landing, merge_congruent, renamed
from feederkit.mechanics.modelerror import kept_part
from feederkit.outline import make_outline
from feederkit.part import Part, make_part


def pose_name(k: int) -> str:
    """The landing name of mesh pose ``k``."""
    return f"pose-{k}"


def landings_of_mesh(
    path: str | Path,
    options: ImportOptions = ImportOptions(),
    name: str | None = None,
    hull_tolerance: float | None = None,
) -> tuple[Landing, ...]:
    """Every resting pose of the mesh file as a landing, congruent poses merged.

    ``hull_tolerance`` simplifies each pose's hull as the import does (default: exact; less
    on a pose whose chords would hold it where it rolls, ``kept_part``). With
    ``options.com`` (a COM given in one pose's plane) the other poses' outlines and COMs
    need the solid's 3-D center of mass: the only landing is then the imported pose
    (``options.pose``, default 0), and the import warns which poses, and what share of
    drops, are left out (:func:`feederkit.importers.mesh.com_pose_note`).
    """
    p = Path(path)
    label = name or p.stem
    budget = Budget(options.limits, str(p))
    mesh, _units, _notes = load_mesh(p, options.units, budget)
    s = solid(mesh, options.com is not None, str(p))
    try:
        poses = resting_poses(s)
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None
    if not poses:
        raise InputError(f"{p}: no resting pose found for the mesh")
    if options.com is not None:
        k = options.pose or 0
        if not 0 <= k < len(poses):
            raise InputError(f"{p}: no pose {k}: the mesh has {len(poses)} resting poses")
        part = _pose_part(s, poses[k], options.com, label, hull_tolerance)
        return (Landing(label, pose_name(k), 1.0, renamed(part, f"{label}/{pose_name(k)}")),)
    check = _naming_poses(budget, len(poses))
    candidates = []
    for k, pose in enumerate(poses):
        check()
        part = _pose_part(s, pose, None, label, hull_tolerance)
        candidates.append((pose_name(k), pose.probability, part))
    return merge_congruent(label, candidates, check)


ROUND_BODY_POSES = 100
"""A mesh with this many resting poses or more is named as a near-round body when its
landings run out of the import's time (a tessellated ball rests on every facet)."""


def _naming_poses(budget: Budget, poses: int) -> Callable[[], None]:
    """The budget's deadline, its refusal naming what the import was doing: comparing the
    mesh's resting poses (one per facet a body can rest on), which no larger limit may
    finish for a ball of a thousand facets."""

    def check() -> None:
        try:
            budget.check_time()
        except InputError as exc:
            why = f"; it was comparing the mesh's {poses} resting poses"
            if poses >= ROUND_BODY_POSES:
                why += (
                    " (a near-round body such as a ball rests on every facet, and none of "
                    "them is a flat pose a fence can orient)"
                )
            raise InputError(f"{exc}{why}") from None

    return check


def judged_by_landings(imported: ImportedPart, landings: Sequence[Landing]) -> ImportedPart:
    """A mesh part judged orientable by its landings rather than by its imported pose alone.

    The import judges the pose it imports (``pose-0``, the likeliest single facet: a
    cylinder's round end, 17 % of drops, disk-like) while ``plan`` judges a mesh by its
    landings (the cylinder on its side, 83 %, orients): when some landing of positive
    probability is orientable (:func:`~feederkit.importers.orientability`), so is the part,
    and the import's warning names the landings that are not and their share of drops.
    Flat parts, and meshes with one landing or an orientable imported pose, are unchanged.
    """
    if imported.source.kind != "mesh" or len(landings) < 2 or imported.orientability.orientable:
        return imported
    verdicts = [(x, orientability(x.part, imported.hull_tolerance)) for x in landings]
    good = [(x, v) for x, v in verdicts if v.orientable and x.probability > 0.0]
    if not good:
        return imported
    bad = [x for x, v in verdicts if not v.orientable]
    share = 100.0 * sum(x.probability for x in bad)
    old = f"{NOT_ORIENTABLE}: {imported.orientability.reason}"
    note = (
        f"{', '.join(x.name for x in bad)} ({share:.3g} % of drops) {NOT_ORIENTABLE}: "
        f"{imported.orientability.reason}; its landings "
        f"{', '.join(x.name for x, _v in good)} are, and a plan orients the part by them"
    )
    best = max(good, key=lambda g: g[0].probability)[1]
    warnings = tuple(note if w == old else w for w in imported.warnings)
    return dataclasses.replace(imported, orientability=best, warnings=warnings)


def _pose_part(s, pose, com2d, label: str, hull_tolerance: float | None) -> Part:
    ring, com, _transform = pose_outline(s, pose, com2d)
    exact = make_part(make_outline(label, ring, (), com, "mm"))
    return kept_part(exact, hull_tolerance)[0]
