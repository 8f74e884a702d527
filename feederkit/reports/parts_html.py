"""The per-part section of the report: stable states drawn on the fence, and the part plot.

One part model: the table and the plot both show the plan's part, its push function rebuilt
from the hull and COM the plan records (:func:`feederkit.plans.model.push_function_of`); a
caller's outline only draws the plate's holes around that hull. The plot is embedded as an
SVG data URI: self-contained, vector for print, and its element ids cannot clash with the
rest of the page.
"""

from __future__ import annotations

import base64
import functools
import time

from feederkit.outline import Outline
from feederkit.plans.model import PlanPart, push_function_of
from feederkit.reports.partplot import part_plot_bytes
from feederkit.reports.svgkit import esc, num, pose_svg
from feederkit.reports.tree_html import Drawing

POSE_PX = 64

PART_PLOTS = 40
"""The report draws the part plots of its first this many members (about 0.2 s and 140 KB of
SVG each: a 50-part mix over both landings took 40 s and 14 MB for its 100); the others keep
their state tables and name ``feederkit part plot``."""


def _states_table(index: int, entry: PlanPart, draw: Drawing) -> str:
    rows = []
    for s in entry.states:
        svg = pose_svg(
            draw.rings[index],
            entry.hull,
            entry.com,
            s.pose_deg,
            radius_mm=draw.radius(index),
            colour=draw.colours[index],
            px=POSE_PX,
            title=f"{entry.label}, state {s.id} on the fence{draw.magnified(index)}",
        )
        lo, hi = s.resting_range_deg
        rows.append(
            f'<tr class="stable-state" data-state="{s.id}"><td>s{s.id}</td><td>e{s.edge}</td>'
            f"<td>{num(s.normal_deg, 2)}\u00b0</td>"
            f"<td>({num(lo, 2)}\u00b0, {num(hi, 2)}\u00b0)</td>"
            f"<td>{num(s.diameter)} mm</td><td>{num(s.pose_deg, 2)}\u00b0</td><td>{svg}</td></tr>"
        )
    return (
        '<table class="grid states"><tr><th>state</th><th>edge</th><th>normal</th>'
        "<th>resting range</th><th>diameter</th><th>pose</th><th>on the fence</th></tr>"
        f"{''.join(rows)}</table>"
    )


@functools.lru_cache(maxsize=32)
def _plot_uri(entry: PlanPart, outline: Outline | None) -> str:
    """The member's part plot as a data URI. The plot is a pure function of the (frozen)
    member and outline and costs about a second to draw, so a process that reports the same
    parts again (a changeover's report, then its plan's) draws each once."""
    svg = part_plot_bytes(push_function_of(entry), "svg", outline=outline)
    return "data:image/svg+xml;base64," + base64.b64encode(svg).decode("ascii")


def part_section(
    index: int,
    entry: PlanPart,
    draw: Drawing,
    outline: Outline | None,
    share: float | None = None,
    plots_until: float | None = None,
) -> str:
    """One member (a part, or a part in one landing; ``index`` in the plan): its label, prior
    share (None: not given), stable-state table with poses, and its radius/push/push-diameter
    plot, or past the first ``PART_PLOTS`` members, or once ``time.monotonic()`` passes
    ``plots_until`` (the command's time limit), a line saying how to draw it."""
    late = plots_until is not None and time.monotonic() >= plots_until
    plot = index < PART_PLOTS and not late
    rev = f' <span class="muted">rev {esc(str(entry.revision))}</span>' if entry.revision else ""
    share_text = (
        "" if share is None else f' <span class="muted">share {num(100.0 * share, 3)}%</span>'
    )
    landing = "" if entry.landing is None else f"Landing {esc(entry.landing)}"
    return (
        f'<section class="part" id="part-{index}" data-part="{esc(entry.name)}" '
        f'data-landing="{esc(entry.landing or "")}" '
        f'data-share="{"" if share is None else num(share, 6)}">'
        f'<h3><span class="swatch" style="background:{draw.colours[index]}"></span>'
        f"{esc(entry.label)}{rev}{share_text}</h3>"
        + (
            f'<p class="muted">{landing}: the hull and COM as the part then lies '
            "(docs/landings.md).</p>"
            if landing
            else ""
        )
        + f'<div class="part-grid"><div>{_states_table(index, entry, draw)}</div>'
        f"{_plot_figure(entry, outline) if plot else _no_plot(entry, late)}</div></section>"
    )


def _plot_figure(entry: PlanPart, outline: Outline | None) -> str:
    return (
        f'<figure class="plot"><img src="{_plot_uri(entry, outline)}" alt="{esc(entry.label)}: '
        'outline, radius, push and push-diameter functions"><figcaption>Outline with hull '
        "(dashed), COM and numbered stable edges (dotted: fragile); below, over the fence "
        "orientation theta: radius, push and push-diameter functions, resting ranges "
        "shaded.</figcaption></figure>"
    )


def _no_plot(entry: PlanPart, late: bool = False) -> str:
    """The words in place of a member's part plot past :data:`PART_PLOTS` (``late``: past the
    command's time limit): the command that draws it (its catalog revision when the plan
    names one)."""
    if entry.revision is None:
        how = (
            "<code>feederkit part plot SOURCE -o PLOT.svg</code> (its outline or CAD file, or "
            "its catalog name with <code>--catalog</code>; a landing of a mesh with "
            "<code>--pose K</code>)"
        )
    else:
        pose = ""
        if entry.landing is not None and entry.landing.startswith("pose-"):
            pose = f" --pose {entry.landing.removeprefix('pose-')}"
        how = (
            f"<code>feederkit part plot {esc(entry.name)}@{esc(str(entry.revision))} -o "
            f"{esc(entry.name)}.svg{pose}</code> (with <code>--catalog</code> naming the "
            "plan's catalog"
            + (
                "; it draws the part face up, this landing is its mirror image)"
                if entry.landing == "down"
                else ")"
            )
        )
    why = (
        "The command's time limit left no time for this member's plot"
        if late
        else f"The report draws the plots of its first {PART_PLOTS} members only"
    )
    return f'<p class="muted plot-skipped">{why}; draw this one with {how}.</p>'
