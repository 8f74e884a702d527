"""An LED array's reading cells are made per run of beam counts, not per count.

A pitch of 0.1 um made ten million cells per millimetre of diameters: a three-state
triangle took 37 s and 0.5 GB to plan, and under ``--time-limit 10`` found no plan. The
cells must be those of the count-by-count construction (the oracle below), neighbours with
the same states merged.
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.machine import ReadingBranch
from feederkit.sensors import LedSensor, _mask, _merge_cells


def _by_count(sensor: LedSensor, diameters, labels) -> list[ReadingBranch]:
    extents = [sensor.counts(d) for d in diameters]
    lo, hi = min(c for c, _ in extents), max(c for _, c in extents)
    cells = []
    for c in range(lo, hi + 1):
        members = [i for i, (a, b) in enumerate(extents) if a <= c <= b]
        cells.append((float(c), float(c), _mask(members, labels)))
    return [
        ReadingBranch(*sensor.window(int(a), int(b)), m) for a, b, m in _merge_cells(cells, gap=1.0)
    ]


_diameter = st.one_of(
    st.floats(1.0, 6.0),
    st.tuples(st.floats(1.0, 6.0), st.sampled_from([0.0, 0.1, 0.5])).map(
        lambda t: (t[0], t[0] + t[1])
    ),
)


@settings(max_examples=300, deadline=None)
@given(
    st.sampled_from([0.1, 0.25, 0.5, 1.0]),
    st.sampled_from([0.0, 0.05, 0.2, 0.6]),
    st.lists(_diameter, min_size=1, max_size=8),
    st.data(),
)
def test_runs_of_counts_are_the_count_by_count_cells(pitch, noise, diameters, data):
    labels = data.draw(
        st.none() | st.lists(st.integers(0, 3), min_size=len(diameters), max_size=len(diameters))
    )
    sensor = LedSensor(pitch, noise)
    assert sensor.split(diameters, labels=labels) == _by_count(sensor, diameters, labels)


def test_a_fine_pitch_has_as_many_cells_as_states_make() -> None:
    sensor = LedSensor(1e-7, 1e-6)
    branches = sensor.split([1.0, 1.4142135623730951, 1.5])
    assert len(branches) == 3 and [b.mask for b in branches] == [1, 2, 4]
