"""The command line's view of plans: rich renderables, and loading a plan file with its limits.

Renderables are built here, never in the library (``feederkit.plans`` does not import rich):
the plan as a tree, its statistics, one run, the verification. Every function takes a
:class:`~feederkit.plans.model.Plan`; a plan file's JSON object is accepted (and checked)
while callers move to the model.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table
from rich.text import Text
from rich.tree import Tree

from feederkit.cell import expectation_words
from feederkit.cli.common import add_count_column, add_name_column, plural
from feederkit.errors import InputError
from feederkit.mechanics.polygon_classes import CLASS_NAMES
from feederkit.plans.execute import Trace
from feederkit.plans.model import Leaf, Plan, Step, member_label, robust_ideal_words
from feederkit.plans.readplan import MAX_PLAN_BYTES, as_plan, read_plan
from feederkit.plans.verify import VerificationReport
from feederkit.sensors import Sensor, sensor_from_dict

MaxPlanMbOpt = Annotated[
    float,
    typer.Option(
        "--max-plan-mb",
        metavar="MB",
        help="Refuse plan files larger than this many megabytes (read before parsing).",
    ),
]
DEFAULT_MAX_PLAN_MB = MAX_PLAN_BYTES / 1e6


def load_plan(path: Path, max_plan_mb: float = DEFAULT_MAX_PLAN_MB) -> Plan:
    """Read and check a plan file for a command; the size limit is ``--max-plan-mb``."""
    if not max_plan_mb > 0.0:
        raise InputError(f"--max-plan-mb must be a positive number, got {max_plan_mb:g}")
    try:
        return read_plan(path, max_bytes=int(max_plan_mb * 1e6))
    except InputError as exc:
        if "more than the limit" in str(exc) and "MB" in str(exc):
            raise InputError(f"{exc} (raise it with --max-plan-mb)") from None
        raise


def sensor_text(sensor: Sensor | Mapping[str, Any]) -> str:
    """The plan's sensor in words (:meth:`Sensor.describe`)."""
    if isinstance(sensor, Mapping):
        sensor = sensor_from_dict(dict(sensor))
    return sensor.describe()


def _interval(r: tuple[float, float] | None) -> str:
    if r is None:
        return "any reading"
    return f"reads {r[0]:.6g} mm" if r[0] == r[1] else f"reads {r[0]:.6g} .. {r[1]:.6g} mm"


def _result_text(leaf: Leaf, plan: Plan) -> Text:
    parts = []
    for e in leaf.results:
        s = plan.part(e.part, e.landing).state(e.state)
        who = member_label(e.part, e.landing)
        parts.append(f"{who} state {e.state} (edge {s.edge}), pose {e.pose_deg:.6g}°")
    if leaf.reject:
        landings = sorted({member_label(e.part, e.landing) for e in leaf.results})
        lead = "reject (recirculate or re-drop): " + ", ".join(landings)
        return Text(lead, style="bold yellow")
    lead = "done: " if len(leaf.results) == 1 else "done, one of: "
    return Text(lead + "; ".join(parts), style="bold green")


def _uses(plan: Plan) -> dict[int, int]:
    """How many branches lead to each distinct step (more than one: a shared subplan)."""
    uses: dict[int, int] = {}
    for node, _number in plan.walk():
        if isinstance(node, Step):
            for b in node.branches:
                if isinstance(b.next, Step):
                    uses[id(b.next)] = uses.get(id(b.next), 0) + 1
    return uses


def _op_text(step: Step, number: int) -> Text:
    if step.action_deg is None:
        return Text(f"op {number}: align (first push from an unknown orientation)", style="bold")
    t = Text(f"op {number}: rotate {step.action_deg:.4f}°", style="bold")
    t.append(f"  margin ±{step.margin_deg:.4f}°", style="cyan")
    return t


PLAN_TREE_LINES = 1000
"""The terminal drawing of a plan stops after this many entries (lines before wrapping): a
plan of a large mix can have tens of thousands, which no one reads in a terminal and which
take longer to draw than the plan took to make. The plan file holds it whole; ``feederkit
report`` draws it."""


