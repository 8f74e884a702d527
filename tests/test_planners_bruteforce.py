"""An independent exhaustive planner agrees with ``feederkit.planning.plan`` on optimal lengths.

Nothing here shares code with the product's mechanics, machine or planners: this file
computes the push function of a random convex polygon itself (stable edges are the edges the
centre of mass projects inside; divergent orientations are the vertex directions that lie
inside their vertex's normal cone; each resting range runs between two divergent
orientations around one stable normal), branches readings itself (a tolerance sensor: a
state of diameter d reads anything strictly within e of d) and searches plainly: a set of
states needs 0 operations when it holds one state, else 1 + the best over the set's
representative rotations of the worst branch, found by depth-bounded recursion over sets.
"""

from __future__ import annotations

import math
import random
from functools import cache

from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from feederkit.machine import build_machine, inseparable
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.planning.options import PlanningOptions
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

GAP = 1e-3
"""Parts whose angles come closer than this (deg) to a tie are skipped as degenerate."""


def polygon(seed: int, n: int) -> tuple[list[tuple[float, float]], tuple[float, float]]:
    """A random convex polygon (counter-clockwise) and a random centre of mass inside it."""
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    a = rng.uniform(5, 30)
    b = a * rng.uniform(0.5, 1.0)
    pts = [(a * math.cos(t), b * math.sin(t)) for t in angles]
    skew = rng.choice([0.2, 1.0, 3.0])  # how far the centre of mass may stray from the middle
    w = [1.0 + skew * rng.random() ** 2 for _ in pts]
    s = sum(w)
    com = (
        sum(wi * p[0] for wi, p in zip(w, pts, strict=True)) / s,
        sum(wi * p[1] for wi, p in zip(w, pts, strict=True)) / s,
    )
    return pts, com


def ang(x: float, y: float) -> float:
    return math.degrees(math.atan2(y, x)) % 360.0


