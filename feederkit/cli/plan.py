"""``feederkit plan SOURCE...``: a verified orienting plan for one part or a product mix.

A thin layer: resolve the parts, choose the sensor, call :func:`feederkit.mix.changeover.plan_mix`
(planner, plan file, verification), write the plan and the report, print the tree.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from feederkit.cli.common import (
    CatalogOpt,
    GroupingOpt,
    LedPitchOpt,
    MinMarginOpt,
    NoiseOpt,
    ObjectiveOpt,
    PlanOutputOpt,
    ReportOpt,
    SensorlessOpt,
    TimeLimitOpt,
    ToleranceOpt,
    check_planning_options,
    console,
    err_console,
    print_json,
)
from feederkit.errors import CheckFailed, InputError
from feederkit.jsonio import write_text_atomic
from feederkit.mechanics.analysis import fragile_warning
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.changeover import plan_mix
from feederkit.mix.pairs import PairWitness
from feederkit.plans.fileformat import write_plan
from feederkit.plans.match import leaf_part_pairs
from feederkit.plans.render import plan_tree, sensor_text, stats_table
from feederkit.sensors import make_sensor
from feederkit.sources import load_part_with_warnings


def _load(sources: list[str], catalog: Path | None) -> tuple[list[PushFunction], list[str]]:
    """The parts' push functions and warnings (import, fragile states); disk-like parts refused."""
    pfs, warnings = [], []
    for source in sources:
        loaded = load_part_with_warnings(source, catalog=catalog)
        if not loaded.orientability.orientable:
            raise InputError(f"{source}: not orientable by pushing: {loaded.orientability.reason}")
        warnings += [f"{source}: {w}" for w in loaded.warnings]
        pfs.append(push_function(loaded.part))
        fragile = fragile_warning(pfs[-1])
        if fragile is not None:
            warnings.append(fragile)
    names = [pf.part.name for pf in pfs]
    for name in names:
        if names.count(name) > 1:
            raise InputError(f"two SOURCEs are both the part {name!r}: a mix names each part once")
    return pfs, warnings


def _pairs_message(witnesses: list[PairWitness], lumped: list[tuple[str, str]]) -> str:
    """One line naming the pairs no plan can tell apart (section 8.4), and any disagreement."""
    lumped_text = ", ".join(f"{a} & {b}" for a, b in lumped) or "none"
    if not witnesses:
        return (
            f"the plan's results lump {lumped_text}, which the mix analysis can tell apart: "
            "please report this as a bug"
        )
    named = "; ".join(f"{w.part_a} & {w.part_b} ({w.reason})" for w in witnesses)
    msg = (
        f"the plan orients every part but cannot tell these parts apart: {named}; "
        "its results list each candidate with its pose"
    )
    if {(w.part_a, w.part_b) for w in witnesses} != set(lumped):
        msg += f" (but the plan's results lump {lumped_text}: please report this as a bug)"
    return msg


def report_html(plan: dict[str, Any], pfs: list[PushFunction], witnesses: list[PairWitness]) -> str:
    """The HTML report (another module's, imported only when asked for)."""
    from feederkit.reports import render_report

    return render_report(
        plan,
        unrecognizable=[w.to_dict() for w in witnesses],
        outlines={pf.part.name: pf.part.outline for pf in pfs},
    )


def write_plan_and_report(
    plan: dict[str, Any],
    pfs: list[PushFunction],
    witnesses: list[PairWitness],
    output: Path | None,
    report: Path | None,
) -> None:
    """Write the plan file and the HTML report where asked (both atomic; the report is
    rendered first, so a report that cannot be made leaves no plan file behind)."""
    html = None if report is None else report_html(plan, pfs, witnesses)
    if output is not None:
        write_plan(output, plan)
    if report is not None and html is not None:
        write_text_atomic(report, html)


def print_written(output: Path | None, report: Path | None) -> None:
    """Say which files were written."""
    for path, what in ((output, "plan"), (report, "report")):
        if path is not None:
            console.print(f"wrote the {what} to {path}", highlight=False, markup=False)


def _header(plan: dict[str, Any], sensor_given: bool) -> str:
    names = escape(", ".join(p["name"] for p in plan["parts"]))
    sensor = sensor_text(plan["sensor"])
    if not sensor_given:
        sensor = "none — no sensor option given, so the plan is sensorless"
    stats = plan["stats"]
    return (
        f"[bold]feederkit plan[/] for {names}\n"
        f"sensor: {sensor}\nobjective: {stats['objective']}, reading branching: "
        f"{stats['grouping']}"
    )


def plan_command(
    sources: Annotated[
        list[str],
        typer.Argument(
            metavar="SOURCE", help="Outline or CAD files, or catalog names; several: a mix."
        ),
    ],
    sensorless: SensorlessOpt = False,
    tolerance: ToleranceOpt = None,
    led_pitch: LedPitchOpt = None,
    noise: NoiseOpt = None,
    objective: ObjectiveOpt = "worst",
    min_margin: MinMarginOpt = 0.0,
    time_limit: TimeLimitOpt = None,
    grouping: GroupingOpt = "exact",
    output: PlanOutputOpt = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the plan file's JSON on stdout.")
    ] = False,
    report: ReportOpt = None,
    catalog: CatalogOpt = None,
) -> None:
    """Plan the shortest conditional sequence of push-align operations that orients the part(s).

    The plan is verified on the kinematic model (every start, reading and branch) before it
    is written or printed. Exit 1 when some parts of a mix cannot be told apart (the plan is
    still written).
    """
    sensor = make_sensor(
        sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
    )
    check_planning_options(objective, grouping, min_margin, time_limit)
    pfs, warnings = _load(sources, catalog)
    for w in warnings:
        err_console.print(f"warning: {w}", highlight=False, markup=False)
    with err_console.status("planning and verifying ..."):
        made, witnesses = plan_mix(
            pfs,
            sensor,
            objective=objective,
            min_margin=min_margin,
            grouping=grouping,
            time_limit=time_limit,
        )
    plan = made.plan
    write_plan_and_report(plan, pfs, witnesses, output, report)
    if json_out:
        print_json(plan)
    else:
        sensor_given = sensorless or tolerance is not None or led_pitch is not None
        console.print(_header(plan, sensor_given), highlight=False)
        console.print(plan_tree(plan))
        console.print(stats_table(plan, made.report))
        print_written(output, report)
    lumped = leaf_part_pairs(plan)
    if witnesses or lumped:
        raise CheckFailed(_pairs_message(witnesses, lumped))


def register(app: typer.Typer) -> None:
    """Add the ``plan`` command to the app."""
    app.command("plan")(plan_command)