def plan_tree(plan: Plan | Mapping[str, Any], max_lines: int = PLAN_TREE_LINES) -> Tree:
    """The plan as a tree: operations, rotations and margins, reading intervals, results.

    A chain of single-branch operations stays flat; a shared subplan (the file's
    ``"nodes"``) is drawn once, with a letter, and named by it in its other places, so the
    drawing grows with the distinct nodes; built without recursion. After ``max_lines``
    lines the drawing stops, and its last line says how much of the plan it left out.
    """
    plan = as_plan(plan)
    tree = Tree(
        Text(f"plan: at most {plural(plan.stats.length, 'push-align operation')}", style="bold")
    )
    uses = _uses(plan)
    names: dict[int, str] = {}
    drawn: set[int] = set()
    lines = 0

    def add(parent: Tree, label: Text, node: object = None) -> Tree:
        nonlocal lines
        lines += 1
        if node is not None:
            drawn.add(id(node))
        return parent.add(label)

    stack: list[tuple[Tree, Step, int]] = [(tree, plan.root, 1)]
    while stack and lines < max_lines:
        parent, step, number = stack.pop()
        if uses.get(id(step), 0) > 1:
            if id(step) in names:
                add(
                    parent,
                    Text(f"the shared subplan {names[id(step)]} (drawn above)", style="cyan"),
                )
                continue
            names[id(step)] = f"S{len(names) + 1}"
            parent = add(parent, Text(f"shared subplan {names[id(step)]}:", style="cyan"))
        while len(step.branches) == 1:  # a chain of single-branch operations
            (b,) = step.branches
            label = _op_text(step, number)
            if b.reading is not None:
                label.append(f", {_interval(b.reading)}", style="yellow")
            add(parent, label, step)
            if isinstance(b.next, Leaf):
                add(parent, _result_text(b.next, plan), b.next)
                break
            if uses.get(id(b.next), 0) > 1:
                stack.append((parent, b.next, number + 1))
                break
            step, number = b.next, number + 1
        else:
            op = add(parent, _op_text(step, number), step)
            later = []
            for b in step.branches:
                line = Text(_interval(b.reading), style="yellow")
                if isinstance(b.next, Leaf):
                    line.append(" → ")
                    line.append_text(_result_text(b.next, plan))
                    add(op, line, b.next)
                else:
                    later.append((add(op, line), b.next, number + 1))
            stack.extend(reversed(later))
    for parent, _step, _number in stack:
        if not parent.children and isinstance(parent.label, Text):  # a branch cut bare
            parent.label.append(" → not drawn here (in the plan file)", style="cyan")
    if stack:
        every = [n for n, _number in plan.walk()]
        ops = sum(1 for n in every if isinstance(n, Step) and id(n) not in drawn)
        results = sum(1 for n in every if isinstance(n, Leaf) and id(n) not in drawn)
        tree.add(
            Text(
                f"... the drawing stops after {lines} entries: "
                f"{plural(ops, 'more operation')} "
                f"and {plural(results, 'more result')} are in the plan file (feederkit run "
                "PLAN --all walks every path; feederkit report draws more of it)",
                style="cyan",
            )
        )
    return tree


