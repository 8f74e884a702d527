"""``feederkit demo``: the main job on the bundled ``catalog/``, printed.

The work is :func:`feederkit.demo.run_demo` (import, analyse, plan each part sensorless and
with a diameter sensor, compile changeovers, one over every landing with the face-down ones
rejected and one with a look-alike pair no plan can tell apart, write every plan file and
report); this module parses the options, shows progress, and prints the result as tables or
``--json``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.box import SIMPLE_HEAD
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import BadFilesError
from feederkit.cell import load_cell, resolve_settings
from feederkit.cli.changeover import CellOpt, landings_text
from feederkit.cli.common import (
    add_name_column,
    console,
    cycle_line,
    err_console,
    flag_words,
    json_option,
    plural,
    print_json,
    progress_bar,
    uncertainty_text,
)
from feederkit.cli.plan_render import plan_tree, stats_table
from feederkit.demo import (
    DemoChangeover,
    DemoPlan,
    DemoResult,
    PartRow,
    default_catalog_dir,
    run_demo,
)
from feederkit.errors import InputError

DEMO_FLAGS = (("sensor tolerance", "--tolerance-percent"),)
"""The demo's flag for the library's term."""

DEMO_BAD_FILES_ADVICE = "the demo reads every file: fix the bad ones or move them out of the folder"
"""What to do about bad part files: the demo has no ``--skip-bad``."""


def margin_text(m: float | None) -> str:
    """A plan's smallest margin in degrees with three significant digits ("-" when none)."""
    if m is None or math.isinf(m):
        return "-"
    return f"{m:.3g}\u00b0"


