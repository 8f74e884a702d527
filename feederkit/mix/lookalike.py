"""Look-alikes: non-similar convex polygons with the same push function (Theorem 4) or the same
push-diameter function (Theorem 6), each checked numerically before it is returned.

Theorem 4. At a transition vertex V (a local maximum of the radius function) with incident
edges e_i = E_i V and e_j = V E_j and center of mass C: pick Q_i inside both V P_i and V E_i
(P_i the foot of C on e_i's line), let R_i be where the perpendicular to C Q_i at Q_i meets
V C (likewise Q_j, R_j), pick T inside V R_i and V R_j. The polygon with Q_i, T, Q_j in place
of V has two new unstable edges and the same stable and divergent orientations.

Theorem 6. The diameters must stay too. A vertex that is the only diameter-determining vertex
(largest distance to the edge) of no stable edge can be spliced as above (cases 1 and 2(a),
and the vertex case 2(b) selects): every stable diameter keeps a vertex realising it. When
every candidate is the only diameter-determining vertex of some stable edge (a regular
polygon, Fig. 24), every such vertex is pulled in along V C so that every stable diameter
shrinks by one factor k, and the polygon is then scaled by 1/k about C (the push function
does not depend on scale). A vertex that is not a transition vertex is cut by one new
unstable edge (the "similar construction" of section 8.3) or, when it is diameter
determining, spliced with a new non-transition vertex on V C.

The look-alike keeps the source's center of mass C: its outline file states the COM
explicitly (the paper's polygon is its vertices and its COM).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.errors import InputError
from feederkit.mechanics.push import PushFunction, com_feet, push_function
from feederkit.mix.signatures import (
    ANGLE_TOL_DEG,
    LENGTH_TOL_MM,
    matching_shifts,
    phase_shift,
    signature,
)
from feederkit.outline import make_outline
from feederkit.part import Part, make_part

Point = tuple[float, float]

CHECK_ANGLE_TOL_DEG = 1e-7
"""Largest difference (deg) of a stable or divergent orientation a look-alike may show."""

CHECK_REL_DIAMETER_TOL = 1e-9
"""Largest difference of a stable diameter, relative to the part's size."""


@dataclass(frozen=True)
class LookalikeCheck:
    """What was checked on a look-alike against its source (same frame, phase shift 0).

    ``angle_error_deg``: largest difference of a stable or divergent orientation;
    ``diameter_error_mm``: largest difference of a stable diameter; ``similar``: whether the
    two hulls are similar polygons (rotation, scale and reflection allowed).
    """

    keep: str
    same_push: bool
    same_push_diameter: bool
    angle_error_deg: float
    diameter_error_mm: float
    similar: bool
    source_vertices: int
    vertices: int

    @property
    def ok(self) -> bool:
        """Whether the look-alike keeps what it must and is not similar to its source."""
        kept = self.same_push_diameter if self.keep == "push-diameter" else self.same_push
        return kept and not self.similar


@dataclass(frozen=True)
class Lookalike:
    """A look-alike part, the construction that built it, and its check."""

    part: Part
    construction: str
    check: LookalikeCheck


def _v(p: Sequence[float]) -> np.ndarray:
    return np.asarray(p, dtype=float)


def transition_vertices(pf: PushFunction) -> list[int]:
    """Hull vertices at which the radius function has a local maximum (transition vertices)."""
    hull, n = pf.part.hull, len(pf.part.hull)
    feet = com_feet(hull, pf.part.com)
    return [(i + 1) % n for i in range(n) if feet[i] < 1.0 and feet[(i + 1) % n] > 0.0]


def _edge_limit(v: np.ndarray, e: np.ndarray, c: np.ndarray) -> float:
    """How far from V along V E a new vertex may go: inside V E and inside V P (P the foot of C)."""
    d = e - v
    length = float(np.hypot(*d))
    s_p = float(np.dot(c - v, d)) / length
    return min(length, s_p) if s_p > 0.0 else length


def _t_perp(v: np.ndarray, q: np.ndarray, c: np.ndarray) -> float:
    """Parameter t of R on V + t (C - V) where the perpendicular to C Q at Q meets V C."""
    den = float(np.dot(c - v, q - c))
    if den == 0.0:
        return 1.0
    return float(np.dot(q - v, q - c)) / den


def _t_chord(v: np.ndarray, qi: np.ndarray, qj: np.ndarray, c: np.ndarray) -> float:
    """Parameter t where V + t (C - V) crosses the chord Q_i Q_j."""
    d = c - v
    w = qj - qi
    den = d[0] * w[1] - d[1] * w[0]
    if den == 0.0:
        return 1.0
    r = qi - v
    return float((r[0] * w[1] - r[1] * w[0]) / den)


