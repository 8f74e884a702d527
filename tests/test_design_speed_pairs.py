"""The strong pair search's shortcuts (feederkit.design.strong.strong_pair_critical): asking
the last breakpoint first and starting above :func:`apart_up_to` find the same interval as
the plain binary search."""

from __future__ import annotations

import numpy as np

from feederkit.design.critical import last_true, last_true_top_first
from feederkit.design.strong import (
    StrongMix,
    _PairProbes,
    apart_up_to,
    gap_breakpoints,
    outcomes_cover_parts,
)
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import span
from feederkit.uncertainty import Uncertainty


def test_top_first_is_last_true():
    for count in range(0, 9):
        for answer in range(-1, count):
            for known in range(-1, answer + 1):

                def test(k, answer=answer):
                    return k <= answer

                assert last_true_top_first(count, test, known) == answer
                assert last_true(count, test, known) == answer


def _pf(rng: np.random.Generator, name: str):
    k = int(rng.integers(3, 7))
    ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, k))
    r = rng.uniform(0.6, 1.0, k) * float(rng.uniform(20.0, 40.0)) / 2.0
    pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
    return push_function(make_part(make_outline(name, pts.tolist())))


def test_no_bisimilar_cross_pair_up_to_the_apart_bound():
    rng = np.random.default_rng(7)
    mix = StrongMix([_pf(rng, f"p{i}") for i in range(4)], Uncertainty(1.0))
    bounds = []
    for a in range(4):
        for b in range(a + 1, 4):
            m = mix.pair(a, b)
            assert outcomes_cover_parts(m)
            spans = [span(s.sensed) for s in m.states]
            sa = [x for x, s in zip(spans, m.states, strict=True) if s.part == 0]
            sb = [x for x, s in zip(spans, m.states, strict=True) if s.part == 1]
            breaks = gap_breakpoints(sa, sb)
            probes = _PairProbes(m)
            bisimilar = [bool(probes.bisimilar(e)) for e in breaks]
            apart = apart_up_to(m, sa, sb, breaks)
            bounds.append(apart)
            assert not any(bisimilar[: apart + 1])
            assert bisimilar == sorted(bisimilar)  # monotone: the binary search's premise
    assert max(bounds) >= 0  # the bound says something on some pair
