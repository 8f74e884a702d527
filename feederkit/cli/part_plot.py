"""``feederkit part plot SOURCE -o FILE.png|svg``: the part's outline and its functions (figs. 3-6).

The lead registers :func:`plot_command` as ``plot`` in the ``part`` group.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from feederkit.cli.common import console
from feederkit.reports import plot_format, write_part_plot
from feederkit.sources import load_part


def plot_command(
    source: Annotated[str, typer.Argument(help="An outline file, CAD file or catalog part name.")],
    output: Annotated[
        Path, typer.Option("-o", "--output", help="The picture to write: FILE.png or FILE.svg.")
    ],
    com: Annotated[
        tuple[float, float] | None,
        typer.Option("--com", help="Center of mass X Y (mm), instead of the plate's centroid."),
    ] = None,
    catalog: Annotated[
        str | None, typer.Option("--catalog", help="Parts catalog for catalog part names.")
    ] = None,
) -> None:
    """Draw the outline with hull, COM and numbered stable edges, and below it the radius,
    push and push-diameter functions with stable orientations and resting ranges marked."""
    plot_format(output)
    part = load_part(source, com=com, catalog=catalog)
    write_part_plot(part, output)
    console.print(f"wrote {output}", highlight=False, markup=False)
