"""How ``--help`` names values: click's conventions, not the Python types typer prints.

Typer 0.2x labels every value with its Python annotation: ``<bool>`` after each flag,
``<list[str]>``, ``<float,float>``, ``<int range>``, a lowercase ``{plan}`` in the usage line
and float defaults as ``[default: 0.0]``. A user reads none of that. :func:`apply` makes
the help read as click's does: flags carry no value label, an option shows its metavar (the
commands give one: ``MM``, ``DEG``, ``FILE``) or else click's type name (``INTEGER``,
``FLOAT``, ``TEXT``, ``PATH``), an argument is named in capitals (``PLAN``, ``SOURCE``) with
no type column (its help says what it is), float defaults print as numbers (``0``,
``60``, ``0.01``) and typer's ``[x>=1]`` range notes are left out (a value out of range is
still refused, with one line naming the option).

Typer's help classes are patched once, when the app is imported (``feederkit.cli.app``); a
typer without these internals keeps its own labels (the help still works).
"""

from __future__ import annotations

import types
import typing
from pathlib import Path
from typing import Any

_CLICK_NAMES: dict[Any, str] = {
    int: "INTEGER",
    float: "FLOAT",
    str: "TEXT",
    Path: "PATH",
    bool: "BOOLEAN",
}


def type_label(annotation: Any) -> str:
    """Click's name for a value of ``annotation``: ``FLOAT``, ``TEXT``, ``FLOAT FLOAT`` (a pair)."""
    origin = typing.get_origin(annotation)
    args = [a for a in typing.get_args(annotation) if a is not type(None)]
    if origin in (typing.Union, types.UnionType) and len(args) == 1:
        return type_label(args[0])
    if origin is list and args:
        return type_label(args[0])
    if origin is tuple and args:
        return " ".join(type_label(a) for a in args)
    return _CLICK_NAMES.get(annotation, "VALUE")


def default_text(value: Any) -> Any:
    """A float default as a number (``0`` not ``0.0``, ``60`` not ``60.0``); others as given."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return type(value)(default_text(v) for v in value)
    return value


def _option_type(self: Any, ctx: Any) -> str | None:
    if getattr(self, "is_flag", False):
        return None
    if self.metavar is not None:
        return self.metavar
    return type_label(self.type_descriptor.annotation)


def _argument_type(self: Any, ctx: Any) -> str | None:
    return None


def _argument_name(self: Any) -> str:
    return self.metavar if self.metavar is not None else self.name.upper()


def _no_range(self: Any) -> None:
    return None


def _numeric_defaults(original: Any) -> Any:
    def default_string(self: Any, *, default_value: Any, **kwargs: Any) -> str:
        return original(self, default_value=default_text(default_value), **kwargs)

    return default_string


_APPLIED = False


def apply() -> None:
    """Patch typer's help classes once (a typer without these internals is left as it is)."""
    global _APPLIED
    if _APPLIED:
        return
    try:
        from typer.core import TyperArgument, TyperOption
    except ImportError:  # pragma: no cover - another typer
        return
    for cls in (TyperOption, TyperArgument):
        wanted = ("display_type_rich", "_get_default_string", "_get_number_range_help_str")
        if not all(hasattr(cls, n) for n in wanted):
            return  # pragma: no cover - another typer
    TyperOption.display_type_rich = _option_type  # type: ignore[method-assign]
    TyperArgument.display_type_rich = _argument_type  # type: ignore[method-assign]
    TyperArgument.display_name_raw = property(_argument_name)  # type: ignore[assignment]
    for cls in (TyperOption, TyperArgument):
        cls._get_default_string = _numeric_defaults(cls._get_default_string)  # type: ignore[method-assign]
        cls._get_number_range_help_str = _no_range  # type: ignore[method-assign]
    _APPLIED = True
