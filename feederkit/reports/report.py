"""The changeover report: one self-contained HTML page (inline SVG, no scripts, no network).

Sections: mix and sensor, the plan as a tree, statistics (with the cycle time in the cell
profile the plan was made for), the sensor design (when the caller gives it), per-part states
and plots, the pairs the plan cannot tell apart, and the conventions. The plan is verified at
its declared uncertainty (:func:`feederkit.plans.verify.verify_declared`: a strong plan for
every outcome and reading, an ideal one on the kinematic model) as it is drawn: a plan that
fails gets a red banner at the top naming the first problem; a plan whose smallest margin is
below 1 degree a warning, and so a plan whose members have fragile states, a result that
lists poses of one part that do not look alike (the part is not oriented), or pairs of
members no plan tells apart (docs/reports.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.errors import InputError
from feederkit.outline import Outline
from feederkit.plans.model import Leaf, Plan, PlanPart, Step
from feederkit.plans.readplan import as_plan
from feederkit.plans.verify import VerificationReport, verify_declared
from feederkit.reports.design_html import design_section
from feederkit.reports.parts_html import part_section
from feederkit.reports.sections import (
    PairRow,
    conventions_section,
    lookalike_section,
    mix_section,
    pair_rows,
    stats_section,
    unrecognized_words,
)
from feederkit.reports.style import CSS
from feederkit.reports.svgkit import Ring, esc
from feederkit.reports.trace import Place, confusions, places, trace_plan
from feederkit.reports.tree_html import drawing_for, tree_html
from feederkit.reports.twins import TwinLeaf, spread_words_of, twin_leaves, unoriented_words

CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:"
"""The page may load nothing: inline styles and data-URI images only."""


def member_outline(part: PlanPart, outlines: Mapping[str, Outline] | None) -> Outline | None:
    """The caller's outline of a member: keyed ``PART/LANDING`` for a landing (the part as
    it then lies, docs/landings.md), else by the part's name; None: draw the hull."""
    if not outlines:
        return None
    if part.landing is not None:
        return outlines.get(f"{part.name}/{part.landing}")
    return outlines.get(part.name)


def member_rings(plan: Plan, outlines: Mapping[str, Outline] | None) -> list[list[Ring]]:
    """Outline and holes of each member the caller gave, else its hull (by member index)."""
    out: list[list[Ring]] = []
    for p in plan.parts:
        outline = member_outline(p, outlines)
        out.append([p.hull] if outline is None else [outline.vertices, *outline.holes])
    return out


def _leaves(n: int) -> str:
    return "leaf" if n == 1 else "leaves"


def tree_section(numbered: Sequence[Place], tree: str) -> str:
    """The plan section: the drawn tree, its distinct nodes, accepting and reject leaves and
    shared subplans counted (also as ``data-`` attributes, for scripts)."""
    leaves = [p.node for p in numbered if isinstance(p.node, Leaf)]
    rejects = sum(leaf.reject for leaf in leaves)
    shared = sum(p.shared and isinstance(p.node, Step) for p in numbered)
    counts = (
        f"{len(numbered)} distinct nodes; {len(leaves) - rejects} accepting "
        f"{_leaves(len(leaves) - rejects)} and {rejects} reject {_leaves(rejects)}"
    )
    if shared:
        counts += (
            f"; {shared} shared subplan{'s' if shared != 1 else ''}, each drawn once and named "
            "where it is used again"
        )
    return (
        f'<section id="plan-tree" data-nodes="{len(numbered)}" data-leaves="{len(leaves)}" '
        f'data-accepts="{len(leaves) - rejects}" data-rejects="{rejects}" '
        f'data-shared="{shared}">'
        '<h2>The plan</h2><p class="muted">Each box is a plan node with the states the part '
        "may be in, drawn on the fence. Each edge says the rotation the robot applies and the "
        "reading that leads there. Shaded boxes are the final poses: green one known pose, blue "
        "poses no plan tells apart that look alike (symmetric or nearly so) or one resting "
        "state over several poses (oriented only that far), orange poses no "
        "plan tells apart that do not look alike (the part is not oriented between them), red "
        "parts the plan cannot tell apart, yellow a reject leaf: landings the next station "
        "cannot take, recirculated or re-dropped.</p>"
        f'<p class="counts">{esc(counts)}.</p>'
        f"{tree}</section>"
    )


