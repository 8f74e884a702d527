"""The analysis of one part: its push function, symmetry and, for a sensor, its Fig. 14 class.

This is what ``feederkit part analyze`` prints; :func:`analysis_to_dict` is its JSON object
(design.md: ``name``, ``units``, ``com``, ``hull``, ``stable_states``, ``symmetry_period_deg``
and, with a sensor model, ``class`` and ``bound``; plus the extras documented in
docs/analysis.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.mechanics.polygon_classes import PolygonClass, polygon_class
from feederkit.mechanics.push import (
    PushFunction,
    StableState,
    edge_normals,
    nearer_vertices,
    push_function,
)
from feederkit.mechanics.symmetry import Symmetry, symmetry
from feederkit.part import Part
from feederkit.sensors import Sensor


@dataclass(frozen=True)
class NearMetastable:
    """An edge whose COM foot lies within a small angle (seen from the COM) of ``vertex``.

    ``margin_deg`` is signed: positive when the foot is on the edge (a stable edge that the
    part may leave for its neighbour), negative when it is just past the vertex (an unstable
    edge the part may still rest on), zero when exactly metastable.
    """

    edge: int
    vertex: int
    kind: str
    margin_deg: float


FRAGILE_BARRIER_REL = 1e-3
"""A stable state whose barrier is below this fraction of the part's size is fragile."""


def fragile_states(pf: PushFunction, rel: float = FRAGILE_BARRIER_REL) -> tuple[int, ...]:
    """Stable states the part leaves for a neighbour at the slightest disturbance.

    A state's barrier (``StableState.barrier_mm``) is how far the radius function rises
    before the part tips out of it. Below ``rel`` times the part's size (0.06 mm on a 60 mm
    part) the kinematic model's state is real but a belt's vibration, a pick-up's offset or
    the flattened facets of a CAD arc decide where the part actually rests; plans that rely
    on such states deserve a physics check (``feederkit simulate``).
    """
    limit = rel * pf.part.size
    return tuple(s.id for s in pf.states if s.barrier_mm < limit)


def fragile_warning(pf: PushFunction) -> str | None:
    """One line naming a part's fragile states, or None when it has none."""
    lines = fragile_member_warnings([[(pf.part.name, pf)]])
    return lines[0] if lines else None


FRAGILE_LINES = 3
"""A mix with more parts than this that have fragile states gets one line for all of them."""

FRAGILE_ADVICE = "may settle on a neighbour; check the plan with feederkit simulate"
"""What every fragile-state warning ends with."""


def _ids(ids: Sequence[int]) -> str:
    """State ids in words: at most eight, then how many more."""
    return ", ".join(str(i) for i in ids[:8]) + (f" (+{len(ids) - 8})" if len(ids) > 8 else "")


def _limit(pf: PushFunction) -> str:
    """The fragile barrier of ``pf``'s part in words."""
    return f"barrier below {FRAGILE_BARRIER_REL * pf.part.size:.3g} mm"


def fragile_member_warnings(
    parts: Sequence[Sequence[tuple[str, PushFunction]]],
) -> list[str]:
    """The fragile states of a mix's parts in words, each member named by its label: the one
    home of the fragile-state wording (``plan``, ``run``, reports, ``part analyze``).

    ``parts`` holds each part's members as ``(label, push function)``: one member named by
    the part's name, or in a plan over landings one per landing, labelled as the plan names
    its members (``l-bracket (up)``, ``box (pose-2)``) because each landing numbers its
    states its own way (a flat part's down side is the mirror image of its up side, with
    the same barriers under other numbers). Up to ``FRAGILE_LINES`` parts with fragile
    states get a line each, naming each member's fragile states::

        l-bracket (up): fragile states 1; l-bracket (down): fragile states 3 (barrier below
        0.06 mm): the part may settle on a neighbour; check the plan with feederkit simulate

    (the barrier given with each member when the members' sizes differ, as a mesh's poses'
    footprints do); more get one line naming each member with its states, so that a large
    mix's warnings stay readable.
    """
    fragile = [
        [(label, pf, ids) for label, pf in members if (ids := fragile_states(pf))]
        for members in parts
    ]
    fragile = [members for members in fragile if members]
    if len(fragile) > FRAGILE_LINES:
        named = "; ".join(
            f"{label} ({'state' if len(ids) == 1 else 'states'} {', '.join(map(str, ids))})"
            for members in fragile
            for label, _, ids in members
        )
        return [
            f"{len(fragile)} parts have fragile states (barrier below "
            f"{FRAGILE_BARRIER_REL:.1%} of the part's size): {named}: a part {FRAGILE_ADVICE}"
        ]
    lines = []
    for members in fragile:
        limits = {_limit(pf) for _, pf, _ in members}
        each = len(limits) > 1
        named = "; ".join(
            f"{label}: fragile states {_ids(ids)}" + (f" ({_limit(pf)})" if each else "")
            for label, pf, ids in members
        )
        shared = "" if each else f" ({limits.pop()})"
        lines.append(f"{named}{shared}: the part {FRAGILE_ADVICE}")
    return lines


TIP_CLEARANCE_REL = 0.02
"""A part whose COM lies closer than this share of its size to its hull's boundary may tip at
the fence instead of turning flat on the belt (:func:`tipping_warnings`): in the physics
check a 40 mm part with its COM 0.39 mm (1 %) from a hull edge leaned 21-47 degrees on the
fence or turned over in 6 of 100 operations; the planar model does not hold for it."""


