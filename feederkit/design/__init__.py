"""Sensor design: which sensor a product mix needs, and the plan it then gets.

- :mod:`~feederkit.design.critical`: exact critical tolerances of pairs and mixes (binary
  search over the breakpoints ``|d - d'| / 2`` with the exact pair test, Theorem 9);
- :mod:`~feederkit.design.steps`: the optimal plan length as a step function of the
  tolerance, with its exact breakpoints (``LengthOracle``: the planner's length alone);
- :mod:`~feederkit.design.strong`: the same for strong plans at a declared uncertainty
  (breakpoints of diameter intervals, pairs decided by exact solvability, lengths in
  segments of constant goal);
- :mod:`~feederkit.design.pitches`: LED arrays, pitch by pitch;
- :mod:`~feederkit.design.sensor`: the ``design sensor`` answer at the declared uncertainty
  (docs/design.md);
- :mod:`~feederkit.design.limit`: its time limit (exact or nothing: ``DesignTimeout``) and
  progress callback.
"""

from feederkit.design.critical import (
    MixCritical,
    PairCritical,
    mix_critical_tolerance,
    pair_breakpoints,
    pair_critical_tolerance,
)
from feederkit.design.limit import DesignTimeout
from feederkit.design.pitches import PitchRow, parse_pitches, pitch_rows
from feederkit.design.sensor import (
    PitchDesign,
    ToleranceDesign,
    design_pitches,
    design_tolerance,
    report_design,
    report_design_or_warning,
)
from feederkit.design.steps import LengthOracle, LengthStep, length_steps, mix_breakpoints
from feederkit.design.strong import (
    StrongLengthOracle,
    StrongMix,
    strong_length_steps,
    strong_mix_critical,
    strong_pair_critical,
)

__all__ = [
    "DesignTimeout",
    "LengthOracle",
    "LengthStep",
    "MixCritical",
    "PairCritical",
    "PitchDesign",
    "PitchRow",
    "StrongLengthOracle",
    "StrongMix",
    "ToleranceDesign",
    "design_pitches",
    "design_tolerance",
    "length_steps",
    "mix_breakpoints",
    "mix_critical_tolerance",
    "pair_breakpoints",
    "pair_critical_tolerance",
    "parse_pitches",
    "pitch_rows",
    "report_design",
    "report_design_or_warning",
    "strong_length_steps",
    "strong_mix_critical",
    "strong_pair_critical",
]
