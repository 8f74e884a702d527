"""``design sensor``'s time limit and progress (docs/design.md, "Time limit").

A design is exact or nothing: past the limit it raises DesignTimeout (one line naming what
was decided) within a small overshoot, a search cut short never becomes an answer (cut at
any poll, a design either times out or equals the unlimited one), and an unlimited run, or
one that finishes within its limit, is the design of today byte for byte.
"""

from __future__ import annotations

import json
import math
import random
import time
from pathlib import Path

import pytest
from rich.console import Console
from shared import one_line_error
from test_deadline import OVERSHOOT_S as PLANNER_OVERSHOOT_S

import feederkit.cli.app as app_module
import feederkit.cli.common as cli_common
from feederkit.cli import design as design_cli
from feederkit.cli.app import main
from feederkit.design import strong
from feederkit.design.critical import mix_critical_tolerance
from feederkit.design.limit import (
    GOALS,
    LENGTHS,
    PAIRS,
    PITCHES,
    DesignClock,
    DesignTimeout,
)
from feederkit.design.sensor import design_pitches, design_tolerance
from feederkit.design.steps import length_steps
from feederkit.design.strong import (
    StrongLengthOracle,
    StrongMix,
    _PairProbes,
    strong_length_steps,
    strong_mix_critical,
)
from feederkit.errors import InputError, PlanningError
from feederkit.loading import load_parts
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.budget import Deadline, Timeout, rss_mb
from feederkit.planning.lumping import LumpingTry
from feederkit.sensors import LedSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = [str(CATALOG / f"{n}.json") for n in ("quadrilateral", "rectangle-2x1", "l-bracket")]
ONE_DEGREE = Uncertainty(1.0, 0.0, 0.0)

OVERSHOOT_S = PLANNER_OVERSHOOT_S
"""How far past its limit a design may stop (the work after the last poll: the planner's own
overshoot, test_deadline.py, and the verification of a plan found at the deadline). It was
1.5 s, below the planner's own 2 s that it includes: in CI's parallel slow run the 20-part
ellipse mix stopped 1.57 and 1.95 s past its 5 s limit (4.6 s alone, also under load)."""


def ellipse_mix(count: int):
    """Random 6- to 10-gons on one 60 x 40 mm ellipse (benchmarks/bench_design.py): similar
    parts whose plans near the critical tolerance take minutes to prove."""
    out = []
    for s in range(count):
        rng = random.Random(100 + s)
        n = random.Random(s).randint(6, 10)
        angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
        pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]
        out.append(push_function(make_part(make_outline(f"mix-{s}", pts))))
    return out


@pytest.fixture(scope="module")
def catalog_mix():
    return list(load_parts(MIX).push_functions)


def _timed_out(run, limit: float) -> tuple[DesignTimeout, list[str]]:
    """Run ``run(time_limit_s, progress)``, which must time out within the overshoot; the
    error and the stages it reported."""
    stages: list[str] = []

    def progress(what: str, done: int, total: int) -> None:
        assert 0 <= done <= total
        if not stages or stages[-1] != what:
            stages.append(what)

    start = time.perf_counter()
    with pytest.raises(DesignTimeout) as info:
        run(limit, progress)
    took = time.perf_counter() - start
    assert took <= limit + OVERSHOOT_S, f"stopped {took - limit:.2f} s past the limit"
    message = str(info.value)
    assert "\n" not in message and isinstance(info.value, PlanningError)
    assert message.startswith(
        f"the sensor design did not finish within the time limit of {limit:g} s"
    )
    assert message.endswith("no partial design is given")
    return info.value, stages


def test_a_hard_mix_stops_at_the_limit_while_deciding_pairs():
    pfs = ellipse_mix(9)  # 36 pairs, about 0.33 s of exact solves at 1 degree, idle
    err, stages = _timed_out(
        lambda t, p: design_tolerance(pfs, uncertainty=ONE_DEGREE, time_limit_s=t, progress=p), 0.15
    )
    assert stages == [PAIRS]
    assert " of 36 pairs)" in str(err)


