"""Every command's help renders at 80 columns: paragraphs rewrapped, code without reST marks."""

from __future__ import annotations

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
