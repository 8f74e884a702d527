"""The demo pipeline: the main job on a folder of part files, as one library call.

Imports the folder into a temporary catalog, analyses every part (states, symmetry, Fig. 14
class and bound), plans each orientable part sensorless and with a diameter sensor, and
compiles changeovers: the paper's triangle and 8-gon (Figs. 18 and 27), the paper's shapes
lying face up (the paper's setting), the feeder parts over every landing with only the
face-up ones accepted (design.md, "Landings": a part that lands face down ends in a reject
result as early as the plan knows), and a mix with a look-alike (Theorem 6: a part with the
same push-diameter function) that no plan can tell apart from its original on either side
(section 8.4). Every plan file and a report per changeover are written to the output folder.
:func:`run_demo` returns what happened; ``feederkit demo`` prints it (docs/changeovers.md,
docs/landings.md).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feederkit.catalog import add_outline, import_directory, list_parts, open_catalog
from feederkit.cell import CellSettings, annotate_cycle_time
from feederkit.errors import InputError, PlanningError
from feederkit.jsonio import OutputFile, write_files
from feederkit.landing import landings_of_outline
from feederkit.landing.plan import load_landings, plan_landings
from feederkit.loading import load_parts
from feederkit.mechanics.analysis import analyze_part
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import CompiledChangeover, compile_changeover, landing_rows
from feederkit.mix.lookalike import build_lookalike
from feederkit.plans.writeplan import plan_file_text
from feederkit.sensors import NoSensor, Sensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty

PAPER_MIX = ("isosceles-right-triangle", "octagon")
"""Figs. 18 and 27: the parts the paper orients and recognizes with one plan."""

LOOKALIKE_MIX = ("quadrilateral", "rectangle-2x1")
"""The look-alike changeover: a look-alike of the first part joins them (when both exist)."""

LOOKALIKE_SEED = 0
"""The look-alike construction's seed (the demo is the same every time)."""

SMALL_PART_MM = 10.0
"""Parts below this size are the paper's unit-sized shapes; larger ones are feeder parts."""

FEEDER_ACCEPT = ("up",)
"""The landings the next station takes in the feeder-parts changeover: face up only."""


@dataclass(frozen=True)
class DemoMix:
    """A changeover the demo compiles: its members, the landings planned (None: every one)
    and accepted (None: every one), and whether it holds a look-alike (a pair no plan can
    tell apart is expected)."""

    name: str
    members: tuple[str, ...]
    landings: tuple[str, ...] | None = None
    accept: tuple[str, ...] | None = None
    lookalike: bool = False


Progress = Callable[[str, int, int | None], None]
"""``progress(what, done, total)``: called as the pipeline advances (total None: unknown)."""


@dataclass(frozen=True)
class PartRow:
    """One part's analysis: states, distinct diameters, symmetry period, class and bound."""

    name: str
    size_mm: float
    states: int
    diameters: int
    period_deg: float
    polygon_class: int | None
    bound: int | None
    sensor: Sensor
    near_metastable_edges: tuple[int, ...]

    def to_dict(self) -> dict[str, Any]:
        """The ``parts`` entry of ``feederkit demo --json``."""
        return {
            "name": self.name,
            "states": self.states,
            "symmetry_period_deg": self.period_deg,
            "class": self.polygon_class,
            "bound": self.bound,
            "sensor": self.sensor.to_dict(),
            "near_metastable_edges": list(self.near_metastable_edges),
        }


@dataclass(frozen=True)
class DemoPlan:
    """One part planned in one landing, sensorless and with the sensor, with its files and
    warnings."""

    name: str
    sensor: Sensor
    sensorless: dict[str, Any]
    sensed: dict[str, Any]
    files: tuple[Path, Path]
    warnings: tuple[str, ...]
    landing: str | None = None
    """The landing planned (``up`` for a flat part; a mesh's first pose)."""

    def to_dict(self) -> dict[str, Any]:
        """The ``plans`` entry of ``feederkit demo --json``."""
        return {
            "name": self.name,
            "landing": self.landing,
            "sensorless": self.sensorless["stats"],
            "sensor": {**self.sensor.to_dict(), **self.sensed["stats"]},
            "files": [str(f) for f in self.files],
            "warnings": list(self.warnings),
        }