def stats_table(plan: Plan | Mapping[str, Any], report: VerificationReport | None = None) -> Table:
    """The plan's statistics, and the verification's summary when given."""
    plan = as_plan(plan)
    s = plan.stats
    t = Table(title="statistics", show_header=False)
    t.add_column("what")
    t.add_column("value")
    t.add_row("length (worst case, first alignment counted)", str(s.length))
    t.add_row(f"expected operations ({expectation_words(plan.parts)})", f"{s.expected_length:.4f}")
    margin = s.min_margin_deg
    shown = "no rotation" if margin is None else f"±{margin:.4f}°"
    if plan.low_margin_warning():
        r = plan.uncertainty.rotation_error_deg
        held = f"±{(margin or 0.0) + r:.2g}° with the declared ±{r:g}°, " if r > 0.0 else ""
        shown += f" ({held}below ±1°: no robot holds it)"
    t.add_row("smallest margin", shown)
    t.add_row("declared uncertainty", plan.uncertainty_words())
    cert = s.certificate
    if cert is not None:
        rot = f"±{cert.max_rotation_error_deg:.4g}°"
        if margin is None:
            rot = "any (the plan makes no rotation)"
        t.add_row("certified rotation error (largest)", rot)
        shape = f"{cert.max_shape_tolerance_mm:.4g} mm"
        if plan.sensor.informative and cert.max_shape_tolerance_mm <= (
            plan.uncertainty.shape_tolerance_mm
        ):
            shape += " (the declared: reading branches end at the declared widths)"
        t.add_row("certified shape tolerance (largest)", shape)
        t.add_row("length: robust / ideal model", robust_ideal_words(s.length, cert.ideal_length))
    bound = "lower bound" if (s.objective or "worst") == "worst" else "worst-case length at least"
    optimal = "yes" if s.optimal else f"not proven ({bound} {s.lower_bound})"
    t.add_row(f"optimal ({s.objective or 'worst'} objective)", optimal)
    if s.grouping:
        t.add_row("reading branching", str(s.grouping))
    if s.polygon_class is not None:
        t.add_row("polygon class (Fig. 14)", f"{s.polygon_class}: {CLASS_NAMES[s.polygon_class]}")
        meets = "within it" if s.meets_bound else "EXCEEDS it"
        t.add_row("class bound", f"{s.class_bound} ({meets})")
    if report is not None:
        verdict = "passed" if report.ok else "FAILED"
        t.add_row(verification_title(plan), f"{verdict}, {plural(report.paths, 'path')}")
    return t


def trace_table(trace: Trace) -> Table:
    """One run, step by step: rotation, where the part rests, reading and branch."""
    who = member_label(trace.part, trace.landing)
    t = Table(title=f"{who} from theta {trace.start_theta_deg:.6g}°")
    for col in ("op", "rotation", "theta", "state (edge)", "diameter", "reading", "branch"):
        t.add_column(col)
    for s in trace.steps:
        rot = "align" if s.action_deg is None else f"{s.action_deg:.4f}°"
        if s.rotation_error_deg:
            rot += f" {s.rotation_error_deg:+.4f}°"
        reading = "-" if s.reading is None else f"{s.reading:.6g}"
        if s.branch is None:
            branch: str | Text = Text("none holds it", style="bold red")
        else:
            branch = f"{s.branch}" + (
                "" if s.interval is None else f" [{s.interval[0]:.6g}, {s.interval[1]:.6g}]"
            )
        t.add_row(
            str(s.number),
            rot,
            f"{s.theta_deg:.4f}°",
            f"{s.state} ({s.edge})",
            f"{s.diameter:.6g}",
            reading,
            branch,
        )
    return t


def verification_title(plan: Plan) -> str:
    """What the verification of ``plan`` checked: the kinematic model, or (under a declared
    uncertainty) every outcome and reading of a strong plan."""
    if plan.uncertainty.is_ideal:
        return "verified on the kinematic model"
    return "verified as a strong plan (every outcome, every reading)"


def verification_table(report: VerificationReport, plan: Plan | None = None) -> Table:
    """Per part: starts, paths, the most operations a path took, the paths ending in an
    unrecognized result (when some do), failed starts."""
    title = "verification"
    if plan is not None:
        title += " " + verification_title(plan).removeprefix("verified ")
    t = Table(title=title)
    landings = any(p.landing is not None for p in report.parts)
    add_name_column(t, "part")
    if landings:
        t.add_column("landing")
    for col in ("starts", "paths", *(["rejects"] if landings else []), "worst operations"):
        add_count_column(t, col)
    unrecognized = report.unrecognized > 0
    if unrecognized:
        add_count_column(t, "unrecognized")
    add_count_column(t, "failed starts")
    for p in report.parts:
        failed = Text(str(p.failed_starts), style="bold red" if p.failed_starts else "green")
        head = [p.part, str(p.landing), str(p.starts), str(p.paths), str(p.rejects)]
        if not landings:
            head = [p.part, str(p.starts), str(p.paths)]
        more = [str(p.unrecognized)] if unrecognized else []
        t.add_row(*head, str(p.worst_operations), *more, failed)
    return t
