"""``feederkit plan SOURCE...``: a verified orienting plan for one part or a product mix.

A thin layer: resolve the parts, choose the sensor, call :func:`feederkit.plans.make.make_plan`
(planner, plan file, verification), write the plan and the report, print the tree.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from feederkit.cli.common import console, err_console, print_json
from feederkit.errors import CheckFailed, InputError
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.pairs import PairWitness, unrecognizable_pairs
from feederkit.plans.fileformat import write_plan, write_text_checked
from feederkit.plans.make import make_plan
from feederkit.plans.match import leaf_part_pairs
from feederkit.plans.render import plan_tree, sensor_text, stats_table
from feederkit.sensors import make_sensor
from feederkit.sources import load_part_with_warnings

OBJECTIVES = ("worst", "expected")
GROUPINGS = ("exact", "components")


def _load(sources: list[str], catalog: str | None) -> tuple[list[PushFunction], list[str]]:
    """The parts' push functions and the imports' warnings; a disk-like part is refused."""
    pfs, warnings = [], []
    for source in sources:
        loaded = load_part_with_warnings(source, catalog=catalog)
        if not loaded.orientability.orientable:
            raise InputError(f"{source}: not orientable by pushing: {loaded.orientability.reason}")
        warnings += [f"{source}: {w}" for w in loaded.warnings]
        pfs.append(push_function(loaded.part))
    names = [pf.part.name for pf in pfs]
    for name in names:
        if names.count(name) > 1:
            raise InputError(f"two SOURCEs are both the part {name!r}: a mix names each part once")
    return pfs, warnings


def _check_options(objective: str, grouping: str, min_margin: float, time_limit: float | None):
    if objective not in OBJECTIVES:
        raise InputError(f"--objective must be worst or expected, got {objective!r}")
    if grouping not in GROUPINGS:
        raise InputError(f"--grouping must be exact or components, got {grouping!r}")
    if not 0.0 <= min_margin < 180.0:
        raise InputError(f"--min-margin must be at least 0 and below 180 degrees, got {min_margin}")
    if time_limit is not None and not time_limit > 0.0:
        raise InputError(f"--time-limit must be a positive number of seconds, got {time_limit}")


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


def _report_html(
    plan: dict[str, Any], pfs: list[PushFunction], witnesses: list[PairWitness]
) -> str:
    """The HTML report (another module's, imported only when asked for)."""
    from feederkit.reports import render_report

    return render_report(
        plan,
        unrecognizable=[w.to_dict() for w in witnesses],
        outlines={pf.part.name: pf.part.outline for pf in pfs},
    )


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
    sensorless: Annotated[
        bool, typer.Option("--sensorless", help="No sensor (the default when none is given).")
    ] = False,
    tolerance: Annotated[
        float | None,
        typer.Option(
            "--tolerance", metavar="MM", help="Diameter sensor: readings strictly within MM of d."
        ),
    ] = None,
    led_pitch: Annotated[
        float | None,
        typer.Option("--led-pitch", metavar="MM", help="LED array with beams every MM."),
    ] = None,
    noise: Annotated[
        float | None,
        typer.Option("--noise", metavar="MM", help="The LED array's alignment noise (mm)."),
    ] = None,
    objective: Annotated[
        str,
        typer.Option(
            "--objective",
            metavar="worst|expected",
            help="worst: fewest operations in the worst case; "
            "expected: fewest on average (uniform start).",
        ),
    ] = "worst",
    min_margin: Annotated[
        float,
        typer.Option(
            "--min-margin", metavar="DEG", help="Use only rotations keeping this margin (deg)."
        ),
    ] = 0.0,
    time_limit: Annotated[
        float | None,
        typer.Option(
            "--time-limit", metavar="S", help="Seconds; then the best plan found, optimal: false."
        ),
    ] = None,
    grouping: Annotated[
        str,
        typer.Option(
            "--grouping",
            metavar="exact|components",
            help="exact (default) or components (the paper's rule).",
        ),
    ] = "exact",
    output: Annotated[
        Path | None,
        typer.Option(
            "-o", "--output", metavar="PLAN.json", help="Write the plan file here (atomic)."
        ),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the plan file's JSON on stdout.")
    ] = False,
    report: Annotated[
        Path | None,
        typer.Option("--report", metavar="REPORT.html", help="Also write the HTML report here."),
    ] = None,
    catalog: Annotated[
        str | None,
        typer.Option("--catalog", metavar="DB", help="The parts catalog for catalog names."),
    ] = None,
) -> None:
    """Plan the shortest conditional sequence of push-align operations that orients the part(s).

    The plan is verified on the kinematic model (every start, reading and branch) before it
    is written or printed. Exit 1 when some parts of a mix cannot be told apart (the plan is
    still written).
    """
    sensor = make_sensor(
        sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
    )
    _check_options(objective, grouping, min_margin, time_limit)
    pfs, warnings = _load(sources, catalog)
    for w in warnings:
        err_console.print(f"warning: {w}", highlight=False, markup=False)
    with err_console.status("planning and verifying ..."):
        made = make_plan(
            pfs,
            sensor,
            objective=objective,
            min_margin=min_margin,
            grouping=grouping,
            time_limit=time_limit,
        )
        witnesses = unrecognizable_pairs(pfs, sensor) if len(pfs) > 1 else []
    plan = made.plan
    html = None if report is None else _report_html(plan, pfs, witnesses)
    if output is not None:
        write_plan(output, plan)
    if report is not None and html is not None:
        write_text_checked(report, html)
    if json_out:
        print_json(plan)
    else:
        sensor_given = sensorless or tolerance is not None or led_pitch is not None
        console.print(_header(plan, sensor_given), highlight=False)
        console.print(plan_tree(plan))
        console.print(stats_table(plan, made.report))
        for path, what in ((output, "plan"), (report, "report")):
            if path is not None:
                console.print(f"wrote the {what} to {path}", highlight=False, markup=False)
    lumped = leaf_part_pairs(plan)
    if witnesses or lumped:
        raise CheckFailed(_pairs_message(witnesses, lumped))


def register(app: typer.Typer) -> None:
    """Add the ``plan`` command to the app."""
    app.command("plan")(plan_command)
