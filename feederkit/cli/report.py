"""``feederkit report PLAN -o REPORT.html``: the self-contained HTML changeover report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from feederkit.cli.common import console
from feederkit.reports import read_plan_file, render_report, write_report


def report_command(
    plan: Annotated[Path, typer.Argument(help="A plan file (feederkit-plan JSON).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The HTML file to write.")],
    seconds_per_op: Annotated[
        float | None,
        typer.Option("--seconds-per-op", help="Seconds per push-align operation: adds cycle time."),
    ] = None,
) -> None:
    """Write one self-contained HTML page: the mix, the plan as a tree, statistics, part plots."""
    html = render_report(read_plan_file(plan), seconds_per_op=seconds_per_op)
    write_report(output, html)
    console.print(f"wrote {output}", highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    """Add the ``report`` command to the app."""
    app.command("report")(report_command)
