"""Exact symmetry of the push and push-diameter functions (definitions 3, 6, 7, 8).

The shifts ``T`` under which a finite set of ``q`` angles on the circle maps onto itself form
a group: the multiples of ``360 / b`` for some ``b`` dividing ``q``, and the shift by ``360 k / q``
sends the ``i``-th angle (in circular order) to the ``(i + k)``-th. So the smallest period is
found by testing the divisors ``k`` of ``q`` in increasing order, each in O(q): the number of
periods ``b = q / k``. Periods of two functions combine through the gcd of their numbers of
periods. Values of the push-diameter function are compared through ``labels`` (one per stable
state): exact diameters for the part's own symmetry, indistinguishable sets for a sensor.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

from feederkit.angles import ANGLE_EPS
from feederkit.mechanics.push import PushFunction

DIAMETER_REL_EPS = 1e-9
"""Diameters equal within this fraction of the part's size are the same diameter."""


def _divisors(q: int) -> list[int]:
    small = [k for k in range(1, math.isqrt(q) + 1) if q % k == 0]
    return sorted(set(small) | {q // k for k in small})


def _invariant(angles: np.ndarray, k: int, ids: np.ndarray | None, eps: float) -> bool:
    """Whether the shift by ``360 k / q`` sends angle ``i`` onto angle ``i + k``, ids kept."""
    q = len(angles)
    t = 360.0 * k / q
    gap = np.mod(np.roll(angles, -k) - angles - t + 180.0, 360.0) - 180.0
    if not bool(np.all(np.abs(gap) < eps)):
        return False
    return ids is None or bool(np.array_equal(np.roll(ids, -k), ids))


def periods_of(
    angles: Sequence[float], ids: Sequence[int] | None = None, eps: float = ANGLE_EPS
) -> int:
    """The number of periods ``b`` of a set of angles (with ids that a shift must keep).

    Its smallest period is ``360 / b``; ``b = 1`` when only the full turn maps it onto itself.
    An empty set has no structure to keep: it returns 0 (every shift is a period).
    """
    q = len(angles)
    if q == 0:
        return 0
    order = np.argsort(np.mod(np.asarray(angles, dtype=float), 360.0), kind="stable")
    a = np.mod(np.asarray(angles, dtype=float), 360.0)[order]
    lab = None if ids is None else np.asarray(ids)[order]
    for k in _divisors(q):
        if k < q and _invariant(a, k, lab, eps):
            return q // k
    return 1


def _period_deg(b: int) -> float:
    return 360.0 / b if b > 0 else 0.0


def push_periods(pf: PushFunction) -> int:
    """Number of periods of the push function: stable and divergent orientations shift alike."""
    s = np.array([x.normal_deg for x in pf.states])
    d = np.array(pf.divergent_deg)
    both = np.concatenate([s, d])
    kind = np.concatenate([np.zeros(len(s), dtype=int), np.ones(len(d), dtype=int)])
    return periods_of(both.tolist(), kind.tolist())


def push_period(pf: PushFunction) -> float:
    """Smallest T in (0, 360] with p(phi + T) = p(phi) + T (definition 3); 360 when asymmetric."""
    return _period_deg(push_periods(pf))


def exact_labels(pf: PushFunction) -> list[int]:
    """Label each state by its diameter; diameters within DIAMETER_REL_EPS of the size are alike."""
    eps = DIAMETER_REL_EPS * pf.part.size
    diam = [s.diameter for s in pf.states]
    order = sorted(range(len(diam)), key=lambda i: diam[i])
    labels = [0] * len(diam)
    label, last = -1, -math.inf
    for i in order:
        if diam[i] - last > eps:
            label += 1
        labels[i] = label
        last = diam[i]
    return labels


def _steps(pf: PushFunction, labels: Sequence[Hashable]) -> tuple[list[float], list[int]]:
    """Breakpoints of the push-diameter step function and an id of the label starting at each."""
    ids: dict[Hashable, int] = {}
    angles, out = [], []
    for k, start in enumerate(pf.divergent_deg):
        here = labels[pf.range_state[k]]
        if here != labels[pf.range_state[k - 1]]:
            angles.append(start)
            out.append(ids.setdefault(here, len(ids)))
    return angles, out


def push_diameter_periods(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> int:
    """Number of periods of the push-diameter function (definition 6); 0 when it is constant."""
    labels = exact_labels(pf) if labels is None else labels
    angles, ids = _steps(pf, labels)
    return periods_of(angles, ids)


def push_diameter_period(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> float:
    """Smallest T in (0, 360] with d(phi + T) = d(phi) (definition 6); 0 when d is constant."""
    return _period_deg(push_diameter_periods(pf, labels))


def stable_periods(pf: PushFunction) -> int:
    """Number of periods of the set S of stable orientations (definitions 7 and 8)."""
    return periods_of([s.normal_deg for s in pf.states])


@dataclass(frozen=True)
class Symmetry:
    """The symmetry of a part's push and push-diameter functions.

    ``kind`` of the push-diameter function: ``"constant"`` (one value), ``"aperiodic"``,
    ``"quasi-symmetric"`` (definition 7: periodic, but no period maps the stable orientations
    onto themselves) or ``"symmetric"`` (definition 8). ``period_deg`` is the push-diameter
    function's smallest symmetric period when symmetric, its smallest period when
    quasi-symmetric, 360 when aperiodic and 0 when constant. ``push_period_deg`` is the push
    function's (definition 3). ``part_period_deg`` is the smallest shift under which the part
    behaves identically (push function and exact diameters alike): orientation is possible
    only up to it.
    """

    kind: str
    period_deg: float
    push_period_deg: float
    part_period_deg: float

    @property
    def periods(self) -> int:
        """Number of periods p of the push-diameter function in 360 degrees."""
        return max(1, round(360.0 / self.period_deg)) if self.period_deg > 0 else 1


NEAR_SYMMETRIC_REL = 0.01
"""Poses whose outlines differ by at most this share of the part's size look alike to the
next station (:func:`pose_difference`): the near-symmetric poses a plan under uncertainty may
list together (docs/planning.md, "Near-symmetric states under uncertainty")."""


def _pose_frame(pf: PushFunction, state: int) -> tuple[np.ndarray, np.ndarray]:
    """The rotation (2 x 2) and the shift that place the part resting in stable state
    ``state``: rotated by its pose, its hull on the fence line (y = 0) and centred along it;
    a point ``p`` goes to ``rot @ p - shift``."""
    t = math.radians(pf.states[state].pose_deg)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    pts = np.asarray(pf.part.hull, dtype=float) @ rot.T
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return rot, np.array([(lo[0] + hi[0]) / 2.0, lo[1]])


def _placed(pf: PushFunction, state: int) -> np.ndarray:
    """The hull's vertices with the part resting in stable state ``state``
    (:func:`_pose_frame`)."""
    rot, shift = _pose_frame(pf, state)
    return np.asarray(pf.part.hull, dtype=float) @ rot.T - shift


def _com_gaps(pf: PushFunction, pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """Per pair of stable states, how far apart (mm) the COM lies in the two poses placed as
    :func:`_placed` places the hull: a hull the poses share hides nothing of the part's mass,
    so a COM off the hull's symmetry (a solid's leg standing up at one end of the side it
    lies on, a hidden insert) sets the poses apart as a hole does."""
    com = np.asarray(pf.part.com, dtype=float)
    used = sorted({i for p in pairs for i in p})
    placed = {}
    for i in used:
        rot, shift = _pose_frame(pf, i)
        placed[i] = rot @ com - shift
    return np.array([float(np.hypot(*(placed[a] - placed[b]))) for a, b in pairs])


def _normals(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A convex polygon's outward edge normals (counter-clockwise vertices ``p``), sorted in
    [0, 2 pi), and the support vertex just past each (edge ``i``'s normal: vertex ``i + 1``)."""
    e = np.roll(p, -1, axis=0) - p
    ang = np.mod(np.arctan2(-e[:, 0], e[:, 1]), 2.0 * math.pi)
    order = np.argsort(ang, kind="stable")
    return ang[order], (order + 1) % len(p)


def _support_gaps(polys: Sequence[np.ndarray], pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """Per pair ``(a, b)`` of convex polygons with the same number of vertices (the poses of
    one hull, counter-clockwise), the largest difference of their support functions,
    exactly: the Hausdorff distance of the two regions (for convex sets it is the sup norm of
    the support functions' difference).

    Between consecutive edge normals of either polygon the difference is ``<w, u>``, ``w``
    the difference of the two support vertices, so its largest magnitude on that arc is at
    an end, or ``|w|`` when ``w`` (or ``-w``) points into the arc. All pairs at once: each
    row's angles are offset by ``4 pi`` per row, so one sorted array serves every search.
    """
    tau = 2.0 * math.pi
    if not pairs:
        return np.zeros(0)
    pts = np.asarray(polys, dtype=float)  # (poses, V, 2)
    found = [_normals(p) for p in pts]
    ns = np.array([f[0] for f in found])
    vs = np.array([f[1] for f in found])
    a = np.array([i for i, _j in pairs])
    b = np.array([j for _i, j in pairs])
    rows, v = len(pairs), pts.shape[1]
    cuts = np.sort(np.concatenate([ns[a], ns[b]], axis=1), axis=1)  # (rows, 2V)
    width = np.diff(np.concatenate([cuts, cuts[:, :1] + tau], axis=1), axis=1)
    mid = cuts + width / 2.0
    shift = 2.0 * tau * np.arange(rows)[:, None]

    def support(side: np.ndarray) -> np.ndarray:
        flat = (ns[side] + shift).ravel()
        k = np.searchsorted(flat, (mid + shift).ravel(), side="right") - 1
        k = k.reshape(rows, -1) - v * np.arange(rows)[:, None]
        k = np.where(k < 0, v - 1, k)  # before a row's first normal: past its last
        vert = np.take_along_axis(vs[side], k, axis=1)
        return pts[side[:, None], vert]  # (rows, 2V, 2)

    w = support(a) - support(b)
    ends = np.stack([np.cos(cuts), np.sin(cuts)], axis=2)
    nxt = np.roll(ends, -1, axis=1)
    best = np.maximum(np.abs(np.sum(w * ends, axis=2)), np.abs(np.sum(w * nxt, axis=2)))
    norm = np.hypot(w[..., 0], w[..., 1])
    alpha = np.arctan2(w[..., 1], w[..., 0])
    inside = (np.mod(alpha - cuts, tau) <= width) | (np.mod(alpha + math.pi - cuts, tau) <= width)
    return np.max(np.where(inside, norm, best), axis=1)


EXACT_CHUNK = 256
"""Pairs per batch of :func:`_support_gaps` (bounds its arrays for many-vertex hulls)."""


SUPPORT_GRID = 128
""":func:`look_alike` first compares the poses' support functions at this many directions
(a lower bound on :func:`pose_difference`), and computes the exact difference only for the
pairs that bound leaves within reach."""


def _grid_support(pts: np.ndarray) -> np.ndarray:
    """The support function of the points at :data:`SUPPORT_GRID` directions (one at +y)."""
    phi = math.pi / 2.0 + np.arange(SUPPORT_GRID) * (2.0 * math.pi / SUPPORT_GRID)
    u = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    return np.max(pts @ u.T, axis=0)


OUTLINE_SPACING_REL = NEAR_SYMMETRIC_REL / 16.0
""":func:`_outline_gaps` samples the outline's boundary this finely (share of the part's
size), and bounds the true distance by the samples' own plus half the spacing."""


def _has_more_than_hull(pf: PushFunction) -> bool:
    """Whether the outline shows more than its contact hull: holes, or a concave boundary
    (the next station sees them; the fence does not)."""
    outline = pf.part.outline
    if outline.holes:
        return True
    # Each vertex's distance to its nearest hull edge, through a tree of the edges: a
    # dense outline's vertices against the whole ring were quadratic (20,000 points: 6 s).
    hull = np.asarray(pf.part.hull, dtype=float)
    edges = shapely.linestrings(np.stack([hull, np.roll(hull, -1, axis=0)], axis=1))
    points = shapely.points(np.asarray(outline.vertices, dtype=float))
    _pairs, gaps = shapely.STRtree(edges).query_nearest(points, return_distance=True)
    return bool(np.max(gaps) > 2.0 * OUTLINE_SPACING_REL * pf.part.size)


def _placed_samples(pf: PushFunction, state: int, spacing: float) -> np.ndarray:
    """Points on the outline's boundary (outer ring and holes) placed as :func:`_placed`
    places the hull, every ``spacing`` mm or closer."""
    rot, shift = _pose_frame(pf, state)
    outline = pf.part.outline
    rings = [np.asarray(r, dtype=float) for r in (outline.vertices, *outline.holes)]
    lines = [np.vstack([r, r[:1]]) @ rot.T - shift for r in rings]
    return shapely.get_coordinates(shapely.segmentize(shapely.MultiLineString(lines), spacing))


COARSE_SPACINGS = (8.0, 3.0)
""":func:`_outline_gaps` deciding against a bound first samples the boundary this many
times :data:`OUTLINE_SPACING_REL` apart (then at that spacing): most pairs are decided
with an eighth of the points or fewer."""


def _outline_gaps(
    pf: PushFunction, pairs: Sequence[tuple[int, int]], tol: float | None = None
) -> np.ndarray:
    """Per pair of stable states, an upper bound (mm) on the Hausdorff distance of the
    outline's boundary in the two poses: the Hausdorff distance ``H`` of the two sample sets
    (:func:`_placed_samples`, nearest neighbours by k-d tree) plus half their spacing ``s``
    (every boundary point lies that close to a sample; the true distance also lies above
    ``H - s / 2``). With ``tol``, a pair whose samples lie farther than ``tol + s`` apart gets
    an infinite bound (it is not close; the k-d tree stops looking there), and a pair is
    decided on coarser samples first
    (:data:`COARSE_SPACINGS`) when their bounds lie both on one side of it: a bound at
    most ``tol``, or one above it with the true distance above it too. Holes and notches a
    hull does not show set poses apart for the next station (a plate's off-centre hole 24 mm
    along the fence in its two flat poses)."""
    fine = OUTLINE_SPACING_REL * pf.part.size
    levels = [fine] if tol is None else [k * fine for k in COARSE_SPACINGS] + [fine]
    out = np.zeros(len(pairs))
    todo = [k for k, (a, b) in enumerate(pairs) if a != b]
    for level, spacing in enumerate(levels):
        used = {i for k in todo for i in pairs[k]}
        samples = {i: _placed_samples(pf, i, spacing) for i in used}
        trees = {i: cKDTree(samples[i]) for i in used}
        last = level == len(levels) - 1
        undecided = []
        # Deciding against tol, a sample farther than tol + spacing / 2 from the other set
        # decides alone (the true distance then exceeds tol): the search stops there.
        cap = np.inf if tol is None else tol + spacing
        for k in todo:
            a, b = pairs[k]
            h = max(
                trees[b].query(samples[a], distance_upper_bound=cap)[0].max(),
                trees[a].query(samples[b], distance_upper_bound=cap)[0].max(),
            )
            out[k] = float(h) + spacing / 2.0
            if not last and tol is not None and out[k] > tol >= float(h) - spacing / 2.0:
                undecided.append(k)  # the bounds straddle tol: finer samples decide
        todo = undecided
        if not todo:
            break
    return out


def pose_differences(pf: PushFunction, pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """:func:`pose_difference` of every pair of stable states in ``pairs`` (mm), at once."""
    if not pairs:
        return np.zeros(0)
    used = sorted({i for p in pairs for i in p})
    index = {i: k for k, i in enumerate(used)}
    polys = [_placed(pf, i) for i in used]
    local = [(index[i], index[j]) for i, j in pairs]
    parts = [
        _support_gaps(polys, local[k : k + EXACT_CHUNK]) for k in range(0, len(local), EXACT_CHUNK)
    ]
    gaps = np.maximum(np.concatenate(parts), _com_gaps(pf, pairs))
    if _has_more_than_hull(pf):
        gaps = np.maximum(gaps, _outline_gaps(pf, pairs))
    return gaps


def pose_difference(pf: PushFunction, a: int, b: int) -> float:
    """How far apart (mm) the part looks resting in stable states ``a`` and ``b``: the
    Hausdorff distance of its hull in the two poses on the fence, each resting on the fence
    line and centred along it (the position along the fence is not observed), exact (the
    largest difference of the two support functions, :func:`_support_gaps`); for an outline
    with holes or notches, at least the bound :func:`_outline_gaps` on its boundary's; at
    least the distance the COM moves between the poses (:func:`_com_gaps`). 0 for states
    that a symmetry of the part maps onto each other (definitions 3, 6); small for the
    near-symmetric states a plan under uncertainty may list together. It is at least the
    difference of the two diameters (the poses' heights above the fence).

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.part import make_part
    >>> from feederkit.outline import make_outline
    >>> rect = push_function(make_part(make_outline("r", [[0, 0], [4, 0], [4, 2], [0, 2]])))
    >>> round(pose_difference(rect, 0, 2), 9), round(pose_difference(rect, 0, 1), 3)
    (0.0, 2.0)
    """
    return float(pose_differences(pf, [(a, b)])[0])


def poses_differences(
    pf: PushFunction, sets: Sequence[tuple[Sequence[int], Sequence[int]]]
) -> np.ndarray:
    """:func:`poses_difference` of every pair ``(g, h)`` of sets of stable states in ``sets``
    (mm), with one :func:`pose_differences` over all the poses they pair: a dense outline's
    boundary is sampled and compared once per pose, not once per pair of sets."""
    pairs = sorted({(i, j) for g, h in sets for i in g for j in h})
    index = {p: k for k, p in enumerate(pairs)}
    d = pose_differences(pf, pairs)
    out = np.zeros(len(sets))
    for k, (g, h) in enumerate(sets):
        m = np.array([[d[index[(i, j)]] for j in h] for i in g]).reshape(len(g), len(h))
        out[k] = max(m.min(axis=1).max(), m.min(axis=0).max())
    return out


def poses_difference(pf: PushFunction, g: Sequence[int], h: Sequence[int]) -> float:
    """How far apart (mm) two sets of poses look (stable states ``g`` and ``h``, e.g. the
    ideal members of two physical resting states): the Hausdorff distance of the sets under
    :func:`pose_difference`, so each pose of either set is this close to one of the other.
    :func:`look_alike` compares it with ``NEAR_SYMMETRIC_REL`` of the part's size.
    """
    return float(poses_differences(pf, [(g, h)])[0])


def look_alike(
    pf: PushFunction, groups: Sequence[Sequence[int]], rel: float = NEAR_SYMMETRIC_REL
) -> tuple[tuple[int, ...], ...]:
    """Per group of stable states (a physical resting state's ideal members, or one state),
    the other groups whose poses look alike: every pose of either group lies within ``rel``
    of the part's size (:func:`pose_difference`) of some pose of the other
    (:func:`poses_difference` at most that). Symmetric; a group is not listed with itself.

    Pairs whose support functions differ by more than the bound at one of
    :data:`SUPPORT_GRID` directions (the height above the fence, the diameter, among them)
    are never compared exactly: that difference is a lower bound on
    :func:`pose_difference`.
    """
    tol = rel * pf.part.size
    ideal = sorted({i for g in groups for i in g})
    row = {i: k for k, i in enumerate(ideal)}
    placed = [_placed(pf, i) for i in ideal]
    grid = np.array([_grid_support(p) for p in placed])
    bound = np.max(np.abs(grid[:, None, :] - grid[None, :, :]), axis=2)  # lower bounds

    def reach(g: Sequence[int], h: Sequence[int]) -> bool:
        """Every member of ``g`` has a pose of ``h`` within the lower bound's reach."""
        return all(any(bound[row[x], row[y]] <= tol for y in h) for x in g)

    pairs = [
        (a, b)
        for a in range(len(groups))
        for b in range(a + 1, len(groups))
        if reach(groups[a], groups[b]) and reach(groups[b], groups[a])
    ]
    todo = sorted(
        {
            (min(row[x], row[y]), max(row[x], row[y]))
            for a, b in pairs
            for x in groups[a]
            for y in groups[b]
            if x != y and bound[row[x], row[y]] <= tol
        }
    )
    gaps = np.concatenate(
        [np.zeros(0)]
        + [
            _support_gaps(placed, todo[k : k + EXACT_CHUNK])
            for k in range(0, len(todo), EXACT_CHUNK)
        ]
    )
    close = {p for p, d in zip(todo, gaps, strict=True) if d <= tol}
    if close:
        # The COM the hull does not show (:func:`_com_gaps`).
        hull_close = sorted(close)
        com = _com_gaps(pf, [(ideal[i], ideal[j]) for i, j in hull_close])
        close = {p for p, d in zip(hull_close, com, strict=True) if d <= tol}
    if close and _has_more_than_hull(pf):
        # Holes and notches the hulls do not show: the outline's own distance decides.
        hull_close = sorted(close)
        outline = _outline_gaps(pf, [(ideal[i], ideal[j]) for i, j in hull_close], tol)
        close = {p for p, d in zip(hull_close, outline, strict=True) if d <= tol}

    def near(x: int, y: int) -> bool:
        i, j = row[x], row[y]
        return i == j or (min(i, j), max(i, j)) in close

    def covers(g: Sequence[int], h: Sequence[int]) -> bool:
        return all(any(near(x, y) for y in h) for x in g)

    out: list[list[int]] = [[] for _ in groups]
    for a, b in pairs:
        if covers(groups[a], groups[b]) and covers(groups[b], groups[a]):
            out[a].append(b)
            out[b].append(a)
    return tuple(tuple(x) for x in out)


def unlike_pairs(
    pf: PushFunction, groups: Sequence[Sequence[int]], rel: float = NEAR_SYMMETRIC_REL
) -> list[tuple[int, int]]:
    """The pairs ``(a, b)``, ``a < b``, of ``groups`` (as in :func:`look_alike`) whose poses do
    not look alike."""
    alike = look_alike(pf, groups, rel)
    return [
        (a, b) for a in range(len(groups)) for b in range(a + 1, len(groups)) if b not in alike[a]
    ]


def symmetry(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> Symmetry:
    """Classify the push-diameter function by definitions 6-8 for the given state labels."""
    labels = exact_labels(pf) if labels is None else list(labels)
    a = push_periods(pf)
    part_b = push_diameter_periods(pf)
    part_t = _period_deg(a if part_b == 0 else math.gcd(a, part_b))
    b = push_diameter_periods(pf, labels)
    tp = _period_deg(a)
    if b == 0:
        return Symmetry("constant", 0.0, tp, part_t)
    if b == 1:
        return Symmetry("aperiodic", 360.0, tp, part_t)
    g = math.gcd(b, stable_periods(pf))
    if g > 1:
        return Symmetry("symmetric", 360.0 / g, tp, part_t)
    return Symmetry("quasi-symmetric", 360.0 / b, tp, part_t)