@dataclass(frozen=True)
class _Splice:
    vertex: int
    fi: float
    fj: float
    ft: float | None  # None: cut the corner by one edge


def _corner(
    hull: Sequence[Point], com: Point, sp: _Splice
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """Vertex V, C, Q_i and Q_j of a splice, and the largest T parameter Theorem 4 allows."""
    n = len(hull)
    v, ei, ej, c = (
        _v(hull[sp.vertex]),
        _v(hull[sp.vertex - 1]),
        _v(hull[(sp.vertex + 1) % n]),
        _v(com),
    )
    ui = (ei - v) / np.hypot(*(ei - v))
    uj = (ej - v) / np.hypot(*(ej - v))
    qi = v + sp.fi * _edge_limit(v, ei, c) * ui
    qj = v + sp.fj * _edge_limit(v, ej, c) * uj
    t_max = min(_t_perp(v, qi, c), _t_perp(v, qj, c), _t_chord(v, qi, qj, c), 1.0)
    return v, c, qi, qj, t_max


def _splice_points(
    hull: Sequence[Point], com: Point, sp: _Splice, t_abs: float | None = None
) -> list[np.ndarray]:
    """The points replacing hull vertex ``sp.vertex``: Q_i, (T,) Q_j."""
    v, c, qi, qj, t_max = _corner(hull, com, sp)
    if sp.ft is None and t_abs is None:
        return [qi, qj]
    if t_abs is None:
        t_abs = sp.ft * t_max
    return [qi, v + t_abs * (c - v), qj]


def _t_limit(hull: Sequence[Point], com: Point, sp: _Splice) -> float:
    """The largest T parameter Theorem 4 allows at this vertex for these Q fractions."""
    return _corner(hull, com, sp)[4]


def _apply(
    hull: Sequence[Point],
    com: Point,
    splices: Sequence[_Splice],
    t_abs: dict[int, float] | None = None,
) -> list[Point]:
    t_abs = t_abs or {}
    by_vertex = {sp.vertex: sp for sp in splices}
    out: list[Point] = []
    for k, p in enumerate(hull):
        if k in by_vertex:
            pts = _splice_points(hull, com, by_vertex[k], t_abs.get(k))
            out.extend((float(q[0]), float(q[1])) for q in pts)
        else:
            out.append((float(p[0]), float(p[1])))
    return out


def _make(name: str, pts: Sequence[Point], com: Point, scale: float = 1.0) -> Part | None:
    com = (com[0] + 0.0, com[1] + 0.0)  # no -0.0: the file and the screen said "(-0, -0)"
    if scale != 1.0:
        pts = [(com[0] + scale * (x - com[0]), com[1] + scale * (y - com[1])) for x, y in pts]
    try:
        part = make_part(make_outline(name, pts, com=com))
    except InputError:
        return None
    if len(part.hull) != len(pts):
        return None  # a new vertex was too close to collinear and got merged away
    return part


def similar(hull_a: Sequence[Point], hull_b: Sequence[Point], rel_tol: float = 1e-6) -> bool:
    """Whether two convex polygons are similar (rotation, translation, scale, reflection)."""
    if len(hull_a) != len(hull_b):
        return False

    def shape(h: Sequence[Point]) -> list[tuple[float, float]]:
        n = len(h)
        lengths = [math.dist(h[i], h[(i + 1) % n]) for i in range(n)]
        per = sum(lengths)
        out = []
        for i in range(n):
            a, b, c = _v(h[i - 1]), _v(h[i]), _v(h[(i + 1) % n])
            u, w = b - a, c - b
            turn = math.atan2(u[0] * w[1] - u[1] * w[0], float(np.dot(u, w)))
            out.append((lengths[i] / per, turn))
        return out

    sa = shape(hull_a)
    sb = shape(hull_b)
    mirrored = [(x, y) for x, y in (shape([(p[0], -p[1]) for p in reversed(hull_b)]))]
    n = len(sa)
    for cand in (sb, mirrored):
        for s in range(n):
            if all(
                abs(sa[k][0] - cand[(k + s) % n][0]) <= rel_tol
                and abs(sa[k][1] - cand[(k + s) % n][1]) <= rel_tol
                for k in range(n)
            ):
                return True
    return False


def check_lookalike(source: PushFunction, new: PushFunction, keep: str) -> LookalikeCheck:
    """Compare a look-alike with its source numerically, in the same frame (phase shift 0)."""
    size = source.part.size
    same_n = source.n == new.n and len(source.divergent_deg) == len(new.divergent_deg)
    angle_err = math.inf
    diam_err = math.inf
    if same_n:
        a = sorted(s.normal_deg for s in source.states)
        b = sorted(s.normal_deg for s in new.states)
        errs = [_adiff(x, y) for x, y in zip(a, b, strict=True)]
        errs += [_adiff(x, y) for x, y in zip(source.divergent_deg, new.divergent_deg, strict=True)]
        angle_err = max(errs)
        da = [s.diameter for s in sorted(source.states, key=lambda s: s.normal_deg)]
        db = [s.diameter for s in sorted(new.states, key=lambda s: s.normal_deg)]
        diam_err = max(abs(x - y) for x, y in zip(da, db, strict=True))
    same_push = angle_err <= CHECK_ANGLE_TOL_DEG
    same_pdf = same_push and diam_err <= CHECK_REL_DIAMETER_TOL * size
    return LookalikeCheck(
        keep=keep,
        same_push=same_push,
        same_push_diameter=same_pdf,
        angle_error_deg=angle_err,
        diameter_error_mm=diam_err,
        similar=similar(source.part.hull, new.part.hull),
        source_vertices=len(source.part.hull),
        vertices=len(new.part.hull),
    )


def _adiff(x: float, y: float) -> float:
    d = abs(x - y) % 360.0
    return min(d, 360.0 - d)


def diameter_determining(pf: PushFunction) -> dict[int, list[int]]:
    """Each stable state's diameter-determining hull vertices (largest distance to its edge)."""
    hull = np.asarray(pf.part.hull, dtype=float)
    eps = 1e-9 * pf.part.size
    out = {}
    for s in pf.states:
        nrm = np.array([math.cos(math.radians(s.normal_deg)), math.sin(math.radians(s.normal_deg))])
        dist = hull[s.edge] @ nrm - hull @ nrm
        far = float(dist.max())
        out[s.id] = [int(k) for k in np.flatnonzero(dist >= far - eps)]
    return out


def _rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    return rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)


