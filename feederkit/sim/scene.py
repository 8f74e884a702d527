"""The MuJoCo scene of one part: belt, fence and the part as a prism (MJCF text, pure).

World frame (design.md): the belt moves toward world -y, the fence face is the plane
y = 0 with the part above it (y > 0), the belt surface is z = 0. Lengths in metres.

- belt: a heavy slab on a slide joint along y; the simulator sets its velocity every step
  and wraps it back when it has travelled far (only its surface matters);
- fence: a fixed box whose face is y = 0; it reaches into the belt so nothing slips under;
- part: the contact hull extruded to a prism (a convex mesh) on a free joint with all six
  degrees of freedom, its body frame at the COM and mid-height, its mass and inertia those
  of the uniform plate with its holes (or of the user's COM).

Belt and fence carry ``priority`` so their friction coefficients are the ones used, and the
contact filter (contype/conaffinity) lets the part touch both while belt and fence ignore
each other. MuJoCo's multi-point convex collision (the ``multiccd`` flag, enabled
explicitly because older MuJoCo versions leave it off) gives several contacts per face, so
a flat face rests on its corners rather than on one point.
"""

from __future__ import annotations

from dataclasses import dataclass

from feederkit.part import Part
from feederkit.sim.massprops import plate_inertia

MM = 1e-3
"""Metres per millimetre."""


@dataclass(frozen=True)
class SceneConfig:
    """Physical settings of the simulated feeder.

    Defaults: a delrin plate (density 1410 kg/m^3) on a belt at 0.1 m/s, belt friction 0.5,
    fence friction 0.2, a 2 ms step.
    """

    belt_speed: float = 0.1  # m/s, toward world -y
    friction_belt: float = 0.5
    friction_fence: float = 0.2
    timestep: float = 0.002  # s
    density: float = 1410.0  # kg/m^3
    thickness_mm: float | None = None  # None: size / 8, clamped to [2, 10] mm
    solref: tuple[float, float] = (0.02, 1.0)
    cone: str = "elliptic"
    iterations: int = 50
    impratio: float = 1.0
    noslip_iterations: int = 0

    def thickness_for(self, size_mm: float) -> float:
        """Plate thickness (mm) used for a part whose larger bounding-box side is ``size_mm``."""
        if self.thickness_mm is not None:
            return self.thickness_mm
        return min(max(size_mm / 8.0, 2.0), 10.0)


@dataclass(frozen=True)
class SceneGeometry:
    """What the simulator needs to know about the scene it built (metres, body frame at COM)."""

    hull: tuple[tuple[float, float], ...]  # hull vertices relative to the COM, metres
    thickness: float  # metres
    mass: float  # kg
    inertia: tuple[float, float, float, float, float, float]  # about the COM, kg m^2


def _fmt(values) -> str:
    return " ".join(f"{v:.10g}" for v in values)


def scene_geometry(part: Part, config: SceneConfig, scale: float = 1.0) -> SceneGeometry:
    """The part's prism in metres, relative to its COM, with lengths multiplied by ``scale``."""
    s = MM * scale
    cx, cy = part.com
    hull = tuple(((x - cx) * s, (y - cy) * s) for x, y in part.hull)
    thickness = config.thickness_for(part.size * scale) * MM
    outer = [((x - cx) * s, (y - cy) * s) for x, y in part.outline.vertices]
    holes = [[((x - cx) * s, (y - cy) * s) for x, y in h] for h in part.outline.holes]
    plate = plate_inertia(outer, holes, (0.0, 0.0), thickness, config.density)
    return SceneGeometry(hull=hull, thickness=thickness, mass=plate.mass, inertia=plate.inertia)


def scene_xml(part: Part, config: SceneConfig, scale: float = 1.0) -> str:
    """MJCF text of the belt, the fence and ``part`` (its lengths multiplied by ``scale``)."""
    geo = scene_geometry(part, config, scale)
    half = geo.thickness / 2
    verts = [c for z in (-half, half) for x, y in geo.hull for c in (x, y, z)]
    size = max(max(abs(x), abs(y)) for x, y in geo.hull)
    reach = max(1.0, 20 * size)  # half-extent of belt and fence, metres
    fence_h = max(4 * geo.thickness, 0.02)
    mu_b, mu_f = config.friction_belt, config.friction_fence
    condim_f = 3 if mu_f > 0.0 else 1  # a frictionless fence: normal force only
    solref = _fmt(config.solref)
    return f"""<mujoco model="feederkit-push-align">
  <compiler angle="radian" boundmass="1e-9" boundinertia="1e-15"/>
  <option timestep="{config.timestep:.10g}" gravity="0 0 -9.81" integrator="implicitfast"
          cone="{config.cone}" iterations="{config.iterations}" impratio="{config.impratio:.6g}"
          noslip_iterations="{config.noslip_iterations}">
    <flag multiccd="enable"/>
  </option>
  <asset>
    <mesh name="part" vertex="{_fmt(verts)}"/>
  </asset>
  <worldbody>
    <geom name="fence" type="box" size="{reach:.6g} 0.01 {fence_h:.6g}"
          pos="0 -0.01 {fence_h - 0.005:.6g}" friction="{mu_f:.6g} 0 0" priority="1"
          condim="{condim_f}" contype="4" conaffinity="0" solref="{solref}"/>
    <body name="belt" pos="0 0 -0.01">
      <joint name="belt" type="slide" axis="0 1 0"/>
      <inertial pos="0 0 0" mass="10000" diaginertia="1000 1000 1000"/>
      <geom name="belt" type="box" size="{reach:.6g} {reach:.6g} 0.01"
            friction="{mu_b:.6g} 0 0" priority="1" condim="3" contype="2" conaffinity="0"
            solref="{solref}"/>
    </body>
    <body name="part" pos="0 {2 * size + 0.01:.6g} {half:.6g}">
      <freejoint name="part"/>
      <inertial pos="0 0 0" mass="{geo.mass:.10g}" fullinertia="{_fmt(geo.inertia)}"/>
      <geom name="part" type="mesh" mesh="part" contype="1" conaffinity="6" condim="3"/>
    </body>
  </worldbody>
</mujoco>
"""
