"""``feederkit plan SOURCE...``: a verified orienting plan for one part or a product mix.

A thin layer: build the sensor and the planning options once, load and check the parts
(:func:`feederkit.loading.load_parts`), call :func:`feederkit.mix.changeover.plan_mix`
(planner, plan file, verification), write the plan and the report together (both or
neither), print the tree and the warnings (a margin below 1 degree, a time limit reached).
"""

from __future__ import annotations

from typing import Annotated, Any

import typer
from rich.markup import escape

from feederkit.cli.common import (
    DEFAULT_TIME_LIMIT_S,
    CatalogOpt,
    ComToleranceOpt,
    GroupingOpt,
    LedPitchOpt,
    MinMarginOpt,
    NoiseOpt,
    ObjectiveOpt,
    PlanOutputOpt,
    ReportOpt,
    RotationErrorOpt,
    SensorlessOpt,
    ShapeToleranceOpt,
    TimeLimitOpt,
    ToleranceOpt,
    console,
    flag_words,
    plan_outputs,
    planning_options,
    print_json,
    print_warnings,
    print_written,
    searching,
    sensor_option,
    time_limit_note,
    uncertainty_option,
    uncertainty_text,
)
from feederkit.cli.plan_render import plan_tree, sensor_text, stats_table
from feederkit.errors import CheckFailed
from feederkit.jsonio import write_files
from feederkit.loading import load_parts
from feederkit.mix.changeover import plan_mix
from feederkit.mix.pairs import PairWitness
from feederkit.plans.match import leaf_part_pairs


def pairs_message(witnesses: list[PairWitness], lumped: list[tuple[str, str]]) -> str:
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


def _header(plan: dict[str, Any], sensor_given: bool) -> str:
    names = escape(", ".join(p["name"] for p in plan["parts"]))
    sensor = sensor_text(plan["sensor"])
    if not sensor_given:
        sensor = "none — no sensor option given, so the plan is sensorless"
    stats = plan["stats"]
    return (
        f"[bold]feederkit plan[/] for {names}\n"
        f"sensor: {sensor}\nuncertainty: {uncertainty_text(plan.get('uncertainty'))}\n"
        f"objective: {stats['objective']}, reading branching: {stats['grouping']}"
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
    time_limit: TimeLimitOpt = DEFAULT_TIME_LIMIT_S,
    grouping: GroupingOpt = "exact",
    output: PlanOutputOpt = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the plan file's JSON on stdout.")
    ] = False,
    report: ReportOpt = None,
    catalog: CatalogOpt = None,
    rotation_error: RotationErrorOpt = 1.0,
    shape_tolerance: ShapeToleranceOpt = 0.0,
    com_tolerance: ComToleranceOpt = 0.0,
) -> None:
    """Plan the shortest conditional sequence of push-align operations that orients the part(s).

    The plan is verified on the kinematic model (every start, reading and branch) before it
    is written or printed; under the declared uncertainty (``--rotation-error``, default 1
    degree) it is a strong plan, verified for every outcome. Exit 1 when some parts of a mix
    cannot be told apart (the plan is still written).
    """
    sensor = sensor_option(sensorless, tolerance, led_pitch, noise)
    options = planning_options(objective, grouping, min_margin, time_limit)
    uncertainty = uncertainty_option(rotation_error, shape_tolerance, com_tolerance)
    loaded = load_parts(sources, catalog=catalog)
    print_warnings(loaded.warnings)
    pfs = list(loaded.push_functions)
    with searching("planning and verifying", options.time_limit_s), flag_words():
        made, witnesses = plan_mix(pfs, sensor, options, uncertainty=uncertainty)
    plan = made.plan
    write_files(plan_outputs(plan, pfs, witnesses, output, report))
    notes = [*made.warnings]
    note = time_limit_note(plan["stats"], options.time_limit_s)
    if note is not None:
        notes.append(note)
    print_warnings(notes)
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
        raise CheckFailed(pairs_message(witnesses, lumped))


def register(app: typer.Typer) -> None:
    """Add the ``plan`` command to the app."""
    app.command("plan")(plan_command)
