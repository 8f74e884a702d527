"""Atomic writes: whole files or none, readable like any file the user writes, one-line errors."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from feederkit.errors import InputError
from feederkit.jsonio import OutputFile, read_json, write_files, write_text_atomic


def test_atomic_write_gives_the_permissions_of_a_plain_write(tmp_path: Path) -> None:
    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    atomic = tmp_path / "atomic.json"
    write_text_atomic(atomic, '{"a": 1}')
    assert stat.S_IMODE(os.stat(atomic).st_mode) == stat.S_IMODE(os.stat(plain).st_mode)
    assert read_json(atomic) == {"a": 1}
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_unwritable_and_unreadable_paths_are_one_line_input_errors(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        write_text_atomic(tmp_path / "no-such-dir" / "plan.json", "{}")
    assert "\n" not in str(exc.value) and "cannot write" in str(exc.value)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError) as exc:
        read_json(bad)
    assert "\n" not in str(exc.value) and "not valid JSON" in str(exc.value)


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ('{"vertices": [[0, ' + "9" * 5000 + "]]}", "5000 digits"),
        ('{"vertices": [[0, ' + "9" * 400 + "]]}", "too large for a number"),
        ('{"x": 1e400}', "1e400 is too large"),
        ('{"x": -1e400}', "-1e400 is too large"),
        ('{"x": NaN}', "NaN: a NaN or infinite number"),
        ('{"x": Infinity}', "Infinity: a NaN or infinite number"),
        ("[" * 600 + "]" * 600, "nested deeper than 512"),
        ("[" * 100_000 + "]" * 100_000, "nested deeper than 512"),
    ],
    ids=["4300-digit limit", "400 digits", "1e400", "-1e400", "NaN", "Infinity", "600", "1e5"],
)
def test_numbers_no_float_holds_and_deep_nesting_name_the_file(
    tmp_path: Path, text: str, why: str
) -> None:
    bad = tmp_path / "part.json"
    bad.write_text(text)
    with pytest.raises(InputError) as exc:
        read_json(bad)
    message = str(exc.value)
    assert "\n" not in message and message.startswith(f"{bad}: ") and why in message


def test_ordinary_numbers_and_a_custom_depth(tmp_path: Path) -> None:
    good = tmp_path / "ok.json"
    good.write_text('{"a": [1, -2.5e3, 1e308, ' + "9" * 300 + "]}")
    assert read_json(good) == {"a": [1, -2500.0, 1e308, int("9" * 300)]}
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 40 + "]" * 40)
    assert read_json(deep, max_depth=40) == read_json(deep)
    with pytest.raises(InputError, match=r"deep\.json: .*nested deeper than 32"):
        read_json(deep, max_depth=32)


def test_unreadable_files_are_named(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such plan file"):
        read_json(tmp_path / "none.json", "plan file")
    with pytest.raises(InputError, match="a folder, not a file"):
        read_json(tmp_path)
    with pytest.raises(InputError, match="File name too long"):
        read_json(tmp_path / ("p" * 300 + ".json"))
    latin = tmp_path / "latin.json"
    latin.write_bytes(b'{"name": "\xe9"}')
    with pytest.raises(InputError, match="not UTF-8 text"):
        read_json(latin)


def test_several_files_are_written_together_or_not_at_all(tmp_path: Path) -> None:
    plan, report = tmp_path / "plan.json", tmp_path / "report.html"
    plan.write_text("old plan")
    with pytest.raises(InputError) as exc:
        write_files(
            [
                OutputFile(plan, b"new plan", "plan file"),
                OutputFile(tmp_path / "gone" / "r.html", b"x", "report"),
            ]
        )
    assert "gone" in str(exc.value) and "cannot write the report" in str(exc.value)
    (tmp_path / "folder.html").mkdir()
    with pytest.raises(InputError, match="a folder is there"):
        write_files(
            [
                OutputFile(plan, b"new plan", "plan file"),
                OutputFile(tmp_path / "folder.html", b"x", "r"),
            ]
        )
    assert plan.read_text() == "old plan"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.html", "plan.json"]
    write_files(
        [OutputFile(plan, b"new plan", "plan file"), OutputFile(report, b"<html>", "report")]
    )
    assert plan.read_text() == "new plan" and report.read_text() == "<html>"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.html", "plan.json", "report.html"]


def test_a_failed_write_in_the_middle_leaves_no_temporaries(tmp_path: Path, monkeypatch) -> None:
    calls = []
    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        calls.append(fd)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    with pytest.raises(InputError, match=r"b\.json: cannot write the file \(No space left"):
        write_files(
            [
                OutputFile(tmp_path / "a.json", b"1", "file"),
                OutputFile(tmp_path / "b.json", b"2", "file"),
            ]
        )
    assert list(tmp_path.iterdir()) == []


def test_a_symbolic_link_is_written_through_to_its_file(tmp_path: Path) -> None:
    """A plan written to ``current.json``, a link to a versioned file, updates that file and
    leaves the link a link (a rename onto the link would replace it and leave the file
    stale)."""
    (tmp_path / "v1").mkdir()
    real = tmp_path / "v1" / "plan.json"
    real.write_text('{"old": true}')
    link = tmp_path / "current.json"
    link.symlink_to(real)
    write_text_atomic(link, '{"new": true}')
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert read_json(real) == {"new": True}
    hidden = [p.name for d in (tmp_path, tmp_path / "v1") for p in d.iterdir() if p.name[0] == "."]
    assert hidden == []
    dangling = tmp_path / "next.json"  # a link to a file not made yet: it is made
    dangling.symlink_to(tmp_path / "v1" / "next-plan.json")
    write_text_atomic(dangling, "{}")
    assert dangling.is_symlink() and read_json(tmp_path / "v1" / "next-plan.json") == {}


def test_a_pipe_or_a_link_to_a_folder_is_not_replaced(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file") as exc:
        write_files([OutputFile(fifo, "{}", "plan file")])
    assert str(exc.value).startswith(f"{fifo}: cannot write the plan file") and "\n" not in str(
        exc.value
    )
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    folder_link = tmp_path / "out.json"
    folder_link.symlink_to(tmp_path)
    with pytest.raises(InputError, match="a folder is there"):
        write_text_atomic(folder_link, "{}")
    assert folder_link.is_symlink()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_undo_puts_back_what_the_commit_replaced(tmp_path: Path) -> None:
    """A changeover whose catalog save fails after its files are in place undoes them: the
    old plan comes back (through a link, into the file it names; the link stays a link),
    and a file that was not there before is removed."""
    from feederkit.jsonio import StagedFiles

    (tmp_path / "v3").mkdir()
    real = tmp_path / "v3" / "plan.json"
    real.write_text('{"old": 1}')
    link = tmp_path / "current.json"
    link.symlink_to(real)
    new = tmp_path / "report.json"
    with StagedFiles([OutputFile(link, "{}", "plan file"), OutputFile(new, "{}")]) as staged:
        staged.commit()
        assert read_json(real) == {} and new.is_file()
        staged.undo()
    assert read_json(real) == {"old": 1} and link.is_symlink() and not new.exists()
    assert sorted(p.name for d in (tmp_path, tmp_path / "v3") for p in d.iterdir()) == [
        "current.json",
        "plan.json",
        "v3",
    ]


def test_a_failed_rename_puts_back_the_files_already_replaced(tmp_path: Path, monkeypatch):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text("old a")
    b.write_text("old b")
    real_replace = os.replace
    calls = []

    def replace(src, dst):
        calls.append(dst)
        if len(calls) == 2:  # the second file's rename fails
            raise OSError(5, "Input/output error")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(InputError, match="b.json: cannot write"):
        write_files([OutputFile(a, "new a"), OutputFile(b, "new b")])
    monkeypatch.setattr(os, "replace", real_replace)
    assert a.read_text() == "old a" and b.read_text() == "old b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "b.json"]


def test_a_file_replaced_keeps_its_permissions_and_group(tmp_path: Path) -> None:
    target = tmp_path / "line3.plan.json"
    target.write_text("{}")
    os.chmod(target, 0o640)
    groups = [g for g in os.getgroups() if g != os.stat(target).st_gid] or [os.getgid()]
    if os.geteuid() == 0:
        groups = [1] + groups  # root may give the file any group (daemon)
    os.chown(target, -1, groups[0])
    write_text_atomic(target, '{"a": 1}')
    st = os.stat(target)
    assert stat.S_IMODE(st.st_mode) == 0o640 and st.st_gid == groups[0]
    assert read_json(target) == {"a": 1}


def _database(path: Path) -> None:
    import sqlite3

    conn = sqlite3.connect(path)
    conn.execute("create table parts (name text)")
    conn.commit()
    conn.close()


@pytest.mark.parametrize("suffix", ["", "-wal", "-shm", "-journal"])
def test_an_sqlite_database_and_its_side_files_are_never_overwritten(
    tmp_path: Path, suffix: str
) -> None:
    db = tmp_path / "feederkit.db"
    _database(db)
    before = db.read_bytes()
    target = Path(f"{db}{suffix}")
    with pytest.raises(InputError) as exc:
        write_text_atomic(target, "{}", what="plan file")
    text = str(exc.value)
    said = "an SQLite database" if not suffix else "a side file (journal or shared memory) of "
    assert "\n" not in text and f"cannot write the plan file over {said}" in text
    assert "of the database" not in text  # "over an SQLite database of the database X"
    assert db.read_bytes() == before and not (suffix and target.exists())
    link = tmp_path / "current.db"
    link.symlink_to(db)
    with pytest.raises(InputError):
        write_text_atomic(link, "{}")  # through a link too
    assert db.read_bytes() == before
    other = tmp_path / "notes-wal"  # a name like a side file, with no database beside it
    write_text_atomic(other, "{}")
    assert read_json(other) == {}
