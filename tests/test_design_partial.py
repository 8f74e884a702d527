"""A sensor design without its length table (docs/design.md, "Time limit and progress").

With ``partial=True`` (the ``design sensor`` command), a limit that passes after every pair
is decided gives the pairs' table and says why the table is missing; under uncertainty the
mix's critical tolerance is then undecided (strong plans may fail below the pairs'), on the
ideal model it is the pairs'. A limit passed while deciding the pairs still stops the
design with one line: a pair cut short is never an answer.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from rich.console import Console
from test_design_time_limit import MIX, ONE_DEGREE, ellipse_mix, in_tmp  # noqa: F401

import feederkit.cli.common as cli_common
import feederkit.design.sensor as sensor_module
from feederkit.cli.app import main
from feederkit.design.limit import DesignTimeout
from feederkit.design.sensor import design_tolerance
from feederkit.loading import load_parts
from feederkit.planning.budget import Timeout
from feederkit.uncertainty import IDEAL

STEP_STAGES = {"strong": "strong_length_steps", "ideal": "length_steps"}


@pytest.fixture(scope="module")
def catalog_mix():
    return list(load_parts(MIX).push_functions)


def _stop_the_table(monkeypatch, name: str, reason: str = "time") -> None:
    """The length table's stage runs out of its limit as soon as it starts."""

    def stopped(*_args, **_kwargs):
        raise Timeout(reason)

    monkeypatch.setattr(sensor_module, name, stopped)


@pytest.mark.parametrize(
    ("uncertainty", "stage"), [(ONE_DEGREE, "strong"), (IDEAL, "ideal")], ids=["1deg", "ideal"]
)
def test_a_table_cut_short_gives_the_pairs_and_says_why(
    catalog_mix, uncertainty, stage, monkeypatch
):
    whole = design_tolerance(catalog_mix, uncertainty=uncertainty)
    assert whole.complete and whole.stopped is None and whole.steps
    _stop_the_table(monkeypatch, STEP_STAGES[stage])
    part = design_tolerance(catalog_mix, uncertainty=uncertainty, time_limit_s=60, partial=True)
    assert not part.complete and part.steps == ()
    assert part.critical == whole.critical  # every pair, exactly as the whole design's
    assert part.stopped.startswith("the sensor design did not finish within the time limit")
    assert part.stopped.endswith("the length table is left out")
    assert "all 3 pairs" in part.stopped
    x = whole.critical.critical_tolerance
    if uncertainty.is_ideal:  # the pairs' tolerance is the mix's (section 8.5)
        assert part.critical_tolerance == x and part.recognizable
        assert part.answer().startswith(f"this mix is recognizable with a tolerance up to {x:.6g}")
    else:  # strong plans may fail below it: undecided, bounded by the pairs'
        assert part.critical_tolerance is None and not part.recognizable
        assert f"every pair of this mix is told apart up to {x:.6g} mm" in part.answer()
        assert "was not decided" in part.answer()
    data = part.to_dict()
    assert data["complete"] is False and data["stopped"] == part.stopped
    assert data["lengths"] == [] and len(data["pairs"]) == 3
    assert whole.to_dict()["complete"] is True and whole.to_dict()["stopped"] is None


def test_without_partial_a_table_cut_short_still_raises(catalog_mix, monkeypatch):
    _stop_the_table(monkeypatch, "strong_length_steps")
    with pytest.raises(DesignTimeout, match="no partial design is given$"):
        design_tolerance(catalog_mix, uncertainty=ONE_DEGREE, time_limit_s=60)


def test_a_memory_limit_in_the_table_names_the_memory(catalog_mix, monkeypatch):
    _stop_the_table(monkeypatch, "strong_length_steps", "memory")
    part = design_tolerance(catalog_mix, uncertainty=ONE_DEGREE, memory_limit_mb=1e6, partial=True)
    assert part.stopped.startswith("the sensor design did not finish within the memory limit")


def test_a_limit_passed_while_deciding_pairs_gives_no_partial_design():
    pfs = ellipse_mix(12)  # 66 pairs: about a second of exact solves at 1 degree
    with pytest.raises(DesignTimeout, match=r" of 66 pairs\); no partial design is given$"):
        design_tolerance(pfs, uncertainty=ONE_DEGREE, time_limit_s=0.3, partial=True)


def test_the_command_prints_the_pairs_and_exits_1(capsys, in_tmp, monkeypatch):  # noqa: F811
    _stop_the_table(monkeypatch, "strong_length_steps")
    assert main(["design", "sensor", *MIX]) == 1
    out, err = capsys.readouterr()
    assert "critical tolerance of each pair" in out and "by tolerance" not in out
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("warning")]
    assert len(lines) == 1 and "Traceback" not in err
    assert lines[0].startswith("result: every pair of this mix is told apart up to ")
    assert lines[0].endswith("allow more with --time-limit S or --memory-limit MB")
    assert not list(Path(in_tmp).iterdir())


def test_the_command_json_says_the_design_is_partial(capsys, in_tmp, monkeypatch):  # noqa: F811
    monkeypatch.setattr(cli_common, "err_console", Console(stderr=True, width=200))
    _stop_the_table(monkeypatch, "strong_length_steps")
    assert main(["design", "sensor", *MIX, "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["complete"] is False and data["lengths"] == []
    # Three parts, two landings each: 15 pairs of landings (design.md, "Landings").
    assert data["critical_tolerance_mm"] is None and len(data["pairs"]) == 15
    assert data["stopped"].endswith("the length table is left out")


def test_the_plot_of_a_partial_design_says_the_table_is_missing(catalog_mix, monkeypatch, tmp_path):
    import matplotlib.pyplot as plt

    from feederkit.design import plot as plot_module

    _stop_the_table(monkeypatch, "strong_length_steps")
    part = design_tolerance(catalog_mix, uncertainty=ONE_DEGREE, time_limit_s=60, partial=True)
    fig, ax = plt.subplots()
    plot_module._tolerance(ax, part)
    words = [t.get_text() for t in ax.texts]
    plt.close(fig)
    assert words == ["the length table was not built within the limit"]
    out = plot_module.plot_design(part, tmp_path / "design.svg")
    assert Path(out).stat().st_size > 0
