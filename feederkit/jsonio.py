"""Reading JSON files and writing files atomically, with one clear line when that fails.

Every file feederkit reads (outline files, plan files) and writes (plan files, outline files,
reports, plots) goes through here: bad paths and bad JSON are bad input (``InputError``), and
a written file is either the old one or the whole new one (a temporary file beside it, then
a rename). A character device such as ``/dev/null`` is written as it is (nothing to rename:
``-o /dev/null`` runs a command only for its checks).
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import stat
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from feederkit.errors import InputError


def _reason(exc: BaseException) -> str:
    if isinstance(exc, UnicodeDecodeError):
        return "not UTF-8 text"
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return type(exc).__name__


MAX_JSON_DEPTH = 512
"""Arrays and objects nested deeper than this are refused: no feederkit file needs it (a plan
node costs three levels), and deeper input would exhaust Python's recursion limit."""

MAX_NUMBER_DIGITS = 400
"""Integers with more digits than this are refused before Python converts them (its own limit
is 4300 digits, and anything beyond 309 digits overflows a float anyway)."""


class _BadNumber(ValueError):
    """A JSON number feederkit cannot use: too large, not finite, or NaN."""


def _parse_int(text: str) -> int | float:
    digits = len(text.lstrip("-"))
    if digits > MAX_NUMBER_DIGITS:
        raise _BadNumber(f"an integer of {digits} digits is too large")
    value = int(text)
    if abs(value) > 1.7976931348623157e308:
        raise _BadNumber(f"the integer {_clip(text)} is too large for a number")
    return value


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _BadNumber(f"the number {_clip(text)} is too large: NaN or infinite as a float")
    return value


def _parse_constant(text: str) -> float:
    raise _BadNumber(f"{text}: a NaN or infinite number, which JSON does not allow")


def _clip(text: str, n: int = 24) -> str:
    return text if len(text) <= n else text[:n] + "..."


