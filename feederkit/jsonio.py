"""Reading JSON files and writing files atomically, with one clear line when that fails.

Every file feederkit reads (outline files, plan files) and writes (plan files, outline files,
reports, plots) goes through here: bad paths and bad JSON are bad input (``InputError``), and
a written file is either the old one or the whole new one (a temporary file beside it, then
a rename).
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

from feederkit.errors import InputError


def _reason(exc: BaseException) -> str:
    if isinstance(exc, UnicodeDecodeError):
        return "not UTF-8 text"
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return type(exc).__name__


def read_json(path: str | os.PathLike[str], what: str = "file") -> object:
    """The JSON value in ``path``; a missing, unreadable or invalid file is bad input.

    ``what`` names the file in the message: ``<path>: no such <what>``.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{p}: no such {what}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read the {what} ({_reason(exc)})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except RecursionError:
        raise InputError(f"{p}: not valid JSON (nested too deeply)") from None


def _umask() -> int:
    """The process's umask (read by setting and restoring it)."""
    current = os.umask(0o022)
    os.umask(current)
    return current


def write_bytes_atomic(
    path: str | os.PathLike[str], data: bytes, *, what: str = "file", mode: int | None = None
) -> None:
    """Write ``data`` to ``path`` atomically: a temporary file beside it, then a rename.

    ``mode`` sets the file's permissions; by default those of a newly created file (0666 less
    the umask), as a plain ``open(path, "w")`` would give, so a controller's account can read
    the plan file. A path that cannot be written is bad input:
    ``<path>: cannot write the <what> (<reason>)``.
    """
    if mode is None:
        mode = 0o666 & ~_umask()
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise InputError(f"{path}: cannot write the {what} ({_reason(exc)})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            os.fchmod(fh.fileno(), mode)
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(f"{path}: cannot write the {what} ({_reason(exc)})") from None
        raise


def write_text_atomic(path: str | os.PathLike[str], text: str, *, what: str = "file") -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically; an unwritable path is bad input."""
    write_bytes_atomic(path, text.encode("utf-8"), what=what)
