"""Command-line defects found by a review of the tool as a new user, each pinned through
``main`` (design.md, "Command line": exit 0 success, 1 a result the user must act on, 2 bad
input or usage; errors one line on stderr; ``--json`` machine-readable output on stdout;
docs/cli.md)."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from shared import no_stray_profile, one_line_error  # noqa: F401 (autouse)

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.jsonio import write_text_atomic
from feederkit.sim import mujoco_available

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
L_BRACKET = str(CATALOG / "l-bracket.json")
T_CLIP = str(CATALOG / "t-clip.json")
OCTAGON = str(CATALOG / "octagon.json")


def run(capsys, args: list[str]) -> tuple[int, str, str]:
    """``feederkit args`` in process: its exit code, stdout and stderr."""
    rc = main(args)
    captured = capsys.readouterr()
    return rc, captured.out, captured.err


def ok(capsys, args: list[str]) -> str:
    """Run ``feederkit args``, which must exit 0; its stdout."""
    rc, out, err = run(capsys, args)
    assert rc == 0, err
    return out


# 1. Exporting a changeover whose parts have newer revisions is a result to act on.


@pytest.fixture()
def stale_catalog(tmp_path, capsys) -> Path:
    """A catalog whose changeover ``mx`` names l-bracket revision 1, the latest being 2."""
    db = tmp_path / "stale.db"
    ok(capsys, ["catalog", "init", "--catalog", str(db)])
    for source in (L_BRACKET, T_CLIP):
        ok(capsys, ["catalog", "add", source, "--catalog", str(db)])
    compile_mx = ["changeover", "compile", "mx", "--mix", "l-bracket,t-clip", "--tolerance", "0.2"]
    ok(capsys, [*compile_mx, "--time-limit", "30", "--catalog", str(db)])
    data = json.loads(Path(L_BRACKET).read_text())
    data["vertices"][0] = [data["vertices"][0][0] - 0.5, data["vertices"][0][1]]
    revised = tmp_path / "l-bracket.json"
    revised.write_text(json.dumps(data))
    ok(capsys, ["catalog", "add", str(revised), "--revise", "--catalog", str(db)])
    return db


def test_export_of_a_stale_changeover_writes_the_file_warns_and_exits_1(
    stale_catalog, tmp_path, capsys
):
    out = tmp_path / "mx.plan.json"
    rc, stdout, err = run(
        capsys, ["changeover", "export", "mx", "-o", str(out), "--catalog", str(stale_catalog)]
    )
    assert rc == 1, err
    assert json.loads(out.read_text())["format"] == "feederkit-plan"  # still exported
    assert f"wrote the plan to {out}" in stdout
    warning, result = err.splitlines()
    assert warning.startswith("warning: l-bracket: the changeover is made for revision 1")
    assert result.startswith("result: changeover 'mx' is out of date") and "compile" in result


def test_list_and_show_of_a_stale_changeover_warn_and_exit_0_its_report_exits_1(
    stale_catalog, tmp_path, capsys
):
    """List and show describe the stored changeover (informational): the warning, in
    ``--json`` too; its report goes to the line as the plan does, so it exits 1 as export
    does (the page written, the warnings on it)."""
    db = ["--catalog", str(stale_catalog)]
    rc, out, err = run(capsys, ["changeover", "show", "mx", "--json", *db])
    assert rc == 0 and "latest is 2" in err
    assert any("latest is 2" in w for w in json.loads(out)["warnings"])
    rc, out, _ = run(capsys, ["changeover", "list", "--json", *db])
    assert rc == 0 and json.loads(out)[0]["warnings"]
    rc, _, err = run(capsys, ["changeover", "report", "mx", "-o", str(tmp_path / "mx.html"), *db])
    assert rc == 1 and "latest is 2" in err and (tmp_path / "mx.html").is_file()


# 2. ``--json`` prints one JSON object on stdout when a command exits 1 without an answer.


def json_result(capsys, args: list[str]) -> dict:
    """Run ``feederkit args --json``: exit 1, one ``result:`` line last on stderr and one
    JSON object on stdout whose ``error`` is that line's message."""
    rc, out, err = run(capsys, [*args, "--json"])
    assert rc == 1, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("result: ") and "Traceback" not in err
    data = json.loads(out)
    assert data["error"] == last.removeprefix("result: ") and data["exit_code"] == 1
    return data


