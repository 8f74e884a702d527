"""The maximal reading branches of a set by the interval sweep (``Readings._interval_cliques``)
against the readings themselves: at every reading the set's states can give, the states that
can give it, the maximal ones kept (an independent brute force over the sensor's reading
intervals). The sweep serves the machines whose diameters are intervals in no common order,
where the sensor's reading windows do not apply: both landings of a random outline under a
rotation error."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import read_alike_sets

from feederkit.landing.model import landings_of_outline
from feederkit.machine import Grouping, build_machine, members
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning import readings as readings_module
from feederkit.planning.choices import children_key
from feederkit.planning.readings import Readings, _cells_are_runs
from feederkit.planning.reindex import by_diameter
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import Uncertainty


def _both_landings_machine(tolerance: float):
    """Both landings of the hull of 200 points at random radii 21-30 mm, under 1 degree."""
    rng = random.Random(4)
    pts = []
    for t in sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(200)):
        f = 30.0 * rng.uniform(0.7, 1.0)
        pts.append((f * math.cos(t), f * math.sin(t)))
    part = make_part(make_outline("random-200", pts))
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    machine = build_machine(pfs, ToleranceSensor(tolerance), Uncertainty(1.0))
    return by_diameter(machine)[0]


@pytest.fixture(scope="module", params=[0.02, 0.1, 0.585, 1.5])
def readings(request):
    machine = _both_landings_machine(request.param)
    out = Readings(machine, Grouping.EXACT, (0,) * machine.n)
    # The sweep's own case: no reading windows, every state's cells one run.
    assert not out._window and out._runs
    return out


def _brute_force_maximal(readings: Readings, image: int) -> set[int]:
    """The maximal sets of the image's states that can give one reading, from the sensor's
    reading intervals (:func:`shared.read_alike_sets`, one probe per gap between ends)."""
    sensor = readings.machine.sensor
    spans = {i: sensor.reading_interval(readings.machine.states[i].sensed) for i in members(image)}
    sets = set(read_alike_sets(spans))
    return {s for s in sets if not any(s != o and s & o == s for o in sets)}


@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_the_sweep_finds_the_maximal_sets_that_read_alike(readings, data):
    n = readings.machine.n
    image = data.draw(st.integers(1, (1 << n) - 1))
    got = readings.children(image)
    assert set(got) == _brute_force_maximal(readings, image)
    assert len(got) == len(set(got))
    assert [c.bit_count() for c in got] == sorted((c.bit_count() for c in got), reverse=True)
    # The members in the order their runs end, by sorting them (large machines) instead
    # of a scan of every state: the same sets in the same order.
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(readings_module, "CLIQUE_SCAN_STATES", 0)
        assert readings._interval_cliques(image) == got


def test_the_whole_machine_reads_as_its_reading_cells(readings):
    full = readings.machine.all_states
    assert set(readings.children(full)) == _brute_force_maximal(readings, full)


def test_cells_that_skip_a_state_are_not_runs():
    # State 0 in cells 0 and 2 but not 1: its span (0, 3) is not what the cells hold.
    assert not _cells_are_runs([0b01, 0b10, 0b01], [(0, 3), (1, 2)])
    assert _cells_are_runs([0b01, 0b11, 0b10], [(0, 2), (1, 3)])


def _one_landing_machine(tolerance: float):
    """A mix of random hexagons to decagons under 1 degree, numbered by diameter: the
    sensor's reading windows apply."""
    rng = random.Random(7)
    pfs = []
    for k in range(6):
        m = rng.randint(6, 10)
        pts = []
        for t in sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(m)):
            f = rng.uniform(20.0, 30.0)
            pts.append((f * math.cos(t), f * math.sin(t)))
        pfs.append(push_function(make_part(make_outline(f"hex-{k}", pts))))
    machine = build_machine(pfs, ToleranceSensor(tolerance), Uncertainty(1.0))
    return by_diameter(machine)[0]


@pytest.fixture(scope="module", params=[0.05, 0.5, 2.0])
def windowed(request):
    machine = _one_landing_machine(request.param)
    out = Readings(machine, Grouping.EXACT, (0,) * machine.n)
    assert out._window  # the windows' own case
    return out


@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_the_window_walk_finds_the_maximal_sets_that_read_alike(windowed, data):
    # The walk jumps from one maximal run to the next (``_first_reaching``); against the
    # readings themselves, and against a run per member kept when it reaches further.
    n = windowed.machine.n
    image = data.draw(st.integers(1, (1 << n) - 1))
    got = windowed.children(image)
    assert set(got) == _brute_force_maximal(windowed, image)
    runs, top = [], -1
    for i in members(image):
        r = image & windowed._window[i]
        if r.bit_length() > top:
            runs.append(r)
            top = r.bit_length()
    assert got == tuple(sorted(runs, key=int.bit_count, reverse=True))
    # The ranking's numbers for many images at once (Readings.branch_keys): the largest
    # maximal branch and the branches' sizes added up.
    # Both ways: the walk per image and the arrays (each the faster at some image size).
    more = [image, *data.draw(st.lists(st.integers(1, (1 << n) - 1), max_size=6))]
    want = [children_key(windowed.children(m)) for m in more]
    assert windowed.branch_keys(more) == want
    assert [windowed.window_key(m) for m in more] == want
    assert windowed._array_keys(more) == want
