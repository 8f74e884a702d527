"""``design sensor``: which sensor a mix needs, and what plan it then gets (docs/design.md).

For a tolerance sensor: every pair's exact critical tolerance and the mix's (the largest
tolerance at which it is recognizable, section 8.5 and Theorem 9), and the optimal plan
length as a step function of the tolerance up to it. For an LED array: the same, pitch by
pitch. Figures are for the ideal model (no rotation error); the cell's rotation error is
carried to the output so a strong-plan model can be applied later (design.md,
"Uncertainty").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from feederkit.design.critical import MixCritical, PairCritical, mix_critical_tolerance
from feederkit.design.pitches import PitchRow, pitch_rows
from feederkit.design.steps import BREAKPOINT_REL_EPS, LengthStep, length_steps
from feederkit.errors import InputError
from feederkit.mechanics.push import PushFunction

MODEL_NOTE = "ideal model: plans assume no rotation error"


def _check_mix(pfs: Sequence[PushFunction]) -> None:
    if len(pfs) < 2:
        raise InputError(
            "design sensor compares the parts of a mix: give at least two parts "
            "(one part alone is recognized with any sensor)"
        )


def _pairs_words(pairs: Sequence[PairCritical], limit: int = 5) -> str:
    words = [f"{p.a} and {p.b}" for p in pairs[:limit]]
    more = len(pairs) - limit
    text = ", ".join(words) + (f" and {more} more pairs" if more > 0 else "")
    reasons = {p.witness.reason for p in pairs if p.witness is not None}
    if len(reasons) == 1:
        text += f" ({reasons.pop()})"
    return text


@dataclass(frozen=True)
class ToleranceDesign:
    """The critical tolerances of a mix and its plan length's steps up to the mix's."""

    parts: tuple[str, ...]
    critical: MixCritical
    steps: tuple[LengthStep, ...]
    rotation_error_deg: float = 0.0

    @property
    def critical_tolerance(self) -> float | None:
        """The largest tolerance (mm) at which the mix is recognizable; None: no tolerance."""
        return self.critical.critical_tolerance

    @property
    def recognizable(self) -> bool:
        """Whether some tolerance makes the mix recognizable."""
        return self.critical_tolerance is not None

    def step_at(self, tolerance: float) -> LengthStep | None:
        """The step holding ``tolerance`` (None beyond the table)."""
        slack = BREAKPOINT_REL_EPS * abs(tolerance)
        for s in self.steps:
            if s.lo < tolerance - slack and (s.hi is None or tolerance <= s.hi + slack):
                return s
        return None

    def answer(self) -> str:
        """The design in one line."""
        x = self.critical_tolerance
        if x is None:
            return "no tolerance makes this mix recognizable: no sensor separates " + _pairs_words(
                self.critical.inseparable
            )
        step = self.step_at(x)
        text = f"this mix is recognizable with a tolerance up to {x:.6g} mm"
        if step is not None:
            text += (
                f"; with it the plan takes {step.length} operations (expected {step.expected:.4g})"
            )
        elif self.steps and self.steps[-1].hi is not None:
            text += f" (plan lengths tabulated up to {self.steps[-1].hi:.6g} mm only)"
        return text

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``design sensor --json`` for a tolerance sensor (docs/design.md)."""
        return {
            "sensor_model": "tolerance",
            "parts": list(self.parts),
            "critical_tolerance_mm": self.critical_tolerance,
            "pairs": [p.to_dict() for p in self.critical.pairs],
            "lengths": [s.to_dict() for s in self.steps],
            "uncertainty": {"rotation_error_deg": self.rotation_error_deg, "applied": False},
            "model": MODEL_NOTE,
            "answer": self.answer(),
        }


