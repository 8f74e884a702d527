"""The report's sensor design section: which sensor the mix needs (docs/design.md).

It draws the JSON of ``feederkit design sensor --json`` (``ToleranceDesign.to_dict`` or
``PitchDesign.to_dict``, computed by the caller: the report never plans): the one-line
answer, the pairs' critical tolerances (Theorem 9), the plan length as a step function of
the tolerance (or per LED pitch) as a table, and the same as an inline SVG step plot.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.errors import InputError
from feederkit.reports.svgkit import esc, num
from feederkit.sensors import LED_EDGE_REL, LedSensor, Sensor
from feederkit.words import shown_tolerance

WIDTH, HEIGHT, PAD = 520, 220, 44
"""The plot's size and its left/bottom padding (px)."""

MAX_PAIRS = 12
"""Pairs listed in the table, tightest first (the rest are counted)."""


def design_section(design: Mapping[str, Any], sensor: Sensor | None = None) -> str:
    """The sensor design as an HTML section (answer, pairs, steps table and plot). A
    tolerance design shown for a plan read by an LED array (``sensor``) also says it in the
    array's terms (:func:`led_terms`) and gives each step its pitches."""
    if not isinstance(design, Mapping) or design.get("sensor_model") not in ("tolerance", "led"):
        raise InputError("the sensor design must be the JSON of 'feederkit design sensor'")
    answer = esc(design.get("answer", ""))
    pairs = _pairs_table(design.get("pairs") or [])
    cut = ""
    if design.get("stopped"):
        cut = (
            '<p class="banner caution" id="design-cut-short">Cut short: the sensor design '
            "stopped at its time limit (the command's --time-limit), so this section shows "
            "only what it decided by then (the line above). <code>feederkit design sensor "
            "--time-limit S</code> decides it with the time it needs.</p>"
        )
    led = sensor if isinstance(sensor, LedSensor) else None
    terms = ""
    if led is not None and design["sensor_model"] == "tolerance":
        terms = f'<p id="led-terms">{esc(led_terms(led, design.get("critical_tolerance_mm")))}</p>'
    if design["sensor_model"] == "tolerance" and not design.get("lengths"):
        table = plot = ""  # no length table: the design was cut short (or reaches no step)
    elif design["sensor_model"] == "tolerance":
        rows = [
            (r["tolerance_mm"][0], r["tolerance_mm"][1], r["length"], r["expected"])
            for r in design.get("lengths") or []
        ]
        table = _steps_table(rows, led)
        plot = _step_plot(rows, design.get("critical_tolerance_mm"))
    else:
        table = _pitch_table(design.get("pitches") or [])
        plot = ""
    note = esc(design.get("model", ""))
    return (
        '<section id="sensor-design"><h2>Sensor design</h2>'
        f'<p><strong>{answer}</strong></p>{terms}{cut}<p class="muted">{note}</p>'
        f"{plot}{table}{pairs}</section>"
    )


LED_HALF = 0.5 + LED_EDGE_REL
"""An LED array of pitch p and noise e reads diameters as finely as a tolerance of
``LED_HALF * p + e``: :func:`led_tolerance`."""


def led_tolerance(sensor: LedSensor) -> float:
    """The tolerance (mm) an LED array reads diameters as finely as. A count of c beams
    leaves the diameter in ``(c p - e', (c + 1) p + e']`` (:meth:`LedSensor.counts`, ``e'``
    the noise plus the beam-edge slack ``LED_EDGE_REL * p``), so within ``p / 2 + e'`` of
    ``(c + 1/2) p``: every plan that is strong for a tolerance sensor of at least that is
    strong for the array, read at ``(c + 1/2) p`` (section 5, a reading consistent with
    fewer diameters)."""
    return LED_HALF * sensor.pitch + sensor.noise


def led_pitch(tolerance: float, noise: float) -> float | None:
    """The pitch (mm) of an array of alignment noise ``noise`` that reads as finely as
    ``tolerance`` (:func:`led_tolerance` inverted); None when the noise alone reads coarser."""
    if tolerance <= noise:
        return None
    return (tolerance - noise) / LED_HALF