def _banners(
    plan: Plan,
    report: VerificationReport,
    twins: Sequence[TwinLeaf] = (),
    pairs: Sequence[PairRow] = (),
) -> str:
    """The verification verdict when it failed, the low-margin warning, the fragile
    states of the plan's members (:meth:`Plan.fragile_warnings`), the poses of one part
    a result lists that do not look alike (:func:`unoriented_words`: not oriented), and the
    pairs of members no plan tells apart (:func:`unrecognized_words`)."""
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
    ideal = plan.ideal_model_warning()
    if ideal:
        out += f'<div class="banner caution" id="ideal-model">Warning: {esc(ideal)}.</div>'
    fragile = plan.fragile_warnings()  # the lines plan and run print, members as named here
    if fragile:
        lines = "<br>".join(f"Warning: {esc(w)}." for w in fragile)
        out += f'<div class="banner caution" id="fragile-states">{lines}</div>'
    spread = spread_words_of(plan, twins)
    if spread:
        out += f'<div class="banner caution" id="spread">Warning: {esc(spread)}.</div>'
    unoriented = unoriented_words(plan, twins)
    if unoriented:
        out += f'<div class="banner caution" id="unoriented">Warning: {esc(unoriented)}.</div>'
    unrecognized = unrecognized_words(plan, pairs)
    if unrecognized:
        out += (
            f'<div class="banner caution" id="unrecognized">Warning: {esc(unrecognized)} '
            '(<a href="#lookalikes">the pairs and their witnesses</a>).</div>'
        )
    return out


def plan_section(plan: Plan, outlines: Mapping[str, Outline] | None = None) -> str:
    """The plan section alone (no part plots): what grows with the plan's distinct nodes."""
    numbered = places(plan)
    draw = drawing_for(plan, member_rings(plan, outlines))
    twins = {t.node_id: t for t in plan_twins(plan, numbered, outlines)}
    tree = tree_html(plan, numbered, trace_plan(plan, numbered), draw, twins=twins)
    return tree_section(numbered, tree)


def plan_twins(
    plan: Plan, numbered: Sequence[Place], outlines: Mapping[str, Outline] | None
) -> list[TwinLeaf]:
    """The leaves listing several poses of one member, compared with the caller's outlines
    (:func:`~feederkit.reports.twins.twin_leaves`)."""
    return twin_leaves(plan, numbered, [member_outline(p, outlines) for p in plan.parts])


def _shares(plan: Plan) -> list[float | None]:
    """Each member's prior share as the report shows it: normalised when the plan gives
    shares (:meth:`Plan.shares`), None when every member is equally likely by default."""
    if any(p.share is None for p in plan.parts):
        return [None] * len(plan.parts)
    return list(plan.shares())


def heading(plan: Plan, changeover: str | None = None) -> tuple[str, str]:
    """The page's ``<title>`` text and ``<h1>`` element (HTML). A stored changeover's report
    names it, so that two changeovers of one mix (another sensor or uncertainty) and their
    printed pages can be told apart; a plan file has no name, so its page names its parts."""
    parts = list(dict.fromkeys(p.name for p in plan.parts))  # one part's landings: one name
    names = esc(", ".join(parts))
    if changeover is None:
        what = "Changeover" if len(parts) > 1 else "Plan"
        return f"feederkit report: {names}", f"<h1>{what} report: {names}</h1>"
    name = esc(changeover)
    return (
        f"feederkit changeover \u2018{name}\u2019: {names}",
        f'<h1 data-changeover="{name}">Changeover \u2018{name}\u2019 report: {names}</h1>',
    )


