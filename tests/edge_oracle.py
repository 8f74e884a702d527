"""An independent checker of a plan file's margins and reading branches (tests only).

It shares no code with feederkit: from each part's hull and COM as the file records them it
computes, in its own words, the stable edges (COM foot strictly inside the edge), the
divergent orientations (directions from the COM to the vertices where the radius function
has a local maximum, Akella & Mason 1999, section 3.1), the resting ranges between them and
the width across each stable edge. It then follows the plan from every stable state:

- at a rotation ``a`` with margin ``m`` each reachable state's turned fence orientation
  ``theta' = normal - a`` must be at least ``m`` (less ``slack``) from every divergent
  orientation; with a rotation error ``delta`` the outcome set changes where the window
  ``theta' ± delta`` starts or stops meeting a push band around a divergent orientation,
  and ``theta'`` must be at least ``m`` from each such place;
- a state of width ``w`` reads anything in the open ``(w - e, w + e)``: the union of the
  node's closed branch intervals must cover it, and every branch meeting it is followed;
  readings within ``reading_slack`` times the part's size of an end are left out (this
  checker's widths differ from feederkit's by rounding; docs/conventions.md takes the same
  ``ROUNDING_REL`` of 1e-12);
- every path must end in a leaf that names the state.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

PUSH_BAND_DEG = 2.0
"""The angular push band on each side of a hilltop (docs/uncertainty.md; the value the
physics measurements gave, restated here so the oracle shares no code)."""

SLENDER_REL = 0.27
"""A hull whose radius of gyration (a uniform plate, about the COM) is below this share of its
diameter is slender: its ordinary bands are ``SLENDER_BAND_DEG`` up to 20 mm, narrowing
linearly to ``PUSH_BAND_DEG`` at 30 mm (docs/uncertainty.md, "Push bands")."""

SLENDER_BAND_DEG = 8.0

SHALLOW_WELLS = 5.0
"""A well shallower than this many vibrations gets the depth rule as well."""


def _norm(a: float) -> float:
    r = math.fmod(a, 360.0)
    return r + 360.0 if r < 0.0 else r


def circle_distance(a: float, b: float) -> float:
    """The distance of two angles on the circle (deg)."""
    d = abs(_norm(a) - _norm(b))
    return min(d, 360.0 - d)


@dataclass(frozen=True)
class Mechanics:
    """A part's stable edges, divergent orientations and widths, from its hull and COM."""

    normals: dict[int, float]  # stable edge -> outward normal (deg)
    widths: dict[int, float]  # stable edge -> width across it (mm)
    divergent: tuple[float, ...]  # ascending, in [0, 360)
    hull: tuple[tuple[float, float], ...]
    com: tuple[float, float]

    def radius(self, theta: float) -> float:
        """The radius function: the COM's distance to the supporting line of normal theta."""
        u = (math.cos(math.radians(theta)), math.sin(math.radians(theta)))
        cx, cy = self.com
        return max((x - cx) * u[0] + (y - cy) * u[1] for x, y in self.hull)

    def ordinary_band(self) -> float:
        """The push band (deg) on each side of an ordinary hilltop: ``PUSH_BAND_DEG``, wider
        for a slender hull (``SLENDER_REL``); the gyration from a fan of triangles at the COM.
        """
        cx, cy = self.com
        pts = [(x - cx, y - cy) for x, y in self.hull]
        area = inertia = 0.0
        for (ax, ay), (bx, by) in zip(pts, pts[1:] + pts[:1], strict=True):
            a = (ax * by - bx * ay) / 2.0  # the triangle (COM, a, b)
            area += a
            inertia += a * (ax * ax + ay * ay + bx * bx + by * by + ax * bx + ay * by) / 6.0
        size = max(math.dist(p, q) for p in self.hull for q in self.hull)
        if math.sqrt(inertia / area) >= SLENDER_REL * size:
            return PUSH_BAND_DEG
        share = min(max((30.0 - size) / 10.0, 0.0), 1.0)
        return PUSH_BAND_DEG + (SLENDER_BAND_DEG - PUSH_BAND_DEG) * share

    def bands(self, depth: float) -> list[tuple[float, float]]:
        """Around each divergent orientation, the fence orientations from which a push may
        end on either side (docs/uncertainty.md, "Push bands"), up to the stable normals on
        either side; ``depth`` 0: the orientation itself (the ideal model).

        With ``depth`` (twice the vibration) > 0: :meth:`ordinary_band` on each side; beside a
        shallow well (the hilltop less than ``SHALLOW_WELLS`` vibrations above either
        neighbouring normal's radius) also where the radius stays within ``depth`` of the
        hilltop."""
        out = []
        normals = sorted(self.normals.values())
        vibration = depth / 2.0
        band = self.ordinary_band() if depth > 0.0 else 0.0
        for d in self.divergent:
            if depth == 0.0:
                out.append((d, d))
                continue
            top = self.radius(d)
            level = top - depth
            left = max((n - 360.0 * (n > d) for n in normals), key=lambda n: n)
            right = min((n + 360.0 * (n < d) for n in normals), key=lambda n: n)
            shallow = min(top - self.radius(left), top - self.radius(right)) < (
                SHALLOW_WELLS * vibration
            )
            ends = [max(left, d - band), min(right, d + band)]
            if shallow:
                for k, far in enumerate((left, right)):
                    near = d
                    if self.radius(far) >= level:
                        end = far
                    else:
                        for _ in range(80):
                            mid = (near + far) / 2.0
                            near, far = (mid, far) if self.radius(mid) >= level else (near, mid)
                        end = far
                    ends[k] = min(ends[k], end) if k == 0 else max(ends[k], end)
            out.append((ends[0], ends[1]))
        return out

    def settle(self, theta: float) -> int:
        """The stable edge a push from fence orientation ``theta`` ends on (the one whose
        normal lies between the divergent orientations on either side of ``theta``)."""
        t = _norm(theta)
        div = self.divergent
        k = max((i for i, d in enumerate(div) if d <= t), default=len(div) - 1)
        lo = div[k]
        width = _norm(div[(k + 1) % len(div)] - lo) or 360.0
        for e, n in self.normals.items():
            if 0.0 < _norm(n - lo) < width:
                return e
        raise AssertionError(f"no stable edge after divergent orientation {lo}")

    def reach(self, theta: float, delta: float, bands: list[tuple[float, float]]) -> set[int]:
        """Every stable edge a push from an orientation within ``delta`` of ``theta`` may end
        on: where the window's ends settle, and both sides of every band it meets."""
        out = {self.settle(theta - delta), self.settle(theta + delta)}
        for lo, hi in bands:
            mid, half = (lo + hi) / 2.0, (hi - lo) / 2.0
            if circle_distance(theta, mid) <= delta + half:
                out.add(self.settle(lo - 1e-9))
                out.add(self.settle(hi + 1e-9))
        return out

    def clearance(self, theta: float, delta: float, bands: list[tuple[float, float]]) -> float:
        """How far (deg) ``theta`` can move before the window ``theta ± delta`` starts or
        stops meeting a band (where the outcome set changes)."""
        return min(
            min(circle_distance(theta, lo - delta), circle_distance(theta, hi + delta))
            for lo, hi in bands
        )


