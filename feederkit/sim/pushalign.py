"""One simulated push-align operation in MuJoCo (paper, section 3; issue 7).

The robot sets the part's yaw, zeroes its velocity and drops it a little upstream of the
fence; the belt carries it into the fence, where it rotates until an edge lies flat; the
operation ends when the part touches the fence, lies flush with one of its hull edges and
its yaw has been still for a window. The LED array then reads the width across the belt.

Conventions (design.md): ``theta`` is the fence's contact normal in the part frame; the
part's world yaw is ``-90 - theta``; rotating the part by ``a`` counter-clockwise adds
``a`` to its yaw, so ``theta' = theta - a``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.angles import norm360
from feederkit.errors import InputError
from feederkit.mechanics.push import com_feet, edge_normals
from feederkit.part import Part
from feederkit.sim.engine import require_mujoco
from feederkit.sim.scene import MM, SceneConfig, scene_geometry, scene_xml

CHUNK_STEPS = 5
"""Physics steps between two looks at the part (10 ms at the 2 ms step)."""

BREATH_MOVES = 5
"""How many times a breath of vibration (:meth:`PushAligner.align`) may move a resting part on
before it is judged where it lies (each move ends lower; MuJoCo may hold a part set down on a
slope for a window)."""

BREATH_MAX_DEG = 90.0
"""How far (deg) either way a breath of vibration follows the part rolling on the fence."""

BREATH_STEP_DEG = 0.05
"""Angular step (deg) of that search (a finely flattened arc's facets span 0.3 degree or
more)."""

BREATH_DROP_REL = 1e-3
"""A breath moves a part only to a point lower than where it lies by this share of the
vibration (the wells of one arc's facets differ by rounding)."""


@dataclass(frozen=True)
class SettleRule:
    """When a push-align operation has ended.

    The part must touch the fence (come within ``touch_tol_mm`` of its face: contacts
    flicker while the belt slides under a part held by the fence), rest flush on an edge
    it can rest on (its fence orientation within ``align_tol_deg`` of the normal of an edge
    whose COM foot lies on the edge: a part pivots through an unstable edge, however
    slowly), and its orientation must have moved less than ``still_tol_deg`` while the belt
    travelled ``window_sizes`` part sizes (at least ``min_window_s`` seconds). Lengths are
    counted in belt travel because quasi-static rotation depends on how far the belt has
    moved, not on how fast. A run not done after ``max_travel_sizes`` part sizes of belt
    travel (at least ``min_max_time_s`` seconds) never settled. With ``drift_tol_deg`` set,
    the part is still when the mean orientation over the window's second half differs from
    the mean over its first half by less than that, not when the window's range is below
    ``still_tol_deg``: a part rolling on a gentle arc (its own outline, docs/simulation.md)
    jitters by a degree or two about an orientation that drifts far less.
    """

    window_sizes: float = 0.5
    min_window_s: float = 0.1
    still_tol_deg: float = 1.0
    align_tol_deg: float = 1.0
    touch_tol_mm: float = 0.3
    max_travel_sizes: float = 20.0
    min_max_time_s: float = 2.0
    drift_tol_deg: float | None = None

    def still(self, recent: list[float]) -> bool:
        """Whether the unwrapped orientations ``recent`` (one window) are still."""
        if self.drift_tol_deg is None:
            return max(recent) - min(recent) < self.still_tol_deg
        half = len(recent) // 2
        first, second = recent[:half], recent[half:]
        return abs(sum(second) / len(second) - sum(first) / len(first)) < self.drift_tol_deg

    def reading(self, thetas: Sequence[float], widths: Sequence[float]) -> tuple[float, float]:
        """Where the part rests (unwrapped, deg) and the width across the belt there (mm), from
        one still window's looks (``thetas`` and ``widths``, one per look).

        Under the range rule every look lies within ``still_tol_deg`` of the others: their
        means. Under the drift rule the window may still hold the end of the part's turn onto
        its rest: a part slams flush at tens of degrees per second, and a few looks several
        degrees off pass the halves' means (a 60 mm part read 0.2 degree off flush and 0.25 mm
        too wide, outside a ±0.2 mm branch). The part at rest is then the window's second half,
        where the drift rule found it still: the medians of its looks, which a jitter about
        the rest (a gentle arc) leaves where the mean would be and a stray look does not move.
        """
        if self.drift_tol_deg is None:
            return sum(thetas) / len(thetas), float(np.mean(widths))
        half = len(thetas) // 2
        return float(np.median(thetas[half:])), float(np.median(widths[half:]))

    def window_s(self, size_m: float, belt_speed: float) -> float:
        """Length (s) of the still window for a part of ``size_m`` metres."""
        return max(self.min_window_s, self.window_sizes * size_m / belt_speed)

    def max_time_s(self, size_m: float, belt_speed: float) -> float:
        """Simulated time (s) after which a run never settled."""
        return max(self.min_max_time_s, self.max_travel_sizes * size_m / belt_speed)


@dataclass(frozen=True)
class PushOutcome:
    """The result of one simulated push-align operation.

    ``theta_start_deg`` is the fence orientation (part frame) the part was dropped at;
    ``theta_end_deg`` the one it came to rest at (averaged over the still window);
    ``edge`` the hull edge flush with the fence (None when the run never settled);
    ``width_mm`` the width across the belt the LED array reads, in the part's millimetres;
    ``tilt_deg`` how far the part's plane leans from the belt's at the end (a part above
    :data:`TILT_MAX_DEG` stands on an edge or turned over: it never settles);
    ``turned_deg`` how far it turned from the drop to the rest, counter-clockwise positive
    and unwrapped (which hilltops it went over, ``benchmarks/bench_overshoot.py``).
    """

    theta_start_deg: float
    settled: bool
    theta_end_deg: float
    edge: int | None
    width_mm: float
    sim_time_s: float
    steps: int
    tilt_deg: float = 0.0
    turned_deg: float = 0.0


TILT_MAX_DEG = 10.0
"""A part whose plane leans more than this from the belt's is not lying flat (it leans on the
fence, stands on an edge or turns over, e.g. a COM close to the hull's boundary): it does not
count as settled, whatever its yaw does. Parts lying flat lean a degree or less."""


def _signed_delta(a: float, b: float) -> float:
    """b - a on the circle, in (-180, 180]."""
    d = norm360(b - a)
    return d - 360.0 if d > 180.0 else d


def range_distance(theta_deg: float, lo_deg: float, hi_deg: float) -> float:
    """Angular distance (deg) from ``theta`` to the arc ``[lo, hi]`` (``hi`` may pass 360;
    0 inside it)."""
    d = norm360(theta_deg - lo_deg)
    width = hi_deg - lo_deg
    if d <= width:
        return 0.0
    return min(d - width, 360.0 - d)


def _range_distance(theta_deg: float, ranges: Sequence[tuple[float, float]]) -> float:
    return min(range_distance(theta_deg, lo, hi) for lo, hi in ranges)


def size_scale(part: Part, lo_mm: float = 20.0, hi_mm: float = 200.0) -> float:
    """Factor applied to the part's lengths in the physics: 1 for parts of 20-200 mm.

    Quasi-static pushing is scale free (the push function depends on shape and COM only),
    so a part drawn in other units, e.g. the paper's unit triangle, is simulated at a
    feeder-like size; widths are scaled back before they are read.
    """
    size = part.size
    if size < lo_mm:
        return lo_mm / size
    if size > hi_mm:
        return hi_mm / size
    return 1.0


def fence_heights(rel: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """The COM's height over the fence (world -y) of a part whose hull about its COM is
    ``rel`` (world axes) after each yaw turn in ``turns`` (rad), touching the fence."""
    return -(np.sin(turns)[:, None] * rel[:, 0] + np.cos(turns)[:, None] * rel[:, 1]).min(axis=1)


def breath_turn(rel: np.ndarray, lift: float) -> float | None:
    """Where a breath of vibration that can lift the COM by ``lift`` takes a resting part whose
    hull about its COM is ``rel`` (world axes, the fence below): the yaw turn (rad) to the
    lowest point it can roll to on the fence without its COM rising more than ``lift`` above
    the bottom of its well, when that lies past a hilltop; None when a barrier higher than
    ``lift`` holds it on both sides.

    The bottom of its own well, not where it lies: MuJoCo's soft contacts hold a part a little
    off it (one held up a slope may go anywhere lower, and one held just past a hilltop, on a
    slope that falls all the way, rolls down it). The lowest point, not any: a part shaken
    among wells drifts down, never up (a row of breaths would climb an arc's facets).
    """
    steps = np.radians(np.arange(0.0, BREATH_MAX_DEG, BREATH_STEP_DEG))
    turns = [steps, -steps]
    heights = [fence_heights(rel, t) for t in turns]
    rises = [np.flatnonzero(np.diff(h) > 0.0) for h in heights]
    own = [int(r[0]) if r.size else 0 for r in rises]  # its well's bottom (none: a slope)
    floor = min(float(h[k]) for h, k in zip(heights, own, strict=True))
    ceiling = max(floor + lift, float(heights[0][0]))
    best, to = BREATH_DROP_REL * lift, None
    for turn, height, bottom in zip(turns, heights, own, strict=True):
        out = np.flatnonzero(height > ceiling)
        reach = height[: int(out[0]) if out.size else len(height)]
        k = int(np.argmin(reach))
        if k > bottom and floor - float(reach[k]) > best:
            best, to = floor - float(reach[k]), float(turn[k])
    return to


class PushAligner:
    """A MuJoCo model of the feeder with one part, reused across push-align operations.

    Each operation starts from a fresh state (the robot picks the part up), so outcomes
    depend only on the drop orientation and the settings.

    ``rests`` (a part on its own outline, docs/simulation.md: an arc drawn as many short
    edges has no one edge to lie flush on) replaces "flush on an edge its COM's foot falls
    on": each ``(lo, hi, rest)`` is a resting range of fence orientations (deg, ``hi`` may pass
    360) and the orientation in it where the part lies lowest; the part has settled when it is
    still within ``align_tol_deg`` of a ``rest``, or, when the belt has run its whole travel,
    wherever it then lies within ``align_tol_deg`` of a range (a part creeping down a gentle
    arc has rested when the fence ends). ``edge`` is then the hull edge nearest its
    orientation.
    """

    def __init__(
        self,
        part: Part,
        config: SceneConfig | None = None,
        rule: SettleRule | None = None,
        scale: float | None = None,
        *,
        rests: Sequence[tuple[float, float, float]] | None = None,
        vibration_mm: float = 0.0,
    ) -> None:
        mujoco = require_mujoco()
        self._mj = mujoco
        self.part = part
        self.config = config or SceneConfig()
        self.rule = rule or SettleRule()
        self.scale = size_scale(part) if scale is None else scale
        self.model = mujoco.MjModel.from_xml_string(scene_xml(part, self.config, self.scale))
        self.data = mujoco.MjData(self.model)
        geo = scene_geometry(part, self.config, self.scale)
        self._geo = geo
        half = geo.thickness / 2
        hull = np.asarray(geo.hull)
        self._verts = np.vstack(
            [np.column_stack([hull, np.full(len(hull), z)]) for z in (-half, half)]
        )
        self._hull = hull
        self._normals = np.asarray(edge_normals(part.hull))
        # Edges the part can rest on: the COM's foot lies on the edge (stable or metastable).
        self._restable = np.array([0.0 <= t <= 1.0 for t in com_feet(part.hull, part.com)])
        self._rests = None if rests is None else [(float(a), float(b)) for a, b, _ in rests]
        self._lowest = None if rests is None else [(float(c), float(c)) for _, _, c in rests]
        m = self.model
        part_joint = m.joint("part").id
        belt_joint = m.joint("belt").id
        self._pq = int(m.jnt_qposadr[part_joint])
        self._pv = int(m.jnt_dofadr[part_joint])
        self._bq = int(m.jnt_qposadr[belt_joint])
        self._bv = int(m.jnt_dofadr[belt_joint])
        self._body = m.body("part").id
        self._size = float(np.max(np.linalg.norm(hull, axis=1)))
        self._wrap = 0.5  # metres of belt travel before the slab is moved back
        self.vibration_mm = float(vibration_mm)

    def set_friction(self, belt: float, fence: float) -> None:
        """Set the belt's and the fence's friction coefficients for the next operations (the
        belt and fence carry ``priority``, so theirs are the contacts' coefficients)."""
        m = self.model
        m.geom_friction[m.geom("belt").id][0] = belt
        m.geom_friction[m.geom("fence").id][0] = fence

    def resting_drift(self, theta_deg: float, seconds: float) -> tuple[float, float, float]:
        """Creep of a settled part: align at ``theta_deg``, then keep the belt running for
        ``seconds`` and return how far the part turned (deg) and slid along the fence and
        away from it (mm, in the part's own units). A quasi-static part held by the fence
        should not move at all; what it does is MuJoCo's soft-contact creep
        (docs/simulation.md compares contact settings by it). Raises InputError when the
        part never settles."""
        out = self.align(theta_deg)
        if not out.settled:
            raise InputError(f"the part never settled from {theta_deg:g} deg: no drift to measure")
        mj, m, d = self._mj, self.model, self.data
        to_mm = MM * self.scale
        yaw0, x0 = self._theta(), float(d.xpos[self._body][0])
        lo0, _ = self._extent_y()
        unwrapped, prev = 0.0, yaw0
        for _ in range(math.ceil(seconds / m.opt.timestep)):
            d.qvel[self._bv] = -self.config.belt_speed
            mj.mj_step(m, d)
            if d.qpos[self._bq] < -self._wrap:
                d.qpos[self._bq] += self._wrap
            theta = self._theta()
            unwrapped += _signed_delta(prev, theta)
            prev = theta
        lo, _ = self._extent_y()
        return (
            abs(unwrapped),
            abs(float(d.xpos[self._body][0]) - x0) / to_mm,
            abs(lo - lo0) / to_mm,
        )

    # -- reading the state ------------------------------------------------------------
    def _theta(self) -> float:
        xm = self.data.xmat[self._body]
        yaw = math.degrees(math.atan2(xm[3], xm[0]))
        return norm360(-90.0 - yaw)

    def _tilt(self) -> float:
        """How far (deg) the part's plane leans from the belt's: the angle of its z axis."""
        zz = float(self.data.xmat[self._body][8])
        return math.degrees(math.acos(max(-1.0, min(1.0, zz))))

    def _extent_y(self) -> tuple[float, float]:
        """Lowest and highest world y of the part (metres)."""
        rot_y = self.data.xmat[self._body][3:6]
        ys = self._verts @ rot_y + self.data.xpos[self._body][1]
        return float(ys.min()), float(ys.max())

    def _nearest_edge(self, theta: float) -> tuple[int, float]:
        offs = np.abs((self._normals - theta + 180.0) % 360.0 - 180.0)
        i = int(np.argmin(offs))
        return i, float(offs[i])

    @property
    def size_m(self) -> float:
        """The simulated part's size (larger bounding-box side), metres."""
        return self.part.size * self.scale * MM

    @property
    def max_time_s(self) -> float:
        """Simulated seconds after which an operation never settled."""
        return self.rule.max_time_s(self.size_m, self.config.belt_speed)

    # -- one operation ----------------------------------------------------------------
    def _drop(self, theta_deg: float) -> None:
        mj, d = self._mj, self.data
        mj.mj_resetData(self.model, d)
        yaw = math.radians(-90.0 - theta_deg)
        c, s = math.cos(yaw), math.sin(yaw)
        ys = s * self._hull[:, 0] + c * self._hull[:, 1]
        gap = max(0.1 * self._size, 0.002)
        drop = 0.0005
        d.qpos[self._pq : self._pq + 3] = (
            0.0,
            gap - float(ys.min()),
            self._geo.thickness / 2 + drop,
        )
        d.qpos[self._pq + 3 : self._pq + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        d.qvel[self._pv : self._pv + 6] = 0.0
        d.qvel[self._bv] = -self.config.belt_speed
        mj.mj_forward(self.model, d)

    def _breathe(self) -> bool:
        """A breath of vibration on the resting part (:func:`breath_turn`, the vibration
        :attr:`vibration_mm`): it is set down at rest where the breath takes it, touching the
        fence as before. Whether it moved."""
        d = self.data
        rot = d.xmat[self._body].reshape(3, 3)[:2, :2]
        rel = self._hull @ rot.T  # the hull about the COM, world axes
        turn = breath_turn(rel, self.vibration_mm * self.scale * MM)
        if turn is None:
            return False
        before, after = fence_heights(rel, np.array([0.0, turn]))
        yaw = math.atan2(rot[1, 0], rot[0, 0]) + turn
        q = self._pq
        d.qpos[q + 1] += float(after - before)
        d.qpos[q + 3 : q + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        d.qvel[self._pv : self._pv + 6] = 0.0
        self._mj.mj_forward(self.model, d)
        return True

    def align(self, theta_deg: float) -> PushOutcome:
        """Drop the part at fence orientation ``theta_deg`` and run until it settles.

        With :attr:`vibration_mm` set (the vibration the plan's model assumes) the feeder
        breathes on the part each time it comes to rest, settled or not, wherever it lies: a
        part that can roll lower on the fence without its COM rising more than the vibration
        is set down there (:meth:`_breathe`) and let come to rest again (at most
        :data:`BREATH_MOVES` times). So it stays only where a barrier above the vibration holds
        it on both sides, as the model assumes; a flattened arc's facets at a hilltop do not
        (the model has no state there, docs/simulation.md, "A breath of vibration").
        """
        self._drop(theta_deg)
        return self._settle(theta_deg)

    def _settle(self, theta_deg: float) -> PushOutcome:
        """Run the dropped part until it settles (:meth:`align`)."""
        mj, m, d = self._mj, self.model, self.data
        rule = self.rule
        v = -self.config.belt_speed
        bv, bq = self._bv, self._bq
        dt = m.opt.timestep * CHUNK_STEPS
        window = max(2, math.ceil(rule.window_s(self.size_m, self.config.belt_speed) / dt))
        max_checks = math.ceil(self.max_time_s / dt)
        to_mm = MM * self.scale
        touch_tol = rule.touch_tol_mm * MM  # physical: the chatter does not scale with the part
        thetas: list[float] = []  # unwrapped fence orientation at each look while touching
        widths: list[float] = []
        steps = 0
        prev = theta_deg
        unwrapped = theta_deg
        moves = 0 if self.vibration_mm > 0.0 else BREATH_MOVES
        breathed: float | None = None  # unwrapped rest a breath last found
        tol = rule.align_tol_deg
        checks = 0
        while checks < max_checks:
            checks += 1
            for _ in range(CHUNK_STEPS):
                d.qvel[bv] = v
                mj.mj_step(m, d)
            steps += CHUNK_STEPS
            if d.qpos[bq] < -self._wrap:
                d.qpos[bq] += self._wrap
            theta = self._theta()
            unwrapped += _signed_delta(prev, theta)
            prev = theta
            lo, hi = self._extent_y()
            if lo > touch_tol or self._tilt() > TILT_MAX_DEG:
                thetas.clear()  # off the fence, or not lying flat: no still window yet
                widths.clear()
                continue
            thetas.append(unwrapped)
            widths.append((hi - lo) / to_mm)
            if len(thetas) < window:
                continue
            recent = thetas[-window:]
            if not rule.still(recent):
                continue
            rest, width = rule.reading(recent, widths[-window:])
            if moves < BREATH_MOVES and (breathed is None or abs(rest - breathed) > tol):
                breathed = rest
                if self._breathe():
                    moves += 1
                    thetas.clear()
                    widths.clear()
                    checks = 0  # the whole travel to come to rest again
                    continue
            turned = rest - theta_deg
            rest = norm360(rest)
            edge, off = self._nearest_edge(rest)
            if self._lowest is not None:
                ok = _range_distance(rest, self._lowest) <= rule.align_tol_deg
            else:
                ok = off <= rule.align_tol_deg and bool(self._restable[edge])
            if ok:
                return PushOutcome(
                    theta_start_deg=norm360(theta_deg),
                    settled=True,
                    theta_end_deg=rest,
                    edge=edge,
                    width_mm=width,
                    sim_time_s=float(d.time),
                    steps=steps,
                    tilt_deg=self._tilt(),
                    turned_deg=turned,
                )
        if self._rests is not None and len(thetas) >= window:  # the end of the fence
            rest, width = rule.reading(thetas[-window:], widths[-window:])
            turned = rest - theta_deg
            rest = norm360(rest)
            if _range_distance(rest, self._rests) <= rule.align_tol_deg:
                return PushOutcome(
                    theta_start_deg=norm360(theta_deg),
                    settled=True,
                    theta_end_deg=rest,
                    edge=self._nearest_edge(rest)[0],
                    width_mm=width,
                    sim_time_s=float(d.time),
                    steps=steps,
                    tilt_deg=self._tilt(),
                    turned_deg=turned,
                )
        lo, hi = self._extent_y()
        return PushOutcome(
            theta_start_deg=norm360(theta_deg),
            settled=False,
            theta_end_deg=self._theta(),
            edge=None,
            width_mm=(hi - lo) / to_mm,
            sim_time_s=float(d.time),
            steps=steps,
            tilt_deg=self._tilt(),
        )