def _name(part: Part, keep: str) -> str:
    return f"{part.name}-lookalike-{keep}"


def _finish(
    source: PushFunction, part: Part | None, keep: str, construction: str
) -> Lookalike | None:
    if part is None:
        return None
    try:
        new = push_function(part)
    except AssertionError:
        return None
    check = check_lookalike(source, new, keep)
    return Lookalike(part, construction, check) if check.ok else None


def lookalike_same_push_detail(
    part: Part,
    rng: np.random.Generator | int | None = None,
    *,
    vertices: Sequence[int] | None = None,
    fractions: Sequence[tuple[float, float, float]] | None = None,
    name: str | None = None,
) -> Lookalike:
    """Theorem 4: splice a new transition vertex in place of transition vertex(es) of ``part``.

    ``vertices`` (hull indices; default one chosen at random) must be transition vertices;
    ``fractions`` gives per vertex (Q_i, Q_j, T) as fractions of the allowed segments
    (default random in [0.25, 0.75]). Raises InputError when the construction does not apply.
    """
    gen = _rng(rng)
    pf = push_function(part)
    trans = transition_vertices(pf)
    if vertices is not None:
        bad = [v for v in vertices if v not in trans]
        if bad:
            raise InputError(f"{part.name}: hull vertex {bad[0]} is not a transition vertex")
    label = name or _name(part, "push")
    for _attempt in range(20):
        chosen = list(vertices) if vertices is not None else [int(gen.choice(trans))]
        if fractions is not None and _attempt == 0:
            fr = list(fractions)
        else:
            fr = [tuple(float(x) for x in gen.uniform(0.25, 0.75, 3)) for _ in chosen]
        splices = [_Splice(v, f[0], f[1], f[2]) for v, f in zip(chosen, fr, strict=True)]
        pts = _apply(part.hull, part.com, splices)
        words = ", ".join(str(v) for v in chosen)
        result = _finish(
            pf, _make(label, pts, part.com), "push", f"Theorem 4 at transition vertex {words}"
        )
        if result is not None:
            return result
    raise InputError(f"{part.name}: Theorem 4's construction failed its check at every attempt")


