"""A "no strong plan" message names each pair of states once.

A D-shape at --shape-tolerance 0.01 was told "no strong plan tells apart poses that do not
look alike (d/up state 0 with d/up state 1/.../12; d/up state 0 with d/up state 1/.../12)":
a wandering state and its twin (planning.wandering) carry one name.
"""

from __future__ import annotations

from types import SimpleNamespace

from feederkit.planning.lumping import WORDS_PAIRS, _listed


def _machine(states):
    return SimpleNamespace(
        part_names=("d/up",),
        states=[SimpleNamespace(part=0, ideal_states=ids) for ids in states],
    )


def test_a_state_and_its_twin_are_named_once() -> None:
    m = _machine([(0,), (1, 2, 3), (1, 2, 3)])  # state 2 is state 1's twin
    assert _listed(m, [(0, 1), (0, 2)]) == "d/up state 0 with d/up state 1/2/3"


def test_more_pairs_than_named_are_counted_once_each() -> None:
    m = _machine([(k,) for k in range(WORDS_PAIRS + 3)])
    pairs = [(0, k) for k in range(1, WORDS_PAIRS + 3)] * 2
    assert _listed(m, pairs).endswith("; and 2 more pairs")
