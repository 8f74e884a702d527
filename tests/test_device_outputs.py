"""Outputs on a character device (docs/cli.md): ``-o /dev/null`` runs a command only for its
checks, with no rename; a pipe, a folder or a standard stream is still refused in one line."""

from __future__ import annotations

import json
import os
import shutil
import stat
from pathlib import Path

import pytest
from shared import cli_ok, one_line_error

from feederkit.errors import InputError
from feederkit.jsonio import OutputFile, StagedFiles, check_writable, is_device, write_files

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
TRIANGLE = str(CATALOG / "isosceles-right-triangle.json")
NULL = "/dev/null"

needs_null = pytest.mark.skipif(
    not (os.path.exists(NULL) and stat.S_ISCHR(os.stat(NULL).st_mode)), reason="no /dev/null"
)
needs_full = pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")


@pytest.fixture()
def db(tmp_path: Path, capsys) -> Path:
    """A catalog with the triangle and the octagon, and the changeover ``fig27`` of both."""
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("isosceles-right-triangle", "octagon"):
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    cli_ok(capsys, ["catalog", "import", str(folder), "--catalog", str(path)])
    mix = ["--mix", "isosceles-right-triangle,octagon", "--tolerance", "0.01"]
    cli_ok(capsys, ["changeover", "compile", "fig27", *mix, "--catalog", str(path)])
    return path


@needs_null
def test_a_character_device_is_written_as_it_is(tmp_path: Path) -> None:
    assert is_device(NULL) and not is_device(tmp_path) and not is_device(tmp_path / "x.json")
    check_writable(NULL, "plan file")
    plan = tmp_path / "plan.json"
    write_files([OutputFile(Path(NULL), "{}", "plan file"), OutputFile(plan, "{}")])
    assert stat.S_ISCHR(os.stat(NULL).st_mode) and plan.read_text() == "{}"
    link = tmp_path / "null.json"  # a link to the device: the device, not a file in its place
    link.symlink_to(NULL)
    write_files([OutputFile(link, "{}", "plan file")])
    assert link.is_symlink() and os.readlink(link) == NULL
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@needs_full
def test_a_device_that_refuses_the_write_is_one_line_and_undoes_the_rest(tmp_path: Path) -> None:
    plan = tmp_path / "plan.json"
    plan.write_text("old")
    files = [OutputFile(plan, "new", "plan file"), OutputFile(Path("/dev/full"), "x", "report")]
    with pytest.raises(InputError) as exc, StagedFiles(files) as staged:
        staged.commit()
    assert str(exc.value) == "/dev/full: cannot write the report (No space left on device)"
    assert plan.read_text() == "old"  # both or neither


@pytest.mark.parametrize("stream", ["/dev/stdout", "/dev/stderr", "/dev/fd/1"])
def test_a_standard_stream_is_refused(stream: str) -> None:
    with pytest.raises(InputError) as exc:
        check_writable(stream, "plan file")
    message = str(exc.value)
    assert message.startswith(f"{stream}: cannot write the plan file to a standard stream")
    assert "/dev/null" in message and "\n" not in message


def test_a_pipe_and_a_folder_are_still_refused(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file: a pipe, socket or block device"):
        check_writable(fifo, "plan file")
    with pytest.raises(InputError, match="a folder is there"):
        check_writable(tmp_path, "plan file")


@needs_null
def test_plan_to_dev_null_checks_and_exits_as_with_a_file(tmp_path: Path, capsys) -> None:
    """``plan -o /dev/null --report /dev/null``: one device takes both, and the report needs
    no .html name there; the exit code is the plan's."""
    out = cli_ok(capsys, ["plan", TRIANGLE, "--tolerance", "0.01", "-o", NULL, "--report", NULL])
    assert "error" not in out.err
    err = one_line_error(capsys, ["plan", TRIANGLE, "-o", str(tmp_path)])
    assert "a folder is there" in err
    err = one_line_error(capsys, ["plan", TRIANGLE, "-o", "/dev/stdout"])
    assert "standard stream" in err
    err = one_line_error(capsys, ["plan", TRIANGLE, "--report", str(tmp_path / "r.txt")])
    assert "name it .html" in err


@needs_null
def test_changeover_outputs_and_report_go_to_dev_null(db: Path, tmp_path: Path, capsys) -> None:
    cat = ["--catalog", str(db)]
    out = cli_ok(capsys, ["changeover", "export", "fig27", "-o", NULL, *cat])
    assert f"wrote the plan to {NULL}" in out.out
    exported = json.loads(
        cli_ok(capsys, ["changeover", "export", "fig27", "-o", NULL, "--json", *cat]).out
    )
    assert exported["output"] == NULL and exported["up_to_date"] is True
    out = cli_ok(capsys, ["changeover", "report", "fig27", "-o", NULL, "--time-limit", "5", *cat])
    assert f"wrote the report to {NULL}" in out.out
    mix = ["--mix", "isosceles-right-triangle,octagon", "--tolerance", "0.01"]
    args = ["changeover", "compile", "again", *mix, "-o", NULL, "--report", NULL, *cat]
    cli_ok(capsys, [*args, "--time-limit", "5"])
    listed = json.loads(cli_ok(capsys, ["changeover", "list", "--json", *cat]).out)
    assert [c["name"] for c in listed] == ["again", "fig27"]
    plan = tmp_path / "fig27.json"
    cli_ok(capsys, ["changeover", "export", "fig27", "-o", str(plan), *cat])
    out = cli_ok(capsys, ["report", str(plan), "-o", NULL])
    assert stat.S_ISCHR(os.stat(NULL).st_mode)
    err = one_line_error(capsys, ["changeover", "export", "fig27", "-o", "/dev/stdout", *cat])
    assert "standard stream" in err
