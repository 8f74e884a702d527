"""Shared pieces of the command line: the console, error reporting, JSON output, the options
several commands take (design.md fixes their names), the progress bar and the search spinner.

A command builds its sensor and its :class:`PlanningOptions` once here; the library validates
them and speaks of its own terms ("minimum margin"), which :func:`with_flags` follows with the
flag that sets them (``--min-margin``). Warnings print as one ``warning:`` line each.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    SpinnerColumn,
    TextColumn,
    TimeElapsedColumn,
)
from rich.table import Column, Table

from feederkit.catalog import (
    CATALOG_ENV,
    DEFAULT_CATALOG,
    DeclaredTolerances,
    RevisionTolerances,
    declared_tolerances,
)
from feederkit.catalog.model import split_revision
from feederkit.catalog.tolerances import TOLERANCE_WORDS
from feederkit.cell import CellSettings, cycle_time_text, load_cell, resolve_settings
from feederkit.errors import FeederkitError, InputError, PlanningError
from feederkit.jsonio import OutputFile, check_writable, is_device
from feederkit.mechanics.push import PushFunction
from feederkit.mix.pairs import PairWitness
from feederkit.planning.budget import rss_mb
from feederkit.planning.options import PlanningOptions
from feederkit.planning.solvable import NoStrongPlan
from feederkit.plans.model import Plan
from feederkit.plans.verify import VerificationReport
from feederkit.plans.writeplan import read_back
from feederkit.sensors import Sensor, make_sensor
from feederkit.uncertainty import ToleranceTooLarge, Uncertainty
from feederkit.words import plural

# No emoji codes: a file name or value such as ``x:100:y`` is printed as typed.
console = Console(emoji=False)
err_console = Console(stderr=True, emoji=False)


class JsonAnswer:
    """``--json`` in this run: whether it was asked for, whether an answer was printed, and
    what the command found so far. A result without an answer (exit 1 before anything was
    printed: no plan, a failed check) still gives scripts one JSON object on stdout
    (:func:`json_failure`, printed by the app's error boundary; docs/cli.md)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the previous run (``main`` is called many times in one process by tests)."""
        self.requested = False
        self.printed = False
        self.found: dict[str, Any] = {}


JSON_ANSWER = JsonAnswer()


class DoneWork:
    """What this run has stored or written for good, in words, so that a Ctrl-C while the
    results are printed says nothing is lost (a script need not redo the work)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the previous run."""
        self.done: list[str] = []

    def note(self, what: str) -> None:
        """``what`` is stored or written, e.g. ``"wrote the plan to P.json"``."""
        self.done.append(what)

    def interrupted(self) -> str:
        """The line for a Ctrl-C now: ``interrupted``, and what was done before it."""
        if not self.done:
            return "interrupted"
        return f"interrupted after it {'; '.join(self.done)} (only the printing was cut)"


DONE_WORK = DoneWork()

PROCESS_AGE_MAX_S = 10.0
"""A process older than this when its command starts is taken not to be a console script
just started (Python's start and the imports take a second or two, more on a loaded
machine): its command starts when ``main`` is called. The start is the process's creation,
so a wrapper's own work before it ``exec``s feederkit counts too, up to this long."""


def process_age_s(stat: str = "/proc/self/stat", uptime: str = "/proc/uptime") -> float | None:
    """Seconds since this process began (Linux: its start time in ``stat``, in clock ticks
    since boot, against ``uptime``; to 10 ms), None where that is not known or not plausible
    (``PROCESS_AGE_MAX_S``)."""
    try:
        with open(stat, "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()  # the name may hold spaces and ')'
        with open(uptime, "rb") as f:
            up = float(f.read().split()[0])
        age = up - int(fields[19]) / os.sysconf("SC_CLK_TCK")  # field 22: starttime
    except (OSError, ValueError, IndexError):
        return None
    return age if 0.0 <= age <= PROCESS_AGE_MAX_S else None


class CommandStart:
    """When this run's command began, the start ``--time-limit`` counts from: the process's
    own start when run as the console script (Python's start and the imports, about a second,
    are part of what a user times), else when ``main`` was called."""

    def __init__(self) -> None:
        self.at: float | None = None

    def mark(self, from_process: bool) -> None:
        """Start the clock now, or at the process's start when ``from_process`` and known."""
        age = process_age_s() if from_process else None
        self.at = time.monotonic() - (age or 0.0)

    def reset(self) -> None:
        """Forget the mark: the run is over (a command called without ``main`` starts now)."""
        self.at = None

    def started(self) -> float:
        """The ``time.monotonic()`` of the command's start (now when not marked)."""
        return time.monotonic() if self.at is None else self.at


COMMAND_START = CommandStart()


def _note_json(value: bool) -> bool:
    """The ``--json`` option's callback: note that machine-readable output was asked for."""
    if value:
        JSON_ANSWER.requested = True
    return value


def json_option(help_text: str = "Machine-readable output on stdout.") -> Any:
    """The ``--json`` option of every command (noted in :data:`JSON_ANSWER`)."""
    return typer.Option("--json", help=help_text, callback=_note_json)


def json_found(**fields: Any) -> None:
    """Note what the command found (its sources, sensor, ...) for :func:`json_failure`."""
    JSON_ANSWER.found.update(fields)


def json_failure(
    message: str, code: int, fields: dict[str, Any] | None = None
) -> dict[str, Any] | None:
    """The JSON object a result without an answer prints with ``--json``: ``error`` (the
    ``result:`` line's message), ``exit_code``, the error's own ``fields``
    (``FeederkitError.json_fields``) and what the command found; None when ``--json`` was
    not asked for or the command already printed its answer."""
    if not JSON_ANSWER.requested or JSON_ANSWER.printed:
        return None
    return {"error": message, "exit_code": code, **(fields or {}), **JSON_ANSWER.found}


SensorlessOpt = Annotated[
    bool,
    typer.Option("--sensorless", help="No sensor (the default when no sensor option is given)."),
]
"""``--sensorless`` of a command that reads no cell profile; see :data:`ProfileSensorlessOpt`."""
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
        metavar="worst|expected|time|worst-time",
        help="worst: fewest operations in the worst case; expected: fewest on average "
        "(weighted by the mix shares); time: fewest seconds per part on average; worst-time: "
        "fewest seconds on the slowest path among the shortest plans (the last two need the "
        "cell profile's timing).",
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
        "--time-limit",
        metavar="S",
        help=(
            "Seconds, from the command's start, for the plan, its verification and its file (a"
            " --report is drawn after); then the best plan found (optimal: false) and a proven"
            " lower bound."
        ),
    ),
]
MemoryLimitOpt = Annotated[
    float | None,
    typer.Option(
        "--memory-limit",
        metavar="MB",
        help="Stop searching when the process holds this many megabytes; then the best plan "
        "found (optimal: false) and a proven lower bound (default: half the machine's memory).",
    ),
]
GroupingOpt = Annotated[
    str,
    typer.Option(
        "--grouping",
        metavar="exact|components",
        help="exact, or components (the paper's rule).",
    ),
]
LumpingOpt = Annotated[
    str,
    typer.Option(
        "--lumping",
        metavar="near-symmetric|any|none",
        help="Which states that no strong plan tells apart a result may list together: "
        "near-symmetric (default: poses whose outlines differ by at most 1 % of the part, "
        "and parts of a mix), any (also poses that look different; the plan then does not "
        "orient the part between them), none.",
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
JsonOpt = Annotated[bool, json_option()]
LandingsOpt = Annotated[
    str | None,
    typer.Option(
        "--landings",
        metavar="all|up|K,...",
        help="The landings to plan for: all (the default), or a list of up, down, pose-K or K.",
    ),
]
AcceptOpt = Annotated[
    str | None,
    typer.Option(
        "--accept",
        metavar="LANDING,...",
        help="The landings the next station takes (default: all); the others end in reject "
        "results.",
    ),
]
LANDING_TERMS = (
    ("has no landing", "--landings"),
    ("every member is rejected", "--accept"),
    ("rejected, but no plan", "--accept"),
)
"""The library's words for what ``--landings`` and ``--accept`` set (the commands that plan
over landings add them to :data:`FLAG_TERMS`)."""
RotationErrorOpt = Annotated[
    float,
    typer.Option(
        "--rotation-error",
        metavar="DEG",
        help="The robot's rotation is off by up to ±DEG (default 1; 0: the ideal model).",
    ),
]
ShapeToleranceOpt = Annotated[
    float | None,
    typer.Option(
        "--shape-tolerance",
        metavar="MM",
        help=(
            "Every hull vertex lies within MM of its drawn position (default: the largest the "
            "planned parts' catalog revisions store, else 0; a profile tolerance of +-P moves "
            "a corner of angle B by P / sin(B/2): docs/uncertainty.md)."
        ),
    ),
]
ComToleranceOpt = Annotated[
    float | None,
    typer.Option(
        "--com-tolerance",
        metavar="MM",
        help="The centre of mass lies within MM of its nominal position (default: the largest "
        "the planned parts' catalog revisions store, else 0).",
    ),
]


DEFAULT_TIME_LIMIT_S = 60.0
"""The ``plan`` and ``changeover compile`` commands' time limit unless ``--time-limit`` is given:
long enough for every sample part, short enough to keep a mistyped mix from hanging."""

FLAG_TERMS = (
    ("minimum margin", "--min-margin"),
    ("time limit", "--time-limit"),
    ("memory limit", "--memory-limit"),
    ("objective", "--objective"),
    ("reading grouping", "--grouping"),
    ("sensor tolerance", "--tolerance"),
    ("beam pitch", "--led-pitch"),
    ("alignment noise", "--noise"),
    ("rotation error", "--rotation-error"),
    ("shape tolerance", "--shape-tolerance"),
    ("com tolerance", "--com-tolerance"),
    ("lumping", "--lumping"),
)
"""The library's words for what a command-line flag sets: a library message that names one
is shown with the flag."""


def check_mix_revision(item: str) -> None:
    """Refuse a ``--mix`` item ``NAME@REV`` whose revision is not a number, in the words every
    command uses for it (:func:`feederkit.catalog.split_revision`), not as a missing file."""
    try:
        split_revision(item)
    except InputError as exc:
        raise InputError(f"--mix {item}: {exc}") from None


def add_name_column(table: Table, header: str, **kwargs: Any) -> None:
    """A table column of part names that shows every name whole: a name too long for the
    column folds onto the next line instead of being cropped with "…" (a name with no spaces
    would otherwise be cut, and a cut name is ambiguous in a mix)."""
    table.add_column(header, overflow="fold", **kwargs)


def add_count_column(table: Table, header: str) -> None:
    """A right-aligned column of small numbers, no wider than its header's longest word (the
    header wraps), so that the name columns keep the room."""
    table.add_column(header, justify="right", max_width=max(len(w) for w in header.split()))


def with_flags(message: str, terms: Sequence[tuple[str, str]] = FLAG_TERMS) -> str:
    """``message`` followed by the flags of the library terms it names, e.g. ``(--min-margin)``.

    A flag the message already names is not repeated, nor one whose term it says does not
    help ("no smaller rotation error helps").
    """
    lower = message.lower()
    flags = [
        f for term, f in terms if term in lower and f not in message and not _no_help(lower, term)
    ]
    flags = list(dict.fromkeys(flags))
    return f"{message} ({', '.join(flags)})" if flags else message


def _no_help(lower: str, term: str) -> bool:
    """Whether a (lower-case) message says that changing ``term`` does not help, or helps
    only beyond what a cell can keep ("a smaller rotation error helps only below ±0.01
    deg, finer than a robot turns"), or declares it 0 already ("shape tolerance 0 mm": no
    smaller value exists, and a larger one never makes a plan)."""
    said = (f"no smaller {term} helps", f"no {term} helps", f"{term} helps only below")
    if any(words in lower for words in said):
        return True
    zero = f"{term} 0 mm"
    return zero in lower and f"smaller {term}" not in lower


@contextmanager
def flag_words(terms: Sequence[tuple[str, str]] = FLAG_TERMS) -> Iterator[None]:
    """Re-raise feederkit's errors inside the block with the flags of the terms they name."""
    try:
        yield
    except FeederkitError as exc:
        text = with_flags(str(exc), terms)
        if text == str(exc):
            raise
        exc.args = (text,)  # the same error (its type, fields and exit code), a new line
        raise


def uncertainty_option(
    rotation_error: float, shape_tolerance: float, com_tolerance: float
) -> Uncertainty:
    """The one declared :class:`Uncertainty` of a command; the library validates, errors name
    flags (a shape tolerance too large for a part is refused when the part is planned)."""
    with flag_words():
        return Uncertainty(rotation_error, shape_tolerance, com_tolerance)


def declared_uncertainty(
    rotation_error: float,
    stored: Iterable[RevisionTolerances],
    shape_tolerance: float | None,
    com_tolerance: float | None,
) -> tuple[Uncertainty, DeclaredTolerances]:
    """The one declared :class:`Uncertainty` of a command that plans parts whose catalog
    revisions store ``stored``, and where its tolerances came from: the flags when given,
    else the largest stored (:func:`feederkit.catalog.declared_tolerances`, the one rule)."""
    declared = declared_tolerances(stored, shape_tolerance, com_tolerance)
    unc = uncertainty_option(rotation_error, declared.shape_tolerance_mm, declared.com_tolerance_mm)
    return unc, declared


def flag_tolerance(value: float | None) -> float:
    """A tolerance flag's value to check before the parts are loaded (None: not given, 0)."""
    return 0.0 if value is None else value


TOLERANCE_FLAGS = {"shape_tolerance_mm": "--shape-tolerance", "com_tolerance_mm": "--com-tolerance"}
"""The flag of each tolerance, keyed as the plan file's ``"uncertainty"``."""


@contextmanager
def stored_tolerance_words(declared: DeclaredTolerances | None) -> Iterator[None]:
    """A tolerance too large for a part (:class:`~feederkit.uncertainty.ToleranceTooLarge`)
    that the catalog gave says which revision stores it and how to plan at another; so does
    "no strong plan exists" (:class:`~feederkit.planning.solvable.NoStrongPlan`) under a
    tolerance the user did not give."""
    try:
        yield
    except ToleranceTooLarge as exc:
        note = "" if declared is None else declared.note(exc.field)
        if note:
            flag = TOLERANCE_FLAGS[exc.field]
            exc.args = (
                f"{exc}; it is the largest the planned parts' catalog revisions store{note}: "
                f"plan at another with {flag} MM",
            )
        raise
    except NoStrongPlan as exc:
        stored = [
            f"the {what} is the largest the planned parts' catalog revisions store"
            f"{declared.note(field)}"
            for field, what in TOLERANCE_WORDS
            if declared is not None and declared.note(field)
        ]
        if stored:
            exc.args = (f"{exc}; {'; '.join(stored)}",)
        raise


def uncertainty_text(
    data: dict[str, Any] | None, declared: DeclaredTolerances | None = None
) -> str:
    """A plan file's ``uncertainty`` in words (every output says which values it used), each
    tolerance taken from the catalog followed by the revision storing it (``declared``)."""
    if data is None:
        return "not declared (a plan made on the ideal model)"
    r, t, c = data["rotation_error_deg"], data["shape_tolerance_mm"], data["com_tolerance_mm"]
    shape = "" if declared is None else declared.note("shape_tolerance_mm")
    com = "" if declared is None else declared.note("com_tolerance_mm")
    text = f"rotation error ±{r:g}°, shape tolerance {t:g} mm{shape}, COM tolerance {c:g} mm{com}"
    return text + (" (the ideal model)" if r == t == c == 0 else "")


def sensor_option(
    sensorless: bool, tolerance: float | None, led_pitch: float | None, noise: float | None
) -> Sensor:
    """The one sensor of a command (:func:`feederkit.sensors.make_sensor`); errors name flags."""
    with flag_words():
        return make_sensor(
            sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
        )


def print_warnings(lines: Iterable[str]) -> None:
    """Each line as ``warning: ...`` on stderr: plain text, one line however long."""
    for line in lines:
        err_console.print(
            f"warning: {with_flags(line)}", highlight=False, markup=False, soft_wrap=True
        )


@contextmanager
def earlier_outputs_noted(*paths: Path | None) -> Iterator[None]:
    """When the block finds no plan (PlanningError: nothing is written), warn that the
    output paths already holding a file hold an earlier one, not this run's: a script that
    reads the path after exit code 1 (which also means "written, with parts it cannot tell
    apart") must not take it for this run's plan."""
    try:
        yield
    except PlanningError:
        old = [str(p) for p in paths if p is not None and p.is_file()]
        if old:
            print_warnings(
                [f"nothing was written: {', '.join(old)} still "
                 f"{'holds an earlier file' if len(old) == 1 else 'hold earlier files'}, "
                 "not this run's"]
            )  # fmt: skip
        raise


@contextmanager
def searching(what: str, time_limit: float | None) -> Iterator[None]:
    """A spinner with the elapsed time on stderr while a search runs, naming ``--time-limit``.

    The spinner and the elapsed time come first and the words are cut with an ellipsis when
    the terminal is narrow: a search whose clock is squeezed out looks hung."""
    limit = "no time limit" if time_limit is None else f"time limit {time_limit:g} s"
    with Progress(
        SpinnerColumn(),
        TimeElapsedColumn(),
        TextColumn(
            f"{escape(what)} ({limit}; set it with --time-limit S)",
            table_column=Column(no_wrap=True, overflow="ellipsis", ratio=1),
        ),
        expand=True,
        console=err_console,
        transient=True,
        disable=not err_console.is_terminal,
    ) as bar:
        bar.add_task(what, total=None)
        yield


def time_limit_note(stats: dict[str, Any], time_limit: float | None) -> str | None:
    """One line when the search stopped under the time limit before proving the plan best
    (at the limit, or earlier, when the exact search handed its share to the fallback
    searches off course: docs/planning.md, "Time and memory limits"): the plan and the
    proven lower bound (a worst-case number of operations whatever the objective: under
    ``expected`` or ``time`` the plan's length may meet it and the plan still not be proven
    best)."""
    if stats.get("optimal", True) or time_limit is None:
        return None
    objective = stats.get("objective") or "worst"
    ops = plural(stats["length"], "operation")
    bound = stats["lower_bound"]
    if objective == "worst":
        what = f"this plan has {ops} and is not proven shortest; a plan needs at least {bound}"
    else:
        what = (
            f"this plan ({ops}) is not proven best for the {objective} objective; every plan "
            f"needs at least {plural(bound, 'operation')} in the worst case"
        )
    return (
        f"the search under the time limit of {time_limit:g} s stopped short: {what} "
        "(allow more time with --time-limit S)"
    )


def report_html(
    plan: dict[str, Any] | Plan,
    pfs: Sequence[PushFunction],
    witnesses: Sequence[PairWitness],
    verification: VerificationReport | None = None,
    plots_until: float | None = None,
) -> str:
    """The HTML report of a plan (the report library's, imported only when asked for);
    ``verification``: the command's own of this plan (not made again), ``plots_until``: the
    command's time limit for the part plots (``render_report``)."""
    from feederkit.reports import render_report

    return render_report(
        plan,
        unrecognizable=[w.to_dict() for w in witnesses],
        outlines={pf.part.name: pf.part.outline for pf in pfs},
        verification=verification,
        plots_until=plots_until,
    )


def plan_outputs(
    plan: dict[str, Any],
    pfs: Sequence[PushFunction],
    witnesses: Sequence[PairWitness],
    output: Path | None,
    report: Path | None,
    verification: VerificationReport | None = None,
    plots_until: float | None = None,
) -> tuple[list[OutputFile], Plan]:
    """The files ``-o`` and ``--report`` ask for (rendered here, before any write) and the
    plan as its file reads back (:func:`~feederkit.plans.writeplan.read_back`: what the
    file holds is what the command shows); the report as :func:`report_html` makes it."""
    text, view = read_back(plan)
    files = []
    if output is not None:
        files.append(OutputFile(output, text, "plan file"))
    if report is not None:
        html = report_html(view, pfs, witnesses, verification, plots_until)
        files.append(OutputFile(report, html, "report"))
    return files, view


def limit_instant(started: float, time_limit_s: float | None) -> float | None:
    """The ``time.monotonic()`` instant a command that started at ``started`` reaches its
    ``--time-limit`` (None: no limit)."""
    return None if time_limit_s is None else started + time_limit_s


def check_outputs(*outputs: tuple[Path | None, str]) -> None:
    """Refuse, before any work is done, each output ``(path, what it is)`` that could not be
    written (None: not asked for): its folder missing, a folder or a pipe at the path, a
    folder that takes no new file (read-only, no permission). The message is the one the
    write itself would give (:func:`feederkit.jsonio.check_writable`), exit 2: a result that
    took a minute must not be lost to a typo in a file name. Two outputs that are one file
    (the same path, or a link to it) are refused too: the second would overwrite the first;
    not a character device such as /dev/null, which takes both."""
    seen: dict[Path, str] = {}
    for path, what in outputs:
        if path is None:
            continue
        same = path.resolve()
        if same in seen and not is_device(path):
            raise InputError(
                f"{path}: the {what} and the {seen[same]} would be the same file: give each "
                "its own path"
            )
        seen[same] = what
        folder = path.parent
        if not folder.is_dir():
            why = "is not a folder" if folder.exists() else "does not exist"
            raise InputError(f"{path}: cannot write the {what}: the folder {folder} {why}")
        check_writable(path, what)


def check_output_folders(
    output: Path | None, report: Path | None, sources: Sequence[str] = ()
) -> None:
    """Refuse ``-o`` and ``--report`` paths that could not be written (:func:`check_outputs`)
    and a ``--report`` not named .html, before any work is done (nor may a page of HTML be
    written as ``report.txt``); and an output that is one of the ``sources`` read (a
    mistyped ``-o part.json`` wrote the plan over the part's outline)."""
    if report is not None:
        check_report_name(report)
    check_outputs((output, "plan file"), (report, "report"))
    for path, what in ((output, "plan file"), (report, "report")):
        if path is None or is_device(path) or not path.exists():
            continue
        for source in sources:
            if Path(source).is_file() and os.path.samefile(path, source):
                raise InputError(
                    f"{path}: the {what} would be written over the SOURCE {source} (a part's "
                    "file): give the output its own path"
                )


def check_report_name(path: Path) -> None:
    """Refuse a report path not named .html (:func:`feederkit.reports.check_report_path`),
    unless it is a character device such as /dev/null, which keeps no name."""
    if is_device(path):
        return
    from feederkit.reports import check_report_path  # the report library, only when asked

    check_report_path(path)


def note_written(*files: tuple[Path | None, str]) -> None:
    """Note (:data:`DONE_WORK`) the files of this run now written: (path, what) pairs, a
    None path not written."""
    for path, what in files:
        if path is not None:
            DONE_WORK.note(f"wrote the {what} to {path}")


def print_written(output: Path | None, report: Path | None) -> None:
    """Say which files were written."""
    for path, what in ((output, "plan"), (report, "report")):
        if path is not None:
            console.print(
                f"wrote the {what} to {path}", highlight=False, markup=False, soft_wrap=True
            )


def print_json(data: Any) -> None:
    """Machine-readable output on stdout (``--json``): one answer per run (noted, so that
    a result after it prints no second object)."""
    JSON_ANSWER.printed = True
    sys.stdout.write(json.dumps(data, indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def fail(message: str, code: int = 2) -> None:
    """Raise the error the app turns into one line on stderr and ``code``."""
    err = InputError(message)
    err.exit_code = code
    raise err


def progress_bar(*extra: Any, disable: bool | None = None) -> Progress:
    """The progress bar of long work: on stderr (``--json`` output stays clean), gone when done.

    ``extra`` columns follow the standard ones (description, bar, done of total, elapsed).
    Shown only on a terminal (``disable=None``): redirected, it would leave an empty line
    before the first message (an error's one line would no longer be the first).
    """
    if disable is None:
        disable = not err_console.is_terminal
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


CellOpt = Annotated[
    Path | None,
    typer.Option(
        "--cell",
        metavar="FILE",
        help="The cell profile (default ./feederkit.toml if present, else built-in defaults; "
        "docs/cell.md).",
    ),
]
ProfileSensorlessOpt = Annotated[
    bool,
    typer.Option(
        "--sensorless",
        help="No sensor, whatever the cell profile says (default: the profile's sensor; none "
        "without a profile).",
    ),
]
"""``--sensorless`` of a command that reads the cell profile (:func:`cell_settings`): without
a sensor option its sensor is the profile's, not none."""
ProfileRotationErrorOpt = Annotated[
    float | None,
    typer.Option(
        "--rotation-error",
        metavar="DEG",
        help="The robot's rotation is off by up to ±DEG (default: the cell profile's, else 1; "
        "0: the ideal model).",
    ),
]


def cell_settings(
    cell: Path | None,
    sensorless: bool,
    tolerance: float | None,
    led_pitch: float | None,
    noise: float | None,
    rotation_error: float | None,
) -> CellSettings:
    """The cell profile (``--cell`` or ./feederkit.toml) with the command line's options on
    top (:func:`feederkit.cell.resolve_settings`); errors name the flags."""
    with flag_words():
        return resolve_settings(
            load_cell(cell),
            sensorless=sensorless,
            tolerance=tolerance,
            led_pitch=led_pitch,
            noise=noise,
            rotation_error=rotation_error,
        )


def cycle_line(cycle: dict[str, Any] | None, settings: CellSettings | None = None) -> str:
    """The cycle time in words for an output whose header already names the cell profile
    (``cell profile: ...``, docs/cell.md): a known one does not name it a second time; an
    unknown one names it and the timing fields it lacks (``settings``)."""
    if settings is None:
        return cycle_time_text(cycle, name_profile=False)
    return cycle_time_text(
        cycle,
        settings.profile.source,
        name_profile=False,
        missing=settings.profile.missing_timing(),
    )


def cell_planning_options(
    settings: CellSettings,
    objective: str,
    grouping: str,
    min_margin: float,
    time_limit: float | None,
    memory_limit: float | None = None,
    lumping: str = "near-symmetric",
) -> PlanningOptions:
    """The command's :class:`PlanningOptions` with the cell's action costs (when the profile
    gives its timing); ``--objective time|worst-time`` without them is one line naming the
    missing profile fields."""
    costs = settings.costs()
    if costs is None and objective in ("time", "worst-time"):
        missing = ", ".join(settings.profile.missing_timing())
        raise InputError(
            f"--objective {objective} needs the cell's timing: {missing} "
            f"({settings.describe()}; docs/cell.md)"
        )
    if memory_limit is not None and math.isfinite(memory_limit) and memory_limit > 0:
        held = rss_mb()
        if memory_limit <= held:
            # No search fits: it would end at once with "no plan within the memory limit".
            raise InputError(
                f"--memory-limit {memory_limit:g} MB is no more than the command already holds "
                f"({held:.0f} MB: Python, its libraries and the parts): give more"
            )
    with flag_words():
        return PlanningOptions(
            objective=objective,
            min_margin_deg=min_margin,
            grouping=grouping,
            time_limit_s=time_limit,
            memory_limit_mb=default_memory_limit() if memory_limit is None else memory_limit,
            costs=costs,
            lumping=lumping,
        )


def default_memory_limit() -> float | None:
    """Half the machine's physical memory in MB (None where the system does not say): the
    planners stop there and answer as at the time limit, before the machine swaps."""
    try:
        total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None
    return total / 2e6 if total > 0 else None