class OwnPart:
    """Stable orientations, resting ranges and diameters of a convex polygon, from scratch."""

    def __init__(self, pts, com):
        n = len(pts)
        cx, cy = com
        normals, stable = [], []
        for i in range(n):
            (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
            dx, dy = x1 - x0, y1 - y0
            normals.append(ang(dy, -dx))
            t = ((cx - x0) * dx + (cy - y0) * dy) / (dx * dx + dy * dy)
            if min(abs(t), abs(t - 1.0)) < 1e-4:
                self.ok = False
                return
            stable.append(0.0 < t < 1.0)
        divergent = []
        for i in range(n):
            v = pts[(i + 1) % n]  # between edge i and edge i + 1
            phi = ang(v[0] - cx, v[1] - cy)
            lo, hi = normals[i], normals[(i + 1) % n]
            span = (hi - lo) % 360.0
            off = (phi - lo) % 360.0
            near = min(off, 360.0 - off, abs(off - span), 360.0 - abs(off - span))
            if near < GAP:
                self.ok = False
                return
            if off < span:
                divergent.append(phi)
        self.psi = sorted(normals[i] for i in range(n) if stable[i])
        self.div = sorted(divergent)
        self.ok = len(self.psi) == len(self.div) >= 1
        if not self.ok:
            return
        # Resting range k runs from div[k] counter-clockwise to div[k + 1].
        self.range_state = []
        for k in range(len(self.div)):
            lo = self.div[k]
            span = (self.div[(k + 1) % len(self.div)] - lo) % 360.0 or 360.0
            inside = [s for s, p in enumerate(self.psi) if 0 < (p - lo) % 360.0 < span]
            if len(inside) != 1:
                self.ok = False
                return
            self.range_state.append(inside[0])
        self.diam = []
        for p in self.psi:
            u = (math.cos(math.radians(p)), math.sin(math.radians(p)))
            proj = [x * u[0] + y * u[1] for x, y in pts]
            self.diam.append(max(proj) - min(proj))

    @property
    def n(self) -> int:
        return len(self.psi)

    def settle(self, theta: float) -> int:
        """The state a fence orientation theta comes to rest in."""
        theta %= 360.0
        k = max((k for k, d in enumerate(self.div) if d <= theta), default=len(self.div) - 1)
        return self.range_state[k]

    def rotations(self, states) -> list[float]:
        """Middles of the cells of the states' action-range boundaries psi - div."""
        b = sorted({(self.psi[s] - d) % 360.0 for s in states for d in self.div})
        cells = list(zip(b, b[1:] + [b[0] + 360.0], strict=True))
        if any(hi - lo < GAP for lo, hi in cells) and len(cells) > 1:
            raise Degenerate
        return [(lo + hi) / 2.0 for lo, hi in cells]


class Degenerate(Exception):
    pass


def own_length(part: OwnPart, tol: float | None, components: bool = False) -> int:
    """Minimum worst-case number of operations, the first alignment counted.

    ``components``: a reading names a whole chain of states whose reading sets overlap
    (the paper's indistinguishable sets) instead of exactly the states that can give it.
    """

    def readings(states: frozenset) -> list[frozenset]:
        if tol is None:
            return [states]
        if components:
            order = sorted(states, key=lambda s: part.diam[s])
            groups = [[order[0]]]
            for s in order[1:]:
                if part.diam[s] - part.diam[groups[-1][-1]] < 2 * tol:
                    groups[-1].append(s)
                else:
                    groups.append([s])
            return [frozenset(g) for g in groups]
        pts = sorted({part.diam[s] + sign * tol for s in states for sign in (-1, 1)})
        out = set()
        for a, b in zip(pts, pts[1:], strict=False):
            x = (a + b) / 2.0
            group = frozenset(s for s in states if abs(part.diam[s] - x) < tol)
            if group:
                out.add(group)
        return list(out)

    @cache
    def within(states: frozenset, k: int) -> bool:
        if len(states) == 1:
            return True
        if k == 0:
            return False
        for a in part.rotations(states):
            image = frozenset(part.settle(part.psi[s] - a) for s in states)
            if all(within(c, k - 1) for c in readings(image)):
                return True
        return False

    worst = 0
    for group in readings(frozenset(range(part.n))):
        k = 0
        while not within(group, k):
            k += 1
            assert k <= 2 * part.n, "the own planner found no plan"
        worst = max(worst, k)
    return 1 + worst


def product_length(pts, com, tol: float | None, components: bool = False) -> int:
    pf = push_function(make_part(make_outline("random", pts), com))
    sensor = NoSensor() if tol is None else ToleranceSensor(tol)
    m = build_machine([pf], sensor, uncertainty=IDEAL)
    assert inseparable(m) == (0,) * m.n  # random parts: every pair can be told apart
    return plan(m, PlanningOptions(grouping="components" if components else "exact")).length


def _compare(seed: int, n: int, rel: float | None, components: bool = False) -> None:
    pts, com = polygon(seed, n)
    own = OwnPart(pts, com)
    assume(own.ok and own.n >= 2)
    size = max(
        max(p[0] for p in pts) - min(p[0] for p in pts),
        max(p[1] for p in pts) - min(p[1] for p in pts),
    )
    tol = None if rel is None else rel * size
    if tol is not None:
        gaps = [abs(abs(a - b) - 2 * tol) for a in own.diam for b in own.diam]
        assume(min(gaps) > 1e-6 * size)
    try:
        mine = own_length(own, tol, components)
    except Degenerate:
        assume(False)
    assert product_length(pts, com, tol, components) == mine


@settings(
    max_examples=200,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.002, 0.08))
@example(seed=10, n=10, rel=0.078125)  # a subset reading set keeps a smaller margin
def test_sensor_based_lengths_agree(seed, n, rel):
    _compare(seed, n, rel)


@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10))
def test_sensorless_lengths_agree(seed, n):
    _compare(seed, n, None)


@settings(
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.002, 0.08))
@example(seed=0, n=9, rel=0.0625)  # a pair inside one component reads apart alone
def test_component_branching_lengths_agree(seed, n, rel):
    _compare(seed, n, rel, components=True)


@settings(
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.1, 1.0))
def test_coarse_sensor_lengths_agree(seed, n, rel):
    # Coarse sensors: often one reading fits every state, and the planner answers with
    # backchaining (methods.readings_carry_nothing); the brute force still follows readings.
    _compare(seed, n, rel)


def test_the_own_planner_knows_the_triangle():
    own = OwnPart([(0, 0), (1, 0), (0, 1)], (1 / 3, 1 / 3))
    assert own.ok and own.n == 3
    assert own_length(own, None) == 3
    assert own_length(own, 0.01) == 2