def test_plan_json_without_a_plan_in_time_says_what_stopped_it_and_the_bound(capsys, monkeypatch):
    # A search stopped by a limit: the JSON says which (``stopped_by``) and the proven
    # bound (``lower_bound``), not only the sentence.
    import feederkit.planning.api as api
    from feederkit.planning.options import OutOfBudget

    def stopped(*_a, **_k):
        raise OutOfBudget("no plan found within the time limit of 1 s", "time", 4)

    monkeypatch.setattr(api, "_plan", stopped)
    data = json_result(capsys, ["plan", T_CLIP, "--time-limit", "1"])
    assert data["stopped_by"] == "time" and data["lower_bound"] == 4
    assert data["members"] == ["t-clip"]
    monkeypatch.undo()
    data = json_result(capsys, ["plan", T_CLIP, "--min-margin", "100"])
    assert "stopped_by" not in data and "lower_bound" not in data  # no limit stopped it


def test_no_plan_says_an_earlier_file_at_the_output_is_not_this_runs(capsys, monkeypatch, tmp_path):
    # Exit 1 also means "written, with parts it cannot tell apart": a script must not read
    # yesterday's plan at the path as this run's.
    import feederkit.planning.api as api
    from feederkit.planning.options import OutOfBudget

    def stopped(*_a, **_k):
        raise OutOfBudget("no plan found within the time limit of 1 s", "time", 4)

    monkeypatch.setattr(api, "_plan", stopped)
    old = tmp_path / "p.json"
    old.write_text("{}")
    rc, _out, err = run(capsys, ["plan", T_CLIP, "-o", str(old), "--time-limit", "1"])
    assert rc == 1 and old.read_text() == "{}"
    assert f"warning: nothing was written: {old} still holds an earlier file" in err
    rc, _out, err = run(capsys, ["plan", T_CLIP, "-o", str(tmp_path / "new.json")])
    assert rc == 1 and "earlier file" not in err  # nothing there before


def test_plan_json_without_a_plan_prints_the_error_and_what_was_found(capsys):
    data = json_result(capsys, ["plan", T_CLIP, "--min-margin", "100"])
    assert "no plan keeps a margin of 100 deg" in data["error"]
    assert data["sources"] == [T_CLIP] and data["members"] == ["t-clip"]
    assert data["sensor"] == {"model": "none"}
    assert data["uncertainty"]["rotation_error_deg"] == 1.0


def test_plan_json_of_landings_that_cannot_be_accepted_apart(capsys):
    data = json_result(capsys, ["plan", L_BRACKET, "--accept", "up", "--time-limit", "30"])
    assert "no plan can tell them apart" in data["error"]
    assert data["members"] == ["l-bracket/up", "l-bracket/down"]


def test_changeover_compile_json_without_a_plan_stores_nothing(tmp_path, capsys):
    db = tmp_path / "c.db"
    ok(capsys, ["catalog", "init", "--catalog", str(db)])
    for source in (L_BRACKET, T_CLIP):
        ok(capsys, ["catalog", "add", source, "--catalog", str(db)])
    args = ["changeover", "compile", "bad", "--mix", "l-bracket,t-clip", "--tolerance", "0.2"]
    data = json_result(capsys, [*args, "--min-margin", "100", "--catalog", str(db)])
    assert data["name"] == "bad" and data["mix"] == ["l-bracket", "t-clip"]
    assert data["cell"]["sensor"] == {"model": "tolerance", "tolerance_mm": 0.2}
    assert json.loads(ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)])) == []


def test_design_sensor_json_cut_short_by_the_time_limit(capsys):
    data = json_result(capsys, ["design", "sensor", T_CLIP, OCTAGON, "--time-limit", "1e-6"])
    assert "did not finish within the time limit" in data["error"]
    assert data["parts"] == ["t-clip", "octagon"]
    assert data["cell_profile"] == "built-in defaults"


