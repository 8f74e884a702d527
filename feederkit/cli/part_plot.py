"""``feederkit part plot SOURCE -o FILE.png|svg``: the part's outline and its functions (figs. 3-6).

The lead registers :func:`plot_command` as ``plot`` in the ``part`` group.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from feederkit.cli.common import CatalogOpt, check_outputs, console
from feederkit.cli.importopts import print_import_warnings, takes_import_options
from feederkit.importers import ImportOptions
from feederkit.reports import plot_format, write_part_plot
from feederkit.sources import load_part_with_warnings


@takes_import_options
def plot_command(
    source: Annotated[str, typer.Argument(help="An outline file, CAD file or catalog part name.")],
    output: Annotated[
        Path,
        typer.Option(
            "-o",
            "--output",
            metavar="FILE.png|svg",
            help="The picture to write: FILE.png or FILE.svg.",
        ),
    ],
    com: Annotated[
        tuple[float, float] | None,
        typer.Option(
            "--com", metavar="X Y", help="Center of mass X Y (mm), instead of the plate's centroid."
        ),
    ] = None,
    catalog: CatalogOpt = None,
    import_opts: ImportOptions = ImportOptions(),
) -> None:
    """Draw the outline with hull, COM and numbered stable edges, and below it the radius,
    push and push-diameter functions with stable orientations and resting ranges marked."""
    plot_format(output)
    check_outputs((output, "file"))
    loaded = load_part_with_warnings(source, com=com, catalog=catalog, options=import_opts)
    print_import_warnings(source, loaded.warnings)
    part = loaded.part
    write_part_plot(part, output)
    console.print(f"wrote {output}", highlight=False, markup=False, soft_wrap=True)
