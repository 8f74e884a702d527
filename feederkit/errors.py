"""Exceptions that the command line turns into one clear line and an exit code."""

from __future__ import annotations

from typing import Any


class FeederkitError(Exception):
    """Base of feederkit's own errors."""

    exit_code = 2

    def json_fields(self) -> dict[str, Any]:
        """Fields a ``--json`` answer without a result adds for this error (docs/cli.md)."""
        return {}


class InputError(FeederkitError):
    """Bad input: a broken file, a degenerate outline, an unknown name, an impossible setting.

    The command line prints the message on one line and exits with code 2.
    """

    exit_code = 2


class CheckFailed(FeederkitError):
    """A result the user must act on (a plan that failed a check, parts that cannot be told apart).

    The command line exits with code 1.
    """

    exit_code = 1


class PlanningError(FeederkitError):
    """No plan satisfies the request (for example no action keeps the required margin)."""

    exit_code = 1