@pytest.mark.skipif(not mujoco_available(), reason="mujoco cannot be imported (feederkit[sim])")
def test_simulate_json_of_a_plan_that_fails_verification(tmp_path, capsys):
    good = tmp_path / "lb.plan.json"
    ok(capsys, ["plan", L_BRACKET, "--led-pitch", "0.5", "-o", str(good), "--time-limit", "30"])
    data = json.loads(good.read_text())
    data["nodes"][next(iter(data["nodes"]))]["action_deg"] = 10.0
    bad = tmp_path / "bad.plan.json"
    bad.write_text(json.dumps(data))
    found = json_result(capsys, ["simulate", str(bad), "--trials", "1"])
    assert "failed verification" in found["error"] and found["plan"] == str(bad)
    assert found["uncertainty"]["rotation_error_deg"] == 1.0


def test_a_json_answer_before_a_result_is_the_only_object(capsys):
    """``plan`` prints the plan, then exits 1 for parts it cannot tell apart: no second object."""
    rc, out, err = run(capsys, ["plan", L_BRACKET, T_CLIP, "--landings", "up", "--json"])
    assert rc == 1 and err.strip().splitlines()[-1].startswith("result: ")
    plan = json.loads(out)  # one JSON value, the plan file
    assert plan["format"] == "feederkit-plan" and "error" not in plan


def test_bad_input_with_json_prints_nothing_on_stdout(capsys):
    rc, out, _ = run(capsys, ["plan", "no-such-part.json", "--json"])
    assert rc == 2 and out == ""


# 3. A usage error click raises without its context names the command that failed.


@pytest.mark.parametrize(
    ("args", "command"),
    [
        (["part", "analyze", L_BRACKET, "--com", "1"], "feederkit part analyze"),
        (["plan", L_BRACKET, "--time-limit"], "feederkit plan"),
        (["changeover", "compile", "mx", "--mix"], "feederkit changeover compile"),
    ],
    ids=["com-one-value", "plan-no-value", "changeover-no-value"],
)
def test_an_option_missing_a_value_names_the_commands_help(capsys, args, command):
    err = one_line_error(capsys, args)
    assert err.rstrip().endswith(f"(see {command} --help)"), err


# 4. ``feederkit`` alone (or a group alone) is a usage error; ``--help`` is not.


@pytest.mark.parametrize(
    "args", [[], ["part"], ["changeover"]], ids=["feederkit", "part", "changeover"]
)
def test_a_group_without_its_command_prints_its_help_and_exits_2(capsys, args):
    rc, out, err = run(capsys, args)
    assert rc == 2 and out == ""
    assert err.count("Usage: ") == 1 and f"Usage: {' '.join(['feederkit', *args])} " in err
    assert "Commands" in err


def test_help_still_exits_0_on_stdout(capsys):
    rc, out, err = run(capsys, ["--help"])
    assert rc == 0 and err == "" and out.count("Usage: feederkit ") == 1


# 5. A standard output that cannot be written is named as such.


class FullStdout:
    """A standard output on a full disk: every write fails as on ``> /dev/full``."""

    encoding = "utf-8"

    def write(self, text: str) -> int:
        raise OSError(errno.ENOSPC, "No space left on device")

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return False


