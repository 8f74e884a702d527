"""The README's working session runs as written, in order, on a fresh folder holding the
bundled catalog (a new user's review found its changeover step refused: the catalog step
before it had stored a shape tolerance the mix then declared)."""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest

from feederkit.cli.app import main

ROOT = Path(__file__).resolve().parents[1]

ACTED_ON = {"catalog analyze": 1}
"""Commands of the session whose answer is a result to act on (exit 1, README): the bundled
catalog has parts no plan tells apart with its sensor."""


def session() -> list[str]:
    """The session's commands, continuation lines joined and comments dropped."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## A working session", 1)[1].split("\n\n", 2)[1]
    out, pending = [], ""
    for raw in block.splitlines():
        if not raw.startswith("    "):
            break
        line = (pending + " " + raw.strip()) if pending else raw[4:]
        pending = ""
        if line.lstrip().startswith("#"):
            continue
        line = re.sub(r"\s{2,}#.*$", "", line).rstrip()
        if line.endswith("\\"):
            pending = line[:-1].rstrip()
        elif line.strip():
            out.append(line.strip())
    return out


def test_the_session_is_parsed_as_the_reader_sees_it():
    commands = session()
    assert commands[0] == "feederkit catalog init" and len(commands) >= 10
    assert all(c.startswith("feederkit ") for c in commands)
    compile_ = next(c for c in commands if c.startswith("feederkit changeover compile"))
    assert compile_.endswith("--report line3.html")  # the continuation line joined


@pytest.mark.slow
def test_the_readmes_working_session_runs_in_order(tmp_path, monkeypatch, capsys):
    pytest.importorskip("mujoco")  # the session simulates
    shutil.copytree(ROOT / "catalog", tmp_path / "catalog")
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    for command in session():
        args = shlex.split(command)[1:]
        code = main(args)
        err = capsys.readouterr().err
        expected = next((c for k, c in ACTED_ON.items() if command.startswith(f"feederkit {k}")), 0)
        assert code == expected, f"{command}: {err}"
        for flag in ("-o", "--report"):
            if flag in args:
                assert (tmp_path / args[args.index(flag) + 1]).is_file(), command
