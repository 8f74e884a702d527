"""Landings: every way a part lands on the belt (design.md, Landings; docs/landings.md).

This package's root holds the values and the geometry (:mod:`feederkit.landing.model`);
mesh poses are in :mod:`feederkit.landing.mesh` and planning over landings, a layer above,
in :mod:`feederkit.landing.plan`.
"""

from feederkit.landing.model import (
    DEFAULT_SIDE_PROBABILITY,
    DOWN,
    UP,
    Landing,
    check_landing_name,
    check_side_probability,
    congruence_rotations,
    congruent,
    landings_of_outline,
    merge_congruent,
    mirror_outline,
    mirror_part,
    select_landings,
)

__all__ = [
    "DEFAULT_SIDE_PROBABILITY",
    "DOWN",
    "UP",
    "Landing",
    "check_landing_name",
    "check_side_probability",
    "congruence_rotations",
    "congruent",
    "landings_of_outline",
    "merge_congruent",
    "mirror_outline",
    "mirror_part",
    "select_landings",
]