def mechanics(hull: list[list[float]], com: list[float]) -> Mechanics:
    """Stable edges, divergent orientations and widths of a CCW convex hull and its COM."""
    n = len(hull)
    cx, cy = com
    normals, widths, feet = {}, {}, []
    for i in range(n):
        (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
        dx, dy = x1 - x0, y1 - y0
        t = ((cx - x0) * dx + (cy - y0) * dy) / (dx * dx + dy * dy)
        feet.append(t)
        if 0.0 < t < 1.0:
            normals[i] = _norm(math.degrees(math.atan2(-dx, dy)))
            length = math.hypot(dx, dy)
            widths[i] = max(((x0 - x) * dy - (y0 - y) * dx) / length for x, y in hull)
    divergent = []
    for j in range(n):
        # vertex j ends edge j - 1 and starts edge j: r rises to it and falls after it
        if feet[j - 1] < 1.0 and feet[j] > 0.0:
            x, y = hull[j]
            divergent.append(_norm(math.degrees(math.atan2(y - cy, x - cx))))
    hull_t = tuple((float(x), float(y)) for x, y in hull)
    return Mechanics(normals, widths, tuple(sorted(divergent)), hull_t, (float(cx), float(cy)))


@dataclass(frozen=True)
class Finding:
    """One violation: what, where."""

    kind: str  # "margin", "reading", "result"
    text: str


def _node(plan: Mapping[str, Any], node: Mapping[str, Any]) -> Mapping[str, Any]:
    while "ref" in node:
        node = plan["nodes"][node["ref"]]
    return node


def _uncovered(lo: float, hi: float, intervals: list[tuple[float, float]]) -> float | None:
    """A point of the open ``(lo, hi)`` no closed interval holds, or None."""
    cur = lo
    for a, b in sorted(intervals):
        if b <= cur:
            continue
        if a > cur:
            return (cur + min(a, hi)) / 2.0
        cur = b
        if cur >= hi:
            return None
    return (cur + hi) / 2.0 if cur < hi else None


def check_plan(
    plan: Mapping[str, Any],
    delta: float | None = None,
    slack: float = 1e-9,
    reading_slack: float = 1e-12,
    push_depth_rel: float = 0.0,
) -> Iterator[Finding]:
    """Every violation of the plan's margins, reading coverage and results (see the module).

    ``delta`` defaults to the file's declared rotation error. ``push_depth_rel`` times the
    part's size is the depth of the push bands around the divergent orientations (0 in the
    ideal model; under uncertainty docs/uncertainty.md, "Push bands": twice the vibration).
    """
    if delta is None:
        delta = float((plan.get("uncertainty") or {}).get("rotation_error_deg", 0.0))
    sensor = plan["sensor"]
    tol = float(sensor["tolerance_mm"]) if sensor["model"] == "tolerance" else None
    for part in plan["parts"]:
        name = part["name"]
        mech = mechanics(part["hull"], part["com"])
        # The part's size: its diameter, the largest distance between two hull vertices.
        size = max(math.dist(p, q) for p in part["hull"] for q in part["hull"])
        inset = reading_slack * size
        bands = mech.bands(push_depth_rel * size)
        state_of = {s["edge"]: s["id"] for s in part["stable_states"]}
        seen: set[tuple[int, int]] = set()
        todo = [(plan["root"], e) for e in mech.normals]
        while todo:
            node, edge = todo.pop()
            node = _node(plan, node)
            if (id(node), edge) in seen:
                continue
            seen.add((id(node), edge))
            if "result" in node:
                names = {(r["part"], r["state"]) for r in node["result"]}
                if (name, state_of[edge]) not in names:
                    yield Finding("result", f"{name} edge {edge} ends in {sorted(names)}")
                continue
            branches = node["branches"]
            if tol is None or all(b["reading"] is None for b in branches):
                followed = branches
            else:
                w = mech.widths[edge]
                lo, hi = max(0.0, w - tol) + inset, w + tol - inset
                ivs = [tuple(b["reading"]) for b in branches]
                miss = _uncovered(lo, hi, ivs)
                if miss is not None:
                    yield Finding(
                        "reading",
                        f"{name} edge {edge} (width {w!r}) reads {miss!r} in no branch of "
                        f"{sorted(ivs)}",
                    )
                followed = [b for b in branches if b["reading"][0] < hi and b["reading"][1] > lo]
            for b in followed:
                nxt = _node(plan, b["next"])
                a = nxt.get("action_deg")
                if a is None:
                    todo.append((nxt, edge))
                    continue
                m = float(nxt["margin_deg"])
                theta = mech.normals[edge] - float(a)
                gap = mech.clearance(theta, delta, bands)
                if gap < m - slack:
                    yield Finding(
                        "margin",
                        f"{name} edge {edge}: rotation {a!r} claims margin {m!r}, but the "
                        f"outcome changes {gap!r} deg away",
                    )
                for e2 in mech.reach(theta, delta, bands):
                    todo.append((nxt, e2))
