"""Outputs that must not harm what is there: a Ctrl-C while an output is staged or its folder
probed leaves no temporary beside it (docs: an interrupted write leaves the old file or none;
a review found empty hidden ``.NAME.tmp`` files after interrupts 3-25 ms into staging), and
``plan`` does not write its plan over a SOURCE it read."""

from __future__ import annotations

import os

import pytest

import feederkit.jsonio as jsonio
from feederkit.jsonio import OutputFile, check_writable, write_files


def test_an_interrupt_while_a_plan_is_encoded_leaves_no_temporary(tmp_path, monkeypatch):
    def interrupted(f):
        raise KeyboardInterrupt

    monkeypatch.setattr(jsonio, "_bytes", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_files([OutputFile(tmp_path / "plan.json", "{}", "plan file")])
    assert os.listdir(tmp_path) == []


def test_an_interrupt_while_a_folder_is_probed_leaves_no_probe(tmp_path, monkeypatch):
    real_close = os.close

    def interrupted(fd):
        real_close(fd)
        raise KeyboardInterrupt

    monkeypatch.setattr(jsonio.os, "close", interrupted)
    with pytest.raises(KeyboardInterrupt):
        check_writable(tmp_path / "plan.json", "plan file")
    monkeypatch.undo()
    assert os.listdir(tmp_path) == []


def test_plan_refuses_an_output_over_its_source(tmp_path, capsys):
    """``plan part.json -o part.json`` wrote the plan over the part's outline."""
    from pathlib import Path

    from shared import one_line_error

    source = tmp_path / "t-clip.json"
    catalog = Path(__file__).resolve().parents[1] / "catalog"
    source.write_text((catalog / "t-clip.json").read_text())
    before = source.read_text()
    err = one_line_error(capsys, ["plan", str(source), "-o", str(source)])
    assert "would be written over the SOURCE" in err
    assert source.read_text() == before
