"""Command-line defects found in review, each pinned through ``main`` (design.md, "Command
line": exit 0 success, 1 a result to act on, 2 bad input, 130 Ctrl-C; one line on stderr).
"""

from __future__ import annotations

import contextlib
import json
import signal
from pathlib import Path

import pytest
from shared import no_stray_profile, one_line_error  # noqa: F401 (autouse)

from feederkit.cell import CellProfile, resolve_settings
from feederkit.cli import run as run_cli
from feederkit.cli.app import _click_command, main
from feederkit.design.pitches import parse_pitches
from feederkit.errors import InputError

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
L_BRACKET = str(CATALOG / "l-bracket.json")
T_CLIP = str(CATALOG / "t-clip.json")


@pytest.fixture(autouse=True)
def python_sigint():
    """Ctrl-C reaches Python's handler, as in a terminal: a process started in the
    background by a shell without job control inherits SIGINT ignored, and main() then
    rightly leaves it ignored, so the Ctrl-C tests below would test nothing."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@pytest.fixture(scope="module")
def good_plan(tmp_path_factory) -> Path:
    """A verified plan of the l-bracket with an LED array (both landings, 3 operations)."""
    path = tmp_path_factory.mktemp("plans") / "lb.plan.json"
    args = ["plan", L_BRACKET, "--led-pitch", "0.5", "-o", str(path), "--time-limit", "30"]
    assert main(args) == 0
    return path


def edited(good: Path, folder: Path, edit) -> Path:
    """A copy of the plan file ``good`` in ``folder`` with ``edit`` applied to its JSON."""
    data = json.loads(good.read_text())
    edit(data)
    path = folder / "edited.plan.json"
    path.write_text(json.dumps(data))
    return path


def failing_plan(good: Path, folder: Path) -> Path:
    """The plan with one shared node's rotation set to 10 degrees: it fails verification."""

    def edit(data):
        first = next(iter(data["nodes"]))
        data["nodes"][first]["action_deg"] = 10.0

    return edited(good, folder, edit)


# 1. ``report`` on a plan that fails verification: the page is written, the exit is 1.


def test_report_of_a_failing_plan_writes_the_page_and_exits_1(good_plan, tmp_path, capsys):
    bad = failing_plan(good_plan, tmp_path)
    page = tmp_path / "bad.html"
    err = one_line_error(capsys, ["report", str(bad), "-o", str(page)], code=1)
    assert err.startswith("result: the plan failed verification: ")
    assert str(page) in err and "do not run" in err
    assert 'data-ok="false"' in page.read_text(encoding="utf-8")  # the red banner is drawn
    # run says the same plan failed: the two agree on the exit code
    assert main(["run", str(bad)]) == 1
    capsys.readouterr()


def test_report_of_a_verified_plan_exits_0(good_plan, tmp_path, capsys):
    page = tmp_path / "ok.html"
    assert main(["report", str(good_plan), "-o", str(page)]) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and f"wrote the report to {page}" in captured.out
    assert 'id="verification"' not in page.read_text(encoding="utf-8")


# 2. A report file must end in .html everywhere, refused before any work.


def test_changeover_compile_refuses_a_report_not_named_html(tmp_path, capsys):
    missing = tmp_path / "no-such.db"  # refused before the catalog is even looked at
    args = ["changeover", "compile", "mx", "--mix", "l-bracket,t-clip", "--tolerance", "0.2"]
    err = one_line_error(
        capsys, [*args, "--report", str(tmp_path / "x.txt"), "--catalog", str(missing)]
    )
    assert "x.txt: the report is an HTML page: name it .html" in err
    assert not (tmp_path / "x.txt").exists()


def test_changeover_report_refuses_an_output_not_named_html(tmp_path, capsys):
    missing = tmp_path / "no-such.db"
    args = ["changeover", "report", "mx", "-o", str(tmp_path / "y.txt"), "--catalog", str(missing)]
    err = one_line_error(capsys, args)
    assert "y.txt: the report is an HTML page: name it .html" in err
    assert not (tmp_path / "y.txt").exists()


def test_plan_refuses_a_report_not_named_html_before_planning(tmp_path, capsys):
    err = one_line_error(capsys, ["plan", L_BRACKET, "--report", str(tmp_path / "z.pdf")])
    assert "z.pdf: the report is an HTML page" in err
    assert not (tmp_path / "z.pdf").exists()