@dataclass(frozen=True)
class DemoChangeover:
    """A compiled changeover with its plan file and report; ``lookalike``: the mix holds a
    look-alike, so some pair is expected to be unrecognizable."""

    compiled: CompiledChangeover
    members: tuple[str, ...]
    plan_path: Path
    report_path: Path | None
    lookalike: bool = False
    note: str | None = None
    """Why the demo planned or reported otherwise than asked (an accept list no plan can
    keep, a sensor design not decided in the report's time)."""
    landings_planned: tuple[str, ...] | None = None
    """The landings planned when not every one (``--landings``)."""

    @property
    def name(self) -> str:
        """The changeover's name."""
        return self.compiled.name

    @property
    def landings(self) -> list[dict[str, Any]]:
        """The landings planned with share and accept (none for a plan of parts)."""
        return landing_rows(self.compiled.plan, self.compiled.rejected)

    @property
    def rejected_share(self) -> float:
        """The share of the parts (by the landings' probabilities) the plan rejects."""
        return sum(r["share"] or 0.0 for r in self.landings if not r["accept"])

    @property
    def cycle_time(self) -> dict[str, Any] | None:
        """The plan's cycle time in the demo's cell profile (None: the profile has no timing)."""
        return self.compiled.plan["stats"].get("cycle_time")

    def to_dict(self) -> dict[str, Any]:
        """The ``changeovers`` entry of ``feederkit demo --json``."""
        stats = self.compiled.plan["stats"]
        return {
            "name": self.name,
            "parts": list(self.members),
            "sensor": self.compiled.plan["sensor"],
            "length": stats["length"],
            "expected_length": stats["expected_length"],
            "cycle_time": self.cycle_time,
            "min_margin_deg": stats.get("min_margin_deg"),
            "lookalike": self.lookalike,
            "landings": self.landings,
            "rejected": sorted(self.compiled.rejected),
            "rejected_share": self.rejected_share,
            "landings_planned": None
            if self.landings_planned is None
            else list(self.landings_planned),
            "note": self.note,
            "unrecognizable_pairs": [w.to_dict() for w in self.compiled.witnesses],
            "warnings": list(self.compiled.warnings),
            "plan": str(self.plan_path),
            "report": None if self.report_path is None else str(self.report_path),
        }


@dataclass(frozen=True)
class DemoResult:
    """Everything the demo did, for printing or as ``--json``."""

    source_dir: Path
    output: Path
    percent: float
    part_count: int
    not_orientable: tuple[str, ...]
    rows: tuple[PartRow, ...]
    notes: tuple[str, ...]
    plans: tuple[DemoPlan, ...]
    changeovers: tuple[DemoChangeover, ...] = ()
    cell: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """``feederkit demo --json``."""
        return {
            "catalog_dir": str(self.source_dir),
            "output": str(self.output),
            "cell_profile": self.cell,
            "not_orientable": list(self.not_orientable),
            "parts": [r.to_dict() for r in self.rows],
            "plans": [p.to_dict() for p in self.plans],
            "changeovers": [c.to_dict() for c in self.changeovers],
        }


def default_catalog_dir() -> Path:
    """``./catalog`` when it exists, else the ``catalog/`` beside the installed package."""
    here = Path("catalog")
    if here.is_dir():
        return here
    return Path(__file__).resolve().parents[1] / "catalog"


def demo_sensor(pfs: list[PushFunction], percent: float) -> ToleranceSensor:
    """A diameter sensor whose tolerance is ``percent`` of the largest part's size (3 digits)."""
    size = max(pf.part.size for pf in pfs)
    return ToleranceSensor(float(f"{size * percent / 100.0:.3g}"))


def _quiet(what: str, done: int, total: int | None) -> None:
    """The default progress: none."""


def analyse(pfs: list[PushFunction], percent: float) -> tuple[list[PartRow], list[str]]:
    """Each part's row (class and bound for its demo sensor) and notes on near-metastable edges."""
    rows, notes = [], []
    for pf in pfs:
        sensor = demo_sensor([pf], percent)
        a = analyze_part(pf.part, sensor)
        cls = a.polygon_class
        if a.near_metastable:
            edges = ", ".join(str(n.edge) for n in a.near_metastable)
            notes.append(f"{pf.part.name}: near-metastable edges {edges} (may rest on a neighbour)")
        rows.append(
            PartRow(
                name=pf.part.name,
                size_mm=pf.part.size,
                states=pf.n,
                diameters=len({round(s.diameter, 9) for s in pf.states}),
                period_deg=a.symmetry.part_period_deg,
                polygon_class=cls.number if cls else None,
                bound=cls.bound if cls else None,
                sensor=sensor,
                near_metastable_edges=tuple(n.edge for n in a.near_metastable),
            )
        )
    return rows, notes