def test_a_full_stdout_says_the_standard_output_in_process(capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdout", FullStdout())
    err = one_line_error(capsys, ["part", "analyze", T_CLIP, "--json"])
    assert err.startswith("error: cannot write the standard output: the disk is full"), err
    assert "a file" not in err


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_a_full_stdout_says_the_standard_output(tmp_path):
    script = Path(sys.executable).with_name("feederkit")
    if not script.exists():
        pytest.skip("the feederkit console script is not installed beside python")
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [str(script), "part", "analyze", T_CLIP, OCTAGON, "--json"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
            check=False,
        )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("error: cannot write the standard output: the disk is full"), line


# 6. Output paths are checked before the work, with the write's own message.


def late_message(path: Path, what: str) -> str:
    """What writing ``path`` at the end would say (the atomic write's InputError)."""
    with pytest.raises(InputError) as info:
        write_text_atomic(path, "x", what=what)
    return str(info.value)


def never(*args, **kwargs):
    raise AssertionError("the work ran before the output path was checked")


def output_cases(tmp_path: Path) -> dict[str, tuple[list[str], str, str, str]]:
    """Per command: its arguments up to the output option, the output's name in messages,
    the output's suffix and the function that starts its long work (``module:name``)."""
    db = str(tmp_path / "none.db")
    plan, changeover = "feederkit.cli.plan", "feederkit.cli.changeover"
    return {
        "plan": (["plan", L_BRACKET, "-o"], "plan file", ".json", f"{plan}:load_landings"),
        "plan --report": (
            ["plan", L_BRACKET, "--report"],
            "report",
            ".html",
            f"{plan}:load_landings",
        ),
        "changeover compile": (
            ["changeover", "compile", "mx", "--mix", "a,b", "--catalog", db, "-o"],
            "plan file",
            ".json",
            f"{changeover}:compile_changeover",
        ),
        "changeover report": (
            ["changeover", "report", "mx", "--catalog", db, "-o"],
            "report",
            ".html",
            f"{changeover}:load_changeover",
        ),
        "report": (["report", "p.json", "-o"], "report", ".html", "feederkit.cli.report:load_plan"),
        "lookalike": (
            ["lookalike", L_BRACKET, "--keep", "push", "-o"],
            "file",
            ".json",
            "feederkit.cli.lookalike:load_part_with_warnings",
        ),
        "part plot": (
            ["part", "plot", L_BRACKET, "-o"],
            "file",
            ".svg",
            "feederkit.cli.part_plot:load_part_with_warnings",
        ),
        "design sensor --plot": (
            ["design", "sensor", L_BRACKET, T_CLIP, "--plot"],
            "plot",
            ".svg",
            "feederkit.cli.design:load_landings",
        ),
    }


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.parametrize("command", list(output_cases(Path("unused"))))
def test_a_pipe_as_output_is_refused_before_any_work(tmp_path, capsys, monkeypatch, command):
    args, what, suffix, work = output_cases(tmp_path)[command]
    module, _, name = work.partition(":")
    monkeypatch.setattr(sys.modules[module], name, never)
    pipe = tmp_path / f"out{suffix}"
    os.mkfifo(pipe)
    err = one_line_error(capsys, [*args, str(pipe)])
    assert err == f"error: {late_message(pipe, what)}\n"


@pytest.mark.parametrize("kind", ["folder", "read-only", "missing folder"])
def test_plan_refuses_an_unwritable_output_before_planning(tmp_path, capsys, monkeypatch, kind):
    monkeypatch.setattr(sys.modules["feederkit.cli.plan"], "load_landings", never)
    out = tmp_path / "out.json"
    if kind == "folder":
        out.mkdir()
    elif kind == "missing folder":
        out = tmp_path / "no-such-folder" / "out.json"
    else:  # a read-only folder (root writes into a mode 555 one, so the system is faked)

        def read_only(*args, **kwargs):
            raise OSError(errno.EROFS, "Read-only file system")

        monkeypatch.setattr(tempfile, "mkstemp", read_only)
    err = one_line_error(capsys, ["plan", L_BRACKET, "-o", str(out)])
    if kind == "missing folder":  # the up-front check names the folder
        assert "the folder" in err and "does not exist" in err
    else:
        assert err == f"error: {late_message(out, 'plan file')}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == (["out.json"] if kind == "folder" else [])


def test_the_accept_refusal_advises_a_sensor_only_where_one_helps(tmp_path, capsys):
    """A sensor tells the bracket's sides apart; nothing tells the bracket's up side from its
    mirror image's down side (the same outline): the advice says which."""
    data = json_result(capsys, ["plan", L_BRACKET, "--accept", "up"])
    assert data["error"].endswith("accept both or neither, or use a sensor (--accept)")
    data = json_result(capsys, ["plan", L_BRACKET, "--accept", "up", "--tolerance", "40"])
    assert data["error"].endswith("or use a finer sensor (--accept)")  # 40 mm reads nothing
    bracket = json.loads(Path(L_BRACKET).read_text())
    mirror = {
        "name": "l-bracket-mirror",
        "units": bracket["units"],
        "vertices": [[-x, y] for x, y in reversed(bracket["vertices"])],
        "holes": [[[-x, y] for x, y in reversed(h)] for h in bracket["holes"]],
    }
    path = tmp_path / "mirror.json"
    path.write_text(json.dumps(mirror))
    args = ["plan", L_BRACKET, str(path), "--tolerance", "0.01", "--accept", "up"]
    data = json_result(capsys, [*args, "--rotation-error", "0"])
    assert "no sensor tells them apart" in data["error"] and "finer" not in data["error"]