def test_changeover_report_writes_html(tmp_path, capsys):
    db = tmp_path / "c.db"
    assert main(["catalog", "init", "--catalog", str(db)]) == 0
    for source in (L_BRACKET, T_CLIP):
        assert main(["catalog", "add", source, "--catalog", str(db)]) == 0
    args = ["changeover", "compile", "mx", "--mix", "l-bracket,t-clip", "--tolerance", "0.2"]
    assert main([*args, "--catalog", str(db), "--time-limit", "30"]) == 0
    page = tmp_path / "mx.html"
    assert main(["changeover", "report", "mx", "-o", str(page), "--catalog", str(db)]) == 0
    assert page.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    capsys.readouterr()


# 3. Ctrl-C is "interrupted" and 130 however it surfaces, never "a bug in feederkit".


def make_run_raise(monkeypatch, boom) -> list[str]:
    """``feederkit run`` calling ``boom`` where it loads the plan; the args to run it."""
    monkeypatch.setattr(run_cli, "load_plan", lambda *args, **kwargs: boom())
    return ["run", "any.plan.json"]


def interrupted(capsys, args: list[str]) -> None:
    before = signal.getsignal(signal.SIGINT)
    assert main(args) == 130
    err = capsys.readouterr().err
    assert err == "error: interrupted\n", err
    assert signal.getsignal(signal.SIGINT) is before  # the handler main set is gone again


def test_ctrl_c_in_a_command_is_interrupted(capsys, monkeypatch):
    def boom():
        raise KeyboardInterrupt

    interrupted(capsys, make_run_raise(monkeypatch, boom))


def test_an_error_while_handling_ctrl_c_is_interrupted_not_a_bug(capsys, monkeypatch):
    def boom():
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise TypeError("cleanup failed") from None  # __context__ still holds it

    interrupted(capsys, make_run_raise(monkeypatch, boom))


def test_an_error_after_a_swallowed_ctrl_c_is_interrupted_not_a_bug(capsys, monkeypatch):
    """trimesh imports its optional parts in ``try: ... except BaseException`` and keeps the
    exception in an ``ExceptionWrapper``: a Ctrl-C there surfaces as an unrelated TypeError
    (``'ExceptionWrapper' | None``), with no KeyboardInterrupt in its chain."""

    def boom():
        with contextlib.suppress(BaseException):  # what trimesh does
            signal.raise_signal(signal.SIGINT)  # a real Ctrl-C, through the SIGINT handler
        raise TypeError("unsupported operand type(s) for |: 'ExceptionWrapper' and 'NoneType'")

    interrupted(capsys, make_run_raise(monkeypatch, boom))


def test_a_command_that_goes_on_after_a_swallowed_ctrl_c_is_interrupted(
    good_plan, capsys, monkeypatch
):
    real = run_cli.load_plan

    def load(*args, **kwargs):
        with contextlib.suppress(BaseException):  # swallowed by a library
            signal.raise_signal(signal.SIGINT)
        return real(*args, **kwargs)

    monkeypatch.setattr(run_cli, "load_plan", load)
    assert main(["run", str(good_plan)]) == 130
    assert capsys.readouterr().err.splitlines()[-1] == "error: interrupted"


def test_a_bug_without_ctrl_c_is_still_a_bug(capsys, monkeypatch):
    def boom():
        raise TypeError("a real bug")

    assert main(make_run_raise(monkeypatch, boom)) == 70
    err = capsys.readouterr().err
    assert "this is a bug in feederkit (TypeError: a real bug)" in err
    Path(err.split("details in ")[1].split()[0]).unlink()


# 4. ``run``'s wording. The lines come from the library (feederkit/plans/match.py, strong.py,
# readplan.py); the command line passes them through.


def test_a_part_not_in_the_plan_names_the_plans_parts_plainly(good_plan, capsys):
    err = one_line_error(capsys, ["run", str(good_plan), T_CLIP])
    assert err.rstrip().endswith("is not one of the plan's parts (l-bracket)")


def test_no_branch_after_the_first_alignment_is_said_so(good_plan, tmp_path, capsys):
    def edit(data):  # no root branch holds any reading the part gives
        for k, branch in enumerate(data["root"]["branches"]):
            branch["reading"] = [10.0 + 2 * k, 11.0 + 2 * k]

    plan = edited(good_plan, tmp_path, edit)
    from feederkit.cli.app import main

    assert main(["run", str(plan), "--all"]) == 1
    *warnings, err = capsys.readouterr().err.strip().splitlines()  # the result line last
    assert all(w.startswith("warning: ") for w in warnings)
    assert "no branch after the first alignment holds" in err
    assert "None" not in err


