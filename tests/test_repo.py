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


def _declared_requirements() -> set[str]:
    """Every distribution pyproject.toml asks for (dependencies and extras), lower-cased."""
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    names = set()
    for m in re.finditer(r'"([A-Za-z0-9_.\-]+)\s*[<>=!~]=?[0-9]', text):
        names.add(m.group(1).lower().replace("_", "-"))
    return names - {"setuptools", "wheel"}


def _locked() -> dict[str, str]:
    out = {}
    for line in (ROOT / "requirements.lock").read_text(encoding="utf-8").splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            name, _, version = line.partition("==")
            assert version, f"requirements.lock: {line!r} is not pinned with =="
            out[name.lower().replace("_", "-")] = version
    return out


def test_the_readme_commands_install_the_locked_versions() -> None:
    for cmd in _readme_commands()[:2]:
        assert "-c requirements.lock" in cmd


def test_every_declared_dependency_is_locked() -> None:
    declared = _declared_requirements()
    assert {"numpy", "shapely", "trimesh", "mujoco", "pytest"} <= declared
    missing = declared - set(_locked())
    assert not missing, f"pin these in requirements.lock: {sorted(missing)}"


def test_ci_runs_the_slow_checks_as_a_second_step() -> None:
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert ".venv/bin/python -m pytest -m slow" in ci
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert "-m 'not slow'" in text
