"""``feederkit demo``: the main job on the bundled ``catalog/``.

Imports the sample outlines into a temporary catalog, analyses every part, plans each part
sensorless and with a diameter sensor side by side, compiles changeovers (the paper's
triangle and 8-gon of Figs. 18 and 27, and larger sample mixes), and writes every plan file
and an HTML report per changeover into the output folder.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.box import SIMPLE_HEAD
from rich.markup import escape
from rich.table import Table

import feederkit
from feederkit.catalog import get_part, import_directory, list_parts, open_catalog
from feederkit.cli.common import console, err_console, print_json, progress_bar
from feederkit.cli.plan import report_html
from feederkit.errors import InputError
from feederkit.jsonio import write_text_atomic
from feederkit.mechanics.analysis import analyze_part
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import CompiledChangeover, compile_changeover
from feederkit.plans.fileformat import write_plan
from feederkit.plans.make import make_plan
from feederkit.plans.render import plan_tree, stats_table
from feederkit.sensors import NoSensor, SensorModel, ToleranceSensor, sensor_to_dict

PAPER_MIX = ("isosceles-right-triangle", "octagon")
"""Figs. 18 and 27: the parts the paper orients and recognizes with one plan."""

SMALL_PART_MM = 10.0
"""Parts below this size are the paper's unit-sized shapes; larger ones are feeder parts."""


@dataclass(frozen=True)
class DemoPlan:
    """One part planned sensorless and with the sensor."""

    name: str
    sensor: SensorModel
    sensorless: dict[str, Any]
    sensed: dict[str, Any]


def default_catalog_dir() -> Path:
    """``./catalog`` when it exists, else the ``catalog/`` beside the installed package."""
    here = Path("catalog")
    if here.is_dir():
        return here
    return Path(feederkit.__file__).resolve().parents[1] / "catalog"


def demo_sensor(pfs: list[PushFunction], percent: float) -> ToleranceSensor:
    """A diameter sensor whose tolerance is ``percent`` of the largest part's size."""
    size = max(pf.part.size for pf in pfs)
    return ToleranceSensor(float(f"{size * percent / 100.0:.3g}"))


def _margin(stats: dict[str, Any]) -> str:
    m = stats.get("min_margin_deg")
    return "-" if m is None or (isinstance(m, float) and math.isinf(m)) else f"{m:.1f}°"


def _import(catalog: Path, source_dir: Path) -> None:
    with progress_bar() as bar:
        task = bar.add_task("importing catalog/", total=None)

        def progress(phase: str, done: int, total: int, item: str) -> None:
            bar.update(task, description=f"{phase} {item}".strip(), completed=done, total=total)

        import_directory(catalog, source_dir, progress=progress)


