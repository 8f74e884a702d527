"""Write the golden plan files: what feederkit plans today for the sample catalog.

The plans are made on the ideal model (zero uncertainty), the paper's, whose output the
structural refactor had to keep byte-identical. Run by hand only
(``.venv/bin/python tests/golden/make_golden.py``), when a change of the plans is intended;
``tests/test_golden_plans.py`` regenerates every case through the library and asserts the
same file (floats to their rounding). The cases: every part of ``catalog/`` sensorless and
with a tolerance sensor of 1 % of its size (as ``feederkit demo`` plans them), one LED
array, and the demo's changeovers (the changeover compiler on a catalog imported from
``catalog/``).
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
CATALOG_DIR = REPO / "catalog"

PAPER_MIX = ("isosceles-right-triangle", "octagon")
"""The mix of Figs. 18 and 27 (as the demo compiles it first)."""

SMALL_PART_MM = 10.0
"""The demo's split of the catalog into the paper's shapes and the feeder parts."""

LED_CASE = ("quadrilateral", 0.05, 0.01)
"""One LED array case: part, beam pitch (mm), alignment noise (mm)."""


def tolerance_for(pfs, percent: float = 1.0):
    """The demo's diameter sensor: ``percent`` of the largest part's size, 3 significant digits."""
    from feederkit.sensors import ToleranceSensor

    size = max(pf.part.size for pf in pfs)
    return ToleranceSensor(float(f"{size * percent / 100.0:.3g}"))


def cases(catalog: Path) -> Iterator[tuple[str, Callable[[], str]]]:
    """Each golden file's name and a function giving the plan file's text as written."""
    from feederkit.catalog import get_part, list_parts
    from feederkit.mechanics.push import push_function
    from feederkit.mix.changeover import compile_changeover
    from feederkit.plans.fileformat import plan_json
    from feederkit.plans.make import make_plan
    from feederkit.sensors import LedSensor, NoSensor
    from feederkit.uncertainty import IDEAL

    pfs = [push_function(get_part(catalog, s.name)) for s in list_parts(catalog) if s.orientable]
    by_name = {pf.part.name: pf for pf in pfs}
    for pf in pfs:
        name = pf.part.name
        yield (
            f"{name}.sensorless.json",
            lambda pf=pf: plan_json(make_plan([pf], NoSensor(), uncertainty=IDEAL).plan),
        )
        yield (
            f"{name}.tolerance.json",
            lambda pf=pf: plan_json(make_plan([pf], tolerance_for([pf]), uncertainty=IDEAL).plan),
        )
    part, pitch, noise = LED_CASE
    yield (
        f"{part}.led.json",
        lambda: plan_json(
            make_plan([by_name[part]], LedSensor(pitch, noise), uncertainty=IDEAL).plan
        ),
    )
    names = list(by_name)
    mixes = []
    if all(n in names for n in PAPER_MIX):
        mixes.append(("fig27-triangle-octagon", list(PAPER_MIX)))
    small = [n for n in names if by_name[n].part.size < SMALL_PART_MM]
    large = [n for n in names if by_name[n].part.size >= SMALL_PART_MM]
    if len(small) > 2:
        mixes.append(("paper-shapes", small))
    if len(large) > 1:
        mixes.append(("feeder-parts", large))
    for mix, members in mixes:
        sensor = tolerance_for([by_name[m] for m in members])

        def compiled(mix=mix, members=members, sensor=sensor) -> str:
            c = compile_changeover(
                catalog, mix, members, sensor, replace=True, uncertainty=IDEAL, landings=("up",)
            )
            return plan_json(c.made.plan)

        yield f"changeover-{mix}.json", compiled


def imported_catalog(tmp: Path) -> Path:
    """A catalog database with every part of ``catalog/`` imported (as the demo does)."""
    from feederkit.catalog import import_directory, open_catalog

    db = tmp / "golden.db"
    open_catalog(db, create=True).close()
    import_directory(db, CATALOG_DIR)
    return db


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="feederkit-golden-") as tmp:
        db = imported_catalog(Path(tmp))
        for name, make in cases(db):
            (HERE / name).write_text(make(), encoding="utf-8")
            print("wrote", name)


if __name__ == "__main__":
    sys.path.insert(0, str(REPO))
    main()