def test_a_hard_mix_stops_at_the_limit_in_a_verified_plan():
    # The ideal model: the pairs take milliseconds, the first plan of the table (at the
    # critical tolerance) minutes; the planner stops at the time left.
    pfs = ellipse_mix(5)
    err, stages = _timed_out(
        lambda t, p: design_tolerance(pfs, uncertainty=IDEAL, time_limit_s=t, progress=p), 1.0
    )
    assert stages[0] == PAIRS
    if stages[-1] == LENGTHS:  # the pairs done (they always are, unless the machine crawls)
        assert "all 10 pairs and 0 of " in str(err) and "intervals of the length table" in str(err)


def test_a_hard_mix_stops_at_the_limit_in_the_goal_search():
    pfs = ellipse_mix(3)  # strong plans: the goal search alone takes seconds
    err, stages = _timed_out(
        lambda t, p: design_tolerance(pfs, uncertainty=ONE_DEGREE, time_limit_s=t, progress=p), 1.0
    )
    assert stages[0] == PAIRS and set(stages) <= {PAIRS, GOALS, LENGTHS}
    if GOALS in stages:
        assert "all 3 pairs" in str(err)


def test_pitches_stop_at_the_limit():
    pfs = ellipse_mix(9)  # about 0.5 s in all, idle (6 parts took 0.23 s, under the limit)
    err, stages = _timed_out(
        lambda t, p: design_pitches(
            pfs, [0.1, 0.5, 1.0, 2.0], uncertainty=ONE_DEGREE, time_limit_s=t, progress=p
        ),
        0.3,
    )
    assert stages[0] == PITCHES


class CutAt(Deadline):
    """A deadline that passes at its ``polls``-th check: a cut at an exact point of the work."""

    def __init__(self, polls: int) -> None:
        super().__init__()
        self.left = polls

    def check(self) -> None:
        self.left -= 1
        if self.left < 0:
            raise Timeout("time")


def test_a_cut_at_any_poll_times_out_or_gives_the_unlimited_design(catalog_mix):
    """Caches survive cuts (one mix machine for every cut) and never hold a cut answer: the
    reference is computed on a machine of its own."""
    mix = StrongMix(catalog_mix, ONE_DEGREE)
    fresh = StrongMix(catalog_mix, ONE_DEGREE)
    critical = strong_mix_critical(fresh)
    steps = strong_length_steps(fresh, critical.critical_tolerance, critical)
    outcomes = []
    for polls in (0, 3, 30, 300, 3000, 10**6):
        clock = DesignClock()
        clock.deadline = CutAt(polls)
        try:
            got = strong_mix_critical(mix, clock)
            got_steps = strong_length_steps(mix, got.critical_tolerance, got, clock=clock)
        except Timeout:
            outcomes.append("cut")
            continue
        assert got == critical and got_steps == steps
        outcomes.append("same")
    assert outcomes[0] == "cut" and outcomes[-1] == "same"


def test_a_cut_on_the_ideal_model_times_out_or_gives_the_unlimited_design(catalog_mix):
    critical = mix_critical_tolerance(catalog_mix)
    steps = length_steps(catalog_mix, critical.critical_tolerance, critical=critical)
    outcomes = []
    for polls in (0, 3, 30, 300, 10**6):
        clock = DesignClock()
        clock.deadline = CutAt(polls)
        try:
            got = mix_critical_tolerance(catalog_mix, clock)
            x = got.critical_tolerance
            got_steps = length_steps(catalog_mix, x, critical=got, clock=clock)
        except Timeout:
            outcomes.append("cut")
            continue
        assert got == critical and got_steps == steps
        outcomes.append("same")
    assert outcomes[0] == "cut" and outcomes[-1] == "same"


class PassesWhenTold(Deadline):
    """A deadline that passes when ``passed`` is set (a search's end, simulated)."""

    passed = False

    def check(self) -> None:
        if self.passed:
            raise Timeout("time")


class NeverWithin:
    """A length oracle that finds no short plan (so the exact solver is asked)."""

    def within(self, mask: int, length: int) -> bool:
        return False


