"""What ``feederkit simulate`` claims about a run (docs/simulation.md).

A success rate comes with its 95 % Wilson interval; the sampled uncertainty is the one
actually drawn; conflicting options are refused; the plan's certificate is named and a
stress test beyond it says failures are expected; a sensor finer than the simulated widths
are accurate is named, since its "reading in no branch" failures measure the simulator.
The pure pieces run without MuJoCo; the command-line checks use two or three trials.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import pytest
from simsummaries import sim_summary

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.plans.fileformat import plan_json
from feederkit.plans.make import make_plan
from feederkit.plans.model import Certificate
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.sim.api import check_rotation_noise
from feederkit.sim.summary import (
    WIDTH_ACCURACY_MM,
    Certified,
    SimSettings,
    beyond_certified_note,
    certified_bounds,
    push_words,
    sensor_width_slack,
    success_words,
    width_accuracy_warning,
    wilson,
)
from feederkit.sim.trial import CAUSES
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL, Uncertainty

ROOT = Path(__file__).resolve().parents[1]


# ---------------------------------------------------------------- the interval


def test_wilson_interval_of_known_counts() -> None:
    lo, hi = wilson(40, 40)
    assert lo == pytest.approx(40 / (40 + 1.959964**2)) and hi == 1.0  # k = n: n / (n + z^2)
    assert wilson(0, 20)[0] == 0.0 and wilson(0, 20)[1] == pytest.approx(0.1611, abs=1e-4)
    assert wilson(200, 200)[0] == pytest.approx(0.981, abs=5e-4)  # the docs' 98.1 %
    with pytest.raises(ValueError):
        wilson(3, 0)


def test_the_benchmark_uses_the_librarys_wilson() -> None:
    text = (ROOT / "benchmarks" / "bench_sim_uncertainty.py").read_text(encoding="utf-8")
    assert "from feederkit.sim.summary import wilson" in text and "def wilson" not in text


def test_success_words_name_the_wilson_interval_rounded_outward() -> None:
    assert success_words(40, 40) == "40 of 40 (100.0 %; 95 % Wilson interval 91.2-100 %)"
    assert success_words(0, 10) == "0 of 10 (0.0 %; 95 % Wilson interval 0-27.8 %)"


def test_the_summary_json_carries_the_interval_and_its_method() -> None:
    d = sim_summary({"part": (40, 40)}).to_dict()
    lo, hi = d["success_interval_95"]
    assert lo == pytest.approx(0.912, abs=1e-3) and hi == 1.0
    assert d["interval_method"] == "wilson"
    assert d["success_words"] == success_words(40, 40)


# ---------------------------------------------------------------- what was sampled


def test_the_sampled_rotation_error_is_the_one_drawn() -> None:
    d = sim_summary({"part": (3, 4)}, sampled=Uncertainty(1.0, 0.0, 0.0)).to_dict()["settings"]
    assert d["sampled_uncertainty"]["rotation_error_deg"] == 1.0
    s = SimSettings(4, 0, 8.0, 0.1, 0.5, 0.2, 0.002, sampled=Uncertainty(1.0, 0.0, 0.0))
    assert s.to_dict()["sampled_uncertainty"]["rotation_error_deg"] == 8.0
    assert "rotation error ±8 deg" in s.to_dict()["sampled"]
    wide = SimSettings(4, 0, 120.0, 0.1, 0.5, 0.2, 0.002, sampled=Uncertainty(1.0, 0.0, 0.0))
    assert wide.to_dict()["sampled_uncertainty"]["rotation_error_deg"] == 120.0


def test_ideal_and_a_rotation_noise_conflict() -> None:
    check_rotation_noise(None, ideal=True)
    check_rotation_noise(8.0, ideal=False)
    with pytest.raises(InputError, match="--ideal") as exc:
        check_rotation_noise(8.0, ideal=True)
    assert "\n" not in str(exc.value) and "--rotation-noise" in str(exc.value)
    with pytest.raises(InputError, match=r"\[0, 180\]"):
        check_rotation_noise(-1.0)


# ---------------------------------------------------------------- what the plan certifies


def test_what_the_plan_holds_comes_from_its_certificate_else_declared_plus_margin() -> None:
    one = Uncertainty(1.0, 0.0, 0.0)
    cert = Certificate(3.15, 0.02, 4)
    assert certified_bounds(one, 2.15, cert) == Certified(3.15, 0.02, True)
    assert certified_bounds(one, 2.15, None) == Certified(3.15, 0.0, False)
    assert certified_bounds(IDEAL, 4.68, None) == Certified(4.68, 0.0, False)  # margin alone
    assert certified_bounds(one, None, None).rotation_error_deg is None  # no rotation
    # ... with a certificate too (its 90 degrees for a plan with no rotation is no figure).
    assert certified_bounds(one, None, Certificate(90.0, 0.02, 1)).rotation_error_deg is None
    assert "its certificate" in Certified(3.15, 0.02, True).words()


def test_a_sample_beyond_what_the_plan_certifies_gets_one_note() -> None:
    held = Certified(3.152, 0.0, True)
    note = beyond_certified_note(8.0, 0.0, held)
    assert note == (
        "sampled rotation error ±8 deg is beyond what the plan certifies (±3.152 deg): "
        "failures are expected"
    )
    assert beyond_certified_note(1.0, 0.0, held) is None
    assert beyond_certified_note(3.152, 0.0, held) is None  # at the bound: held
    shape = beyond_certified_note(1.0, 0.05, Certified(3.0, 0.01, True))
    assert shape is not None and "shape tolerance 0.05 mm" in shape and "(0.01 mm)" in shape
    assert beyond_certified_note(80.0, 0.0, Certified(None, 0.0, False)) is None
    # an ideal plan without a certificate: its smallest margin, as the old note said
    ideal = certified_bounds(IDEAL, 4.68, None)
    assert beyond_certified_note(2.34, 0.0, ideal) is None
    assert "(±4.68 deg)" in (beyond_certified_note(11.7, 0.0, ideal) or "")
    # without a certificate the figure is a claim, not a certificate, and says so
    assert "beyond what the plan claims" in (beyond_certified_note(11.7, 0.0, ideal) or "")
    assert (ideal.verb, held.verb) == ("claims", "certifies")


def test_the_summary_carries_the_note_in_its_json() -> None:
    from dataclasses import replace

    s = replace(sim_summary({"part": (3, 4)}), certified=Certified(3.15, 0.0, True))
    assert s.to_dict()["beyond_certified"] is None
    loud = replace(s, settings=replace(s.settings, rotation_noise_deg=8.0))
    assert "beyond what the plan certifies (±3.15 deg)" in loud.to_dict()["beyond_certified"]
    assert loud.to_dict()["certified"] == {
        "rotation_error_deg": 3.15,
        "shape_tolerance_mm": 0.0,
        "source": "certificate",
    }


# ---------------------------------------------------------------- the simulator's width accuracy


def test_the_width_accuracy_is_the_figure_docs_simulation_md_measured() -> None:
    text = _words((ROOT / "docs" / "simulation.md").read_text(encoding="utf-8"))
    assert f"its width within about {WIDTH_ACCURACY_MM:g} mm of the diameter" in text


def test_a_sensor_finer_than_the_simulated_widths_is_named() -> None:
    fine = width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.05)))
    assert fine is not None
    assert "±0.05 mm" in fine and f"about {WIDTH_ACCURACY_MM:g} mm" in fine
    assert "'reading in no branch' failures" in fine and "not the plan" in fine
    assert width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.5))) is None
    # at the accuracy itself readings fall out of their windows too (6 of 300 trials)
    at = width_accuracy_warning(sensor_width_slack(ToleranceSensor(WIDTH_ACCURACY_MM)))
    assert at is not None and "is no coarser than the simulator's width accuracy" in at
    assert width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.31))) is None
    assert width_accuracy_warning(sensor_width_slack(NoSensor())) is None
    led = width_accuracy_warning(sensor_width_slack(LedSensor(0.1, 0.0)))
    assert led is not None and "alignment noise ±0 mm" in led and "pitch 0.1 mm" in led
    assert width_accuracy_warning(sensor_width_slack(LedSensor(1.0, 0.5))) is None
    # a part simulated 10 times larger: widths good to 0.03 mm in the plan's units
    assert width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.1)), scale=10.0) is None
    assert width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.03)), scale=10.0)
    scaled = width_accuracy_warning(sensor_width_slack(ToleranceSensor(0.01)), scale=10.0)
    assert scaled is not None and "0.03 mm at the plan's size" in scaled


# ---------------------------------------------------------------- the command line (MuJoCo)

needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these",
)


@lru_cache(maxsize=4)
def _plan_text(name: str, tolerance: float) -> str:
    part = load_part(str(ROOT / "catalog" / f"{name}.json"))
    made = make_plan([push_function(part)], ToleranceSensor(tolerance))
    return plan_json(made.plan)


def _plan(tmp_path: Path, name: str, tolerance: float) -> Path:
    path = tmp_path / f"{name}.plan.json"
    path.write_text(_plan_text(name, tolerance), encoding="utf-8")
    return path


def _words(text: str) -> str:
    return " ".join(text.split())  # the terminal wraps lines


@needs_mujoco
def test_simulate_refuses_ideal_with_a_rotation_noise(tmp_path: Path, capsys) -> None:
    path = _plan(tmp_path, "rectangle-2x1", 0.3)
    args = ["simulate", str(path), "--trials", "20", "--ideal", "--rotation-noise", "8"]
    assert main(args) == 2
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert len(lines) == 1 and "--ideal" in lines[0] and "--rotation-noise" in lines[0]
    assert captured.out == ""


@needs_mujoco
def test_simulate_states_interval_sampled_noise_and_certificate(tmp_path: Path, capsys) -> None:
    path = _plan(tmp_path, "rectangle-2x1", 0.3)
    args = ["simulate", str(path), "--trials", "3", "--rotation-noise", "8"]
    assert main([*args, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["settings"]["sampled_uncertainty"]["rotation_error_deg"] == 8.0
    assert d["interval_method"] == "wilson" and len(d["success_interval_95"]) == 2
    cert = json.loads(path.read_text(encoding="utf-8"))["stats"]["certificate"]
    assert d["certified"]["source"] == "certificate"
    assert d["certified"]["rotation_error_deg"] == pytest.approx(cert["max_rotation_error_deg"])
    assert "beyond what the plan certifies" in d["beyond_certified"]
    assert main(args) == 0
    out = _words(capsys.readouterr().out)
    assert "95 % Wilson interval" in out
    assert f"rotation error up to ±{cert['max_rotation_error_deg']:.4g} deg" in out
    assert (
        f"note: sampled rotation error ±8 deg is beyond what the plan certifies "
        f"(±{cert['max_rotation_error_deg']:.4g} deg): failures are expected"
    ) in out
    assert main(["simulate", str(path), "--trials", "2"]) == 0
    assert "beyond what the plan certifies" not in capsys.readouterr().out


@needs_mujoco
def test_simulate_warns_when_the_sensor_is_finer_than_the_simulated_widths(
    tmp_path: Path, capsys
) -> None:
    path = _plan(tmp_path, "t-clip", 0.05)
    assert main(["simulate", str(path), "--trials", "2"]) == 0
    # On stderr, one line (a log reader takes warning: lines from there), as with --json.
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "width accuracy" in x]
    assert "warning: the sensor tolerance ±0.05 mm is no coarser than the simulator's width" in line
    assert "'reading in no branch' failures then measure the simulator's width error" in line
    assert main(["simulate", str(path), "--trials", "2", "--json"]) == 0
    captured = capsys.readouterr()
    assert "±0.05 mm" in json.loads(captured.out)["width_accuracy_warning"]
    (line,) = [x for x in captured.err.splitlines() if "width accuracy" in x]
    assert line.startswith("warning: ") and "failures then measure" in line
    coarse = _plan(tmp_path, "t-clip", 0.5)
    assert main(["simulate", str(coarse), "--trials", "2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["width_accuracy_warning"] is None


def test_push_words_add_the_physical_state_only_when_it_counts_more() -> None:
    assert push_words(5, 5, 5) == "5 of 5 settled pushes (100.0%) end where the push function says"
    assert push_words(3, 7, None) == push_words(3, 7, 3)
    assert push_words(3, 7, 7).endswith(
        "; 7 of 7 (100.0%) in the same physical state (the plan's model merges states a "
        "vibration knocks over)"
    )


@needs_mujoco
def test_a_merged_states_facets_count_as_the_same_physical_state(tmp_path: Path, capsys) -> None:
    """The d-washer's arc is many facet states the plan's model merges into one physical
    state: a push that ends on another facet of it is no miss to the plan."""
    path = _plan(tmp_path, "d-washer", 0.3)
    assert main(["simulate", str(path), "--trials", "6", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["push_agreements"] < d["physical_agreements"] <= d["settled_pushes"]
    assert d["push_words"] == push_words(
        d["push_agreements"], d["settled_pushes"], d["physical_agreements"]
    )
    assert main(["simulate", str(path), "--trials", "6"]) == 0
    assert "in the same physical state" in _words(capsys.readouterr().out)


def test_no_branch_failures_under_a_fine_sensor_are_put_down_to_the_simulators_widths(capsys):
    """With the width warning on, the cause row of 'reading in no branch' says it measures
    the simulator's widths (they were listed as plain model errors)."""
    import dataclasses

    from feederkit.cli.simulate import _print_summary
    from feederkit.sim.summary import TrialResult

    miss = TrialResult(3, "part", 10.0, "failure", 2, "reading 26.86", None, (), CAUSES[2], False)
    base = sim_summary({"part": (9, 10)}, failures=(miss,))
    for warning, shown in ((None, False), ("the sensor is finer than the widths", True)):
        _print_summary(dataclasses.replace(base, width_warning=warning), "declared")
        out = " ".join(capsys.readouterr().out.split())
        assert "reading in no branch" in out
        assert ("(the simulator's widths: see the warning)" in out) is shown


def test_a_plan_with_no_rotation_certifies_any_rotation_error_in_words(tmp_path, capsys):
    # A scalene triangle's three states read apart: one operation, no rotation. Its
    # certificate stores 90 degrees (docs/plans.md); the table says what that means.
    path = tmp_path / "tri.json"
    path.write_text(json.dumps({"name": "tri", "vertices": [[0, 0], [40, 0], [10, 30]]}))
    rc = main(["plan", str(path), "--tolerance", "0.01", "--landings", "up"])
    out = capsys.readouterr().out
    assert rc == 0 and "at most 1 push-align operation" in out
    assert "any (the plan makes no rotation)" in " ".join(out.split())
    assert "±90°" not in out