def analysis_table(rows: tuple[PartRow, ...], percent: float) -> Table:
    """The parts: size, states, distinct diameters, symmetry period, Fig. 14 class and bound."""
    t = Table(
        title=f"parts (sensor: tolerance {percent:g}% of each part's size)",
        box=SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    add_name_column(t, "part")
    for col in ("mm", "states", "diam.", "period", "class", "bound"):
        t.add_column(col, justify="right")
    for r in rows:
        t.add_row(
            escape(r.name),
            f"{r.size_mm:.3g}",
            str(r.states),
            str(r.diameters),
            "none" if r.period_deg >= 360.0 else f"{r.period_deg:g}°",
            "-" if r.polygon_class is None else str(r.polygon_class),
            "-" if r.bound is None else str(r.bound),
        )
    return t


def _certified(stats: dict) -> str:
    """The sensed plan's certified rotation error (design.md's certificate), or '-'."""
    cert = stats.get("certificate")
    return "-" if cert is None else f"±{cert['max_rotation_error_deg']:.3g}°"


def _length(stats: dict) -> tuple[str, str]:
    """A plan's worst-case length and its expected number of operations, as two cells."""
    return str(stats["length"]), f"{stats['expected_length']:.2f}"


def plans_tables(plans: tuple[DemoPlan, ...]) -> tuple[Table, Table]:
    """Each part's sensorless plan, then its sensor plan with bound and certificate, in two
    tables narrow enough for 80 columns."""
    style = {"box": SIMPLE_HEAD, "pad_edge": False, "collapse_padding": True}
    blind = Table(
        title="sensorless plans, each part face up: worst-case length, expected, smallest margin",
        **style,
    )
    sensed = Table(
        title="sensor plans, face up; cert = certified rotation error, ideal = ideal-model length",
        **style,
    )
    add_name_column(blind, "part")
    add_name_column(sensed, "part")
    for col in ("length", "expected", "margin"):
        blind.add_column(col, justify="right", no_wrap=True)
    for col in ("tol mm", "length", "exp.", "margin", "bound", "cert", "ideal"):
        sensed.add_column(col, justify="right", no_wrap=True)
    for p in plans:
        a, b = p.sensorless["stats"], p.sensed["stats"]
        bound = b.get("class_bound")
        meets = "" if b.get("meets_bound") in (None, True) else " exceeded!"
        blind.add_row(escape(p.name), *_length(a), margin_text(a.get("min_margin_deg")))
        sensed.add_row(
            escape(p.name),
            f"{p.sensor.to_dict()['tolerance_mm']:g}",
            *_length(b),
            margin_text(b.get("min_margin_deg")),
            ("-" if bound is None else str(bound)) + meets,
            _certified(b),
            str(b.get("certificate", {}).get("ideal_length", "-")),
        )
    return blind, sensed


def print_changeover(say: Console, c: DemoChangeover) -> None:
    """One changeover: parts, sensor, statistics, warnings, the pairs no plan tells apart."""
    compiled = c.compiled
    tol = compiled.plan["sensor"].get("tolerance_mm")
    say.print(
        f"\n[bold]changeover {escape(c.name)}[/]: {escape(', '.join(c.members))} "
        f"(tolerance {tol:g} mm)",
        highlight=False,
    )
    if c.name == "fig27-triangle-octagon":
        say.print(plan_tree(compiled.plan))
    lands = landings_text(compiled.plan, compiled.rejected)
    if lands is None:
        lands = "landings: one per part (mirror-symmetric: face down is the same shape)"
    elif c.landings_planned is not None:
        lands = f"landings: {', '.join(c.landings_planned)} only (--landings), as in the paper"
    say.print(f"  {escape(lands)}", highlight=False)
    if c.note is not None:
        say.print(f"  note: {escape(c.note)}", highlight=False)
    say.print(stats_table(compiled.plan, compiled.made.report))
    declared = uncertainty_text(compiled.plan.get("uncertainty"))
    say.print(f"  uncertainty: {escape(declared)}", highlight=False)
    if c.cycle_time is not None:
        say.print(f"  {escape(cycle_line(c.cycle_time))}", highlight=False)
    for warning in compiled.warnings:
        say.print(f"  warning: {escape(warning)}", highlight=False)
    for w in compiled.witnesses:
        say.print(
            f"  cannot be told apart: {escape(w.part_a)} & {escape(w.part_b)}: {escape(w.reason)}",
            highlight=False,
        )
    if c.lookalike and compiled.witnesses:
        say.print(
            "  the plan orients every part, recognizes the others, and its results list both "
            "look-alikes with their poses (section 8.4), on either side; the report says so",
            highlight=False,
        )
    if compiled.rejected:
        say.print(
            "  a part in a rejected landing ends in a reject result as soon as the plan knows "
            "(docs/landings.md); run says reject and the controller re-drops it",
            highlight=False,
        )
    say.print(f"  plan: {c.plan_path}", highlight=False)
    if c.report_path is not None:
        say.print(f"  report: {c.report_path}", highlight=False)


def print_result(say: Console, result: DemoResult) -> None:
    """The demo's tables and notes, for people."""
    parts = plural(result.part_count, "part")
    head = f"[bold]feederkit demo[/]: {parts} from {escape(str(result.source_dir))}"
    if result.not_orientable:
        head += f"; not orientable by pushing: {escape(', '.join(result.not_orientable))}"
    say.print(head, highlight=False)
    if result.cell is not None:
        say.print(escape(result.cell), highlight=False)
    say.print(analysis_table(result.rows, result.percent))
    for note in result.notes:
        say.print(f"  note: {escape(note)}", highlight=False)
    if result.plans:
        declared = result.plans[0].sensed.get("uncertainty")
        say.print(f"plans are strong for: {uncertainty_text(declared)}", highlight=False)
    for table in plans_tables(result.plans):
        say.print(table)
    for p in result.plans:
        for w in p.warnings:
            say.print(f"  warning: {escape(w)}", highlight=False)
    for c in result.changeovers:
        print_changeover(say, c)


def demo_command(
    catalog_dir: Annotated[
        Path | None,
        typer.Option(
            "--catalog-dir",
            metavar="DIR",
            help="Folder of part files to import (default: ./catalog, else the bundled one).",
        ),
    ] = None,
    output: Annotated[
        Path,
        typer.Option(
            "-o", "--output", metavar="DIR", help="Folder for the plan files and reports."
        ),
    ] = Path("demo-out"),
    percent: Annotated[
        float,
        typer.Option(
            "--tolerance-percent",
            metavar="PERCENT",
            help="The diameter sensor's tolerance, in percent of the part's size (each part's "
            "own plan) or of the largest part's (each changeover).",
        ),
    ] = 1.0,
    json_out: Annotated[bool, json_option("A summary on stdout as JSON.")] = False,
    cell: CellOpt = None,
) -> None:
    """The main job on the bundled catalog: import, analyse, plan, compile changeovers, report.

    With a cell profile (``--cell`` or ./feederkit.toml) that gives the robot's and belt's
    timing, every changeover also shows its cycle time (docs/cell.md).
    """
    source_dir = catalog_dir if catalog_dir is not None else default_catalog_dir()
    settings = resolve_settings(load_cell(cell))
    with progress_bar() as bar, flag_words(DEMO_FLAGS):
        task = bar.add_task("demo", total=None)

        def progress(what: str, done: int, total: int | None) -> None:
            bar.update(task, description=what, completed=done, total=total)

        try:
            result = run_demo(source_dir, output, percent, progress, cell=settings)
        except BadFilesError as exc:  # its advice is catalog import's --skip-bad
            raise InputError(exc.with_advice(DEMO_BAD_FILES_ADVICE)) from None
    if json_out:
        print_result(err_console, result)
        print_json(result.to_dict())
        return
    print_result(console, result)
    console.print(f"\nplans and reports are in {output}/", highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    """Add ``feederkit demo``."""
    app.command("demo")(demo_command)
