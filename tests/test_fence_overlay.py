"""The overshoot zones laid over the fence cells, against the direct overlay.

``_overlay`` sweeps the zones once (a 5,000-gon drawn as one polyline has as many zones as
cells, and the direct overlay, every cell against every zone, took 30 s of its import); the
direct one below is the oracle: each cell cut at every zone end inside it, each piece
targeting the zones holding it.
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.angles import norm360
from feederkit.mechanics.uncertain import FenceCell, _overlay


def _direct(cells, zones):
    base = cells[0].lo
    spans = []
    for lo, hi, extra in zones:
        if hi - lo >= 360.0:
            spans.append((base, base + 360.0, extra))
            continue
        x = base + norm360(lo - base)
        y = x + (hi - lo)
        spans.append((x, min(y, base + 360.0), extra))
        if y > base + 360.0:
            spans.append((base, y - 360.0, extra))
    out = []
    for cell in cells:
        cuts = sorted(
            {cell.lo, cell.hi} | {v for a, b, _ in spans for v in (a, b) if cell.lo < v < cell.hi}
        )
        for a, b in zip(cuts, cuts[1:], strict=False):
            targets = cell.targets.union(*(e for x, y, e in spans if x <= a and b <= y))
            last = out[-1] if out else None
            if (
                last is not None
                and last.hi == a
                and last.closed == cell.closed
                and last.targets == targets
                and last.lo >= cell.lo
            ):
                out[-1] = FenceCell(last.lo, b, cell.closed, targets)
            else:
                out.append(FenceCell(a, b, cell.closed, targets))
    return tuple(out)


# Angles on a coarse grid, so that zone ends fall on cell ends and on each other often.
_angle = st.integers(0, 72).map(lambda k: 5.0 * k)


@st.composite
def _cells_and_zones(draw):
    base = draw(st.sampled_from([0.0, 12.5, 200.0]))
    cuts = sorted(set(draw(st.lists(st.integers(1, 71).map(lambda k: 5.0 * k), max_size=12))))
    ends = [base, *(base + c for c in cuts), base + 360.0]
    cells = tuple(
        FenceCell(a, b, k % 2 == 0, frozenset(draw(st.sets(st.integers(0, 4), max_size=2))))
        for k, (a, b) in enumerate(zip(ends, ends[1:], strict=False))
    )
    zones = []
    for _ in range(draw(st.integers(0, 10))):
        lo = draw(_angle) - 180.0
        width = draw(st.sampled_from([0.0, 2.5, 5.0, 30.0, 95.0, 359.0, 360.0, 400.0]))
        zones.append((lo, lo + width, frozenset(draw(st.sets(st.integers(5, 9), max_size=2)))))
    return cells, zones


@settings(max_examples=300, deadline=None)
@given(_cells_and_zones())
def test_the_swept_overlay_is_the_direct_one(case):
    cells, zones = case
    assert _overlay(cells, zones) == _direct(cells, zones)


def test_a_zone_that_holds_no_cell_end_splits_its_cell():
    cells = (
        FenceCell(0.0, 180.0, True, frozenset({0})),
        FenceCell(180.0, 360.0, False, frozenset()),
    )
    got = _overlay(cells, [(10.0, 20.0, frozenset({3}))])
    assert got == (
        FenceCell(0.0, 10.0, True, frozenset({0})),
        FenceCell(10.0, 20.0, True, frozenset({0, 3})),
        FenceCell(20.0, 180.0, True, frozenset({0})),
        FenceCell(180.0, 360.0, False, frozenset()),
    )