def tipping_warnings(members: Sequence[tuple[str, PushFunction]]) -> list[str]:
    """One line per member ``(label, push function)`` whose COM lies within
    :data:`TIP_CLEARANCE_REL` of its size of a hull edge, naming the edge; members at the
    same distance (one part's mirrored landings) are named once.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> q = make_part(make_outline("q", [(0, 0), (40, 0), (40, 20), (0, 8)], com=(0.3, 4)))
    >>> tipping_warnings([("q", push_function(q))])  # doctest: +ELLIPSIS
    ['q: its COM lies 0.3 mm from hull edge 3 (0.7% of its size): pushed against the fence ...']
    """
    out, seen = [], set()
    for label, pf in members:
        part = pf.part
        h = np.asarray(part.hull, dtype=float)
        d = np.roll(h, -1, axis=0) - h
        c = np.asarray(part.com, dtype=float) - h
        gaps = np.abs(d[:, 0] * c[:, 1] - d[:, 1] * c[:, 0]) / np.hypot(d[:, 0], d[:, 1])
        edge = int(np.argmin(gaps))
        gap = float(gaps[edge])
        if gap < TIP_CLEARANCE_REL * part.size and f"{gap:.4g}" not in seen:
            seen.add(f"{gap:.4g}")
            out.append(
                f"{label}: its COM lies {gap:.3g} mm from hull edge {edge} "
                f"({gap / part.size:.1%} of its size): pushed against the fence the part may "
                "tip onto that edge or over rather than turn flat on the belt (the planar "
                "model assumes it lies flat); check the plan with feederkit simulate"
            )
    return out


def fragile_warnings(pfs: Sequence[PushFunction]) -> list[str]:
    """The fragile states of a mix's parts in words, each named by its part's name
    (:func:`fragile_member_warnings` with one member per part): a line per part
    (:func:`fragile_warning`) for up to ``FRAGILE_LINES`` such parts, else one line naming
    each part with its states.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> bar = push_function(make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)])))
    >>> fragile_warnings([bar])
    []
    """
    return fragile_member_warnings([[(pf.part.name, pf)] for pf in pfs])


@dataclass(frozen=True)
class PartAnalysis:
    """A part with its push function, symmetry, and (when a sensor is given) its class."""

    part: Part
    push: PushFunction
    symmetry: Symmetry
    sensor: Sensor | None
    polygon_class: PolygonClass | None
    indistinguishable_sets: tuple[tuple[int, ...], ...]
    near_metastable: tuple[NearMetastable, ...]


def analyze_part(part: Part, sensor: Sensor | None = None) -> PartAnalysis:
    """Analyse ``part``: exact push function and symmetry; its Fig. 14 class for ``sensor``."""
    pf = push_function(part)
    sym = symmetry(pf)
    cls = None
    sets: tuple[tuple[int, ...], ...] = ()
    if sensor is not None:
        diam = [s.diameter for s in pf.states]
        sets = tuple(tuple(sorted(g)) for g in sensor.indistinguishable_sets(diam))
        cls = polygon_class(pf, sensor, sets)
    vertex = nearer_vertices(pf) if pf.near_metastable_edges else []
    near = tuple(
        NearMetastable(
            edge=e,
            vertex=vertex[e],
            kind=pf.edge_kinds[e],
            margin_deg=pf.edge_margin_deg[e],
        )
        for e in pf.near_metastable_edges
    )
    return PartAnalysis(part, pf, sym, sensor, cls, sets, near)


def stable_state_to_dict(state: StableState) -> dict[str, object]:
    """A stable state as the plan file writes it (design.md)."""
    return {
        "id": state.id,
        "edge": state.edge,
        "normal_deg": state.normal_deg,
        "resting_range_deg": [state.resting_range_deg[0], state.resting_range_deg[1]],
        "diameter": state.diameter,
        "pose_deg": state.pose_deg,
    }


def analysis_to_dict(a: PartAnalysis) -> dict[str, object]:
    """The JSON object of ``part analyze --json`` for one part."""
    part, pf, sym = a.part, a.push, a.symmetry
    out: dict[str, object] = {
        "name": part.name,
        "units": "mm",
        "com": [part.com[0], part.com[1]],
        "hull": [[x, y] for x, y in part.hull],
        "stable_states": [stable_state_to_dict(s) for s in pf.states],
        "symmetry_period_deg": sym.part_period_deg,
    }
    if part.revision is not None:
        out["revision"] = part.revision
    if a.sensor is not None and a.polygon_class is not None:
        c = a.polygon_class
        out["class"] = c.number
        out["bound"] = c.bound
        out["sensor"] = a.sensor.to_dict()
        out["class_description"] = c.description
        out["m"] = c.m
        out["p"] = c.p
        out["indistinguishable_sets"] = [list(g) for g in a.indistinguishable_sets]
    out["push_period_deg"] = sym.push_period_deg
    out["push_diameter_symmetry"] = {
        "kind": sym.kind,
        "period_deg": sym.period_deg,
        "periods": sym.periods if sym.kind in ("symmetric", "quasi-symmetric") else 1,
    }
    out["divergent_deg"] = list(pf.divergent_deg)
    out["resting_width_deg"] = [s.resting_range_deg[1] - s.resting_range_deg[0] for s in pf.states]
    out["barrier_mm"] = [s.barrier_mm for s in pf.states]
    out["fragile_states"] = list(fragile_states(pf))
    out["edge_normals_deg"] = edge_normals(part.hull)
    out["edge_kinds"] = list(pf.edge_kinds)
    out["edge_margin_deg"] = list(pf.edge_margin_deg)
    out["near_metastable_edges"] = [
        {"edge": n.edge, "vertex": n.vertex, "kind": n.kind, "margin_deg": n.margin_deg}
        for n in a.near_metastable
    ]
    return out
