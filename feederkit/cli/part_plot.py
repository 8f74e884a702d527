"""``feederkit part plot SOURCE -o FILE.png|svg``: the part's outline and its functions (figs. 3-6).

The lead registers :func:`plot_command` as ``plot`` in the ``part`` group.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from feederkit.cli.common import console
from feederkit.cli.importopts import (
    AllowLargeOpt,
    AllPartsOpt,
    FlattenOpt,
    HullOpt,
    ImportTimeOpt,
    LayerOpt,
    MaxCrossingsOpt,
    MaxEntitiesOpt,
    MaxFacesOpt,
    MaxHullFacesOpt,
    MaxLoopsOpt,
    MaxVerticesOpt,
    PoseOpt,
    SpaceOpt,
    UnitsOpt,
    import_options,
    print_import_warnings,
)
from feederkit.importers import DEFAULT_FLATTEN_TOLERANCE
from feederkit.importers.budget import (
    DEFAULT_MAX_CROSSINGS,
    DEFAULT_MAX_ENTITIES,
    DEFAULT_MAX_FACES,
    DEFAULT_MAX_HULL_FACES,
    DEFAULT_MAX_LOOPS,
    DEFAULT_MAX_VERTICES,
    DEFAULT_TIME_LIMIT_S,
)
from feederkit.reports import plot_format, write_part_plot
from feederkit.sources import load_part_with_warnings


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
    units: UnitsOpt = None,
    layer: LayerOpt = None,
    space: SpaceOpt = "model",
    all_parts: AllPartsOpt = False,
    pose: PoseOpt = None,
    flatten_tolerance: FlattenOpt = DEFAULT_FLATTEN_TOLERANCE,
    hull_tolerance: HullOpt = None,
    allow_large: AllowLargeOpt = False,
    max_entities: MaxEntitiesOpt = DEFAULT_MAX_ENTITIES,
    max_vertices: MaxVerticesOpt = DEFAULT_MAX_VERTICES,
    max_loops: MaxLoopsOpt = DEFAULT_MAX_LOOPS,
    max_crossings: MaxCrossingsOpt = DEFAULT_MAX_CROSSINGS,
    max_faces: MaxFacesOpt = DEFAULT_MAX_FACES,
    max_hull_faces: MaxHullFacesOpt = DEFAULT_MAX_HULL_FACES,
    import_time_limit: ImportTimeOpt = DEFAULT_TIME_LIMIT_S,
) -> None:
    """Draw the outline with hull, COM and numbered stable edges, and below it the radius,
    push and push-diameter functions with stable orientations and resting ranges marked."""
    plot_format(output)
    opts = import_options(
        units,
        layer,
        flatten_tolerance,
        hull_tolerance,
        all_parts,
        pose,
        None,
        allow_large,
        space=space,
        max_entities=max_entities,
        max_vertices=max_vertices,
        max_loops=max_loops,
        max_crossings=max_crossings,
        max_faces=max_faces,
        max_hull_faces=max_hull_faces,
        import_time_limit=import_time_limit,
    )
    loaded = load_part_with_warnings(source, com=com, catalog=catalog, options=opts)
    print_import_warnings(source, loaded.warnings)
    part = loaded.part
    write_part_plot(part, output)
    console.print(f"wrote {output}", highlight=False, markup=False, soft_wrap=True)