def plan_parts(
    pfs: list[PushFunction],
    percent: float,
    folder: Path,
    progress: Progress = _quiet,
    catalog: Path | None = None,
) -> list[DemoPlan]:
    """Plan each part in its first landing (a flat part face up, the paper's setting; a mesh
    its first pose), sensorless and with its demo sensor; write both plan files. The files
    name the landing (design.md, "Landings": a plan covers every landing unless told
    otherwise, and then says which); the changeovers plan over every landing."""
    plans = []
    for k, pf in enumerate(pfs):
        progress(f"planning {pf.part.name}", k, len(pfs))
        name = pf.part.name
        first = (
            load_landings([name], catalog=catalog).all[0]
            if catalog is not None
            else landings_of_outline(pf.part)[0]
        )
        sensor = demo_sensor([pf], percent)
        blind = plan_landings([first], NoSensor()).made
        sensed = plan_landings([first], sensor).made
        files = (folder / f"{name}.sensorless.json", folder / f"{name}.sensor.json")
        write_files(
            [
                OutputFile(files[0], plan_file_text(blind.plan), "plan file"),
                OutputFile(files[1], plan_file_text(sensed.plan), "plan file"),
            ]
        )
        warnings = [f"{name} (sensorless): {w}" for w in blind.warnings]
        warnings += [f"{name} (sensor): {w}" for w in sensed.warnings]
        plans.append(
            DemoPlan(name, sensor, blind.plan, sensed.plan, files, tuple(warnings), first.name)
        )
    progress("planning", len(pfs), len(pfs))
    return plans


def demo_mixes(pfs: list[PushFunction]) -> list[DemoMix]:
    """The changeovers to compile: Figs. 18/27 (mirror-symmetric parts: one landing each), the
    paper's shapes face up (the paper's setting), the feeder parts over every landing with
    the face-up ones accepted."""
    names = [pf.part.name for pf in pfs]
    size = {pf.part.name: pf.part.size for pf in pfs}
    mixes: list[DemoMix] = []
    if all(n in names for n in PAPER_MIX):
        mixes.append(DemoMix("fig27-triangle-octagon", PAPER_MIX))
    small = tuple(n for n in names if size[n] < SMALL_PART_MM)
    large = tuple(n for n in names if size[n] >= SMALL_PART_MM)
    if len(small) > 2:
        mixes.append(DemoMix("paper-shapes", small, landings=("up",)))
    if len(large) > 1:
        mixes.append(DemoMix("feeder-parts", large, accept=FEEDER_ACCEPT))
    return mixes


def add_lookalike(catalog: Path, pfs: list[PushFunction]) -> DemoMix | None:
    """Store a look-alike of ``LOOKALIKE_MIX[0]`` (same push-diameter function, Theorem 6) in the
    catalog; return its changeover, over every landing (the look-alike is one on either
    side), or None when the mix's parts are missing."""
    by_name = {pf.part.name: pf for pf in pfs}
    if not all(n in by_name for n in LOOKALIKE_MIX):
        return None
    original = by_name[LOOKALIKE_MIX[0]].part
    twin_name = f"{original.name}-twin"
    twin = build_lookalike(original, "push-diameter", LOOKALIKE_SEED).part
    add_outline(catalog, twin.outline, name=twin_name)
    members = (original.name, twin_name, *LOOKALIKE_MIX[1:])
    return DemoMix("lookalike-pair", members, lookalike=True)


def _report(compiled: CompiledChangeover, notes: list[str]) -> str:
    """The changeover's HTML report (the report library's), naming the pairs no plan tells
    apart, with the mix's sensor design when it is decided in time
    (:func:`feederkit.design.report_design_or_warning`; else its warning goes to ``notes``)."""
    from feederkit.design import report_design_or_warning
    from feederkit.reports import render_report

    u = compiled.plan.get("uncertainty")
    design, warning = report_design_or_warning(
        compiled.parts, Uncertainty.from_dict(u) if u else None
    )
    if warning is not None:
        notes.append(warning)
    return render_report(
        compiled.plan if compiled.view is None else compiled.view,  # the plan as stored
        unrecognizable=[w.to_dict() for w in compiled.witnesses],
        outlines={pf.part.name: pf.part.outline for pf in compiled.parts},
        design=design,
        verification=compiled.made.report,  # the compile's own, not made again
    )


