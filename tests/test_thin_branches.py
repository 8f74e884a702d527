"""Reading branches narrower than the sensor can read: warned about when the plan takes the
parts as drawn (shape tolerance 0), since a part made to a looser tolerance may read in
another's branch; not with a declared shape tolerance, whose model covers the spread."""

from __future__ import annotations

import pytest

from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.fileformat import distinct_nodes
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

PENT = [(0, 0), (30, 0), (36, 18), (15, 31), (-6, 18)]


def _pair(shift: float):
    """A pentagon and a copy with one vertex moved ``shift`` mm outward."""
    near = [*PENT[:2], (36 + shift, 18), *PENT[3:]]
    return [
        push_function(make_part(make_outline("pent", PENT))),
        push_function(make_part(make_outline("pent-near", near))),
    ]


def _widths(plan) -> list[float]:
    return [
        b["reading"][1] - b["reading"][0]
        for node in distinct_nodes(plan)
        if len(node.get("branches") or ()) > 1
        for b in node["branches"]
    ]


@pytest.mark.parametrize("unc", [IDEAL, Uncertainty(rotation_error_deg=0.5)])
def test_a_branch_finer_than_the_sensor_is_warned_about_when_parts_are_as_drawn(unc):
    made = make_plan(_pair(0.02), ToleranceSensor(0.1), uncertainty=unc, certify=False)
    thin = [w for w in made.warnings if "narrower than 1% of the sensor's window" in w]
    narrowest = min(_widths(made.plan))
    assert narrowest < 0.002  # the brute force: the file's own branches
    assert len(thin) == 1 and f"the narrowest {narrowest:.2g} mm" in thin[0]


def test_no_warning_with_a_declared_shape_tolerance_or_branches_the_sensor_reads():
    unc = Uncertainty(rotation_error_deg=0.5, shape_tolerance_mm=0.02)
    made = make_plan(_pair(0.02), ToleranceSensor(0.1), uncertainty=unc, certify=False)
    assert not [w for w in made.warnings if "narrower than" in w]
    made = make_plan(_pair(2.0), ToleranceSensor(0.1), uncertainty=IDEAL, certify=False)
    assert min(_widths(made.plan)) >= 0.002
    assert not [w for w in made.warnings if "narrower than" in w]