def test_a_plan_over_a_tiny_size_limit_gives_both_sizes(good_plan, capsys):
    err = one_line_error(capsys, ["run", str(good_plan), "--max-plan-mb", "0.001"])
    assert "more than the limit of 0.001 MB" in err
    assert "0.0 MB" not in err


# 5. ``--pitches START:STOP:STEP`` with START above STOP is an empty range, not a zero pitch.


def test_a_range_that_starts_above_its_stop_is_said_empty():
    with pytest.raises(
        InputError,
        match=r"the range '1:0:0\.5' is empty, it ends before it starts: START 1 is above STOP 0",
    ):
        parse_pitches("1:0:0.5")


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("0:1:0.5", "a pitch must be a positive number of mm, got 0"),
        ("0.5:1:0", "needs a positive STEP of mm, got 0"),
        ("0.5:1:-0.1", "needs a positive STEP of mm, got -0.1"),
        ("0.5:nan:0.1", "a finite number of mm, got nan"),
    ],
)
def test_other_bad_ranges_say_what_is_wrong(text, said):
    with pytest.raises(InputError, match=said):
        parse_pitches(text)


def test_ranges_still_include_their_stop():
    assert parse_pitches("0.5:1:0.25,2") == (0.5, 0.75, 1.0, 2.0)
    assert parse_pitches("0.5:0.5:0.1") == (0.5,)


def test_design_sensor_says_the_range_is_empty(capsys):
    err = one_line_error(capsys, ["design", "sensor", L_BRACKET, "--pitches", "1:0:0.5"])
    assert "is empty, it ends before it starts: START 1 is above STOP 0" in err
    assert "positive" not in err


# 6. The overrides name the options that replaced a profile field (docs/cell.md); the profile
# has no shape or COM tolerance, so those two are in the uncertainty line, not the overrides.


def test_overrides_are_profile_fields_and_the_uncertainty_line_has_the_rest():
    settings = resolve_settings(CellProfile(), tolerance=0.2, rotation_error=0.5)
    assert settings.overrides == ("--tolerance", "--rotation-error")


def test_plan_prints_the_shape_tolerance_it_was_given(capsys):
    args = ["plan", L_BRACKET, "--tolerance", "0.2", "--rotation-error", "0.5"]
    args += ["--shape-tolerance", "0.02", "--com-tolerance", "0.01", "--time-limit", "30"]
    assert main(args) in (0, 1)  # 1: landings no plan tells apart, a result, not an error
    out = " ".join(capsys.readouterr().out.split())  # the terminal wraps long lines
    assert "cell profile: built-in defaults (overridden: --tolerance, --rotation-error)" in out
    assert "shape tolerance 0.02 mm, COM tolerance 0.01 mm" in out


# 8. ``--sensorless``'s help says what the default is where a cell profile gives the sensor.


def option_help(*path: str, name: str = "sensorless") -> str:
    command = _click_command()
    for word in path:
        command = command.commands[word]  # type: ignore[attr-defined]
    (param,) = [p for p in command.params if p.name == name]
    return param.help


def test_sensorless_help_names_the_profile_where_one_is_read():
    assert "the profile's sensor" in option_help("changeover", "compile")
    assert "default when no sensor option" in option_help("catalog", "analyze")  # no profile


def test_plan_sensorless_help_names_the_profile():
    assert "the profile's sensor" in option_help("plan")


def test_an_ignored_ctrl_c_stays_ignored(capsys, monkeypatch):
    # nohup, or a background job of a shell without job control: SIGINT is ignored, and a
    # command must not start taking it (nor leave a handler of its own behind).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    seen = []

    def boom():
        seen.append(signal.getsignal(signal.SIGINT))
        raise TypeError("a real bug")

    assert main(make_run_raise(monkeypatch, boom)) == 70
    assert seen == [signal.SIG_IGN]
    assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    capsys.readouterr()


def test_plan_and_report_may_not_be_one_file(tmp_path, capsys):
    """``-o`` and ``--report`` naming one file (or a link to it): refused before any work, the
    existing file untouched (the report would overwrite the plan)."""
    same = tmp_path / "same.html"
    same.write_text("keep")
    err = one_line_error(capsys, ["plan", T_CLIP, "-o", str(same), "--report", str(same)])
    assert "would be the same file" in err and same.read_text() == "keep"
    link = tmp_path / "link.json"
    link.symlink_to(same)
    err = one_line_error(capsys, ["plan", T_CLIP, "-o", str(link), "--report", str(same)])
    assert "would be the same file" in err and same.read_text() == "keep"