def design_tolerance(
    pfs: Sequence[PushFunction],
    *,
    max_tolerance: float | None = None,
    rotation_error_deg: float = 0.0,
) -> ToleranceDesign:
    """Critical tolerances and length steps; the steps reach the mix's critical tolerance,
    or ``max_tolerance`` (mm) when given (beyond the critical one the mix is not recognized,
    its plans end in results that name several parts)."""
    _check_mix(pfs)
    if max_tolerance is not None and not max_tolerance > 0.0:
        raise InputError(f"--max-tolerance must be a positive number of mm, got {max_tolerance}")
    critical = mix_critical_tolerance(pfs)
    up_to = max_tolerance if max_tolerance is not None else critical.critical_tolerance
    steps = length_steps(pfs, up_to, critical=critical) if up_to is not None else ()
    names = tuple(pf.part.name for pf in pfs)
    return ToleranceDesign(names, critical, steps, rotation_error_deg)


@dataclass(frozen=True)
class PitchDesign:
    """LED pitches decided one by one, and the pairs no sensor at all can separate."""

    parts: tuple[str, ...]
    noise: float
    rows: tuple[PitchRow, ...]
    critical: MixCritical
    rotation_error_deg: float = 0.0

    @property
    def critical_pitch(self) -> float | None:
        """The largest pitch of the list that makes the mix recognizable (None: none does)."""
        ok = [r.pitch for r in self.rows if r.recognizable]
        return max(ok) if ok else None

    @property
    def recognizable(self) -> bool:
        """Whether some pitch of the list makes the mix recognizable."""
        return self.critical_pitch is not None

    def answer(self) -> str:
        """The design in one line."""
        y = self.critical_pitch
        if y is None:
            text = "no LED pitch in the list makes this mix recognizable"
            if self.critical.inseparable:
                text += ": no sensor separates " + _pairs_words(self.critical.inseparable)
            else:
                worst = sorted({p for r in self.rows for p in r.unrecognizable})
                text += ": it cannot tell apart " + ", ".join(f"{a} and {b}" for a, b in worst[:5])
                text += "; try finer pitches"
            return text
        row = next(r for r in self.rows if r.pitch == y)
        return (
            f"this mix is recognizable with an LED pitch of {y:.6g} mm "
            f"(noise {self.noise:.6g} mm); with it the plan takes {row.length} operations "
            f"(expected {row.expected:.4g})"
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``design sensor --json`` for an LED array (docs/design.md)."""
        return {
            "sensor_model": "led",
            "parts": list(self.parts),
            "noise_mm": self.noise,
            "critical_pitch_mm": self.critical_pitch,
            "pitches": [r.to_dict() for r in self.rows],
            "critical_tolerance_mm": self.critical.critical_tolerance,
            "pairs": [p.to_dict() for p in self.critical.pairs],
            "uncertainty": {"rotation_error_deg": self.rotation_error_deg, "applied": False},
            "model": MODEL_NOTE,
            "answer": self.answer(),
        }


def design_pitches(
    pfs: Sequence[PushFunction],
    pitches: Sequence[float],
    *,
    noise: float = 0.0,
    rotation_error_deg: float = 0.0,
) -> PitchDesign:
    """Each pitch decided on its own (:mod:`feederkit.design.pitches`), and the pairs' exact
    critical tolerances, which name the pairs no sensor can separate."""
    _check_mix(pfs)
    if not pitches:
        raise InputError("--pitches is empty: give pitches in mm, e.g. 0.1,0.2,0.5")
    if noise < 0.0:
        raise InputError(f"--noise must be zero or a positive number of mm, got {noise}")
    rows = pitch_rows(pfs, pitches, noise)
    names = tuple(pf.part.name for pf in pfs)
    return PitchDesign(names, noise, rows, mix_critical_tolerance(pfs), rotation_error_deg)


def report_design(
    pfs: Sequence[PushFunction], rotation_error_deg: float = 0.0
) -> dict[str, Any] | None:
    """The sensor design a changeover report shows (``ToleranceDesign.to_dict``), or None for
    a single part (nothing to tell apart)."""
    if len(pfs) < 2:
        return None
    return design_tolerance(list(pfs), rotation_error_deg=rotation_error_deg).to_dict()
