"""The README's two commands and CI agree: CI runs the README's test command verbatim."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return [m.group(1).strip() for m in re.finditer(r"^    (python3 -m venv .+)$", text, re.M)]


def test_readme_opens_with_the_two_commands() -> None:
    cmds = _readme_commands()
    assert len(cmds) >= 2
    assert cmds[0].endswith("feederkit demo")
    assert "pytest" in cmds[1] and "[test" in cmds[1]


def test_ci_runs_the_readme_test_command_verbatim() -> None:
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    test_cmd = _readme_commands()[1]
    ci_lines = [line.strip() for line in ci.splitlines()]
    assert test_cmd in ci_lines
    assert any(line.startswith(".venv/bin/ruff check") for line in ci_lines)


def test_pyproject_declares_the_console_script_and_extras() -> None:
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert 'feederkit = "feederkit.cli.app:run"' in text
    assert re.search(r"^test = \[", text, re.M)
    assert re.search(r"^sim = \[", text, re.M)
