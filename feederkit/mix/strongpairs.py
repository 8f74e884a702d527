"""Pairs of parts that section 8 tells apart on the ideal model but no strong plan does under
a declared uncertainty (design.md, "Uncertainty").

The exact test of section 8 assumes exact rotations: two parts that differ only by resting
ranges a fraction of a degree apart (a near-duplicate drawn 0.05 mm longer) are told apart
there, and confused by every plan at a rotation error of 1 degree. For one pair of parts,
:func:`strong_pair_witness` builds the machine of the two under the uncertainty and takes
the pairs of their physical states that no strong plan resolves: the bisimilar ones and the
unresolvable ones (:func:`feederkit.planning.lumping.unresolvable_pairs`), across the two
parts: the pairs ``changeover compile`` reports for a mix of the two
(:func:`feederkit.mix.changeover.strong_witnesses`; the states named may differ, compile
naming those its whole plan lumps). :func:`reading_pairs` gives the pairs worth checking.
"""

from __future__ import annotations

from collections.abc import Sequence

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

UNDECIDED = "undecided"
"""What :func:`strong_pair_witness` answers when its search ran out of sets."""


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


def strong_pair_witness(
    a: PushFunction,
    b: PushFunction,
    sensor: Sensor,
    uncertainty: Uncertainty,
    deadline: Deadline | None = None,
) -> PairWitness | None | str:
    """The witness that no strong plan tells ``a`` from ``b`` under ``uncertainty`` with
    ``sensor`` (its states: the ideal members of the physical states confused), None when
    some strong plan can, :data:`UNDECIDED` when the search ran out of sets. Timeout when
    ``deadline`` passes."""
    machine, _old = by_diameter(build_machine([a, b], sensor, uncertainty))
    found = unresolvable_pairs(Problem(machine, "exact", 0.0), deadline)
    if found is None:
        return UNDECIDED
    states = machine.states
    across = [(i, j) for i, j in found if states[i].part != states[j].part]
    witnesses = strong_witnesses(machine, across)
    return witnesses[0] if witnesses else None


__all__ = ["UNDECIDED", "reading_pairs", "strong_pair_witness"]
