"""The ``feederkit`` command: registers each command group's module and is the one error boundary.

Exit codes (design.md): 0 success, 1 a result the user must act on (one ``result: ...`` line
on stderr), 2 bad input or usage, 130 interrupted (Ctrl-C), 70 a bug in feederkit. Errors are
one clear ``error: ...`` line on stderr, never a traceback: feederkit's own errors carry their
message; errors from the system (SQLite, files, numbers too large, input nested too deeply)
are named with what to do. Anything else is a bug: one line says so and names the log file
that holds the traceback. Ctrl-C is ``interrupted`` and 130 however it surfaces: as a
KeyboardInterrupt, as an error raised while handling one, or as an error after one was
swallowed (a library that catches BaseException around a lazy import, as trimesh does,
fails later with an unrelated TypeError); :class:`_CtrlCWatch` notes that SIGINT came.
"""

from __future__ import annotations

import contextlib
import signal
import sys

_loading_interrupted = False  # a SIGINT came while the modules below were loading


def _note_loading_interrupt(signum: int, frame: object) -> None:
    """SIGINT while the modules load: noted, then the previous handler (KeyboardInterrupt).
    A C extension interrupted in its initialisation fails with an ImportError instead
    (scipy: "initialization failed"), which is then the interrupt's, not a broken install."""
    global _loading_interrupted
    _loading_interrupted = True
    _previous_sigint(signum, frame)


_previous_sigint = signal.getsignal(signal.SIGINT)
if callable(_previous_sigint):
    with contextlib.suppress(ValueError):  # not the main thread: no handler can be set
        signal.signal(signal.SIGINT, _note_loading_interrupt)


def _restore_sigint() -> None:
    """The SIGINT handler as it was before the modules began loading."""
    if signal.getsignal(signal.SIGINT) is _note_loading_interrupt:
        signal.signal(signal.SIGINT, _previous_sigint)


def _loading_failed(exc: BaseException) -> None:
    """Ctrl-C while the modules load: one line, 130; any other failure goes on up, with the
    SIGINT handler as it was (an importer that catches the failure keeps a working Ctrl-C)."""
    if isinstance(exc, KeyboardInterrupt) or _loading_interrupted:
        sys.stderr.write("error: interrupted\n")
        raise SystemExit(130) from None
    _restore_sigint()


try:  # Ctrl-C while the heavy modules load (typer, rich, numpy, shapely) is one line, too.
    import errno
    import functools
    import importlib
    import os
    import sqlite3
    import tempfile
    import traceback
    from collections.abc import Callable, Iterator, Sequence
    from datetime import UTC, datetime
    from types import FrameType
    from typing import Annotated, Any, TextIO

    import typer
    from rich.markup import escape
    from typer.exceptions import Abort

    try:  # typer 0.2x carries its own click
        from typer._click.exceptions import ClickException, NoArgsIsHelpError, UsageError
    except ImportError:  # pragma: no cover - typer on the click package
        from click.exceptions import ClickException, NoArgsIsHelpError, UsageError

    import feederkit
    from feederkit.catalog import set_busy_notifier
    from feederkit.cli import helpstyle
    from feederkit.cli.common import (
        COMMAND_START,
        DONE_WORK,
        JSON_ANSWER,
        err_console,
        json_failure,
        print_json,
    )
    from feederkit.errors import FeederkitError
except (KeyboardInterrupt, ImportError) as exc:
    _loading_failed(exc)
    raise

helpstyle.apply()

EXIT_RESULT = 1
"""A result the user must act on (design.md): printed as ``result: ...``, not as an error."""
EXIT_INTERRUPTED = 130
EXIT_BUG = 70
"""``EX_SOFTWARE`` of sysexits.h: an internal error."""