def _down(x: float, digits: int = 4) -> str:
    """``x`` with ``digits`` significant digits, rounded down (a pitch bound is not
    overstated by more than the beam-edge slack, ``LED_EDGE_REL``, which it forgives)."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return f"{math.floor(x * scale * (1.0 + 10.0 * LED_EDGE_REL)) / scale:.{digits}g}"


def led_terms(sensor: LedSensor, critical: float | None) -> str:
    """The design for a plan read by an LED array, in the array's terms: the tolerance the
    array reads as (:func:`led_tolerance`) against the mix's critical tolerance, and the
    coarsest pitch at the array's noise that reads as finely. It is a bound: beam grids of
    different pitches are not nested, so a coarser pitch may recognize the mix too
    (docs/design.md; ``feederkit design sensor --pitches`` decides each pitch)."""
    p, e = sensor.pitch, sensor.noise
    reads = led_tolerance(sensor)
    text = (
        f"In this plan's LED array's terms (pitch {num(p, 6)} mm, noise {num(e, 6)} mm): an "
        "array reads diameters as finely as a tolerance of half its pitch plus its noise, so "
        f"this one reads as {num(reads, 4)} mm"
    )
    if critical is None:
        return text + "."
    coarsest = led_pitch(critical, e)
    if reads < critical:
        text += f", within the {shown_tolerance(critical)} mm that keeps the mix recognizable"
    else:
        text += (
            f", not within the {shown_tolerance(critical)} mm up to which this design keeps the "
            "mix recognizable"
        )
    if coarsest is None:
        text += f"; at a noise of {num(e, 6)} mm no pitch reads that finely"
    else:
        text += f"; at this noise every pitch below {_down(coarsest)} mm keeps it recognizable"
    return text + (
        "; other pitches may too (beam grids of different pitches are not nested): feederkit "
        "design sensor --pitches decides each on its own."
    )


def _pairs_table(pairs: Sequence[Mapping[str, Any]]) -> str:
    if not pairs:
        return ""

    def key(p: Mapping[str, Any]) -> float:
        x = p.get("critical_tolerance_mm")
        return -1.0 if x is None else float(x)

    shown = sorted(pairs, key=key)[:MAX_PAIRS]
    rows = "".join(
        f"<tr><td>{esc(p['a'])}</td><td>{esc(p['b'])}</td><td>"
        + (
            "none: no sensor separates them"
            if p.get("critical_tolerance_mm") is None
            else f"{shown_tolerance(float(p['critical_tolerance_mm']))} mm"
        )
        + "</td></tr>"
        for p in shown
    )
    more = len(pairs) - len(shown)
    extra = f'<p class="muted">and {more} more pairs</p>' if more > 0 else ""
    return (
        '<table class="design-pairs"><caption>Critical tolerance of each pair (the largest at '
        "which they still read apart), tightest first</caption>"
        "<tr><th>part A</th><th>part B</th><th>critical tolerance</th></tr>"
        f"{rows}</table>{extra}"
    )


def _pitch_cell(lo: float, hi: float | None, led: LedSensor) -> str:
    """The pitches of ``led``'s noise that read as finely as a tolerance in ``(lo, hi]``
    (:func:`led_pitch`), and a mark on the step that holds ``led`` itself."""
    top = None if hi is None else led_pitch(hi, led.noise)
    bottom = led_pitch(lo, led.noise)
    if hi is not None and top is None:
        cell = "none at this noise"
    elif top is None:
        cell = "any" if bottom is None else f"above {_down(bottom)} mm"
    elif bottom is None:
        cell = f"below {_down(top)} mm"
    else:
        cell = f"{_down(bottom)} to {_down(top)} mm"
    reads = led_tolerance(led)
    if lo < reads and (hi is None or reads <= hi):
        cell += f" <strong>(this plan's array: {num(led.pitch, 6)} mm)</strong>"
    return f"<td>{cell}</td>"


def _steps_table(
    rows: Sequence[tuple[float, float | None, int | None, float | None]],
    led: LedSensor | None = None,
) -> str:
    """The length steps as a table; for a plan read by ``led``, each step's pitches at its
    noise (an array reading as finely needs at most that step's length)."""
    body = "".join(
        f"<tr><td>{shown_tolerance(lo)} &lt; tolerance &le; "
        f"{'&infin;' if hi is None else shown_tolerance(hi)} mm</td>"
        + ("" if led is None else _pitch_cell(lo, hi, led))
        + (
            '<td colspan="2">no strong plan</td></tr>'
            if length is None
            else f"<td>{length}</td><td>{num(expected, 4)}</td></tr>"
        )
        for lo, hi, length, expected in rows
    )
    pitch = (
        ""
        if led is None
        else f"<th>LED pitch reading as finely (noise {num(led.noise, 6)} mm)</th>"
    )
    return (
        '<table class="design-steps"><caption>Optimal plan length against the sensor '
        f"tolerance</caption><tr><th>tolerance</th>{pitch}<th>length (operations)</th>"
        "<th>expected operations at the upper end (parts equally likely, uniform start "
        f"orientation)</th></tr>{body}</table>"
    )


def _pitch_table(rows: Sequence[Mapping[str, Any]]) -> str:
    body = "".join(
        f"<tr><td>{num(float(r['pitch_mm']), 6)} mm</td>"
        f"<td>{'yes' if r.get('recognizable') else 'no'}</td>"
        f"<td>{'' if r.get('length') is None else esc(r['length'])}</td>"
        f"<td>{'' if r.get('expected') is None else num(float(r['expected']), 4)}</td></tr>"
        for r in rows
    )
    return (
        '<table class="design-steps"><caption>LED pitches, each decided on its own</caption>'
        "<tr><th>pitch</th><th>recognizable</th><th>length</th><th>expected operations "
        "(parts equally likely, uniform start orientation)</th>"
        f"</tr>{body}</table>"
    )


def _step_plot(
    rows: Sequence[tuple[float, float | None, int | None, float | None]], critical: float | None
) -> str:
    """Plan length (y) against tolerance (x) as an SVG step plot; the critical tolerance as
    a dashed line. Steps with no strong plan are left out of the plot (the table names
    them)."""
    rows = [r for r in rows if r[2] is not None]
    if not rows:
        return ""
    ends = [hi for _lo, hi, _n, _e in rows if hi is not None]
    # Past the critical tolerance: the axis's end is no tolerance the mix is recognized at.
    x_max = max(ends + [1.25 * (critical or 0.0), rows[-1][0] * 2.0]) or 1.0
    y_max = max(n for _lo, _hi, n, _e in rows) + 1
    w, h = WIDTH - PAD - 10, HEIGHT - PAD - 10

    def x(v: float) -> float:
        return PAD + w * v / x_max

    def y(v: float) -> float:
        return 10 + h * (1.0 - v / y_max)

    segments = "".join(
        f'<line x1="{x(lo):.1f}" y1="{y(n):.1f}" x2="{x(x_max if hi is None else hi):.1f}" '
        f'y2="{y(n):.1f}" stroke="#0072b2" stroke-width="3"/>'
        for lo, hi, n, _e in rows
    )
    ticks = "".join(
        f'<text x="{PAD - 6}" y="{y(k) + 4:.1f}" text-anchor="end" font-size="11">{k}</text>'
        for k in range(0, y_max + 1)
    )
    marks = ""
    if critical is not None:
        marks = (
            f'<line x1="{x(critical):.1f}" y1="10" x2="{x(critical):.1f}" y2="{10 + h}" '
            'stroke="#d55e00" stroke-dasharray="4 3"/>'
            f'<text x="{x(critical) - 4:.1f}" y="22" text-anchor="end" font-size="11" '
            f'fill="#d55e00">critical {shown_tolerance(critical)} mm</text>'
        )
    axes = (
        f'<line x1="{PAD}" y1="{10 + h}" x2="{PAD + w}" y2="{10 + h}" stroke="#444"/>'
        f'<line x1="{PAD}" y1="10" x2="{PAD}" y2="{10 + h}" stroke="#444"/>'
        f'<text x="{PAD}" y="{HEIGHT - 8}" font-size="11">0</text>'
        f'<text x="{PAD + w}" y="{HEIGHT - 8}" text-anchor="end" font-size="11">'
        f"{num(x_max, 4)} mm</text>"
        f'<text x="{PAD + w / 2:.1f}" y="{HEIGHT - 8}" text-anchor="middle" font-size="11">'
        "sensor tolerance</text>"
    )
    return (
        f'<svg class="design-plot" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" '
        f'height="{HEIGHT}" role="img" aria-label="plan length against sensor tolerance">'
        f"{axes}{ticks}{segments}{marks}</svg>"
    )
