"""Mass properties of a part as a uniform plate of constant thickness (pure geometry, SI units).

The simulator needs the mass, the COM and the inertia tensor of the plate with its holes.
Area moments come from Green's theorem over the outer ring minus the holes; the COM the
user gave (design.md: it overrides the plate centroid) is honoured by moving the inertia
to it with the parallel-axis theorem.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

Point = tuple[float, float]


@dataclass(frozen=True)
class AreaMoments:
    """Signed-area-free moments of a region: area, first moments and second moments."""

    area: float
    sx: float  # integral of x dA
    sy: float  # integral of y dA
    sxx: float  # integral of x^2 dA
    syy: float  # integral of y^2 dA
    sxy: float  # integral of x y dA


def ring_moments(ring: Sequence[Point]) -> AreaMoments:
    """Moments of the region a simple ring encloses, whatever its orientation."""
    a = sx = sy = sxx = syy = sxy = 0.0
    n = len(ring)
    for i in range(n):
        x0, y0 = ring[i]
        x1, y1 = ring[(i + 1) % n]
        c = x0 * y1 - x1 * y0
        a += c
        sx += (x0 + x1) * c
        sy += (y0 + y1) * c
        sxx += (x0 * x0 + x0 * x1 + x1 * x1) * c
        syy += (y0 * y0 + y0 * y1 + y1 * y1) * c
        sxy += (x0 * y1 + 2 * x0 * y0 + 2 * x1 * y1 + x1 * y0) * c
    sign = 1.0 if a >= 0 else -1.0
    return AreaMoments(
        area=sign * a / 2,
        sx=sign * sx / 6,
        sy=sign * sy / 6,
        sxx=sign * sxx / 12,
        syy=sign * syy / 12,
        sxy=sign * sxy / 24,
    )


def region_moments(outer: Sequence[Point], holes: Sequence[Sequence[Point]] = ()) -> AreaMoments:
    """Moments of the outer ring minus its holes."""
    m = ring_moments(outer)
    for h in holes:
        k = ring_moments(h)
        m = AreaMoments(
            m.area - k.area, m.sx - k.sx, m.sy - k.sy, m.sxx - k.sxx, m.syy - k.syy, m.sxy - k.sxy
        )
    return m


@dataclass(frozen=True)
class PlateInertia:
    """Mass (kg) and full inertia (kg m^2: ixx, iyy, izz, ixy, ixz, iyz) about the given COM."""

    mass: float
    inertia: tuple[float, float, float, float, float, float]


def plate_inertia(
    outer: Sequence[Point],
    holes: Sequence[Sequence[Point]],
    com: Point,
    thickness: float,
    density: float,
) -> PlateInertia:
    """Inertia of a uniform plate (coordinates and thickness in metres) about ``com``.

    The plate lies in the xy plane, centred on z = 0; the tensor is taken about the point
    (com, 0), so a user COM away from the centroid shifts it by the parallel-axis theorem.
    """
    m = region_moments(outer, holes)
    rho = density * thickness  # kg per m^2
    mass = rho * m.area
    cx, cy = com
    # Second moments about (cx, cy): integral of (x - cx)^2 dA etc.
    ixx_a = m.sxx - 2 * cx * m.sx + cx * cx * m.area
    iyy_a = m.syy - 2 * cy * m.sy + cy * cy * m.area
    ixy_a = m.sxy - cx * m.sy - cy * m.sx + cx * cy * m.area
    tz = mass * thickness * thickness / 12.0
    ixx = rho * iyy_a + tz  # about the x axis: y^2 + z^2
    iyy = rho * ixx_a + tz
    izz = rho * (ixx_a + iyy_a)
    return PlateInertia(mass=mass, inertia=(ixx, iyy, izz, -rho * ixy_a, 0.0, 0.0))