app = typer.Typer(
    rich_markup_mode="markdown",
    name="feederkit",
    help="Orient and recognize flat parts on a flexible parts feeder (Akella & Mason 1999).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

# Each module registers its commands on ``app`` when imported (see its ``register``).
COMMAND_MODULES = (
    "feederkit.cli.part",
    "feederkit.cli.plan",
    "feederkit.cli.run",
    "feederkit.cli.catalog",
    "feederkit.cli.changeover",
    "feederkit.cli.lookalike",
    "feederkit.cli.report",
    "feederkit.cli.simulate",
    "feederkit.cli.demo",
    "feederkit.cli.design",
)


def version_text() -> str:
    """``feederkit X.Y.Z``: the installed distribution's version, else the package's."""
    try:
        from importlib.metadata import PackageNotFoundError, version

        return f"feederkit {version('feederkit')}"
    except PackageNotFoundError:
        return f"feederkit {feederkit.__version__}"


def _version(value: bool) -> None:
    if value:
        typer.echo(version_text())
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """Orient and recognize flat parts on a flexible parts feeder (Akella & Mason 1999)."""


def _register() -> None:
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(app)


try:
    _register()
except (KeyboardInterrupt, ImportError) as exc:
    _loading_failed(exc)
    raise
finally:
    _restore_sigint()  # loaded: the handler as it was


@functools.cache
def _click_command() -> typer.core.TyperGroup:
    """Typer's command tree, built once per process (building it costs tens of ms)."""
    return typer.main.get_command(app)  # type: ignore[return-value]


def _command_words(args: Sequence[str]) -> tuple[list[str], Any]:
    """The command words ``args`` start with (``["part", "analyze"]``, options between them
    skipped) and the command they name (the app itself for none)."""
    command: Any = _click_command()
    words: list[str] = []
    for arg in args:
        sub = getattr(command, "commands", {}).get(arg)
        if sub is None:
            if arg.startswith("-"):
                continue
            break
        command, words = sub, [*words, arg]
    return words, command


def _command_path(args: Sequence[str]) -> str:
    """``feederkit part analyze``: the command ``args`` name, for a usage error that click
    raises without its context (an option missing one of its values, ``--com 1``)."""
    return " ".join(["feederkit", *_command_words(args)[0]])


def _refuse_lists_given_twice(args: Sequence[str]) -> None:
    """Refuse an option whose value is a comma-separated list (``--mix A,B``, its metavar
    says so) given more than once: click keeps the last, which would drop the earlier
    list's parts from a mix without a word."""
    _words, command = _command_words(args)
    given = list(args[: args.index("--")] if "--" in args else args)
    for param in getattr(command, "params", []):
        metavar = getattr(param, "metavar", None) or ""
        if getattr(param, "param_type_name", "") != "option" or "," not in metavar:
            continue
        if getattr(param, "multiple", False):
            continue
        names = [n for n in param.opts if n.startswith("--")]
        count = sum(1 for a in given if a in names or a.startswith(tuple(n + "=" for n in names)))
        if count > 1:
            raise UsageError(
                f"{names[0]} given {'twice' if count == 2 else f'{count} times'} (a later one "
                "would replace the earlier): "
                f"give one list, comma-separated: {names[0]} {metavar}"
            )


def _group_alone(args: Sequence[str]) -> list[str] | None:
    """The words of a group given without a command and nothing else (``[]`` for
    ``feederkit`` alone, ``["part"]``), else None."""
    words, command = _command_words(args)
    return words if len(words) == len(args) and hasattr(command, "commands") else None


def _say(message: str) -> None:
    """One line on stderr, ``error: ...`` (markup in the message is shown as typed)."""
    err_console.print(
        f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True, markup=True
    )


def _say_result(message: str) -> None:
    """One line on stderr, ``result: ...``: an outcome the user must act on (exit 1, design.md),
    not a fault in the input, so not ``error:``; on stderr so ``--json`` output stays clean."""
    err_console.print(
        f"[bold yellow]result:[/] {escape(message)}", highlight=False, soft_wrap=True, markup=True
    )


def _notify_busy(message: str) -> None:
    err_console.print(f"{message} ...", highlight=False, soft_wrap=True, markup=False)


def _oneline(text: object) -> str:
    return " ".join(str(text).split())


_OS_ADVICE = {
    errno.ENOSPC: "the disk is full; free some space and try again",
    errno.EDQUOT: "the disk quota is exceeded; free some space and try again",
    errno.EACCES: "permission denied; check the file's and its folder's permissions",
    errno.EPERM: "operation not permitted; check the file's and its folder's permissions",
    errno.EROFS: "the file system is read-only; write somewhere else",
    errno.ENAMETOOLONG: "the file name is too long (file systems allow 255 bytes per name)",
    errno.ENOENT: "no such file or folder",
    errno.ENOTDIR: "a part of the path is not a folder",
    errno.EISDIR: "a folder, not a file",
    errno.EMFILE: "too many open files; raise the limit (ulimit -n) and try again",
    errno.EIO: "input/output error; check the disk",
}


class StdoutError(OSError):
    """Writing the standard output failed (``> /dev/full``, a full disk): an OSError from a
    write names no file, so without this the message could only say "a file"."""


class _GuardedStdout:
    """``sys.stdout`` while a command runs: the same stream, whose write errors are
    :class:`StdoutError`. Everything else is the stream's own (rich and click ask it for
    ``isatty``, ``encoding``, ...)."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror) from exc

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror) from exc

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


@contextlib.contextmanager
def _guarded_stdout() -> Iterator[None]:
    """Install :class:`_GuardedStdout` for the block; the stream comes back after (unless a
    library replaced it meanwhile, as click does after a broken pipe)."""
    stream = sys.stdout
    guard = _GuardedStdout(stream)
    sys.stdout = guard  # type: ignore[assignment]
    try:
        yield
    finally:
        if sys.stdout is guard:
            sys.stdout = stream


def system_error_message(exc: BaseException) -> str | None:
    """The one line for an error from the system or the input, or None when it is not one.

    SQLite errors (busy, read-only, disk full, damaged file), file errors (disk full,
    permission, name too long), numbers too large, input nested too deeply, text that is
    not UTF-8.
    """
    if isinstance(exc, sqlite3.Error):
        code = getattr(exc, "sqlite_errorname", None) or type(exc).__name__
        return (
            f"catalog error ({_oneline(exc)}, {code}); check the catalog file given by "
            "--catalog or $FEEDERKIT_CATALOG"
        )
    if isinstance(exc, StdoutError):
        what = _OS_ADVICE.get(exc.errno or -1) or _oneline(exc.strerror or exc)
        return f"cannot write the standard output: {what}"
    if isinstance(exc, OSError):
        what = _OS_ADVICE.get(exc.errno or -1) or _oneline(exc.strerror or exc)
        name = exc.filename if exc.filename is not None else "a file"
        return f"{_oneline(os.fsdecode(name))}: {what}"
    if isinstance(exc, OverflowError):
        return f"a number is too large to compute with ({_oneline(exc)}); check the input's values"
    if isinstance(exc, RecursionError):
        return "the input is nested too deeply to process; check the input file"
    if isinstance(exc, UnicodeDecodeError):
        return f"an input is not UTF-8 text ({_oneline(exc.reason)} at byte {exc.start})"
    if isinstance(exc, MemoryError):
        return "out of memory; the input is too large for this machine"
    return None


def write_crash_log(exc: BaseException, argv: list[str] | None) -> str | None:
    """Write the traceback of an unexpected exception to a log file in the system temp dir;
    its path, or None when even that fails."""
    stamp = datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    try:
        fd, path = tempfile.mkstemp(prefix=f"feederkit-{stamp}-", suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8", errors="backslashreplace") as fh:
            fh.write(f"{version_text()}\nargv: {argv if argv is not None else sys.argv}\n\n")
            fh.write("".join(traceback.format_exception(exc)))
    except OSError:
        return None
    return path


class _CtrlCWatch:
    """Notes whether SIGINT arrived while a command ran, and raises KeyboardInterrupt as before.

    Installed only over a Python-level handler (the default one, or a caller's, which is
    still called), so an ignored SIGINT stays ignored; only in the main thread, where
    signal handlers can be set. A context manager: the previous handler comes back.
    """

    def __init__(self) -> None:
        self.seen = False
        self._previous: Callable[[int, FrameType | None], Any] | None = None

    def _handler(self, signum: int, frame: FrameType | None) -> None:
        self.seen = True
        if self._previous is not None:
            self._previous(signum, frame)  # the default handler raises KeyboardInterrupt

    def __enter__(self) -> _CtrlCWatch:
        previous = signal.getsignal(signal.SIGINT)
        if callable(previous):
            self._previous = previous  # before the handler: a SIGINT at once must reach it
            try:
                signal.signal(signal.SIGINT, self._handler)
            except ValueError:  # not the main thread: no handler can be set
                self._previous = None
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None


def _from_interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` is, or was raised while handling, a KeyboardInterrupt (or click's
    Abort for one), following ``__cause__`` and ``__context__``."""
    seen: set[int] = set()
    todo: list[BaseException | None] = [exc]
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        seen.add(id(e))
        if isinstance(e, KeyboardInterrupt | Abort):
            return True
        todo += [e.__cause__, e.__context__]
    return False


def main(argv: list[str] | None = None, *, from_process: bool = False) -> int:
    """Entry point: run the app and turn every error into one line on stderr and an exit code.

    ``from_process``: the command's ``--time-limit`` counts from the process's start (the
    console script, :func:`run`), not from this call.

    Usage errors (unknown options, missing arguments, bad values) are one line too, naming
    the command's ``--help``, and exit with 2, as click does. After Ctrl-C the end is
    ``interrupted`` and 130, whatever error followed (the interrupt's doing, not a bug or bad
    input) and even when a library swallowed the interrupt and the command went on.
    """
    set_busy_notifier(_notify_busy)
    JSON_ANSWER.reset()
    DONE_WORK.reset()
    COMMAND_START.mark(from_process)
    try:
        return _main(sys.argv[1:] if argv is None else list(argv))
    finally:
        COMMAND_START.reset()


def _main(args: list[str]) -> int:
    """:func:`main` once its run's state is set."""
    with _CtrlCWatch() as ctrl_c, _guarded_stdout():
        try:
            code = _run_app(args)
            if ctrl_c.seen and code != EXIT_INTERRUPTED:  # a library swallowed the interrupt
                _say(DONE_WORK.interrupted())
                return EXIT_INTERRUPTED
            return code
        except Exception as exc:  # noqa: BLE001 - the boundary: every error becomes one line
            if ctrl_c.seen or _from_interrupt(exc):
                _say(DONE_WORK.interrupted())
                return EXIT_INTERRUPTED
            return _error_exit(exc, args)
        except KeyboardInterrupt:
            _say(DONE_WORK.interrupted())
            return EXIT_INTERRUPTED
        finally:
            set_busy_notifier(None)


def _run_app(args: list[str]) -> int:
    """Run the command; its exit code (a SystemExit becomes one, Ctrl-C's saying so).

    ``feederkit`` or a group without a command is a usage error: its help on stderr, exit 2
    (``--help`` asks for the help: stdout, exit 0).
    """
    group = _group_alone(args)
    if group is not None:
        with contextlib.redirect_stdout(sys.stderr):
            _click_command().main(
                args=[*group, "--help"], prog_name="feederkit", standalone_mode=False
            )
        return 2
    _refuse_lists_given_twice(args)
    try:
        code = _click_command().main(args=args, prog_name="feederkit", standalone_mode=False)
    except SystemExit as exc:
        code = exc.code
        if code is None:
            return 0
        if not isinstance(code, int):
            return 2
    if isinstance(code, int) and code == EXIT_INTERRUPTED:  # typer's Exit(130) for Ctrl-C
        _say(DONE_WORK.interrupted())
    return code if isinstance(code, int) else 0


def _error_exit(exc: Exception, args: list[str]) -> int:
    """Say ``exc`` in one line on stderr and return its exit code (not for Ctrl-C's errors)."""
    if isinstance(exc, FeederkitError):
        if exc.exit_code == EXIT_RESULT:
            _say_result(_oneline(exc))
            _print_json_failure(_oneline(exc), exc.exit_code, exc.json_fields())
        else:
            _say(_oneline(exc))
        return exc.exit_code
    if isinstance(exc, NoArgsIsHelpError):  # click printed the help when it raised this
        return 2
    if isinstance(exc, UsageError):
        where = exc.ctx.command_path if exc.ctx is not None else _command_path(args)
        _say(f"{_oneline(exc.format_message())} (see {where} --help)")
        return 2
    if isinstance(exc, ClickException):
        _say(_oneline(exc.format_message()))
        return exc.exit_code
    message = system_error_message(exc)
    log = write_crash_log(exc, args)
    where = f"; details in {log}" if log else ""
    if message is not None:
        _say(f"{message}{where}")
        return 2
    _say(
        f"this is a bug in feederkit ({type(exc).__name__}: {_oneline(exc)[:200]}); "
        f"please report it with the log{where}"
    )
    return EXIT_BUG


def _print_json_failure(message: str, code: int, fields: dict | None = None) -> None:
    """With ``--json``, a result without an answer still prints one JSON object on stdout
    (:func:`feederkit.cli.common.json_failure`); a stdout that cannot take it changes
    nothing (the ``result:`` line on stderr has said it)."""
    data = json_failure(message, code, fields)
    if data is None:
        return
    with contextlib.suppress(OSError):
        print_json(data)


def end_quietly_on_closed_pipe() -> None:
    """A closed stdout (``feederkit plan PART | head -1``) ends feederkit as it ends ``cat``:
    by SIGPIPE's default action, exit status 141 in the shell, nothing on stderr.

    Python ignores SIGPIPE and raises BrokenPipeError instead, which click and rich turn
    into exit 1: here that is a result the user must act on (design.md), so it must not be.
    Only the console script does this; :func:`main` called in-process keeps Python's way.
    """
    if hasattr(signal, "SIGPIPE"):  # not on Windows
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)


def _quiet_interrupts(hook: Callable[[Any], object]) -> Callable[[Any], object]:
    """``sys.unraisablehook`` that drops a KeyboardInterrupt (Ctrl-C inside a finalizer or a
    weak reference's callback, which Python would print as "Exception ignored" with a
    traceback) and passes anything else to ``hook``; the command says "interrupted"."""

    def quiet(unraisable: Any) -> object:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            return None
        return hook(unraisable)

    return quiet


def run() -> None:
    """Console-script wrapper around :func:`main`. Once it has answered, a Ctrl-C changes
    nothing: SIGINT is ignored while Python exits (else an interrupt in its shutdown would
    end a finished command with 130 and no word)."""
    end_quietly_on_closed_pipe()
    sys.unraisablehook = _quiet_interrupts(sys.unraisablehook)
    try:
        code = main(from_process=True)
    except KeyboardInterrupt:  # Ctrl-C while printing the error itself
        sys.stderr.write("error: interrupted\n")
        code = EXIT_INTERRUPTED
    with contextlib.suppress(ValueError):  # not the main thread
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.exit(code)