def test_the_search_spinner_keeps_its_clock_on_a_narrow_terminal(monkeypatch):
    """At 80 columns a long changeover name is cut, not the spinner and the elapsed time."""
    import io

    from rich.console import Console

    import feederkit.cli.common as common

    out = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(width=80, force_terminal=True, file=out))
    with common.searching("compiling changeover line3-week48-and-a-long-name", 60.0):
        pass
    frame = out.getvalue().split("\r")[1]
    assert "0:00:00" in frame and "…" in frame and "compiling changeover" in frame


def test_ctrl_c_inside_a_finalizer_prints_no_traceback_and_other_errors_still_do():
    """A Ctrl-C inside a weak reference's callback while the results print was "Exception
    ignored in: <function WeakSet...> Traceback ... KeyboardInterrupt" (a new user's review)."""
    import types

    from feederkit.cli.app import _quiet_interrupts

    seen = []
    hook = _quiet_interrupts(seen.append)

    def unraisable(exc: BaseException) -> types.SimpleNamespace:
        return types.SimpleNamespace(exc_value=exc, exc_type=type(exc), object=None)

    assert hook(unraisable(KeyboardInterrupt())) is None and seen == []
    other = unraisable(ValueError("a real one"))
    hook(other)
    assert seen == [other]


def test_ctrl_c_while_the_modules_load_is_interrupted_even_as_an_import_error(capsys, monkeypatch):
    """A C extension interrupted in its initialisation fails with ImportError ("initialization
    failed", scipy): after a SIGINT that is the interrupt's, one line and 130, no traceback."""
    import feederkit.cli.app as app_module

    monkeypatch.setattr(app_module, "_loading_interrupted", True)
    with pytest.raises(SystemExit) as info:
        app_module._loading_failed(ImportError("initialization failed"))
    assert info.value.code == 130 and capsys.readouterr().err == "error: interrupted\n"
    monkeypatch.setattr(app_module, "_loading_interrupted", False)
    app_module._loading_failed(ImportError("no module named scipy"))  # not ours: goes on up
    with pytest.raises(SystemExit):
        app_module._loading_failed(KeyboardInterrupt())
    assert signal.getsignal(signal.SIGINT) is not app_module._note_loading_interrupt  # loaded


def test_a_real_import_failure_while_loading_puts_the_sigint_handler_back(monkeypatch):
    # The loading handler notes a Ctrl-C for the interrupt's ImportError; a real failure goes
    # on up with the handler the process had, so whoever catches it keeps a plain Ctrl-C.
    import feederkit.cli.app as app_module

    before = signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(app_module, "_loading_interrupted", False)
    monkeypatch.setattr(app_module, "_previous_sigint", before)
    try:
        signal.signal(signal.SIGINT, app_module._note_loading_interrupt)
        app_module._loading_failed(ImportError("no module named scipy"))
        assert signal.getsignal(signal.SIGINT) is before
    finally:
        signal.signal(signal.SIGINT, before)


def test_once_the_command_answered_a_late_ctrl_c_changes_nothing(monkeypatch):
    """SIGINT is ignored while Python exits after the answer (a new user's review: a finished
    compile, its files written, ended 130 with no word when Ctrl-C came at the very end)."""
    import sys

    import feederkit.cli.app as app_module

    monkeypatch.setattr(app_module, "main", lambda **_: 0)
    monkeypatch.setattr(app_module, "end_quietly_on_closed_pipe", lambda: None)
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)
    before = signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(SystemExit) as info:
            app_module.run()
        assert info.value.code == 0
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_plan_that_fails_says_its_certificate_is_only_claimed(good_plan, tmp_path, capsys):
    # A strong plan's failing path is a problem with no counts per part: ``--json`` had
    # "failures": [] and "parts": [] beside "ok": false, and the text printed the
    # certificate as if it held.
    def edit(data):
        for k, branch in enumerate(data["root"]["branches"]):
            branch["reading"] = [10.0 + 2 * k, 11.0 + 2 * k]

    plan = edited(good_plan, tmp_path, edit)
    from feederkit.cli.app import main

    assert main(["run", str(plan), "--all", "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] is False
    assert "no branch after the first alignment" in report["first_problem"]
    assert main(["run", str(plan), "--all"]) == 1
    out = capsys.readouterr().out
    assert "certificate claimed (the plan failed verification):" in out
    assert main(["run", str(good_plan), "--all", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["first_problem"] is None
    assert main(["run", str(good_plan), "--all"]) == 0
    assert "\ncertificate: " in "\n" + capsys.readouterr().out