def _analysis_table(
    pfs: list[PushFunction], percent: float
) -> tuple[Table, list[str], list[dict[str, Any]]]:
    t = Table(
        title=f"parts (sensor: tolerance {percent:g}% of each part's size)",
        box=SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    t.add_column("part", no_wrap=True)
    for col in ("mm", "states", "diam.", "period", "class", "bound"):
        t.add_column(col, justify="right")
    notes, rows = [], []
    for pf in pfs:
        sensor = demo_sensor([pf], percent)
        a = analyze_part(pf.part, sensor)
        cls = a.polygon_class
        if a.near_metastable:
            edges = ", ".join(str(n.edge) for n in a.near_metastable)
            notes.append(f"{pf.part.name}: near-metastable edges {edges} (may rest on a neighbour)")
        ndiam = len({round(s.diameter, 9) for s in pf.states})
        period = a.symmetry.part_period_deg
        t.add_row(
            escape(pf.part.name),
            f"{pf.part.size:.3g}",
            str(pf.n),
            str(ndiam),
            "none" if period >= 360.0 else f"{period:g}°",
            str(cls.number) if cls else "-",
            str(cls.bound) if cls else "-",
        )
        rows.append(
            {
                "name": pf.part.name,
                "states": pf.n,
                "symmetry_period_deg": period,
                "class": cls.number if cls else None,
                "bound": cls.bound if cls else None,
                "sensor": sensor_to_dict(sensor),
                "near_metastable_edges": [n.edge for n in a.near_metastable],
            }
        )
    return t, notes, rows


def _plan_parts(pfs: list[PushFunction], percent: float, out: Path) -> list[DemoPlan]:
    plans = []
    with progress_bar() as bar:
        task = bar.add_task("planning", total=len(pfs))
        for pf in pfs:
            bar.update(task, description=f"planning {pf.part.name}")
            sensor = demo_sensor([pf], percent)
            blind = make_plan([pf], NoSensor()).plan
            sensed = make_plan([pf], sensor).plan
            write_plan(out / f"{pf.part.name}.sensorless.json", blind)
            write_plan(out / f"{pf.part.name}.sensor.json", sensed)
            plans.append(DemoPlan(pf.part.name, sensor, blind, sensed))
            bar.advance(task)
    return plans


def _plans_table(plans: list[DemoPlan]) -> Table:
    t = Table(
        title="plans: length (expected), smallest margin; blind = sensorless",
        box=SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    t.add_column("part", no_wrap=True)
    for col in ("blind", "margin", "tol mm", "sensor", "margin", "bound"):
        t.add_column(col, justify="right", no_wrap=True)
    for p in plans:
        a, b = p.sensorless["stats"], p.sensed["stats"]
        bound = b.get("class_bound")
        meets = "" if b.get("meets_bound") in (None, True) else " exceeded!"
        t.add_row(
            escape(p.name),
            f"{a['length']} ({a['expected_length']:.2f})".replace(".00)", ")"),
            _margin(a),
            f"{p.sensor.tolerance:g}",
            f"{b['length']} ({b['expected_length']:.2f})".replace(".00)", ")"),
            _margin(b),
            ("-" if bound is None else str(bound)) + meets,
        )
    return t


def _mixes(pfs: list[PushFunction]) -> list[tuple[str, list[str]]]:
    """The changeovers to compile: Figs. 18/27, then the paper's shapes, then the feeder parts."""
    names = [pf.part.name for pf in pfs]
    size = {pf.part.name: pf.part.size for pf in pfs}
    mixes: list[tuple[str, list[str]]] = []
    if all(n in names for n in PAPER_MIX):
        mixes.append(("fig27-triangle-octagon", list(PAPER_MIX)))
    small = [n for n in names if size[n] < SMALL_PART_MM]
    large = [n for n in names if size[n] >= SMALL_PART_MM]
    if len(small) > 2:
        mixes.append(("paper-shapes", small))
    if len(large) > 1:
        mixes.append(("feeder-parts", large))
    return mixes


def _compile(
    catalog: Path, pfs: dict[str, PushFunction], name: str, members: list[str], percent: float
) -> CompiledChangeover:
    sensor = demo_sensor([pfs[m] for m in members], percent)
    return compile_changeover(catalog, name, [(m, None) for m in members], sensor, replace=True)


def _write_report(compiled: CompiledChangeover, path: Path) -> None:
    html = report_html(compiled.plan, list(compiled.parts), list(compiled.witnesses))
    write_text_atomic(path, html)


def demo_command(
    catalog_dir: Annotated[
        Path | None,
        typer.Option(
            "--catalog-dir",
            help="Folder of part files to import (default: ./catalog, else the bundled one).",
        ),
    ] = None,
    output: Annotated[
        Path,
        typer.Option("-o", "--output", help="Folder for the plan files and reports."),
    ] = Path("demo-out"),
    percent: Annotated[
        float,
        typer.Option(
            "--tolerance-percent",
            help="The diameter sensor's tolerance, in percent of the largest part's size.",
        ),
    ] = 1.0,
    json_out: Annotated[bool, typer.Option("--json", help="A summary on stdout as JSON.")] = False,
) -> None:
    """The main job on the bundled catalog: import, analyse, plan, compile changeovers, report."""
    source_dir = catalog_dir if catalog_dir is not None else default_catalog_dir()
    if not source_dir.is_dir():
        raise InputError(f"{source_dir}: no such folder of part files")
    if not (0.0 < percent < 50.0):
        raise InputError(f"--tolerance-percent must be above 0 and below 50, got {percent}")
    output.mkdir(parents=True, exist_ok=True)
    (output / "plans").mkdir(exist_ok=True)
    (output / "changeovers").mkdir(exist_ok=True)
    say = err_console if json_out else console
    with tempfile.TemporaryDirectory(prefix="feederkit-demo-") as tmp:
        catalog = Path(tmp) / "demo.db"
        open_catalog(catalog, create=True).close()
        _import(catalog, source_dir)
        summaries = list_parts(catalog)
        skipped = [s.name for s in summaries if not s.orientable]
        pfs = [analyze_part(get_part(catalog, s.name)).push for s in summaries if s.orientable]
        head = f"[bold]feederkit demo[/]: {len(summaries)} parts from {escape(str(source_dir))}"
        if skipped:
            head += f"; not orientable by pushing: {escape(', '.join(skipped))}"
        say.print(head, highlight=False)
        table, notes, analysis = _analysis_table(pfs, percent)
        say.print(table)
        for note in notes:
            say.print(f"  note: {escape(note)}", highlight=False)
        plans = _plan_parts(pfs, percent, output / "plans")
        say.print(_plans_table(plans))
        by_name = {pf.part.name: pf for pf in pfs}
        changeovers = []
        for name, members in _mixes(pfs):
            with err_console.status(f"compiling changeover {name} ..."):
                compiled = _compile(catalog, by_name, name, members, percent)
            plan_path = output / "changeovers" / f"{name}.json"
            report_path = output / "changeovers" / f"{name}.html"
            write_plan(plan_path, compiled.plan)
            _write_report(compiled, report_path)
            stats = compiled.plan["stats"]
            tol = compiled.plan["sensor"].get("tolerance_mm")
            say.print(
                f"\n[bold]changeover {escape(name)}[/]: {escape(', '.join(members))} "
                f"(tolerance {tol:g} mm)",
                highlight=False,
            )
            if name == "fig27-triangle-octagon":
                say.print(plan_tree(compiled.plan))
            say.print(stats_table(compiled.plan, compiled.made.report))
            for warning in compiled.warnings:
                say.print(f"  warning: {escape(warning)}", highlight=False)
            for w in compiled.witnesses:
                say.print(
                    f"  cannot be told apart: {escape(w.part_a)} & {escape(w.part_b)}: "
                    f"{escape(w.reason)}",
                    highlight=False,
                )
            say.print(f"  plan: {plan_path}\n  report: {report_path}", highlight=False)
            changeovers.append(
                {
                    "name": name,
                    "parts": members,
                    "sensor": compiled.plan["sensor"],
                    "length": stats["length"],
                    "expected_length": stats["expected_length"],
                    "unrecognizable_pairs": [w.to_dict() for w in compiled.witnesses],
                    "plan": str(plan_path),
                    "report": str(report_path),
                }
            )
    if json_out:
        print_json(
            {
                "catalog_dir": str(source_dir),
                "output": str(output),
                "not_orientable": skipped,
                "parts": analysis,
                "plans": [
                    {
                        "name": p.name,
                        "sensorless": p.sensorless["stats"],
                        "sensor": {**sensor_to_dict(p.sensor), **p.sensed["stats"]},
                        "files": [
                            str(output / "plans" / f"{p.name}.sensorless.json"),
                            str(output / "plans" / f"{p.name}.sensor.json"),
                        ],
                    }
                    for p in plans
                ],
                "changeovers": changeovers,
            }
        )
    else:
        console.print(f"\nplans and reports are in {output}/", highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    """Add ``feederkit demo``."""
    app.command("demo")(demo_command)