def _solver_runs_out(deadline: PassesWhenTold):
    def unsolvable(problem, roots, budget=None, max_sets=None):
        assert budget is deadline
        deadline.passed = True
        raise Timeout("time")

    return unsolvable


def test_a_pair_test_cut_short_raises_and_is_not_remembered(catalog_mix, monkeypatch):
    mix = StrongMix(catalog_mix, ONE_DEGREE)
    machine = mix.pair(0, 1)
    tolerance = strong_mix_critical(mix).pairs[0].critical_tolerance
    assert _PairProbes(machine).separable(tolerance)
    expired = _PairProbes(machine, Deadline(end=time.perf_counter() - 1.0))
    with pytest.raises(Timeout):
        expired.separable(tolerance)
    # The exact solver is cut short: that is no "not separable".
    deadline = PassesWhenTold()
    probes = _PairProbes(machine, deadline)
    monkeypatch.setattr(strong, "make_oracle", lambda problem, method, budget: NeverWithin())
    monkeypatch.setattr(strong, "unsolvable", _solver_runs_out(deadline))
    with pytest.raises(Timeout):
        probes.separable(tolerance)
    assert tolerance not in probes._separable
    monkeypatch.undo()
    deadline.passed = False
    assert probes.separable(tolerance)


def test_a_goal_cut_short_raises_and_is_not_remembered(catalog_mix, monkeypatch):
    mix = StrongMix(catalog_mix, ONE_DEGREE)
    tolerance = 0.5
    expected = StrongLengthOracle(mix).goal(tolerance)
    deadline = PassesWhenTold()
    oracle = StrongLengthOracle(mix, deadline)
    monkeypatch.setattr(strong, "make_oracle", lambda problem, method, budget: NeverWithin())
    monkeypatch.setattr(strong, "unsolvable", _solver_runs_out(deadline))
    with pytest.raises(Timeout):
        oracle.goal(tolerance)
    # Lumping answers "undecided" (no goal) when its deadline passes: no "no strong plan".
    deadline.passed = False
    monkeypatch.setattr(strong, "unsolvable", lambda problem, roots, budget=None: [roots[0]])

    def try_lumping(machine, grouping, budget, rule):
        deadline.passed = True
        return LumpingTry(None, decided=False)

    monkeypatch.setattr(strong, "try_lumping", try_lumping)
    with pytest.raises(Timeout):
        oracle.goal(tolerance)
    assert not oracle._goals
    monkeypatch.undo()
    deadline.passed = False
    assert oracle.goal(tolerance) == expected


def test_a_strong_plan_search_cut_short_is_not_an_answer(catalog_mix, monkeypatch):
    mix = StrongMix(catalog_mix, ONE_DEGREE)
    clock = DesignClock()
    clock.deadline = passing = PassesWhenTold()

    def exists(machine, options=None, deadline=None):
        assert deadline is passing
        passing.passed = True
        return True  # what it answers when its deadline passes

    monkeypatch.setattr(strong, "strong_plan_exists", exists)
    with pytest.raises(Timeout):
        strong.strong_pitch(mix, LedSensor(1.0), clock)


@pytest.mark.parametrize("uncertainty", [IDEAL, ONE_DEGREE], ids=["ideal", "1deg"])
def test_within_the_limit_the_design_is_the_unlimited_one(catalog_mix, uncertainty):
    seen: dict[str, list[tuple[int, int]]] = {}

    def progress(what: str, done: int, total: int) -> None:
        seen.setdefault(what, []).append((done, total))

    plain = design_tolerance(catalog_mix, uncertainty=uncertainty)
    timed = design_tolerance(catalog_mix, uncertainty=uncertainty, time_limit_s=60.0,
                             progress=progress)  # fmt: skip
    assert json.dumps(timed.to_dict()) == json.dumps(plain.to_dict())
    order = [PAIRS, LENGTHS] if uncertainty.is_ideal else [PAIRS, GOALS, LENGTHS]
    assert list(seen) == order
    for calls in seen.values():
        dones = [d for d, _ in calls]
        assert dones == sorted(dones) and calls[-1][0] == calls[-1][1]
    assert seen[PAIRS][-1] == (3, 3)
    pitches = design_pitches(catalog_mix, [1.0], uncertainty=uncertainty)
    limited = design_pitches(catalog_mix, [1.0], uncertainty=uncertainty, time_limit_s=60.0)
    assert json.dumps(limited.to_dict()) == json.dumps(pitches.to_dict())


