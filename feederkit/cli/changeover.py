"""``feederkit changeover compile|list|show|remove|export|report``: one verified plan for a
product mix, stored in the catalog against the exact part revisions (section 8.5;
docs/changeovers.md).

``compile`` exits 1 when the mix has parts no plan can tell apart: the plan still orients
them (Corollary 7), is still written and stored, and its results list each candidate part.
Every command that shows a stored changeover warns when a part has a newer revision.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import list_changeovers, remove_changeover, resolve_catalog_path
from feederkit.cli.common import (
    DEFAULT_TIME_LIMIT_S,
    CatalogOpt,
    ComToleranceOpt,
    GroupingOpt,
    JsonOpt,
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
    report_html,
    searching,
    sensor_option,
    time_limit_note,
    uncertainty_option,
    uncertainty_text,
)
from feederkit.cli.plan_render import plan_tree, sensor_text, stats_table
from feederkit.errors import CheckFailed, InputError
from feederkit.jsonio import OutputFile, write_files
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import (
    changeover_exists,
    compile_changeover,
    load_changeover,
    stale_revisions,
)
from feederkit.mix.pairs import PairWitness
from feederkit.plans.fileformat import plan_json

changeover_app = typer.Typer(
    rich_markup_mode="markdown",
    name="changeover",
    help="Changeovers: one verified plan that orients and recognizes every part of a mix.",
    no_args_is_help=True,
)

NameArg = Annotated[str, typer.Argument(help="Name of the changeover.")]


def parse_mix(text: str) -> list[str]:
    """``A,B@2,C`` as catalog SOURCEs (``NAME@REV`` is resolved by :mod:`feederkit.sources`)."""
    members = [m.strip() for m in text.split(",")]
    if not text.strip() or any(not m for m in members):
        raise InputError(
            f"--mix must be a comma-separated list of catalog part names, got {text!r}"
        )
    return members


def _pairs_table(witnesses: list[PairWitness], pfs: list[PushFunction]) -> Table:
    t = Table(title="parts this plan orients but cannot tell apart (section 8.4, Corollary 7)")
    t.add_column("part A")
    t.add_column("part B")
    t.add_column("inseparable states (A ~ B)")
    t.add_column("why")
    for w in witnesses:
        t.add_row(
            escape(w.part_a),
            escape(w.part_b),
            ", ".join(f"{i}~{j}" for i, j in w.pairs),
            escape(w.reason),
        )
    return t


@changeover_app.command("compile")
def compile_command(
    name: NameArg,
    mix: Annotated[
        str,
        typer.Option("--mix", help="Catalog parts, comma-separated: A,B,C (NAME@REV pins one)."),
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
    report: ReportOpt = None,
    replace: Annotated[
        bool, typer.Option("--replace", help="Replace a stored changeover of the same name.")
    ] = False,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
    rotation_error: RotationErrorOpt = 1.0,
    shape_tolerance: ShapeToleranceOpt = 0.0,
    com_tolerance: ComToleranceOpt = 0.0,
) -> None:
    """Plan one verified sequence of push-align operations that orients (and, where possible,
    recognizes) every part of the mix, and store it against the parts' exact revisions.

    Exit 1 when some parts cannot be told apart (the plan is still written and stored).
    """
    sensor = sensor_option(sensorless, tolerance, led_pitch, noise)
    options = planning_options(objective, grouping, min_margin, time_limit)
    uncertainty = uncertainty_option(rotation_error, shape_tolerance, com_tolerance)
    path = resolve_catalog_path(catalog)
    members = parse_mix(mix)
    if not replace and changeover_exists(path, name):
        raise InputError(f"a changeover named {name!r} already exists (use --replace)")

    def outputs(c) -> list[OutputFile]:
        return plan_outputs(c.plan, list(c.parts), list(c.witnesses), output, report)

    with searching(f"compiling changeover {name}", options.time_limit_s), flag_words():
        compiled = compile_changeover(
            path,
            name,
            members,
            sensor,
            options,
            replace=replace,
            outputs=outputs,
            uncertainty=uncertainty,
        )
    plan, witnesses, pfs = compiled.plan, list(compiled.witnesses), list(compiled.parts)
    warnings = list(compiled.warnings)
    note = time_limit_note(plan["stats"], options.time_limit_s)
    if note is not None:
        warnings.append(note)
    print_warnings(warnings)
    if json_out:
        print_json(
            {
                "name": name,
                "parts": [{"name": n, "revision": r} for n, r in compiled.revisions],
                "unrecognizable_pairs": [w.to_dict() for w in witnesses],
                "warnings": warnings,
                "plan": plan,
            }
        )
    else:
        mix_text = ", ".join(f"{n}@{r}" for n, r in compiled.revisions)
        console.print(
            f"[bold]changeover {escape(name)}[/]: {escape(mix_text)}\n"
            f"sensor: {sensor_text(sensor.to_dict())}\n"
            f"uncertainty: {uncertainty_text(plan.get('uncertainty'))}",
            highlight=False,
        )
        console.print(plan_tree(plan))
        console.print(stats_table(plan, compiled.made.report))
        if witnesses:
            console.print(_pairs_table(witnesses, pfs))
        console.print(f"stored changeover {name!r} in {path}", highlight=False, markup=False)
        print_written(output, report)
    lumped = compiled.lumped
    if witnesses or lumped:
        named = "; ".join(f"{w.part_a} & {w.part_b} ({w.reason})" for w in witnesses)
        if not witnesses:
            named = ", ".join(f"{a} & {b}" for a, b in lumped)
        raise CheckFailed(
            f"changeover {name!r} orients every part but cannot tell these apart: {named}; "
            "the plan's results list each candidate with its pose"
        )


@changeover_app.command("list")
def list_command(json_out: JsonOpt = False, catalog: CatalogOpt = None) -> None:
    """The stored changeovers: name, parts with revisions, sensor, when and by whom."""
    path = resolve_catalog_path(catalog)
    infos = list_changeovers(path)
    stale = {i.name: stale_revisions(path, i.parts) for i in infos}
    print_warnings(f"changeover {i.name}: {w}" for i in infos for w in stale[i.name])
    if json_out:
        print_json([{**_info_dict(i), "warnings": stale[i.name]} for i in infos])
        return
    if not infos:
        console.print("no changeovers in the catalog")
        return
    t = Table(title="changeovers")
    for col in ("name", "parts", "sensor", "created", "by"):
        t.add_column(col, overflow="fold")
    for i in infos:
        t.add_row(
            escape(i.name) + (" (newer revisions)" if stale[i.name] else ""),
            escape(", ".join(f"{n}@{r}" for n, r in i.parts)),
            sensor_text(dict(i.sensor)),
            i.created_at,
            escape(i.created_by),
        )
    console.print(t)


@changeover_app.command("show")
def show_command(name: NameArg, json_out: JsonOpt = False, catalog: CatalogOpt = None) -> None:
    """A stored changeover: its parts (exact revisions), sensor and plan."""
    co = load_changeover(resolve_catalog_path(catalog), name)
    print_warnings(co.warnings)
    if json_out:
        print_json({**_info_dict(co.info), "warnings": list(co.warnings), "plan": co.plan})
        return
    info = co.info
    console.print(
        f"[bold]changeover {escape(info.name)}[/]: "
        f"{escape(', '.join(f'{n}@{r}' for n, r in info.parts))}\n"
        f"sensor: {sensor_text(dict(info.sensor))}\ncreated {info.created_at} by "
        f"{escape(info.created_by)}",
        highlight=False,
    )
    console.print(plan_tree(co.plan))
    console.print(stats_table(co.plan))


@changeover_app.command("remove")
def remove_command(name: NameArg, catalog: CatalogOpt = None) -> None:
    """Delete a stored changeover (its parts stay in the catalog)."""
    path = resolve_catalog_path(catalog)
    remove_changeover(path, name)
    console.print(f"removed changeover {name!r} from {path}", highlight=False, markup=False)


OutputOpt = Annotated[Path, typer.Option("-o", "--output", help="Write the file here (atomic).")]


@changeover_app.command("export")
def export_command(name: NameArg, output: OutputOpt, catalog: CatalogOpt = None) -> None:
    """Write a stored changeover's plan file, for feederkit run or a controller."""
    co = load_changeover(resolve_catalog_path(catalog), name)
    print_warnings(co.warnings)
    write_files([OutputFile(output, plan_json(co.plan), "plan file")])
    console.print(f"wrote the plan to {output}", highlight=False, markup=False)


@changeover_app.command("report")
def report_command(name: NameArg, output: OutputOpt, catalog: CatalogOpt = None) -> None:
    """Write a stored changeover's HTML report, with the pairs of parts no plan can tell apart."""
    co = load_changeover(resolve_catalog_path(catalog), name)
    print_warnings(co.warnings)
    html = report_html(co.plan, co.parts, co.witnesses())
    write_files([OutputFile(output, html, "report")])
    console.print(f"wrote the report to {output}", highlight=False, markup=False)


def _info_dict(info) -> dict[str, Any]:
    return {
        "name": info.name,
        "created_at": info.created_at,
        "created_by": info.created_by,
        "parts": [{"name": n, "revision": r} for n, r in info.parts],
        "sensor": dict(info.sensor),
    }


def register(app: typer.Typer) -> None:
    """Add the ``changeover`` command group to the app."""
    app.add_typer(changeover_app, name="changeover")