def json_depth(value: object, limit: int) -> int:
    """The nesting depth of a parsed JSON value (a scalar is 0), counted without recursion;
    the count stops once it passes ``limit``."""
    deepest = 0
    stack: list[tuple[object, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children = item.values()
        elif isinstance(item, list):
            children = item
        else:
            continue
        depth += 1
        deepest = max(deepest, depth)
        if deepest > limit:
            return deepest
        stack.extend((child, depth) for child in children if isinstance(child, dict | list))
    return deepest


def parse_json(text: str, where: str, max_depth: int = MAX_JSON_DEPTH) -> object:
    """The JSON value of ``text``; invalid JSON, numbers no float can hold (over 400 digits,
    1e400), ``NaN``/``Infinity`` and nesting deeper than ``max_depth`` are bad input naming
    ``where`` on one line."""
    try:
        value = json.loads(
            text,
            parse_int=_parse_int,
            parse_float=_parse_float,
            parse_constant=_parse_constant,
        )
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{where}: not valid JSON ({exc.msg.removesuffix(' at')} at line {exc.lineno})"
        ) from None
    except _BadNumber as exc:
        raise InputError(f"{where}: not valid JSON for feederkit ({exc})") from None
    except RecursionError:
        raise InputError(f"{where}: not valid JSON (nested deeper than {max_depth})") from None
    except (ValueError, OverflowError) as exc:  # int() refusing a number, float overflow
        raise InputError(f"{where}: not valid JSON for feederkit ({exc})") from None
    if json_depth(value, max_depth) > max_depth:
        raise InputError(f"{where}: not valid JSON for feederkit (nested deeper than {max_depth})")
    return value


def read_json(
    path: str | os.PathLike[str], what: str = "file", *, max_depth: int = MAX_JSON_DEPTH
) -> object:
    """The JSON value in ``path``; a missing, unreadable or invalid file is bad input.

    ``what`` names the file in the message: ``<path>: no such <what>``. Numbers must fit a
    float and be finite, and nesting is limited to ``max_depth`` (see :func:`parse_json`).
    A UTF-8 byte order mark (Windows tools write one) is skipped, as RFC 8259 lets a parser.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"{p}: no such {what}") from None
    except IsADirectoryError:
        raise InputError(f"{p}: cannot read the {what} (a folder, not a file)") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read the {what} ({_reason(exc)})") from None
    return parse_json(text, str(p), max_depth)


def _umask() -> int:
    """The process's umask (read without changing it for long)."""
    current = os.umask(0o022)
    os.umask(current)
    return current


@dataclass(frozen=True)
class OutputFile:
    """A file to write: where, its content (text is written as UTF-8), and what it is (for
    error messages: ``<path>: cannot write the <what> (<reason>)``)."""

    path: Path
    data: str | bytes
    what: str = "file"


def _cannot(path: object, what: str, exc: OSError) -> InputError:
    return InputError(f"{path}: cannot write the {what} ({_reason(exc)})")


STANDARD_STREAMS = ("/dev/stdin", "/dev/stdout", "/dev/stderr")
"""Paths that name the process's own streams (as do ``/dev/fd/N`` and ``/proc/self/fd/N``):
not a file to write, for a command prints its own lines on its standard output."""


def _is_stream(path: Path) -> bool:
    """Whether ``path`` names one of the process's own streams (:data:`STANDARD_STREAMS`)."""
    text = os.path.abspath(path)
    return text in STANDARD_STREAMS or text.startswith(("/dev/fd/", "/proc/self/fd/"))


def is_device(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a character device such as ``/dev/null`` (through links), which
    a write goes to as it is: no temporary file, no rename, no file name to check."""
    given = Path(path)
    if _is_stream(given):
        return False
    try:
        return stat.S_ISCHR(os.stat(given).st_mode)
    except OSError:
        return False


SQLITE_MAGIC = b"SQLite format 3\x00"
"""The first 16 bytes of every SQLite database file (a feederkit catalog)."""

SQLITE_SIDE_SUFFIXES = ("-wal", "-shm", "-journal")
"""SQLite's files beside a database ``DB``: ``DB-wal``, ``DB-shm``, ``DB-journal``."""


def _is_database(path: Path) -> bool:
    """Whether the regular file at ``path`` is an SQLite database (:data:`SQLITE_MAGIC`)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(len(SQLITE_MAGIC)) == SQLITE_MAGIC
    except OSError:
        return False


def _database_file(target: Path) -> Path | None:
    """The SQLite database that a write to ``target`` would destroy: ``target`` itself, or
    the database beside it whose journal or shared-memory file it is; None for any other."""
    if target.is_file() and _is_database(target):
        return target
    for suffix in SQLITE_SIDE_SUFFIXES:
        if target.name.endswith(suffix) and len(target.name) > len(suffix):
            main = target.with_name(target.name[: -len(suffix)])
            if main.is_file() and _is_database(main):
                return main
    return None


def destination(path: str | os.PathLike[str], what: str = "file") -> Path:
    """Where a file written to ``path`` lands: through symbolic links to the file they name
    (a plan written to ``current.plan.json``, a link to a versioned file, updates that file,
    as a plain ``open`` would; renaming over the link would replace the link instead), or a
    character device such as ``/dev/null`` (written as it is, :func:`is_device`). Bad input
    when that is a folder, a standard stream (``/dev/stdout``: the command prints there too),
    or exists and is neither a regular file nor a character device (a pipe, socket or block
    device, which a rename would replace), or an SQLite database or its side files (a
    catalog: ``-o feederkit.db`` would replace every part and changeover with one file)."""
    given = Path(path)
    if _is_stream(given):
        raise InputError(
            f"{given}: cannot write the {what} to a standard stream (the command prints there "
            "too): give a file, or /dev/null to run the command only for its checks"
        )
    target = Path(os.path.realpath(given)) if given.is_symlink() else given
    database = _database_file(target)
    if database is not None:
        whose = (
            "an SQLite database"
            if database == target
            else f"a side file (journal or shared memory) of the SQLite database {database}"
        )
        raise InputError(
            f"{given}: cannot write the {what} over {whose} (a feederkit catalog?): give the "
            "file another path"
        )
    try:
        st = os.stat(target)
    except OSError:
        return target  # not there yet (or not reachable: staging says why)
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{given}: cannot write the {what} (a folder is there)")
    if not (stat.S_ISREG(st.st_mode) or stat.S_ISCHR(st.st_mode)):
        raise InputError(
            f"{given}: cannot write the {what} (not a regular file: a pipe, socket or block "
            "device is there)"
        )
    return target


def _temporary(path: object, target: Path, what: str) -> tuple[int, str]:
    """A new temporary file beside ``target`` (its descriptor and path); bad input naming
    ``path`` when the folder takes no new file (missing, read-only, no permission)."""
    directory = target.parent if str(target.parent) else Path(".")
    try:
        return tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise _cannot(path, what, exc) from None


def check_writable(path: str | os.PathLike[str], what: str = "file") -> None:
    """Refuse now a ``path`` that writing it later would refuse, with the same message: a
    folder, pipe, socket or device there (:func:`destination`), or a folder that takes no
    new file. A command checks its outputs before long work with this; the temporary file
    it makes to find out is removed at once. A character device (``/dev/null``) must only
    take writing."""
    target = destination(path, what)
    if is_device(target):
        if not os.access(target, os.W_OK):
            raise _cannot(path, what, PermissionError(errno.EACCES, os.strerror(errno.EACCES)))
        return
    fd, tmp = _temporary(path, target, what)
    try:
        os.close(fd)
    finally:  # a Ctrl-C here must not leave the probe behind
        os.unlink(tmp)


def _bytes(f: OutputFile) -> bytes:
    return f.data.encode("utf-8") if isinstance(f.data, str) else f.data


def _write_device(f: OutputFile, target: Path) -> None:
    """Write ``f`` straight to the character device ``target`` (``/dev/null``): there is no
    file to rename onto; an error (``/dev/full``: no space) is bad input naming it."""
    try:
        with open(target, "wb") as fh:
            fh.write(_bytes(f))
    except OSError as exc:
        raise _cannot(f.path, f.what, exc) from None


def _stage(f: OutputFile, mode: int | None) -> tuple[Path, str | None]:
    """Write ``f`` in full to a temporary file beside its :func:`destination`; return that
    destination and the temporary's path (None for a character device, written on commit).

    ``mode`` None: a file replaced keeps its permissions and (where the process may set it)
    its group, as writing it in place would (a plan folder shared with a controller's
    account through its group stays readable there); a new file gets those of ``open``."""
    target = destination(f.path, f.what)
    if is_device(target):
        return target, None
    group = -1
    if mode is None:
        try:
            st = os.stat(target)
        except OSError:
            mode = 0o666 & ~_umask()
        else:
            mode, group = st.st_mode & 0o777, st.st_gid
    data = _bytes(f)  # before the temporary: encoding a large plan takes a while
    fd, tmp = _temporary(f.path, target, f.what)
    try:  # from the temporary's creation on: a Ctrl-C while writing it takes it away
        with os.fdopen(fd, "wb") as fh:
            if group != -1:  # not a member of that group: the process's own group stays
                with contextlib.suppress(OSError):
                    os.fchown(fh.fileno(), -1, group)
            os.fchmod(fh.fileno(), mode)
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException as exc:
        os.unlink(tmp)
        if isinstance(exc, OSError):
            raise _cannot(f.path, f.what, exc) from None
        raise
    return target, tmp


class StagedFiles:
    """Files written in full to temporaries beside their targets, not yet in place.

    The slow part (where a full disk or an unwritable folder shows) happens on staging;
    :meth:`commit` then renames every temporary onto its target, which on one file system
    does not fail halfway for lack of space. Leaving a ``with`` block without a commit
    discards the temporaries. ``mode`` sets the permissions; by default a file replaced
    keeps its own (and its group), and a new one gets those of a newly created file (0666
    less the umask), as a plain ``open(path, "w")`` gives, so a controller's account can
    read a plan file. A file a commit replaces is kept (a hard
    link beside it) until the block ends, so :meth:`undo` can put it back. A character
    device (``/dev/null``) is written on commit, as it is; nothing undoes that.
    """

    def __init__(self, files: Iterable[OutputFile], mode: int | None = None) -> None:
        self._staged: list[tuple[OutputFile, Path, str | None]] = []
        self._kept: dict[Path, str] = {}
        self._done: list[Path] = []
        self.committed = False
        try:
            for f in files:
                self._staged.append((f, *_stage(f, mode)))
        except BaseException:
            self.discard()
            raise

    @property
    def paths(self) -> list[Path]:
        """The target paths as given, in order."""
        return [Path(f.path) for f, _, _ in self._staged]

    def commit(self) -> None:
        """Rename every temporary onto its destination (a link's file), in order; a character
        device is written instead. A failure puts back the files already replaced."""
        for f, target, tmp in self._staged:
            try:
                self._put(f, target, tmp)
            except InputError:
                self.committed = True
                self.undo()  # the files already replaced come back: all or none
                self.discard()
                raise
            if tmp is not None:
                self._done.append(target)
        self.committed = True

    def _put(self, f: OutputFile, target: Path, tmp: str | None) -> None:
        """One file in place: its temporary renamed onto ``target`` (the old file kept), or
        its content written to a character device (``tmp`` None)."""
        if tmp is None:
            _write_device(f, target)
            return
        self._keep(target, tmp)
        try:
            os.replace(tmp, target)
        except OSError as exc:
            raise _cannot(f.path, f.what, exc) from None

    def _keep(self, target: Path, tmp: str) -> None:
        """A hard link to the file at ``target``, if any, beside its temporary (best effort:
        without one, :meth:`undo` removes the new file instead)."""
        if target.is_file():
            kept = tmp + ".old"
            try:
                os.link(target, kept)
            except OSError:
                return
            self._kept[target] = kept

    def discard(self) -> None:
        """Remove the temporaries not yet renamed, and the kept old files."""
        for _, _, tmp in self._staged:
            if tmp is not None and os.path.exists(tmp):
                os.unlink(tmp)
        for kept in self._kept.values():
            if os.path.exists(kept):
                os.unlink(kept)
        self._kept.clear()

    def undo(self) -> None:
        """Put back what a commit replaced: the old file where there was one, else remove
        the new one (through a link: the file it names, the link left as it was)."""
        if self.committed:
            for target in self._done:
                kept = self._kept.pop(target, None)
                if kept is not None:
                    os.replace(kept, target)
                elif target.is_file():
                    target.unlink()
            self._done.clear()
            self.committed = False

    def __enter__(self) -> StagedFiles:
        return self

    def __exit__(self, *exc: object) -> None:
        self.discard()


def write_files(files: Iterable[OutputFile], mode: int | None = None) -> None:
    """Write every file, or (when one cannot be written) none: ``plan -o PLAN --report
    REPORT`` writes both or neither. Errors are bad input naming the file."""
    with StagedFiles(files, mode) as staged:
        staged.commit()


def write_bytes_atomic(
    path: str | os.PathLike[str], data: bytes, *, what: str = "file", mode: int | None = None
) -> None:
    """Write ``data`` to ``path`` atomically: a temporary file beside it, then a rename."""
    write_files([OutputFile(Path(path), data, what)], mode)


def write_text_atomic(path: str | os.PathLike[str], text: str, *, what: str = "file") -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically; an unwritable path is bad input."""
    write_files([OutputFile(Path(path), text, what)])