@pytest.mark.parametrize("limit", [0, -1.0, math.nan, math.inf, True])
def test_a_bad_time_limit_is_input_error(catalog_mix, limit):
    with pytest.raises(InputError, match="time limit must be a finite positive number of seconds"):
        design_tolerance(catalog_mix, time_limit_s=limit)


@pytest.mark.parametrize("limit", [0, -1.0, math.nan, math.inf, True])
def test_a_bad_memory_limit_is_input_error(catalog_mix, limit):
    with pytest.raises(InputError, match="memory limit must be a finite positive number of MB"):
        design_tolerance(catalog_mix, memory_limit_mb=limit)


@pytest.mark.parametrize("uncertainty", [IDEAL, ONE_DEGREE], ids=["ideal", "1deg"])
def test_a_memory_limit_below_the_process_stops_the_design_naming_it(catalog_mix, uncertainty):
    with pytest.raises(DesignTimeout) as info:
        design_tolerance(catalog_mix, uncertainty=uncertainty, memory_limit_mb=1.0)
    text = str(info.value)
    assert "within the memory limit of 1 MB" in text and "0 of 3 pairs" in text
    assert "\n" not in text


@pytest.mark.parametrize(
    ("time_s", "memory_mb", "reason", "words"),
    [
        (3.0, 5.0, "memory", "the memory limit of 5 MB"),
        (3.0, 5.0, "time", "the time limit of 3 s"),
        (None, 5.0, "time", "the memory limit of 5 MB"),  # the only limit there is
        (3.0, None, "memory", "the time limit of 3 s"),
    ],
)
def test_the_timeout_names_the_limit_that_stopped_it(time_s, memory_mb, reason, words):
    text = str(DesignClock(time_s, None, memory_mb).timeout(reason))
    assert f"did not finish within {words} (it decided nothing yet)" in text


def test_a_memory_limit_with_room_gives_the_unlimited_design(catalog_mix):
    # Only a memory limit: the planner's searches get it too (DesignClock.plan), answers alike.
    plain = design_tolerance(catalog_mix, uncertainty=ONE_DEGREE)
    roomy = design_tolerance(catalog_mix, uncertainty=ONE_DEGREE, memory_limit_mb=rss_mb() + 4000)
    assert json.dumps(roomy.to_dict()) == json.dumps(plain.to_dict())


# The command line.


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    """The command on the app, run from an empty folder (no stray profile or catalog)."""
    group = app_module._click_command()
    if "design" not in getattr(group, "commands", {}):
        design_cli.register(app_module.app)
        app_module._click_command.cache_clear()
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    return tmp_path


@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_cli_bad_time_limit_is_one_line_exit_2(capsys, in_tmp, value):
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--time-limit", value])
    assert err.startswith("error: the time limit must be a finite positive number of seconds")
    assert "(--time-limit)" in err


def test_cli_timeout_is_one_line_exit_1(capsys, in_tmp):
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--time-limit", "0.001"], code=1)
    assert err.startswith(
        "result: the sensor design did not finish within the time limit of 0.001 s"
    )
    # Three parts, two landings each: 15 pairs of landings (design.md, "Landings").
    assert " of 15 pairs" in err and err.rstrip().endswith("allow more time with --time-limit S")
    assert not list(in_tmp.iterdir())


def test_cli_memory_limit_is_one_line(capsys, in_tmp):
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--memory-limit", "1"], code=1)
    assert err.startswith("result: the sensor design did not finish within the memory limit")
    assert err.rstrip().endswith("allow more memory with --memory-limit MB")
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--memory-limit", "-5"])
    assert err.startswith("error: the memory limit must be a finite positive number of MB")
    assert not list(in_tmp.iterdir())


