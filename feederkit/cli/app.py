"""The ``feederkit`` command: registers each command group's module and maps errors to exit codes.

Exit codes (design.md): 0 success, 1 a result the user must act on, 2 bad input or usage.
Errors are one clear line on stderr, never a traceback.
"""

from __future__ import annotations

import functools
import importlib
import sys

import typer
from rich.markup import escape

from feederkit.cli.common import err_console
from feederkit.errors import FeederkitError

app = typer.Typer(
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
)


def _register() -> None:
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(app)


_register()


@functools.cache
def _click_command() -> typer.core.TyperGroup:
    """Typer's command tree, built once per process (building it costs tens of ms)."""
    return typer.main.get_command(app)  # type: ignore[return-value]


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app; feederkit errors become one line on stderr and their exit code.

    Usage errors (unknown options, missing arguments) exit with 2, as click does.
    """
    try:
        _click_command().main(args=argv, prog_name="feederkit")
    except FeederkitError as exc:
        err_console.print(
            f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True, markup=True
        )
        return exc.exit_code
    except SystemExit as exc:
        if exc.code is None:
            return 0
        return exc.code if isinstance(exc.code, int) else 2
    except KeyboardInterrupt:
        err_console.print("error: interrupted")
        return 130
    return 0


def run() -> None:
    """Console-script wrapper around :func:`main`."""
    sys.exit(main())
