"""Pairs of parts that section 8 tells apart on the ideal model but no strong plan does under
a declared uncertainty (design.md, "Uncertainty").

The exact test of section 8 assumes exact rotations: two parts that differ only by resting
ranges a fraction of a degree apart (a near-duplicate drawn 0.05 mm longer) are told apart
there, and confused by every plan at a rotation error of 1 degree. For one pair of parts,
:func:`check_strong_pair` builds the machine of the two under the uncertainty and takes
the pairs of their physical states that no strong plan resolves: the bisimilar ones and the
unresolvable ones (:func:`feederkit.planning.lumping.unresolvable_pairs`), across the two
parts: the pairs ``changeover compile`` reports for a mix of the two
(:func:`feederkit.mix.changeover.strong_witnesses`; the states named may differ, compile
naming those its whole plan lumps). :func:`reading_pairs` gives the pairs worth checking.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.machine.build import build_machine
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import strong_witnesses
from feederkit.mix.pairs import PairWitness
from feederkit.planning.budget import Deadline
from feederkit.planning.lumping import unresolvable_pairs
from feederkit.planning.problem import Problem
from feederkit.planning.reindex import by_diameter
from feederkit.sensors import Sensor
from feederkit.uncertainty import Uncertainty


@dataclass(frozen=True)
class StrongPairCheck:
    """Whether some strong plan tells two parts apart: ``witness`` the pair of their states
    no strong plan resolves (None when one does), ``decided`` False when the search ran out
    of sets before it knew (``witness`` is then None)."""

    witness: PairWitness | None
    decided: bool = True


def reading_pairs(pfs: Sequence[PushFunction], sensor: Sensor) -> set[tuple[int, int]]:
    """The pairs ``(i, j)``, ``i < j``, of parts with some states that may read alike (in one
    connected component of the sensor's overlap relation over all their states, Definition
    10): the only pairs a strong plan may fail to tell apart. The ideal analysis's
    candidates are fewer (its grid looks at the smallest and largest diameters), since on
    the ideal model a plan can always rotate into the states that read apart; under a
    rotation error it may not reach them (a bar standing on its end)."""
    owner = [k for k, pf in enumerate(pfs) for _ in pf.states]
    diameters = [s.diameter for pf in pfs for s in pf.states]
    out: set[tuple[int, int]] = set()
    for component in sensor.indistinguishable_sets(diameters):
        parts = sorted({owner[i] for i in component})
        out.update((a, b) for x, a in enumerate(parts) for b in parts[x + 1 :])
    return out


def check_strong_pair(
    a: PushFunction,
    b: PushFunction,
    sensor: Sensor,
    uncertainty: Uncertainty,
    deadline: Deadline | None = None,
) -> StrongPairCheck:
    """Whether a strong plan tells ``a`` from ``b`` under ``uncertainty`` with ``sensor``;
    where none does, the witness (its states: the ideal members of the physical states
    confused). Timeout when ``deadline`` passes."""
    machine, _old = by_diameter(build_machine([a, b], sensor, uncertainty))
    found = unresolvable_pairs(Problem(machine, "exact", 0.0), deadline)
    if found is None:
        return StrongPairCheck(None, decided=False)
    states = machine.states
    across = [(i, j) for i, j in found if states[i].part != states[j].part]
    witnesses = strong_witnesses(machine, across)
    return StrongPairCheck(witnesses[0] if witnesses else None)


__all__ = ["StrongPairCheck", "check_strong_pair", "reading_pairs"]
