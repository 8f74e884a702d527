"""Strong verification reads like the ideal verifier: touching open reading ends do not overlap.

At a tolerance equal to half the difference of two diameters the two states' open reading
intervals touch; in floating point ``d1 - e`` and ``d2 + e`` may then differ by an ulp the
wrong way. The planner's reading cells say they do not overlap, and so must the verifier
(docs/conventions.md, numeric tolerances).
"""

from __future__ import annotations

import numpy as np
from test_design_critical import random_pf

from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor


def test_a_mix_planned_at_a_breakpoint_tolerance_verifies_as_a_strong_plan() -> None:
    rng = np.random.default_rng(302)
    while True:
        pfs = [random_pf(rng, f"t2p{i}") for i in range(3)]
        if sum(pf.n for pf in pfs) <= 9:
            break
    d = sorted(s.diameter for pf in pfs for s in pf.states)
    # The breakpoint found by the sensor design search for this mix: |10.3444 - 3.9679| / 2.
    e = 3.188271131790178
    assert any(abs(abs(a - b) / 2.0 - e) < 1e-12 for a in d for b in d)
    made = make_plan(pfs, ToleranceSensor(e))
    assert made.result.length >= 2


def test_narrowing_moves_only_open_ends() -> None:
    s = ToleranceSensor(1.0)
    assert s.narrowed(1e-6).tolerance == 1.0 - 1e-6
    assert s.narrowed(5.0).tolerance == 0.5


def test_an_ideal_plan_at_a_breakpoint_tolerance_verifies() -> None:
    """The ideal verifier reads the same way: at e = (12.3912 - 3.3246) / 2 the two states'
    open intervals touch and overlap by an ulp in floats (d2 - e < d1 + e)."""
    from feederkit.uncertainty import IDEAL

    rng = np.random.default_rng(304)
    while True:
        pfs = [random_pf(rng, f"t4p{i}") for i in range(3)]
        if sum(pf.n for pf in pfs) <= 9:
            break
    made = make_plan(pfs, ToleranceSensor(4.533321953052435), uncertainty=IDEAL)
    assert made.report.ok
