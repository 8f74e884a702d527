"""The shared import options (feederkit/cli/importopts.py, docs/import.md): one set on every
command that reads a SOURCE, turned into one :class:`ImportOptions` by one function."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import typer
from typer.testing import CliRunner

from feederkit.cli.app import app, main
from feederkit.cli.importopts import (
    IMPORT_PARAMETERS,
    import_options,
    takes_import_options,
    with_com,
)
from feederkit.importers import ImportOptions
from feederkit.importers.budget import ImportLimits

SOURCE_COMMANDS = (
    ("part", "analyze"),
    ("part", "plot"),
    ("lookalike",),
    ("catalog", "add"),
    ("catalog", "import"),
)
NAMES = [p.name for p in IMPORT_PARAMETERS]


def _command(path: tuple[str, ...]) -> Any:
    cmd = typer.main.get_command(app)
    for name in path:
        cmd = cmd.commands[name]
    return cmd


def _option_view(param: Any) -> tuple:
    return (tuple(param.opts), param.default, getattr(param, "help", None), param.multiple)


def test_every_source_command_takes_the_same_import_options():
    views = {}
    for path in SOURCE_COMMANDS:
        params = {p.name: p for p in _command(path).params}
        missing = [n for n in NAMES if n not in params]
        assert not missing, (path, missing)
        views[path] = [_option_view(params[n]) for n in NAMES]
    first = views[SOURCE_COMMANDS[0]]
    for path, view in views.items():
        assert view == first, path


def _recording_app(seen: list) -> typer.Typer:
    sub = typer.Typer()

    @sub.command("go")
    @takes_import_options
    def go(
        source: str,
        import_opts: ImportOptions = ImportOptions(),
        com: tuple[float, float] | None = typer.Option(None, "--com"),
        tag: str = typer.Option("x", "--tag"),
    ) -> None:
        seen.append((source, with_com(import_opts, com), tag))

    @sub.command("other")
    def other() -> None:  # a second command keeps "go" a subcommand
        pass

    return sub


def test_the_options_become_one_import_options_with_the_library_defaults():
    seen: list = []
    runner = CliRunner()
    assert runner.invoke(_recording_app(seen), ["go", "a.dxf"]).exit_code == 0
    assert seen == [("a.dxf", ImportOptions(), "x")]
    args = ["go", "b.dxf", "--units", "in", "--layer", "A", "--layer", "B", "--space", "paper"]
    args += ["--pose", "1", "--all-parts", "--max-loops", "7", "--import-time-limit", "2.5"]
    args += ["--com", "1", "2", "--tag", "y", "--hull-tolerance", "0.1", "--allow-large"]
    result = runner.invoke(_recording_app(seen), args)
    assert result.exit_code == 0, result.output
    source, opts, tag = seen[-1]
    assert (source, tag) == ("b.dxf", "y")
    assert opts == ImportOptions(
        units="in",
        layers=("A", "B"),
        space="paper",
        pose=1,
        all_parts=True,
        hull_tolerance=0.1,
        allow_large=True,
        com=(1.0, 2.0),
        limits=ImportLimits(loops=7, seconds=2.5),
    )


def test_a_decorated_command_is_still_callable_from_python():
    seen: list = []

    @takes_import_options
    def cmd(source: str, import_opts: ImportOptions = ImportOptions(), flag: bool = False) -> None:
        seen.append((source, import_opts, flag))

    cmd("p.json", units="cm", flag=True)
    assert seen == [("p.json", import_options(units="cm"), True)]
    with pytest.raises(TypeError):
        cmd("p.json", import_opts=ImportOptions())  # the options are given one by one
    assert cmd.__doc__ is None and cmd.__name__ == "cmd"


def test_a_command_without_the_parameter_or_with_a_clash_is_a_programming_error():
    def plain(source: str) -> None: ...

    def clash(source: str, units: str = "", import_opts: ImportOptions = ImportOptions()): ...

    with pytest.raises(TypeError, match="import_opts"):
        takes_import_options(plain)
    with pytest.raises(TypeError, match="units"):
        takes_import_options(clash)


def test_with_com_sets_only_the_center_of_mass():
    opts = ImportOptions(units="mm")
    assert with_com(opts, None) is opts
    assert with_com(opts, (1, 2)) == ImportOptions(units="mm", com=(1.0, 2.0))


def test_a_bad_shared_option_is_one_line_and_exit_2_on_each_command(tmp_path, capsys):
    src = tmp_path / "rect.json"
    src.write_text(json.dumps({"name": "rect", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]}))
    db = str(tmp_path / "c.db")
    for args in (
        ["part", "analyze", str(src)],
        ["lookalike", str(src), "--keep", "push"],
        ["catalog", "add", str(src), "--catalog", db],
        ["catalog", "import", str(tmp_path), "--catalog", db],
    ):
        assert main([*args, "--space", "sheet"]) == 2, args
        err = capsys.readouterr().err.strip()
        assert err == "error: --space must be model or paper, got 'sheet'", (args, err)
    assert not Path(db).exists()
