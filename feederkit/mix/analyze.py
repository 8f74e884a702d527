"""A catalog's (or a mix's) analysis: behaviour classes, counts, unrecognizable pairs (section 8).

Without a sensor no two parts can be recognized (section 8.6): the pairs are not listed, only
the classes (parts with one push function share a sensorless plan, Corollary 5).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mix.behaviour import BehaviourClass, push_classes, push_diameter_classes
from feederkit.mix.pairs import PairWitness, candidate_pairs, unrecognizable_pairs
from feederkit.mix.signatures import ANGLE_TOL_DEG, LENGTH_TOL_MM, signature
from feederkit.mix.strongpairs import (
    check_alone,
    check_strong_pair,
    physical_mechanics,
    reading_pairs,
)
from feederkit.sensors import Sensor
from feederkit.uncertainty import IDEAL, Uncertainty, check_for_part


@dataclass(frozen=True)
class MixAnalysis:
    """Classes of a set of parts and, with a sensor, every pair no plan can tell apart.

    ``pairs`` is None without a sensor (every pair is unrecognizable). ``candidates`` is how
    many pairs the cheap tests (diameters and landing profiles,
    :func:`~feederkit.mix.pairs.candidate_pairs`) left for the exact fixpoint. ``seconds``
    times each stage. Under a declared uncertainty the pairs told apart whose states may read
    alike are checked again for strong plans (``strong_pairs``): section 8's test is the
    ideal model's.
    """

    names: tuple[str, ...]
    sensor: Sensor
    angle_tol_deg: float
    length_tol_mm: float
    push_classes: tuple[BehaviourClass, ...]
    push_diameter_classes: tuple[BehaviourClass, ...]
    pairs: tuple[PairWitness, ...] | None
    candidates: int
    seconds: dict[str, float] = field(default_factory=dict)
    uncertainty: Uncertainty = IDEAL
    """The uncertainty (rotation error, shape and COM tolerances) the pairs were checked
    under besides the ideal model."""
    strong_pairs: tuple[PairWitness, ...] = ()
    """Pairs told apart on the ideal model that no strong plan tells apart under
    ``uncertainty`` (:func:`~feederkit.mix.strongpairs.check_strong_pair`)."""
    undecided: int = 0
    """Pairs whose check under ``uncertainty`` ran out of sets."""
    alone: tuple[tuple[int, tuple[int, ...]], ...] = ()
    """The members no strong plan orients even alone under ``uncertainty``, each with its
    states no strong plan tells apart (:func:`~feederkit.mix.strongpairs.check_alone`): every
    mix holding one fails, so its pairs are not checked."""
    undecided_alone: int = 0
    """Members whose check alone ran out of sets (their pairs are checked)."""
    uncertain_pairs: int = 0
    """Pairs to check under ``uncertainty`` (those that may read alike, less those the exact
    analysis or a member's failure alone decides): ``undecided`` counts among them."""
    cut: bool = False
    """The deadline ended the checks under ``uncertainty``: the members and pairs left are
    counted in ``undecided_alone`` and ``undecided`` (not checked)."""

    @property
    def shared_push(self) -> list[BehaviourClass]:
        """Push classes with more than one part."""
        return [c for c in self.push_classes if c.size > 1]

    @property
    def shared_push_diameter(self) -> list[BehaviourClass]:
        """Push-diameter classes with more than one part."""
        return [c for c in self.push_diameter_classes if c.size > 1]

    def counts(self) -> dict[str, int | None]:
        """The numbers a summary shows."""
        n = len(self.names)
        return {
            "parts": n,
            "push_classes": len(self.push_classes),
            "push_diameter_classes": len(self.push_diameter_classes),
            "parts_sharing_a_push_function": sum(c.size for c in self.shared_push),
            "parts_sharing_a_push_diameter_function": sum(
                c.size for c in self.shared_push_diameter
            ),
            "candidate_pairs": self.candidates,
            "unrecognizable_pairs": n * (n - 1) // 2 if self.pairs is None else len(self.pairs),
            "apart_only_on_the_ideal_model": len(self.strong_pairs),
            "pairs_checked_under_uncertainty": self.uncertain_pairs,
            "undecided_pairs": self.undecided,
            "no_strong_plan_alone": len(self.alone),
            "undecided_alone": self.undecided_alone,
        }

    def to_dict(self) -> dict[str, Any]:
        """As JSON: counts, classes with more than one member (by name), pairs with witnesses."""

        def cls(c: BehaviourClass) -> dict[str, Any]:
            return {
                "members": [self.names[i] for i in c.members],
                "phases_deg": [round(a, 9) for a in c.phases_deg],
            }

        return {
            "sensor": self.sensor.to_dict(),
            # The exact analysis of section 8 is the ideal model's; the pairs checked again
            # under the declared uncertainty say which (design.md).
            "uncertainty": self.uncertainty.to_dict(),
            "tolerances": {"angle_deg": self.angle_tol_deg, "diameter_mm": self.length_tol_mm},
            "counts": self.counts(),
            "push_classes": [cls(c) for c in self.shared_push],
            "push_diameter_classes": [cls(c) for c in self.shared_push_diameter],
            "all_pairs_unrecognizable": self.pairs is None and len(self.names) > 1,
            "unrecognizable_pairs": [] if self.pairs is None else [w.to_dict() for w in self.pairs],
            "apart_only_on_the_ideal_model": [w.to_dict() for w in self.strong_pairs],
            "no_strong_plan_alone": [
                {"part": self.names[i], "states": list(states)} for i, states in self.alone
            ],
            "cut_by_time_limit": self.cut,
        }


def analyze_mix(
    pfs: Sequence[PushFunction],
    sensor: Sensor,
    *,
    angle_tol: float = ANGLE_TOL_DEG,
    length_tol: float = LENGTH_TOL_MM,
    uncertainty: Uncertainty | None = None,
    deadline: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> MixAnalysis:
    """Classes (push, push-diameter) and, with a sensor, the exact unrecognizable pairs; under
    a declared ``uncertainty`` (rotation error, shape and COM tolerances: design.md), also
    the pairs only the ideal model tells apart, each pair that may read alike
    (:func:`~feederkit.mix.strongpairs.reading_pairs`, the physical states' diameter
    intervals under a shape or COM tolerance) checked for strong plans on its own, after
    each member alone (:func:`~feederkit.mix.strongpairs.check_alone`): a pair holding a
    member no strong plan orients alone is that member's failure, not the pair's.

    The checks under the uncertainty stop at ``deadline`` (a ``time.monotonic()`` instant;
    None: none), each check run whole: the members and pairs left are counted undecided and
    ``cut`` says so. ``progress(done, total)`` is called as they go (members, then pairs).

    Raises InputError naming the part when a tolerance is too large for one
    (:func:`~feederkit.uncertainty.check_for_part`), before any work, as ``plan`` does."""
    unc = IDEAL if uncertainty is None else uncertainty
    if not unc.is_ideal:
        for pf in pfs:
            check_for_part(unc, pf.part)
    t0 = time.perf_counter()
    sigs = [signature(pf) for pf in pfs]
    t1 = time.perf_counter()
    pc = push_classes(sigs, angle_tol)
    pdc = push_diameter_classes(sigs, angle_tol, length_tol)
    t2 = time.perf_counter()
    if not sensor.informative:
        pairs, cand = None, len(pfs) * (len(pfs) - 1) // 2
    else:
        todo = candidate_pairs(pfs, sensor)
        cand = len(todo)
        pairs = tuple(unrecognizable_pairs(pfs, sensor, todo, signatures=sigs))
    t3 = time.perf_counter()
    strong: list[PairWitness] = []
    undecided = undecided_alone = 0
    alone: list[tuple[int, tuple[int, ...]]] = []
    mechs = None if unc.is_ideal else physical_mechanics(pfs, unc)  # once for every check
    # The parts' own widths, as make_plan reads each state (once for every check).
    offs = [] if mechs is None else part_offsets(pfs)
    cut = False
    checked: list[tuple[int, int]] = []

    def late() -> bool:
        return deadline is not None and time.monotonic() >= deadline

    if mechs is not None:
        for i, pf in enumerate(pfs):
            if progress is not None:
                progress(i, len(pfs))
            if cut or late():
                cut = True
                undecided_alone += 1
                continue
            verdict = check_alone(pf, sensor, unc, mechanics=mechs[i], offsets=offs[i])
            undecided_alone += not verdict.decided
            if verdict.decided and not verdict.orients:
                alone.append((i, verdict.states))
    if pairs is not None and mechs is not None:
        # A mix holding a member no strong plan orients alone fails whatever the other part.
        confused = {(w.index_a, w.index_b) for w in pairs}
        hopeless = {i for i, _states in alone}
        near = reading_pairs(pfs, sensor, unc, mechanics=mechs, offsets=offs)
        checked = [
            (i, j)
            for i, j in sorted(set(todo) | near)
            if (i, j) not in confused and i not in hopeless and j not in hopeless
        ]
        for k, (i, j) in enumerate(checked):
            if progress is not None:
                progress(len(pfs) + k, len(pfs) + len(checked))
            if cut or late():
                cut = True
                undecided += 1
                continue
            check = check_strong_pair(
                pfs[i],
                pfs[j],
                sensor,
                unc,
                mechanics=[mechs[i], mechs[j]],
                offsets=[offs[i], offs[j]],
            )
            if not check.decided:
                undecided += 1
            elif check.witness is not None:
                strong.append(replace(check.witness, index_a=i, index_b=j))
    return MixAnalysis(
        names=tuple(pf.part.name for pf in pfs),
        sensor=sensor,
        angle_tol_deg=angle_tol,
        length_tol_mm=length_tol,
        push_classes=tuple(pc),
        push_diameter_classes=tuple(pdc),
        pairs=pairs,
        candidates=cand,
        seconds={
            "signatures": t1 - t0,
            "classes": t2 - t1,
            "pairs": t3 - t2,
            "strong_pairs": time.perf_counter() - t3,
        },
        uncertainty=unc,
        strong_pairs=tuple(strong),
        undecided=undecided,
        alone=tuple(alone),
        undecided_alone=undecided_alone,
        uncertain_pairs=len(checked),
        cut=cut,
    )
