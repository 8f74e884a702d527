"""Atomic writes: whole files or none, readable like any file the user writes, one-line errors."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from feederkit.errors import InputError
from feederkit.jsonio import read_json, write_text_atomic


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
