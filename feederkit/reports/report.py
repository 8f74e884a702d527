"""The changeover report: one self-contained HTML page (inline SVG, no scripts, no network).

Sections: mix and sensor, the plan as a tree, statistics, per-part states and plots, the pairs
the plan cannot tell apart, and the conventions.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.errors import InputError
from feederkit.outline import Outline
from feederkit.reports.parts_html import part_section
from feederkit.reports.planview import PlanView, leaves, nodes, plan_view
from feederkit.reports.sections import (
    conventions_section,
    lookalike_section,
    mix_section,
    stats_section,
)
from feederkit.reports.style import CSS
from feederkit.reports.svgkit import Ring, esc
from feederkit.reports.trace import confusions, trace_plan
from feederkit.reports.tree_html import drawing_for, tree_html

CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:"
"""The page may load nothing: inline styles and data-URI images only."""


def _rings(view: PlanView, outlines: Mapping[str, Outline] | None) -> dict[str, list[Ring]]:
    """Outline and holes of each part the caller gave, else its hull."""
    out: dict[str, list[Ring]] = {}
    for p in view.parts:
        outline = (outlines or {}).get(p.name)
        out[p.name] = [p.hull] if outline is None else [outline.vertices, *outline.holes]
    return out


def _tree_section(view: PlanView, tree: str) -> str:
    n_nodes = len(nodes(view.root))
    n_leaves = len(leaves(view.root))
    return (
        f'<section id="plan-tree" data-nodes="{n_nodes}" data-leaves="{n_leaves}">'
        '<h2>The plan</h2><p class="muted">Each box is a plan node with the states the part '
        "may be in, drawn on the fence. Each edge says the rotation the robot applies and the "
        "reading that leads there. Shaded boxes are the final poses: green one known pose, blue "
        "poses alike up to symmetry, red parts the plan cannot tell apart.</p>"
        f"{tree}</section>"
    )


def render_report(
    plan: dict[str, Any],
    *,
    seconds_per_op: float | None = None,
    simulation: Mapping[str, Any] | None = None,
    unrecognizable: Sequence[Mapping[str, Any]] | None = None,
    outlines: Mapping[str, Outline] | None = None,
) -> str:
    """The HTML report of a loaded plan file (design.md, plan file version 1).

    ``seconds_per_op`` adds the cycle time; ``simulation`` (``trials``, ``successes``, ...) the
    simulator's result; ``unrecognizable`` pairs ``{part_a, part_b, states_a, states_b, reason}``
    from the mix analysis; ``outlines`` (part name -> Outline) draws holes. Raises InputError for
    a malformed plan or option.
    """
    if seconds_per_op is not None and not (math.isfinite(seconds_per_op) and seconds_per_op > 0):
        raise InputError("seconds per operation must be a positive number")
    view = plan_view(plan)
    trace = trace_plan(view)
    draw = drawing_for(view, _rings(view, outlines))
    names = ", ".join(p.name for p in view.parts)
    body = "".join(
        [
            f"<h1>Changeover report: {esc(names)}</h1>",
            mix_section(view, draw),
            _tree_section(view, tree_html(view, trace, draw)),
            stats_section(view, seconds_per_op, simulation),
            '<section id="parts"><h2>Parts</h2>',
            "".join(part_section(i, p, draw, outlines) for i, p in enumerate(view.parts)),
            "</section>",
            lookalike_section(view, confusions(view, trace), list(unrecognizable or [])),
            conventions_section(view),
        ]
    )
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
        f"<title>feederkit report: {esc(names)}</title><style>{CSS}</style></head>"
        f'<body><main>{body}<footer class="muted">Made by feederkit from a plan file '
        "(Akella &amp; Mason 1999, push-align operations with partial sensing).</footer>"
        "</main></body></html>\n"
    )
