"""The plot of ``design sensor``: plan length (and expected length) against the sensor.

matplotlib (Agg) is imported only to draw. A tolerance design is drawn as the step function
of its exact breakpoints; an LED design as one point per pitch (pitches are not ordered in
what they can tell apart, :mod:`feederkit.design.pitches`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

from feederkit.design.sensor import PitchDesign, ToleranceDesign
from feederkit.errors import InputError
from feederkit.reports.partplot import drawable
from feederkit.words import shown_tolerance

PLOT_SUFFIXES = (".png", ".svg")


def plot_design(design: ToleranceDesign | PitchDesign, path: str | Path) -> Path:
    """Draw the design's lengths to ``path`` (.png or .svg); InputError for another suffix."""
    out = Path(path)
    if out.suffix.lower() not in PLOT_SUFFIXES:
        raise InputError(f"{out}: the plot is written as .png or .svg")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a glyph the font lacks is drawn escaped (titles)
            if isinstance(design, ToleranceDesign):
                _tolerance(ax, design)
            else:
                _pitches(ax, design)
            ax.set_ylabel("operations")
            ax.grid(True, alpha=0.3)
            if ax.get_legend_handles_labels()[0]:  # none when there is no step to draw
                ax.legend(loc="upper left")
            fig.tight_layout()
            fig.savefig(out)
    finally:
        plt.close(fig)
    return out


def _tolerance(ax, design: ToleranceDesign) -> None:
    steps = design.steps
    if not steps:
        words = ("no tolerance makes this mix recognizable" if design.complete
                 else "the length table was not built within the limit")  # fmt: skip
        ax.text(0.5, 0.5, words, ha="center", transform=ax.transAxes)
        return
    top = steps[-1].hi if steps[-1].hi is not None else 2.0 * steps[-1].lo
    drawn = False
    for s in steps:
        hi = s.hi if s.hi is not None else top
        if s.length is None or s.expected is None:  # no strong plan on this step
            ax.axvspan(s.lo, hi, color="C3", alpha=0.15, label="no strong plan")
            continue
        ax.hlines(s.length, s.lo, hi, colors="C0", label=None if drawn else "length (worst case)")
        ax.plot([hi], [s.length], "o", color="C0")  # the closed right end
        ax.plot([hi], [s.expected], "x", color="C1", label=None if drawn else
                "expected, at the step's end")  # fmt: skip
        drawn = True
    x = design.critical_tolerance
    if x is not None:
        label = f"critical tolerance {shown_tolerance(x)} mm"  # rounded down: it works
        ax.axvline(x, color="C3", linestyle="--", label=label)
    u = design.uncertainty
    ax.set_xlabel("sensor tolerance (mm)" + ("" if u.is_ideal else
                  f"; strong plans, rotation error {u.rotation_error_deg:g} deg"))  # fmt: skip
    names = drawable(", ".join(design.parts[:4]) + (", ..." if len(design.parts) > 4 else ""))[0]
    ax.set_title(f"optimal plan length by sensor tolerance ({names})")


def _pitches(ax, design: PitchDesign) -> None:
    ok = [r for r in design.rows if r.recognizable]
    bad = [r for r in design.rows if not r.recognizable]
    if ok:
        ax.plot([r.pitch for r in ok], [r.length for r in ok], "o", color="C0",
                label="length (worst case)")  # fmt: skip
        ax.plot([r.pitch for r in ok], [r.expected for r in ok], "x", color="C1",
                label="expected")  # fmt: skip
    if bad:
        ax.plot([r.pitch for r in bad], [0 for _ in bad], "s", color="C3",
                label="not recognizable")  # fmt: skip
    ax.set_xlabel(f"LED pitch (mm), noise {design.noise:.4g} mm")
    ax.set_title("optimal plan length by LED pitch")