def test_cli_json_stays_clean_with_the_progress_bar_shown(capsys, in_tmp, monkeypatch):
    monkeypatch.setattr(
        cli_common, "err_console", Console(stderr=True, force_terminal=True, width=120)
    )
    assert main(["design", "sensor", *MIX, "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["sensor_model"] == "tolerance" and data["critical_tolerance_mm"] > 0
    assert "pairs' critical tolerances" in captured.err  # the bar was drawn, on stderr


@pytest.mark.slow
@pytest.mark.parametrize("uncertainty", [IDEAL, ONE_DEGREE], ids=["ideal", "1deg"])
def test_the_benchmark_ellipse_mix_stops_at_the_limit(uncertainty):
    """The benchmark's 20-part ellipse mix (minutes uncapped, and gigabytes) stops in time."""
    pfs = ellipse_mix(20)
    _timed_out(
        lambda t, p: design_tolerance(pfs, uncertainty=uncertainty, time_limit_s=t, progress=p),
        5.0,
    )


@pytest.mark.parametrize("wait_s", [0.0, 0.5])
def test_a_proven_plan_whose_ties_the_work_budget_cut_is_the_design_answer_whenever_it_comes(
    wait_s,
):
    # With the fallback off every plan the planner returns is proven shortest, and ties cut
    # by its work budget (the same on any computer) are cut alike without a limit: the
    # unlimited design's answer, however late inside the limit it comes.
    from types import SimpleNamespace

    from feederkit.planning.tree import TIES_NONE

    limit_s = 1.0
    made = SimpleNamespace(result=SimpleNamespace(optimal=True, tie_breaks=TIES_NONE))

    def make(options):
        assert options is not None and options.time_limit_s <= limit_s
        time.sleep(wait_s)
        return made

    assert DesignClock(limit_s).plan(make) is made


def test_a_limit_that_ran_out_in_the_planner_is_a_timeout_and_other_errors_are_answers():
    # The planner's goal relation or lumping cut short (OutOfBudget) stops the design
    # whenever it happens, with the limit that ran out; a PlanningError about the problem
    # (no strong plan exists) is the design's answer, as without a limit.
    from feederkit.errors import PlanningError
    from feederkit.planning.options import OutOfBudget

    def cut(options):
        raise OutOfBudget("no plan found within the memory limit of 300 MB: ...", "memory")

    with pytest.raises(Timeout) as info:
        DesignClock(30.0).plan(cut)
    assert info.value.reason == "memory"

    def none(options):
        raise PlanningError("no strong plan exists under the declared uncertainty")

    with pytest.raises(PlanningError, match="no strong plan exists"):
        DesignClock(30.0).plan(none)

    def late(options):  # the limit passed while the planner gave up
        time.sleep(0.25)
        raise PlanningError("no strong plan found within 36 operations")

    with pytest.raises(Timeout) as info:
        DesignClock(0.2).plan(late)
    assert info.value.reason == "time"
    with pytest.raises(Timeout) as info:  # the time ran out, though a memory limit is set
        DesignClock(0.2, memory_limit_mb=1e6).plan(late)
    assert info.value.reason == "time"


def test_the_planner_of_a_limited_design_has_its_fallback_off_and_its_cut_is_a_timeout():
    # A plan not proven optimal is no design: the planner stops where its fallback would
    # start (seconds of a large unproven plan's statistics and verification, past the limit,
    # on the 20-part ellipse mix), and that stop is the design's Timeout.
    from feederkit.planning.fallback import NoFallback

    asked = []

    def make(options):
        asked.append(options)
        raise NoFallback(options, "time")

    with pytest.raises(Timeout) as info:
        DesignClock(5.0).plan(make)
    assert info.value.reason == "time"
    assert [o.fallback for o in asked] == [False]
    made = object()
    assert DesignClock().plan(lambda options: made if options is None else None) is made
