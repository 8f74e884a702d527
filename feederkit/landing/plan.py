"""Plan a part over its landings: each landing is one member of a mix (section 8.5).

The paper's multi-part planner orients a product mix and tells its parts apart; the
landings of one part (``up``/``down``, mesh poses) are such members: the plan's results name
the landing's part (``PART/up``, ``PART/pose-2``), which :class:`LandingPlan` maps back to
``(part, landing, state)``. Landings that no plan can tell apart (section 8.4) are reported
as the mix's indistinguishable pairs, and a result leaf then lists several landings. The
planners and the plan file are used unchanged (docs/landings.md says what is left for them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from feederkit.errors import InputError
from feederkit.landing.model import Landing
from feederkit.mechanics.push import push_function
from feederkit.mix.changeover import plan_mix
from feederkit.mix.pairs import PairWitness
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import plan_from_dict
from feederkit.plans.make import MadePlan
from feederkit.sensors import Sensor
from feederkit.uncertainty import Uncertainty


@dataclass(frozen=True)
class LandingResult:
    """One answer of a plan over landings: ``part`` lying in ``landing``, resting in ``state``
    (a stable state of that landing's outline) at ``pose_deg``."""

    part: str
    landing: str
    state: int
    pose_deg: float

    def to_dict(self) -> dict[str, object]:
        """The plan file version 2 result entry (design.md)."""
        return {
            "part": self.part,
            "landing": self.landing,
            "state": self.state,
            "pose_deg": self.pose_deg,
        }


@dataclass(frozen=True)
class LandingPair:
    """Two landings no plan can tell apart, and the witness of the mix analysis."""

    a: Landing
    b: Landing
    witness: PairWitness


@dataclass(frozen=True)
class LandingPlan:
    """A verified plan over landings, its landings in plan-part order, and the pairs of
    landings no plan can tell apart."""

    landings: tuple[Landing, ...]
    made: MadePlan
    indistinguishable: tuple[LandingPair, ...]

    def landing_of(self, plan_part: str) -> Landing:
        """The landing whose part the plan calls ``plan_part`` (``PART/LANDING``)."""
        for x in self.landings:
            if x.label == plan_part:
                return x
        raise InputError(f"the plan has no landing part {plan_part!r}")

    def resolve(self, entry: Mapping[str, object]) -> LandingResult:
        """A plan file result entry (``{"part": "PART/LANDING", "state", "pose_deg"}``) as
        the part, its landing and its state."""
        x = self.landing_of(str(entry["part"]))
        return LandingResult(x.part_name, x.name, int(entry["state"]), float(entry["pose_deg"]))

    def leaves(self) -> tuple[tuple[LandingResult, ...], ...]:
        """Every result leaf of the plan (pre-order) with its entries resolved."""
        plan = plan_from_dict(self.made.plan)
        return tuple(
            tuple(
                self.resolve({"part": e.part, "state": e.state, "pose_deg": e.pose_deg})
                for e in leaf.results
            )
            for leaf in plan.leaves()
        )


def plan_landings(
    landings: Sequence[Landing],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
) -> LandingPlan:
    """Plan over ``landings`` (of one part, or of several) as the members of one mix.

    Every landing's part becomes a push function for
    :func:`feederkit.mix.changeover.plan_mix` (which goes through
    :func:`feederkit.plans.make.make_plan` and verifies the plan); ``uncertainty`` defaults
    to design.md's. The landings' probabilities are not used by the planners yet: the plan
    is a strong plan for every landing. Raises InputError for no landings or two with the
    same label.
    """
    members = tuple(landings)
    if not members:
        raise InputError("no landings to plan for")
    labels = [x.label for x in members]
    dup = sorted({n for n in labels if labels.count(n) > 1})
    if dup:
        raise InputError(f"landing {dup[0]} is given twice")
    pfs = [push_function(x.part) for x in members]
    made, pairs = plan_mix(pfs, sensor, options, uncertainty=uncertainty)
    by_label = {x.label: x for x in members}
    found = tuple(LandingPair(by_label[w.part_a], by_label[w.part_b], w) for w in pairs)
    return LandingPlan(members, made, found)