def compile_demo_changeover(
    catalog: Path,
    mix: DemoMix,
    folder: Path,
    percent: float,
    report: bool = True,
    cell: CellSettings | None = None,
) -> DemoChangeover:
    """Compile one changeover with the demo sensor over the mix's landings; its plan file and
    (when ``report``) its report are written with it, with the cycle time when the ``cell``
    profile has timing. When no plan can accept the mix's ``accept`` landings and reject the
    others (the sensor reads them alike), every landing is accepted and ``note`` says so."""
    loaded = load_parts(list(mix.members), catalog=catalog)
    sensor = demo_sensor(list(loaded.push_functions), percent)
    plan_path, report_path = folder / f"{mix.name}.json", folder / f"{mix.name}.html"
    report_notes: list[str] = []

    def outputs(c: CompiledChangeover, text: str) -> list[OutputFile]:
        files = [OutputFile(plan_path, text, "plan file")]
        if report:
            files.append(OutputFile(report_path, _report(c, report_notes), "report"))
        return files

    def compiled(accept: tuple[str, ...] | None) -> CompiledChangeover:
        return compile_changeover(
            catalog,
            mix.name,
            list(mix.members),
            sensor,
            replace=True,
            outputs=outputs,
            prepare=None if cell is None else lambda made: annotate_cycle_time(made, cell),
            landings=mix.landings,
            accept=accept,
        )

    note = None
    try:
        done = compiled(mix.accept)
    except PlanningError as exc:
        if mix.accept is None:
            raise
        note = f"every landing accepted: {exc}"
        report_notes.clear()
        done = compiled(None)
    if report_notes:
        note = "; ".join(x for x in (note, *report_notes) if x)
    return DemoChangeover(
        done,
        mix.members,
        plan_path,
        report_path if report else None,
        mix.lookalike,
        note,
        mix.landings,
    )


def run_demo(
    source_dir: str | os.PathLike[str],
    output: str | os.PathLike[str],
    percent: float = 1.0,
    progress: Progress = _quiet,
    *,
    reports: bool = True,
    cell: CellSettings | None = None,
) -> DemoResult:
    """Run the demo on the part files in ``source_dir``, writing into ``output``.

    ``percent``: the diameter sensor's tolerance in percent of the largest part's size of
    what is planned (each part alone, then each changeover's mix), in (0, 50); ``reports``:
    write each changeover's HTML report (its part plots are most of the demo's time);
    ``cell``: the cell profile whose timing gives each changeover's cycle time (the demo
    keeps its own sensor). Raises InputError for a missing folder, a bad percentage, or bad
    part files.
    """
    src, out = Path(source_dir), Path(output)
    if not src.is_dir():
        raise InputError(f"{src}: no such folder of part files")
    if not (0.0 < percent < 50.0):
        raise InputError(
            f"the sensor tolerance must be above 0 and below 50 percent, got {percent}"
        )
    try:
        (out / "plans").mkdir(parents=True, exist_ok=True)
        (out / "changeovers").mkdir(exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out}: cannot make the output folder ({exc.strerror})") from None
    with tempfile.TemporaryDirectory(prefix="feederkit-demo-") as tmp:
        catalog = Path(tmp) / "demo.db"
        open_catalog(catalog, create=True).close()

        def imported(phase: str, done: int, total: int, item: str) -> None:
            progress(f"{phase} {item}".strip(), done, total)

        import_directory(catalog, src, progress=imported)
        summaries = list_parts(catalog)
        loaded = load_parts(
            [s.name for s in summaries], catalog=catalog, leave_out_not_orientable=True
        )
        skipped = tuple(s.name for s in summaries if s.name not in loaded.names)
        pfs = list(loaded.push_functions)
        rows, notes = analyse(pfs, percent)
        plans = plan_parts(pfs, percent, out / "plans", progress, catalog)
        mixes = demo_mixes(pfs)
        twin = add_lookalike(catalog, pfs)
        if twin is not None:
            mixes.append(twin)
        changeovers = []
        for k, mix in enumerate(mixes):
            progress(f"compiling changeover {mix.name}", k, len(mixes))
            changeovers.append(
                compile_demo_changeover(catalog, mix, out / "changeovers", percent, reports, cell)
            )
    return DemoResult(
        source_dir=src,
        output=out,
        percent=percent,
        part_count=len(summaries),
        not_orientable=skipped,
        rows=tuple(rows),
        notes=(*loaded.warnings, *notes),
        plans=tuple(plans),
        changeovers=tuple(changeovers),
        cell=None if cell is None else cell.describe(),
    )
