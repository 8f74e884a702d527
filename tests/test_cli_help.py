"""Every command's help renders at 80 columns: paragraphs rewrapped, code without reST marks."""

from __future__ import annotations

import re

import pytest
from typer.testing import CliRunner

from feederkit.cli.app import app

COMMANDS = [
    [],
    ["demo"],
    ["plan"],
    ["run"],
    ["report"],
    ["simulate"],
    ["lookalike"],
    ["part", "analyze"],
    ["part", "plot"],
    ["catalog"],
    ["catalog", "add"],
    ["catalog", "import"],
    ["catalog", "analyze"],
    ["changeover", "compile"],
    ["changeover", "report"],
    ["design", "sensor"],
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c) or "feederkit")
def test_help_reads_well_at_80_columns(command: list[str]) -> None:
    result = CliRunner().invoke(app, [*command, "--help"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    text = result.output
    assert "``" not in text
    assert max(len(line) for line in text.splitlines()) <= 80
    # No paragraph line broken after a word or two: the docstrings' own line breaks are gone.
    body = [
        ln.strip() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("│")
    ]
    short = [ln for ln in body[:-1] if len(ln) < 20 and not ln.endswith((".", ":", ")"))]
    assert len(short) <= 2, short


def _all_commands() -> list[list[str]]:
    """Every command and group of the app, as argument lists (``[]`` is ``feederkit``)."""
    import typer

    found: list[list[str]] = []

    def walk(cmd, path: list[str]) -> None:
        found.append(path)
        for name, sub in sorted(getattr(cmd, "commands", {}).items()):
            walk(sub, [*path, name])

    walk(typer.main.get_command(app), [])
    return found


ALL_COMMANDS = _all_commands()


@pytest.mark.parametrize("command", ALL_COMMANDS, ids=lambda c: " ".join(c) or "feederkit")
def test_help_names_values_as_click_does(command: list[str]) -> None:
    """No Python types (``<bool>``, ``<list[str]>``, ``<float,float>``), no typer range notes
    (``[x>=1]``), no float reprs (``[default: 0.0]``), arguments in capitals."""
    result = CliRunner().invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    text = result.output
    assert not re.search(r"<(bool|str|int|float|path|list|int range|float range)\b", text), text
    assert "[x>=" not in text and "<=x" not in text, text
    assert not re.search(r"\[default: -?\d+\.0\]", text), text
    usage = next(line for line in text.splitlines() if "Usage:" in line)
    assert not re.search(r"[{\[][a-z_]+[}\]]", usage), usage
    assert "--help" in text and "Show this message and exit." in text


def test_every_option_has_help_and_a_value_name() -> None:
    import typer

    def walk(cmd, path: str) -> list[str]:
        missing = []
        for p in getattr(cmd, "params", []):
            if not (p.help or "").strip():
                missing.append(f"{path} {p.name}: no help")
        for name, sub in getattr(cmd, "commands", {}).items():
            missing += walk(sub, f"{path} {name}")
        return missing

    assert walk(typer.main.get_command(app), "feederkit") == []


def test_a_flag_shows_no_value_and_an_option_its_metavar() -> None:
    result = CliRunner().invoke(app, ["plan", "--help"], env={"COLUMNS": "200"})
    rows = {line.split()[1]: line for line in result.output.splitlines() if line.startswith("│ --")}
    assert rows["--json"].split()[2] == "Print", rows["--json"]
    assert rows["--tolerance"].split()[2] == "MM"
    assert rows["--max-entities"].split()[2] == "N"
    assert "[default: 60]" in result.output  # --time-limit, not 60.0
