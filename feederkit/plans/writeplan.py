"""Writing a plan file: what feederkit writes is read back first.

:func:`read_back` checks the object a file's text is written from as the reader
(:func:`~feederkit.plans.readplan.plan_from_dict`) will, and :func:`plan_file_text` and
:func:`write_plan` (atomic: a temporary file beside it, then a rename) write only such text,
so a file the reader refuses is a bug in feederkit, never a file on disk.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from feederkit.errors import InputError
from feederkit.jsonio import write_text_atomic
from feederkit.plans.fileformat import plan_json, plan_to_dict
from feederkit.plans.model import Plan
from feederkit.plans.readplan import plan_from_dict


def plan_file_text(plan: Plan | Mapping[str, Any]) -> str:
    """The text every plan feederkit writes (:func:`~feederkit.plans.fileformat.plan_json`),
    checked as a reader will check it (:func:`read_back`) before anything is written."""
    return read_back(plan)[0]


def read_back(plan: Plan | Mapping[str, Any]) -> tuple[str, Plan]:
    """A plan's file text and the :class:`Plan` a reader gets from it: the object the text
    is written from, checked by the loader's validator (:func:`plan_from_dict`; the writer
    writes exactly it, and parsing an 11 MB plan again would cost a command its deadline). A
    file the loader refuses is a bug in feederkit, never a written file (AssertionError)."""
    value = plan_to_dict(plan) if isinstance(plan, Plan) else plan
    text = plan_json(value)  # ValueError for a NaN or an infinity, which JSON cannot hold
    try:
        return text, plan_from_dict(value, "the plan to write")
    except InputError as exc:
        raise AssertionError(f"feederkit made a plan file its own loader refuses: {exc}") from None


def write_plan(
    plan: Plan | str | os.PathLike[str], path: str | os.PathLike[str] | Plan | Mapping[str, Any]
) -> None:
    """Write a plan file atomically (a temporary file beside it, then a rename), its text
    checked first (:func:`plan_file_text`: ValueError for a NaN or an infinity,
    AssertionError for a plan the loader would refuse; no file either way).

    ``write_plan(plan, path)``; the older order ``write_plan(path, plan_dict)`` is accepted
    while callers move to the :class:`Plan`.
    """
    if isinstance(plan, Plan | Mapping):
        target, value = path, plan
    else:
        target, value = plan, path
    assert isinstance(target, str | os.PathLike)
    write_text_atomic(target, plan_file_text(value), what="plan file")  # type: ignore[arg-type]
