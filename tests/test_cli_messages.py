"""Errors are one clean line: no doubled words from the JSON parser, no blank line first."""

from __future__ import annotations

import pytest

from feederkit.errors import InputError
from feederkit.jsonio import read_json


def test_a_truncated_json_file_is_named_without_a_doubled_word(tmp_path) -> None:
    path = tmp_path / "trunc.json"
    path.write_text('{"format": "feederkit-plan",\n "x": "abc')
    with pytest.raises(InputError) as exc:
        read_json(path, "plan file")
    assert "at at" not in str(exc.value) and "line 2" in str(exc.value)


def test_simulate_errors_start_on_the_first_line(tmp_path, capfd) -> None:
    pytest.importorskip("mujoco")
    from pathlib import Path

    from feederkit.cli.app import main

    plan = Path(__file__).resolve().parent / "golden" / "t-clip.tolerance.json"
    assert main(["simulate", str(plan), "--trials", "0"]) == 2
    err = capfd.readouterr().err
    assert err.startswith("error:") and len(err.strip().splitlines()) == 1


def test_a_sensor_finer_than_rounding_is_bad_input(capsys) -> None:
    from pathlib import Path

    from feederkit.cli.app import main

    part = Path(__file__).resolve().parents[1] / "catalog" / "rectangle-2x1.json"
    assert main(["plan", str(part), "--tolerance", "1e-300"]) == 2
    err = capsys.readouterr().err
    assert "resolution" in err and "root has no branches" not in err
    assert len(err.strip().splitlines()) == 1


def test_lookalike_prints_its_check_as_json(tmp_path, capsys) -> None:
    import json
    from pathlib import Path

    from feederkit.cli.app import main

    part = Path(__file__).resolve().parents[1] / "catalog" / "l-bracket.json"
    out = tmp_path / "twin.json"
    assert main(["lookalike", str(part), "--keep", "push", "-o", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["same_push"] is True and d["similar"] is False
    assert json.loads(out.read_text())["vertices"] == d["outline"]["vertices"]
