"""A plan says when its certificate does not cover a part made to its drawing.

The import simplifies a drawn outline's contact hull (``--hull-tolerance``, 0.05 mm by
default for drawings); the declared shape tolerance and the plan's certificate are measured
from that hull. A 40 x 25 plate with 0.5 mm fillets stored with ``--shape-tolerance 0.01``
got a plan "certified to 0.01 mm" whose hull lay 0.037 mm from the drawing: not even the
part as drawn was inside the zone, and only ``simulate --part`` said so.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf

from feederkit.cli.app import main


def _filleted_plate(path: Path, r: float = 0.5) -> Path:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    w, h, b = 40.0, 25.0, math.tan(math.radians(90.0) / 4.0)
    pts = [
        (r, 0, 0), (w - r, 0, b), (w, r, 0), (w, h - r, b),
        (w - r, h, 0), (r, h, b), (0, h - r, 0), (0, r, b),
    ]  # fmt: skip
    doc.modelspace().add_lwpolyline(pts, format="xyb", close=True)
    doc.saveas(path)
    return path


def test_a_plan_whose_certificate_misses_the_drawing_says_so(tmp_path: Path, capsys) -> None:
    src = str(_filleted_plate(tmp_path / "plate.dxf"))
    args = ["plan", src, "--tolerance", "0.2", "--landings", "up", "-o", str(tmp_path / "p.json")]
    assert main([*args, "--shape-tolerance", "0.01"]) in (0, 1)
    err = " ".join(capsys.readouterr().err.split())
    assert "the plan's hulls simplify the drawings" in err
    assert "is not covered by the certificate" in err
    # Imported exactly (no simplification), the drawing is the hull: nothing to say.
    assert main([*args, "--shape-tolerance", "0.01", "--hull-tolerance", "0"]) in (0, 1)
    assert "the plan's hulls simplify the drawings" not in capsys.readouterr().err
