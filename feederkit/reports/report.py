"""The changeover report: one self-contained HTML page (inline SVG, no scripts, no network).

Sections: mix and sensor, the plan as a tree, statistics, per-part states and plots, the pairs
the plan cannot tell apart, and the conventions. The plan is verified at its declared
uncertainty (:func:`feederkit.plans.verify.verify_declared`: a strong plan for every outcome and
reading, an ideal one on the kinematic model) as it is drawn: a plan that fails gets a red
banner at the top naming the first problem; a plan whose smallest margin is below 1 degree a
warning (docs/reports.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.errors import InputError
from feederkit.outline import Outline
from feederkit.plans.fileformat import as_plan
from feederkit.plans.model import Leaf, Plan
from feederkit.plans.verify import VerificationReport, verify_declared
from feederkit.reports.parts_html import part_section
from feederkit.reports.sections import (
    conventions_section,
    lookalike_section,
    mix_section,
    stats_section,
)
from feederkit.reports.style import CSS
from feederkit.reports.svgkit import Ring, esc
from feederkit.reports.trace import Place, confusions, places, trace_plan
from feederkit.reports.tree_html import drawing_for, tree_html

CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:"
"""The page may load nothing: inline styles and data-URI images only."""


def _rings(plan: Plan, outlines: Mapping[str, Outline] | None) -> dict[str, list[Ring]]:
    """Outline and holes of each part the caller gave, else its hull."""
    out: dict[str, list[Ring]] = {}
    for p in plan.parts:
        outline = (outlines or {}).get(p.name)
        out[p.name] = [p.hull] if outline is None else [outline.vertices, *outline.holes]
    return out


def _tree_section(numbered: Sequence[Place], tree: str) -> str:
    n_leaves = sum(isinstance(p.node, Leaf) for p in numbered)
    return (
        f'<section id="plan-tree" data-nodes="{len(numbered)}" data-leaves="{n_leaves}">'
        '<h2>The plan</h2><p class="muted">Each box is a plan node with the states the part '
        "may be in, drawn on the fence. Each edge says the rotation the robot applies and the "
        "reading that leads there. Shaded boxes are the final poses: green one known pose, blue "
        "poses alike up to symmetry, red parts the plan cannot tell apart.</p>"
        f"{tree}</section>"
    )


def _banners(plan: Plan, report: VerificationReport) -> str:
    """The verification verdict when it failed, and the low-margin warning."""
    out = ""
    where = (
        "on the kinematic model"
        if plan.uncertainty.is_ideal
        else "at its declared uncertainty (every outcome, every reading)"
    )
    if not report.ok:
        out += (
            '<div class="banner fail" id="verification" data-ok="false">This plan FAILED '
            f"verification {where}: do not run it. "
            f"{esc(report.first_problem() or '')}</div>"
        )
    warning = plan.low_margin_warning()
    if warning:
        out += f'<div class="banner caution" id="low-margin">Warning: {esc(warning)}.</div>'
    return out


def render_report(
    plan: Plan | Mapping[str, Any],
    *,
    seconds_per_op: float | None = None,
    simulation: Mapping[str, Any] | None = None,
    unrecognizable: Sequence[Mapping[str, Any]] | None = None,
    outlines: Mapping[str, Outline] | None = None,
) -> str:
    """The HTML report of a plan (or a plan file's JSON object, checked; design.md).

    ``seconds_per_op`` adds the cycle time; ``simulation`` (``trials``, ``successes``, ...) the
    simulator's result; ``unrecognizable`` pairs ``{part_a, part_b, states_a, states_b, reason}``
    from the mix analysis; ``outlines`` (part name -> Outline) draws holes around the plan's
    hulls. Raises InputError for a malformed plan or option.
    """
    if seconds_per_op is not None and not (math.isfinite(seconds_per_op) and seconds_per_op > 0):
        raise InputError("seconds per operation must be a positive number")
    plan = as_plan(plan)
    report = verify_declared(plan)
    numbered = places(plan)
    trace = trace_plan(plan, numbered)
    draw = drawing_for(plan, _rings(plan, outlines))
    names = ", ".join(p.name for p in plan.parts)
    symmetric = [(p.node_id, p.node) for p in numbered if isinstance(p.node, Leaf)]
    body = "".join(
        [
            f"<h1>Changeover report: {esc(names)}</h1>",
            _banners(plan, report),
            mix_section(plan, draw),
            _tree_section(numbered, tree_html(plan, numbered, trace, draw)),
            stats_section(plan, seconds_per_op, simulation),
            '<section id="parts"><h2>Parts</h2>',
            "".join(part_section(i, p, draw, outlines) for i, p in enumerate(plan.parts)),
            "</section>",
            lookalike_section(
                plan, confusions(numbered, trace), list(unrecognizable or []), symmetric
            ),
            conventions_section(plan),
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
