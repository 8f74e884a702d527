"""The analysis of one part: its push function, symmetry and, for a sensor, its Fig. 14 class.

This is what ``feederkit part analyze`` prints; :func:`analysis_to_dict` is its JSON object
(design.md: ``name``, ``units``, ``com``, ``hull``, ``stable_states``, ``symmetry_period_deg``
and, with a sensor model, ``class`` and ``bound``; plus the extras documented in
docs/analysis.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

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
    ids = fragile_states(pf)
    if not ids:
        return None
    limit = FRAGILE_BARRIER_REL * pf.part.size
    named = ", ".join(str(i) for i in ids[:8]) + (f" (+{len(ids) - 8})" if len(ids) > 8 else "")
    return (
        f"{pf.part.name}: fragile states {named} (barrier below {limit:.3g} mm): the part may "
        "settle on a neighbour; check the plan with feederkit simulate"
    )


FRAGILE_LINES = 3
"""A mix with more parts than this that have fragile states gets one line for all of them."""


def fragile_warnings(pfs: Sequence[PushFunction]) -> list[str]:
    """The fragile states of a mix's parts in words: a line per part (:func:`fragile_warning`)
    for up to ``FRAGILE_LINES`` such parts, else one line naming each part with its states,
    so that a large mix's warnings stay readable.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> bar = push_function(make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)])))
    >>> fragile_warnings([bar])
    []
    """
    fragile = [(pf, fragile_states(pf)) for pf in pfs]
    fragile = [(pf, ids) for pf, ids in fragile if ids]
    if len(fragile) <= FRAGILE_LINES:
        return [line for pf, _ in fragile if (line := fragile_warning(pf)) is not None]
    named = "; ".join(f"{pf.part.name} ({', '.join(map(str, ids))})" for pf, ids in fragile)
    return [
        f"{len(fragile)} parts have fragile states (barrier below "
        f"{FRAGILE_BARRIER_REL:.1%} of the part's size): {named}: a part may settle on a "
        "neighbour; check the plan with feederkit simulate"
    ]


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
