"""Rich renderables for people: the plan as a tree, its statistics, runs and verification.

Library code: these build renderables and never print.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rich.table import Table
from rich.text import Text
from rich.tree import Tree

from feederkit.mechanics.classes import CLASS_NAMES
from feederkit.plans.execute import Trace
from feederkit.plans.verify import VerificationReport


def sensor_text(sensor: dict[str, Any]) -> str:
    """The plan's sensor in words."""
    model = sensor.get("model")
    if model == "tolerance":
        return f"diameter sensor, tolerance {sensor['tolerance_mm']:g} mm"
    if model == "led":
        return (
            f"LED array, pitch {sensor['pitch_mm']:g} mm, noise {sensor.get('noise_mm', 0.0):g} mm"
        )
    return "none (sensorless)"


def _interval(r: Sequence[float] | None) -> str:
    if r is None:
        return "any reading"
    return f"reads {r[0]:.6g} mm" if r[0] == r[1] else f"reads {r[0]:.6g} .. {r[1]:.6g} mm"


def _result_text(node: dict[str, Any], states: dict[tuple[str, int], dict[str, Any]]) -> Text:
    entries = node["result"]
    parts = []
    for e in entries:
        s = states[(e["part"], e["state"])]
        parts.append(
            f"{e['part']} state {e['state']} (edge {s['edge']}), pose {e['pose_deg']:.6g}°"
        )
    lead = "done: " if len(entries) == 1 else "done, one of: "
    return Text(lead + "; ".join(parts), style="bold green")


def _op_text(node: dict[str, Any], number: int) -> Text:
    if node["action_deg"] is None:
        return Text(f"op {number}: align (first push from an unknown orientation)", style="bold")
    t = Text(f"op {number}: rotate {node['action_deg']:.4f}°", style="bold")
    t.append(f"  margin ±{node['margin_deg']:.4f}°", style="cyan")
    return t


def _add(tree: Tree, node: dict[str, Any], number: int, states: dict) -> None:
    """Add an operation and what follows; a chain of single-branch operations stays flat."""
    while True:
        label = _op_text(node, number)
        branches = node["branches"]
        if len(branches) > 1:
            break
        (b,) = branches
        if b["reading"] is not None:
            label.append(f", {_interval(b['reading'])}", style="yellow")
        tree.add(label)
        node = b["next"]
        if "result" in node:
            tree.add(_result_text(node, states))
            return
        number += 1
    op = tree.add(label)
    for b in branches:
        nxt = b["next"]
        line = Text(_interval(b["reading"]), style="yellow")
        if "result" in nxt:
            line.append(" → ")
            line.append_text(_result_text(nxt, states))
            op.add(line)
        else:
            _add(op.add(line), nxt, number + 1, states)


def plan_tree(plan: dict[str, Any]) -> Tree:
    """The plan as a tree: operations, rotations and margins, reading intervals, results."""
    states = {(p["name"], s["id"]): s for p in plan["parts"] for s in p["stable_states"]}
    length = plan["stats"]["length"]
    tree = Tree(Text(f"plan: at most {length} push-align operations", style="bold"))
    _add(tree, plan["root"], 1, states)
    return tree


def stats_table(plan: dict[str, Any], report: VerificationReport | None = None) -> Table:
    """The plan's statistics, and the verification's summary when given."""
    s = plan["stats"]
    t = Table(title="statistics", show_header=False)
    t.add_column("what")
    t.add_column("value")
    t.add_row("length (worst case, first alignment counted)", str(s["length"]))
    t.add_row("expected operations (uniform start)", f"{s['expected_length']:.4f}")
    margin = s["min_margin_deg"]
    t.add_row("smallest margin", "no rotation" if margin is None else f"±{margin:.4f}°")
    optimal = "yes" if s["optimal"] else f"not proven (lower bound {s['lower_bound']})"
    t.add_row(f"optimal ({s.get('objective', 'worst')} objective)", optimal)
    if s.get("grouping"):
        t.add_row("reading branching", str(s["grouping"]))
    if s.get("class") is not None:
        t.add_row("polygon class (Fig. 14)", f"{s['class']}: {CLASS_NAMES[s['class']]}")
        meets = "meets it" if s.get("meets_bound") else "EXCEEDS it"
        t.add_row("class bound", f"{s['class_bound']} ({meets})")
    if report is not None:
        verdict = "passed" if report.ok else "FAILED"
        t.add_row("verified on the kinematic model", f"{verdict}, {report.paths} paths")
    return t


def trace_table(trace: Trace) -> Table:
    """One run, step by step: rotation, where the part rests, reading and branch."""
    t = Table(title=f"{trace.part} from theta {trace.start_theta_deg:.6g}°")
    for col in ("op", "rotation", "theta", "state (edge)", "diameter", "reading", "branch"):
        t.add_column(col)
    for s in trace.steps:
        rot = "align" if s.action_deg is None else f"{s.action_deg:.4f}°"
        if s.rotation_error_deg:
            rot += f" {s.rotation_error_deg:+.4f}°"
        reading = "-" if s.reading is None else f"{s.reading:.6g}"
        if s.branch is None:
            branch = Text("none holds it", style="bold red")
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


def verification_table(report: VerificationReport) -> Table:
    """Per part: starts, paths, the most operations a path took, failed starts."""
    t = Table(title="verification on the kinematic model")
    for col in ("part", "starts", "paths", "worst operations", "failed starts"):
        t.add_column(col)
    for p in report.parts:
        failed = Text(str(p.failed_starts), style="bold red" if p.failed_starts else "green")
        t.add_row(p.part, str(p.starts), str(p.paths), str(p.worst_operations), failed)
    return t
