"""``feederkit part``: analyse one or more parts (and, wired below, plot one).

``part analyze SOURCE... [--com X Y] [--tolerance MM | --led-pitch MM [--noise MM]] [--json]``
prints per part its stable states, symmetry and, with a sensor model, its Fig. 14 class and
worst-case plan length. No logic of its own: :mod:`feederkit.mechanics.analysis` does the work.
"""

from __future__ import annotations

from typing import Annotated

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from feederkit.cli.common import (
    CatalogOpt,
    JsonOpt,
    LedPitchOpt,
    NoiseOpt,
    ToleranceOpt,
    console,
    err_console,
    plural,
    print_json,
    print_warnings,
)
from feederkit.cli.importopts import takes_import_options
from feederkit.cli.part_plot import plot_command
from feederkit.importers import ImportOptions
from feederkit.mechanics.analysis import (
    PartAnalysis,
    analysis_to_dict,
    analyze_part,
    fragile_warning,
)
from feederkit.sensors import make_sensor
from feederkit.sources import labelled_warnings, load_parts_with_warnings

NEAR_LIST_MAX = 8
"""At most this many near-metastable edges are named in a warning line; the rest are counted."""

part_app = typer.Typer(
    rich_markup_mode="markdown",
    name="part",
    help="Analyse a part's push-align mechanics, or plot them.",
    no_args_is_help=True,
)


def _deg(x: float) -> str:
    return f"{x:.2f}"


def _near_list(a: PartAnalysis) -> str:
    near = a.near_metastable
    named = ", ".join(
        f"edge {n.edge} ({n.kind}, foot {abs(n.margin_deg):.3g} deg from vertex {n.vertex})"
        for n in near[:NEAR_LIST_MAX]
    )
    more = f" and {len(near) - NEAR_LIST_MAX} more" if len(near) > NEAR_LIST_MAX else ""
    return named + more


def near_metastable_warning(a: PartAnalysis) -> str | None:
    """One line naming the part's near-metastable edges, or None when it has none."""
    if not a.near_metastable:
        return None
    return (
        f"{a.part.name}: near-metastable {_near_list(a)}; "
        "in practice the part may rest on either neighbour"
    )


def _num(x: float, digits: int = 4, zero: float = 0.0) -> str:
    return f"{(0.0 if abs(x) <= zero else x) + 0.0:.{digits}g}"


def _print_analysis(a: PartAnalysis) -> None:
    part, pf, sym = a.part, a.push, a.symmetry
    rev = f" revision {part.revision}" if part.revision is not None else ""
    tiny = 1e-9 * part.size
    console.print(
        f"[bold]{escape(part.name)}[/]{escape(rev)}: COM ({_num(part.com[0], 6, tiny)}, "
        f"{_num(part.com[1], 6, tiny)}) mm, hull of "
        f"{plural(len(part.hull), 'vertex', 'vertices')}, "
        f"{plural(pf.n, 'stable state')}",
        highlight=False,
    )
    near_edges = set(pf.near_metastable_edges)
    table = Table(
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
        header_style="bold",
        caption="angles in degrees (theta of design.md), lengths in mm"
        + ("; * near-metastable" if near_edges else ""),
        caption_justify="left",
    )
    for col in ("state", "edge", "normal", "resting range", "width", "diameter", "pose", "barrier"):
        table.add_column(col, justify="right", no_wrap=True)
    for s in pf.states:
        lo, hi = s.resting_range_deg
        table.add_row(
            str(s.id),
            f"{s.edge}*" if s.edge in near_edges else str(s.edge),
            _deg(s.normal_deg),
            f"{_deg(lo)} .. {_deg(hi)}",
            _deg(hi - lo),
            f"{s.diameter:.4f}",
            _deg(s.pose_deg),
            f"{s.barrier_mm:.3g}",
        )
    console.print(table)
    kind = sym.kind
    if kind in ("symmetric", "quasi-symmetric"):
        kind = f"{kind}, period {_num(sym.period_deg, 6)}"
    console.print(
        f"symmetry: part {_num(sym.part_period_deg, 6)} deg, push function "
        f"{_num(sym.push_period_deg, 6)} deg, push-diameter function {kind}",
        highlight=False,
    )
    if a.near_metastable:
        console.print(f"[yellow]near-metastable:[/] {escape(_near_list(a))}", highlight=False)
    if a.polygon_class is not None:
        c = a.polygon_class
        console.print(
            f"class {c.number} (Fig. 14): {c.description}; worst-case plan length {c.bound} "
            f"(m = {c.m}, n = {c.n}, p = {c.p}) for this side alone on the ideal model (a plan "
            "over both landings, or under a rotation error, may need more)",
            highlight=False,
        )
    console.print()


@part_app.command("analyze")
@takes_import_options
def analyze_command(
    sources: Annotated[
        list[str],
        typer.Argument(
            help="Outline files, CAD files or catalog part names.",
            metavar="SOURCE",
            show_default=False,
        ),
    ],
    com: Annotated[
        tuple[float, float] | None,
        typer.Option(
            "--com",
            metavar="X Y",
            help="Center of mass X Y (mm) for every SOURCE, instead of its own.",
        ),
    ] = None,
    sensorless: Annotated[
        bool, typer.Option("--sensorless", help="Classify for no sensor (Fig. 14 classes 7, 8).")
    ] = False,
    tolerance: ToleranceOpt = None,
    led_pitch: LedPitchOpt = None,
    noise: NoiseOpt = None,
    catalog: CatalogOpt = None,
    json_out: JsonOpt = False,
    import_opts: ImportOptions = ImportOptions(),
) -> None:
    """Stable states, resting ranges, diameters, symmetry and (with a sensor) the Fig. 14 class."""
    given = sensorless or tolerance is not None or led_pitch is not None or noise is not None
    sensor = (
        make_sensor(sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise)
        if given
        else None
    )
    parts = []
    for src in sources:
        every = load_parts_with_warnings(src, com=com, catalog=catalog, options=import_opts)
        print_warnings(labelled_warnings(src, every))
        parts += [loaded.part for loaded in every]
    analyses = [analyze_part(p, sensor) for p in parts]
    for a in analyses:
        for warning in (near_metastable_warning(a), fragile_warning(a.push)):
            if warning is not None:
                err_console.print(
                    f"[yellow]warning:[/] {escape(warning)}", highlight=False, soft_wrap=True
                )
    if json_out:
        print_json([analysis_to_dict(a) for a in analyses])
        return
    for a in analyses:
        _print_analysis(a)


part_app.command("plot")(plot_command)


def register(app: typer.Typer) -> None:
    """Add the ``part`` group (``analyze``, ``plot``) to the ``feederkit`` command."""
    app.add_typer(part_app, name="part")
