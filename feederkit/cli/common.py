"""Shared pieces of the command line: the console, error reporting, JSON output, the options
several commands take (design.md fixes their names) and the progress bar."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from feederkit.catalog import CATALOG_ENV, DEFAULT_CATALOG
from feederkit.errors import InputError

console = Console()
err_console = Console(stderr=True)

OBJECTIVES = ("worst", "expected")
GROUPINGS = ("exact", "components")

SensorlessOpt = Annotated[
    bool,
    typer.Option("--sensorless", help="No sensor (the default when no sensor option is given)."),
]
ToleranceOpt = Annotated[
    float | None,
    typer.Option(
        "--tolerance", metavar="MM", help="Diameter sensor: readings strictly within MM of d."
    ),
]
LedPitchOpt = Annotated[
    float | None,
    typer.Option("--led-pitch", metavar="MM", help="LED array with beams every MM."),
]
NoiseOpt = Annotated[
    float | None,
    typer.Option("--noise", metavar="MM", help="The LED array's alignment noise (mm)."),
]
ObjectiveOpt = Annotated[
    str,
    typer.Option(
        "--objective",
        metavar="worst|expected",
        help="worst: fewest operations in the worst case; "
        "expected: fewest on average (uniform start).",
    ),
]
MinMarginOpt = Annotated[
    float,
    typer.Option(
        "--min-margin", metavar="DEG", help="Use only rotations keeping this margin (deg)."
    ),
]
TimeLimitOpt = Annotated[
    float | None,
    typer.Option(
        "--time-limit", metavar="S", help="Seconds; then the best plan found, optimal: false."
    ),
]
GroupingOpt = Annotated[
    str,
    typer.Option(
        "--grouping",
        metavar="exact|components",
        help="exact (default) or components (the paper's rule).",
    ),
]
CatalogOpt = Annotated[
    Path | None,
    typer.Option(
        "--catalog",
        metavar="DB",
        envvar=CATALOG_ENV,
        show_envvar=True,
        help=f"The parts catalog (default ${CATALOG_ENV}, else ./{DEFAULT_CATALOG}).",
    ),
]
PlanOutputOpt = Annotated[
    Path | None,
    typer.Option("-o", "--output", metavar="PLAN.json", help="Write the plan file here (atomic)."),
]
ReportOpt = Annotated[
    Path | None,
    typer.Option("--report", metavar="REPORT.html", help="Also write the HTML report here."),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Machine-readable output on stdout.")]


def check_planning_options(
    objective: str, grouping: str, min_margin: float, time_limit: float | None
) -> None:
    """Bad planning options (``--objective``, ``--grouping``, ``--min-margin``,
    ``--time-limit``) are bad input, one line each."""
    if objective not in OBJECTIVES:
        raise InputError(f"--objective must be worst or expected, got {objective!r}")
    if grouping not in GROUPINGS:
        raise InputError(f"--grouping must be exact or components, got {grouping!r}")
    if not 0.0 <= min_margin < 180.0:
        raise InputError(f"--min-margin must be at least 0 and below 180 degrees, got {min_margin}")
    if time_limit is not None and not time_limit > 0.0:
        raise InputError(f"--time-limit must be a positive number of seconds, got {time_limit}")


def print_json(data: Any) -> None:
    """Machine-readable output on stdout (``--json``)."""
    sys.stdout.write(json.dumps(data, indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def fail(message: str, code: int = 2) -> None:
    """Raise the error the app turns into one line on stderr and ``code``."""
    err = InputError(message)
    err.exit_code = code
    raise err


def progress_bar(*extra: Any, disable: bool = False) -> Progress:
    """The progress bar of long work: on stderr (``--json`` output stays clean), gone when done.

    ``extra`` columns follow the standard ones (description, bar, done of total, elapsed).
    """
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        *extra,
        console=err_console,
        transient=True,
        disable=disable,
    )
