"""The report after review 66b (docs/reports.md): the sensor design's critical tolerances
rounded down as the terminal rounds them (F5)."""

from __future__ import annotations

import random

from feederkit.design.sensor import shown_tolerance
from feederkit.reports.design_html import design_section, tolerance_mm
from feederkit.sensors import LedSensor

# --- F5: critical tolerances as the terminal shows them ------------------------------------------

CRITICAL = 0.4552137502
"""quadrilateral & rectangle-2x1's critical tolerance: 0.455213 works, 0.455214 does not."""

DESIGN = {
    "sensor_model": "tolerance",
    "critical_tolerance_mm": CRITICAL,
    "pairs": [{"a": "quad25/up", "b": "quad25/down", "critical_tolerance_mm": CRITICAL}],
    "lengths": [
        {"tolerance_mm": [0.0, 0.3 - 1e-12], "length": 3, "expected": 2.5},
        {"tolerance_mm": [0.3 - 1e-12, CRITICAL], "length": 5, "expected": 3.25},
    ],
    "model": "strong plans at the declared uncertainty",
    "answer": "this mix is recognizable with a tolerance up to 0.455213 mm",
}


def test_the_design_section_never_rounds_a_critical_tolerance_up():
    html = design_section(DESIGN)
    assert "0.455214" not in html  # num(x, 6) rounded it up: compiling there fails
    assert "0.3 &lt; tolerance &le; 0.455213 mm" in html  # the steps, both ends
    assert "0 &lt; tolerance &le; 0.3 mm" in html  # float noise is not shown as 0.299999
    assert "<td>quad25/up</td><td>quad25/down</td><td>0.455213 mm</td>" in html  # the pairs
    assert "critical 0.455213 mm" in html  # the plot's mark
    led = design_section(DESIGN, LedSensor(0.1, 0.02))
    assert "within the 0.455213 mm that keeps the mix recognizable" in led
    assert "0.455214" not in led


def test_the_report_shows_tolerances_as_the_terminal_does():
    # One rule (feederkit.design.sensor.shown_tolerance), which the reports layer may not import.
    rng = random.Random(66)
    values = [CRITICAL, 0.3 - 1e-12, 0.3, 6.0274084767, 0.000123456789, 0.0, 12.5, 1e-7]
    values += [rng.uniform(0.0, 10.0) for _ in range(500)]
    values += [round(rng.uniform(0.0, 2.0), rng.randint(1, 8)) for _ in range(500)]
    for x in values:
        assert tolerance_mm(x) == shown_tolerance(x), x
        assert float(tolerance_mm(x)) <= float(f"{x:.9g}")