def lookalike_same_push_diameter_detail(
    part: Part, rng: np.random.Generator | int | None = None, *, name: str | None = None
) -> Lookalike:
    """Theorem 6: a non-similar convex polygon with the same push-diameter function, checked.

    Raises InputError naming why when the construction does not apply to ``part``.
    """
    gen = _rng(rng)
    pf = push_function(part)
    label = name or _name(part, "push-diameter")
    trans = set(transition_vertices(pf))
    dd = diameter_determining(pf)
    unique_for: dict[int, list[int]] = {}
    for sid, verts in dd.items():
        if len(verts) == 1:
            unique_for.setdefault(verts[0], []).append(sid)
    free = [v for v in range(len(part.hull)) if v not in unique_for]
    # Cases 1, 2(a), 2(b): a vertex that no stable diameter depends on alone.
    for v in sorted(free, key=lambda v: (v not in trans, v)):
        for _attempt in range(8):
            f = gen.uniform(0.25, 0.75, 3)
            if v in trans:
                sp = _Splice(v, float(f[0]), float(f[1]), float(f[2]))
                how = "Theorem 4 at transition vertex"
            else:
                scale = 0.5**_attempt
                sp = _Splice(v, float(f[0]) * scale, float(f[1]) * scale, None)
                how = "a new unstable edge at non-transition vertex"
            shared = [sid for sid, verts in dd.items() if v in verts]
            case = "case 1" if not shared else "case 2(a)/(b)"
            words = f"Theorem 6 {case}: {how} {v}"
            if shared:
                words += " (its stable diameters keep another determining vertex)"
            result = _finish(
                pf,
                _make(label, _apply(part.hull, part.com, [sp]), part.com),
                "push-diameter",
                words,
            )
            if result is not None:
                return result
    # Case 2: every candidate is the only diameter-determining vertex of some stable edge.
    result = _shrink_and_expand(part, pf, unique_for, trans, gen, label)
    if result is not None:
        return result
    raise InputError(
        f"{part.name}: Theorem 6's construction does not apply here (every vertex alone determines "
        "stable diameters that cannot all shrink by one factor)"
    )


def _shrink_and_expand(
    part: Part,
    pf: PushFunction,
    unique_for: dict[int, list[int]],
    trans: set[int],
    gen: np.random.Generator,
    label: str,
) -> Lookalike | None:
    """Case 2: pull determining vertices in along V C, every stable diameter by one factor k;
    then scale by 1/k about C."""
    c = _v(part.com)
    hull = part.hull
    states = {s.id: s for s in pf.states}
    rate: dict[int, float] = {}
    for v, sids in unique_for.items():
        ratios = []
        for sid in sids:
            s = states[sid]
            nrm = np.array(
                [math.cos(math.radians(s.normal_deg)), math.sin(math.radians(s.normal_deg))]
            )
            h = float(_v(hull[s.edge]) @ nrm - c @ nrm)  # distance from C to the edge line
            ratios.append((s.diameter - h) / s.diameter)  # D(t)/D = 1 - t * ratio
        if max(ratios) - min(ratios) > 1e-9:
            return None
        rate[v] = ratios[0]
    for _attempt in range(12):
        f = gen.uniform(0.55, 0.9, 2)
        splices = {v: _Splice(v, float(f[0]), float(f[1]), 0.5) for v in unique_for}
        limits = {v: _t_limit(hull, part.com, sp) for v, sp in splices.items()}
        shrink = 0.5**_attempt * 0.5 * min(limits[v] * rate[v] for v in unique_for)  # 1 - k
        t_abs = {v: shrink / rate[v] for v in unique_for}
        pts = _apply(hull, part.com, list(splices.values()), t_abs)
        k = 1.0 - shrink
        words = (
            "Theorem 6 case 2: every diameter-determining vertex "
            f"({', '.join(map(str, sorted(unique_for)))}) pulled in so each stable diameter "
            f"shrinks by {100 * shrink:.3g}%, then scaled by 1/{k:.6g}"
        )
        result = _finish(pf, _make(label, pts, part.com, 1.0 / k), "push-diameter", words)
        if result is not None:
            return result
    return None


def build_lookalike(
    part: Part, keep: str, rng: np.random.Generator | int | None = None
) -> Lookalike:
    """The look-alike keeping ``keep`` ("push" or "push-diameter"), with its check."""
    if keep == "push":
        return lookalike_same_push_detail(part, rng)
    if keep == "push-diameter":
        return lookalike_same_push_diameter_detail(part, rng)
    raise InputError(f"a look-alike keeps the push or the push-diameter function, got {keep!r}")


__all__ = [
    "Lookalike",
    "LookalikeCheck",
    "build_lookalike",
    "check_lookalike",
    "diameter_determining",
    "lookalike_same_push_detail",
    "lookalike_same_push_diameter_detail",
    "matching_shifts",
    "phase_shift",
    "signature",
    "similar",
    "transition_vertices",
    "ANGLE_TOL_DEG",
    "LENGTH_TOL_MM",
]
