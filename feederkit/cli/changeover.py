"""``feederkit changeover compile|list|show``: one verified plan for a product mix, stored in the
catalog against the exact part revisions (section 8.5).

``compile`` exits 1 when the mix has parts no plan can tell apart: the plan still orients
them (Corollary 7), is still written and stored, and its results list each candidate part.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import (
    CATALOG_ENV,
    get_changeover,
    list_changeovers,
)
from feederkit.cli.catalog_analyze import catalog_file
from feederkit.cli.common import console, err_console, print_json
from feederkit.errors import CheckFailed, InputError
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import compile_changeover
from feederkit.mix.pairs import PairWitness
from feederkit.plans.fileformat import validate_plan, write_plan, write_text_checked
from feederkit.plans.render import plan_tree, sensor_text, stats_table
from feederkit.sensors import make_sensor, sensor_to_dict

changeover_app = typer.Typer(
    name="changeover",
    help="Changeovers: one verified plan that orients and recognizes every part of a mix.",
    no_args_is_help=True,
)

CatalogOpt = Annotated[
    Path | None,
    typer.Option(
        "--catalog",
        envvar=CATALOG_ENV,
        help="Catalog file (default $FEEDERKIT_CATALOG, else ./feederkit.db).",
        show_envvar=True,
    ),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Machine-readable output on stdout.")]

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
    sensorless: Annotated[
        bool, typer.Option("--sensorless", help="No sensor (the default).")
    ] = False,
    tolerance: Annotated[
        float | None,
        typer.Option("--tolerance", help="Diameter sensor: readings strictly within MM of d."),
    ] = None,
    led_pitch: Annotated[
        float | None, typer.Option("--led-pitch", help="LED array with beams every MM.")
    ] = None,
    noise: Annotated[
        float | None, typer.Option("--noise", help="The LED array's alignment noise (mm).")
    ] = None,
    objective: Annotated[
        str, typer.Option("--objective", help="worst (default) or expected number of operations.")
    ] = "worst",
    min_margin: Annotated[
        float, typer.Option("--min-margin", help="Use only rotations keeping this margin (deg).")
    ] = 0.0,
    time_limit: Annotated[
        float | None,
        typer.Option("--time-limit", help="Seconds; then the best plan found, optimal: false."),
    ] = None,
    grouping: Annotated[
        str, typer.Option("--grouping", help="exact (default) or components (the paper's rule).")
    ] = "exact",
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="Also write the plan file here (atomic).")
    ] = None,
    report: Annotated[
        Path | None, typer.Option("--report", help="Also write the HTML report here.")
    ] = None,
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
    if objective not in ("worst", "expected"):
        raise InputError(f"--objective must be worst or expected, got {objective!r}")
    if grouping not in ("exact", "components"):
        raise InputError(f"--grouping must be exact or components, got {grouping!r}")
    if not 0.0 <= min_margin < 180.0:
        raise InputError(f"--min-margin must be at least 0 and below 180 degrees, got {min_margin}")
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
    plan, witnesses, pfs, revisions = (
        compiled.plan,
        list(compiled.witnesses),
        list(compiled.parts),
        list(compiled.revisions),
    )
    html = None
    if report is not None:
        from feederkit.reports import render_report

        html = render_report(
            plan,
            unrecognizable=[w.to_dict() for w in witnesses],
            outlines={pf.part.name: pf.part.outline for pf in pfs},
        )
    if output is not None:
        write_plan(output, plan)
    if report is not None:
        write_text_checked(report, html)
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
        for p, what in ((output, "plan"), (report, "report")):
            if p is not None:
                console.print(f"wrote the {what} to {p}", highlight=False, markup=False)
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
