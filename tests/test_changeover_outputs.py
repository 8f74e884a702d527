"""Several output files as one effect (``feederkit.outputs``), and library terms shown with the
command line's flags (``feederkit.cli.common.with_flags``)."""

from __future__ import annotations

import pytest

from feederkit.cli.common import flag_words, with_flags
from feederkit.errors import InputError, PlanningError
from feederkit.jsonio import OutputFile, StagedFiles, write_files


def test_all_files_are_written(tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.html"
    write_files([OutputFile(a, "{}\n"), OutputFile(b, "<p>é</p>")])
    assert a.read_text() == "{}\n" and b.read_text(encoding="utf-8") == "<p>é</p>"


def test_none_is_written_when_one_cannot_be(tmp_path):
    a = tmp_path / "a.json"
    a.write_text("old")
    with pytest.raises(InputError, match=r"r\.html: cannot write the report"):
        write_files([OutputFile(a, "new"), OutputFile(tmp_path / "x" / "r.html", "", "report")])
    assert a.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]
    with pytest.raises(InputError, match="cannot write the plan file .a folder is there."):
        write_files([OutputFile(a, "new"), OutputFile(tmp_path, "", "plan file")])
    assert a.read_text() == "old"


def test_staged_files_are_discarded_without_a_commit_and_undone_after_one(tmp_path):
    a = tmp_path / "a.json"
    with StagedFiles([OutputFile(a, "x")]) as staged:
        assert staged.paths == [a] and not a.exists()
    assert list(tmp_path.iterdir()) == []
    staged = StagedFiles([OutputFile(a, "x")])
    staged.commit()
    assert a.read_text() == "x"
    staged.undo()
    assert not a.exists()


def test_library_terms_are_followed_by_their_flags():
    msg = "the minimum margin must be in [0, 180) degrees, got 180"
    assert with_flags(msg) == msg + " (--min-margin)"
    assert with_flags("--tolerance must be positive") == "--tolerance must be positive"
    assert with_flags("nothing to map") == "nothing to map"
    with pytest.raises(PlanningError) as err, flag_words():
        raise PlanningError("no plan found within the time limit of 1 s")
    assert str(err.value).endswith("(--time-limit)") and err.value.exit_code == 1
