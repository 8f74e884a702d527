"""Shared pieces of the command line: the console, error reporting, JSON output."""

from __future__ import annotations

import json
import sys
from typing import Any

from rich.console import Console

from feederkit.errors import InputError

console = Console()
err_console = Console(stderr=True)


def print_json(data: Any) -> None:
    """Machine-readable output on stdout (``--json``)."""
    sys.stdout.write(json.dumps(data, indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def fail(message: str, code: int = 2) -> None:
    """Raise the error the app turns into one line on stderr and ``code``."""
    err = InputError(message)
    err.exit_code = code
    raise err
