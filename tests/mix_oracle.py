"""An independent exhaustive planner for product mixes, for the tests only (issue 5).

No product code: its own push function from the hull and COM (walking down the radius
function), its own reading branching for a tolerance sensor, its own goal (every pair of
(part, state) inseparable, by its own greatest fixpoint) and plain recursion over sets of
(part, state) pairs with iterative deepening.
"""

from __future__ import annotations

import math
from functools import cache

TWO_PI = 2.0 * math.pi


def _ang(x: float) -> float:
    return x % TWO_PI


def _ccw(a: float, b: float) -> float:
    """Counter-clockwise distance from a to b, in [0, 2 pi)."""
    return (b - a) % TWO_PI


class OraclePart:
    """Stable orientations, divergent orientations and diameters of a convex polygon with a COM.

    Angles in radians. ``hull`` is counter-clockwise; edge i joins vertex i to vertex i+1.
    """

    def __init__(self, hull: list[tuple[float, float]], com: tuple[float, float]):
        self.hull = hull
        self.com = com
        n = len(hull)
        self.normals = []
        for i in range(n):
            (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
            self.normals.append(_ang(math.atan2(-(x1 - x0), y1 - y0)))
        self.vdir = [_ang(math.atan2(y - com[1], x - com[0])) for x, y in hull]
        # Stable edges: the COM's foot strictly inside the edge.
        self.stable = []
        for i in range(n):
            (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
            dx, dy = x1 - x0, y1 - y0
            t = ((com[0] - x0) * dx + (com[1] - y0) * dy) / (dx * dx + dy * dy)
            if 0.0 < t < 1.0:
                self.stable.append(i)
        self.psi = [self.normals[i] for i in self.stable]
        self.diam = [self.width(p) for p in self.psi]
        # Divergent orientations: vertex directions strictly inside their own normal cone.
        self.divergent = []
        for j in range(n):
            lo, hi = self.normals[j - 1], self.normals[j]
            d = self.vdir[j]
            if 0.0 < _ccw(lo, d) < _ccw(lo, hi):
                self.divergent.append(d)

    def width(self, phi: float) -> float:
        u = (math.cos(phi), math.sin(phi))
        proj = [x * u[0] + y * u[1] for x, y in self.hull]
        return max(proj) - min(proj)

    def settle(self, theta: float) -> int:
        """The stable state index reached from fence orientation ``theta`` (walk downhill)."""
        n = len(self.hull)
        theta = _ang(theta)
        # The vertex whose normal cone holds theta: cone of vertex j is (normals[j-1], normals[j]).
        j = next(
            j
            for j in range(n)
            if _ccw(self.normals[j - 1], theta) < _ccw(self.normals[j - 1], self.normals[j])
        )
        for _ in range(2 * n + 2):
            d = self.vdir[j]
            # r = |v| cos(theta - d): downhill is toward d's far side; moving ccw if theta past d.
            past = _ccw(d, theta) < math.pi  # theta is ccw of d (within the cone)
            if past:
                e = j  # walk ccw to edge j's normal
                nxt = (j + 1) % n
                if (
                    _ccw(self.normals[e], self.vdir[nxt]) < math.pi
                    and _ccw(self.normals[e], self.vdir[nxt]) > 0
                ):
                    return self.stable.index(e)
                j, theta = nxt, self.normals[e] + 1e-12
            else:
                e = (j - 1) % n  # walk cw to edge j-1's normal
                prv = e
                if (
                    _ccw(self.vdir[prv], self.normals[e]) < math.pi
                    and _ccw(self.vdir[prv], self.normals[e]) > 0
                ):
                    return self.stable.index(e)
                j, theta = prv, self.normals[e] - 1e-12
        raise AssertionError("no stable edge reached")


def _cells(points: list[float]) -> list[float]:
    """Midpoints between consecutive distinct angles (cyclic), the representative actions."""
    pts: list[float] = []
    for p in sorted(_ang(p) for p in points):
        if not pts or p - pts[-1] > 1e-9:
            pts.append(p)  # angles closer than 1e-9 rad are one boundary (symmetric parts)
    if len(pts) > 1 and pts[0] + TWO_PI - pts[-1] <= 1e-9:
        pts.pop()
    if len(pts) <= 1:
        return [(pts[0] + math.pi) % TWO_PI] if pts else [0.0]
    out = []
    for k, p in enumerate(pts):
        q = pts[(k + 1) % len(pts)]
        out.append(_ang(p + _ccw(p, q) / 2.0))
    return out


class MixOracle:
    """Plain recursion over sets of (part, state) pairs; a tolerance sensor (None: sensorless)."""

    def __init__(self, parts: list[OraclePart], tolerance: float | None):
        self.parts = parts
        self.e = tolerance
        self.states = [(p, s) for p, part in enumerate(parts) for s in range(len(part.psi))]
        self.index = {st: k for k, st in enumerate(self.states)}
        self.insep = self._fixpoint()

    def d(self, k: int) -> float:
        p, s = self.states[k]
        return self.parts[p].diam[s]

    def alike(self, a: int, b: int) -> bool:
        return self.e is None or abs(self.d(a) - self.d(b)) < 2.0 * self.e

    def actions(self, ks) -> list[float]:
        pts = []
        for k in ks:
            p, s = self.states[k]
            part = self.parts[p]
            pts += [part.psi[s] - dv for dv in part.divergent]
        return _cells(pts)

    def after(self, k: int, a: float) -> int:
        p, s = self.states[k]
        part = self.parts[p]
        return self.index[(p, part.settle(part.psi[s] - a))]

    def _fixpoint(self) -> set[frozenset]:
        n = len(self.states)
        alive = {frozenset((a, b)) for a in range(n) for b in range(a + 1, n) if self.alike(a, b)}
        changed = True
        while changed:
            changed = False
            for pair in list(alive):
                a, b = tuple(pair)
                for act in self.actions((a, b)):
                    x, y = self.after(a, act), self.after(b, act)
                    if x == y or frozenset((x, y)) not in alive:
                        alive.discard(pair)
                        changed = True
                        break
        return alive

    def goal(self, ks: frozenset) -> bool:
        lst = sorted(ks)
        return all(frozenset((a, b)) in self.insep for i, a in enumerate(lst) for b in lst[i + 1 :])

    def split(self, ks: frozenset) -> list[frozenset]:
        if self.e is None:
            return [ks]
        pts = sorted({self.d(k) + s * self.e for k in ks for s in (-1, 1)})
        out = set()
        for lo, hi in zip(pts, pts[1:], strict=False):
            x = (lo + hi) / 2.0
            sub = frozenset(k for k in ks if abs(self.d(k) - x) < self.e)
            if sub:
                out.add(sub)
        return sorted(out, key=sorted)

    def solvable(self, ks: frozenset, budget: int) -> bool:
        return self._solvable(ks, budget)

    @cache  # noqa: B019  (one oracle per test case)
    def _solvable(self, ks: frozenset, budget: int) -> bool:
        if self.goal(ks):
            return True
        if budget == 0:
            return False
        for a in self.actions(ks):
            img = frozenset(self.after(k, a) for k in ks)
            if all(self._solvable(b, budget - 1) for b in self.split(img)):
                return True
        return False

    def length(self, cap: int = 12) -> int:
        """The minimum worst-case number of operations, the first alignment counted."""
        worst = 0
        for branch in self.split(frozenset(range(len(self.states)))):
            k = 0
            while not self._solvable(branch, k):
                k += 1
                if k > cap:
                    raise AssertionError("no plan within the cap")
            worst = max(worst, k)
        return 1 + worst