def render_report(
    plan: Plan | Mapping[str, Any],
    *,
    seconds_per_op: float | None = None,
    simulation: Mapping[str, Any] | None = None,
    unrecognizable: Sequence[Mapping[str, Any]] | None = None,
    outlines: Mapping[str, Outline] | None = None,
    cycle_time: Mapping[str, Any] | None = None,
    design: Mapping[str, Any] | None = None,
    verification: VerificationReport | None = None,
    cautions: Sequence[str] = (),
    plots_until: float | None = None,
    changeover: str | None = None,
) -> str:
    """The HTML report of a plan (or a plan file's JSON object, checked; design.md).

    ``cycle_time`` (default: the plan file's ``stats.cycle_time``, docs/cell.md) gives the
    seconds per part in a named cell profile; ``seconds_per_op`` a flat cycle time instead;
    ``simulation`` (``trials``, ``successes``, ...) the simulator's result; ``unrecognizable``
    pairs ``{part_a, part_b, states_a, states_b, reason}`` from the mix analysis (``feederkit
    report`` decides them from the plan file: ``cli.report.plan_pairs``);
    ``outlines`` (part name, or ``PART/LANDING`` for a member of a plan over landings, ->
    Outline) draws holes around the plan's hulls; ``design`` (the
    JSON of ``feederkit design sensor``) adds the sensor design table and plot;
    ``verification``, the plan's :func:`~feederkit.plans.verify.verify_declared` when the
    caller has it (else it is made here), gives the banner; ``cautions`` are lines the page
    must say first (a stored changeover whose parts have newer revisions);
    ``plots_until``, a ``time.monotonic()`` instant (a command's time limit) past which the
    part plots are not drawn (each member then names the command that draws it);
    ``changeover``, the stored changeover's name, heads the page (:func:`heading`). Raises
    InputError for a malformed plan or option.
    """
    if seconds_per_op is not None and not (math.isfinite(seconds_per_op) and seconds_per_op > 0):
        raise InputError("seconds per operation must be a positive number")
    if cycle_time is None and isinstance(plan, Mapping):
        stats = plan.get("stats")
        cycle_time = stats.get("cycle_time") if isinstance(stats, Mapping) else None
    plan = as_plan(plan)
    report = verify_declared(plan) if verification is None else verification
    numbered = places(plan)
    trace = trace_plan(plan, numbered)
    draw = drawing_for(plan, member_rings(plan, outlines))
    title, h1 = heading(plan, changeover)
    twins = plan_twins(plan, numbered, outlines)
    tree = tree_html(plan, numbered, trace, draw, twins={t.node_id: t for t in twins})
    given = list(unrecognizable or [])
    found = confusions(plan, numbered, trace)
    body = "".join(
        [
            h1,
            "".join(
                f'<div class="banner caution" id="caution-{i}">Warning: {esc(c)}.</div>'
                for i, c in enumerate(cautions)
            ),
            _banners(plan, report, twins, pair_rows(plan, found, given)),
            mix_section(plan, draw),
            tree_section(numbered, tree),
            stats_section(plan, seconds_per_op, simulation, cycle_time),
            "" if design is None else design_section(design, plan.sensor),
            '<section id="parts"><h2>Parts</h2>',
            "".join(
                part_section(i, p, draw, member_outline(p, outlines), share, plots_until)
                for i, (p, share) in enumerate(zip(plan.parts, _shares(plan), strict=True))
            ),
            "</section>",
            lookalike_section(plan, found, given, twins),
            conventions_section(plan),
        ]
    )
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
        f"<title>{title}</title><style>{CSS}</style></head>"
        f'<body><main>{body}<footer class="muted">Made by feederkit from a plan file '
        "(Akella &amp; Mason 1999, push-align operations with partial sensing).</footer>"
        "</main></body></html>\n"
    )
