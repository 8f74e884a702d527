"""``feederkit changeover compile|list|show``: one verified plan for a product mix, stored in the
catalog against the exact part revisions (section 8.5).

``compile`` exits 1 when the mix has parts no plan can tell apart: the plan still orients
them (Corollary 7), is still written and stored, and its results list each candidate part.
"""

from __future__ import annotations

import re
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import get_changeover, list_changeovers
from feederkit.cli.catalog_analyze import catalog_file
from feederkit.cli.common import (
    CatalogOpt,
    GroupingOpt,
    JsonOpt,
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
from feederkit.cli.plan import print_written, write_plan_and_report
from feederkit.errors import CheckFailed, InputError
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import compile_changeover
from feederkit.mix.pairs import PairWitness
from feederkit.plans.fileformat import validate_plan
from feederkit.plans.render import plan_tree, sensor_text, stats_table
from feederkit.sensors import make_sensor, sensor_to_dict

changeover_app = typer.Typer(
    name="changeover",
    help="Changeovers: one verified plan that orients and recognizes every part of a mix.",
    no_args_is_help=True,
)

_MEMBER_RE = re.compile(r"^(?P<name>.+)@(?P<rev>\d+)$")


def parse_mix(text: str) -> list[tuple[str, int | None]]:
    """``A,B@2,C`` as (name, revision or None for the latest); bad lists are bad input."""
    members = [m.strip() for m in text.split(",")]
    if not text.strip() or any(not m for m in members):
        raise InputError(
            f"--mix must be a comma-separated list of catalog part names, got {text!r}"
        )
    out: list[tuple[str, int | None]] = []
    for m in members:
        found = _MEMBER_RE.match(m)
        out.append((found["name"], int(found["rev"])) if found else (m, None))
    names = [n for n, _ in out]
    for n in names:
        if names.count(n) > 1:
            raise InputError(f"--mix names the part {n!r} twice")
    return out


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
    name: Annotated[str, typer.Argument(help="Name of the changeover.")],
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
    time_limit: TimeLimitOpt = None,
    grouping: GroupingOpt = "exact",
    output: PlanOutputOpt = None,
    report: ReportOpt = None,
    replace: Annotated[
        bool, typer.Option("--replace", help="Replace a stored changeover of the same name.")
    ] = False,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
) -> None:
    """Plan one verified sequence of push-align operations that orients (and, where possible,
    recognizes) every part of the mix, and store it against the parts' exact revisions.

    Exit 1 when some parts cannot be told apart (the plan is still written and stored).
    """
    sensor = make_sensor(
        sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
    )
    check_planning_options(objective, grouping, min_margin, time_limit)
    path = catalog_file(catalog)
    with err_console.status("planning and verifying ..."):
        compiled = compile_changeover(
            path,
            name,
            parse_mix(mix),
            sensor,
            objective=objective,
            min_margin=min_margin,
            grouping=grouping,
            time_limit=time_limit,
            replace=replace,
        )
    for warning in compiled.warnings:
        err_console.print(f"warning: {warning}", highlight=False, markup=False)
    plan, witnesses, pfs, revisions = (
        compiled.plan,
        list(compiled.witnesses),
        list(compiled.parts),
        list(compiled.revisions),
    )
    write_plan_and_report(plan, pfs, witnesses, output, report)
    if json_out:
        print_json(
            {
                "name": name,
                "parts": [{"name": n, "revision": r} for n, r in revisions],
                "unrecognizable_pairs": [w.to_dict() for w in witnesses],
                "plan": plan,
            }
        )
    else:
        mix_text = ", ".join(f"{n}@{r}" for n, r in revisions)
        console.print(
            f"[bold]changeover {escape(name)}[/]: {escape(mix_text)}\n"
            f"sensor: {sensor_text(sensor_to_dict(sensor))}",
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
    infos = list_changeovers(catalog_file(catalog))
    if json_out:
        print_json([_info_dict(i) for i in infos])
        return
    if not infos:
        console.print("no changeovers in the catalog")
        return
    t = Table(title="changeovers")
    for col in ("name", "parts", "sensor", "created", "by"):
        t.add_column(col)
    for i in infos:
        t.add_row(
            escape(i.name),
            escape(", ".join(f"{n}@{r}" for n, r in i.parts)),
            sensor_text(dict(i.sensor)),
            i.created_at,
            escape(i.created_by),
        )
    console.print(t)


@changeover_app.command("show")
def show_command(
    name: Annotated[str, typer.Argument(help="Name of the changeover.")],
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
) -> None:
    """A stored changeover: its parts (exact revisions), sensor and plan."""
    co = get_changeover(catalog_file(catalog), name)
    plan = validate_plan(_loads(co.plan_json), f"changeover {name!r}")
    if json_out:
        data = _info_dict(co.info)
        data["plan"] = plan
        print_json(data)
        return
    info = co.info
    console.print(
        f"[bold]changeover {escape(info.name)}[/]: "
        f"{escape(', '.join(f'{n}@{r}' for n, r in info.parts))}\n"
        f"sensor: {sensor_text(dict(info.sensor))}\ncreated {info.created_at} by "
        f"{escape(info.created_by)}",
        highlight=False,
    )
    console.print(plan_tree(plan))
    console.print(stats_table(plan))


def _loads(text: str) -> Any:
    import json

    return json.loads(text)


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
