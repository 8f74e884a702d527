"""Reading intervals that hold the part itself, not only its model.

A plan is made on the parts' contact hulls, which import may simplify; the part itself can
read a little more or less than its model's diameter
(:mod:`feederkit.mechanics.modelerror`). A controller follows the branch whose closed
interval holds the reading and stops when none does (design.md), so each branch's interval
is widened by the offsets of the states that may read in it, up to its sibling branches'
intervals: readings no model state gives then lead where the part itself belongs. Where a
sibling is in the way, the part may read in the wrong branch, and the member is named.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.mechanics.modelerror import Offset
from feederkit.sensors import Sensor

StateOffsets = Sequence[Sequence[Offset | None]]
"""Per part of the plan file, per stable state: its reading offset (mm) or None."""


def widen_readings(
    data: dict[str, Any], offsets: StateOffsets, sensor: Sensor
) -> tuple[float, set[int]]:
    """Widen ``data``'s branch intervals in place: a state of diameter ``d`` that can read
    in a branch may, as the part itself, give any reading ``sensor`` gives for a diameter
    in ``[d + lo, d + hi]`` (its offset ``(lo, hi)``; for a tolerance ``e``, the interval
    ``(d + lo - e, d + hi + e)``). Returns the largest widening (mm) and the parts (indices
    into ``data["parts"]``) with a state that may still read outside its branch, because a
    sibling branch's interval is in the way. Nothing changes sensorless.

    >>> leaf = {"result": []}
    >>> node = {"action_deg": None, "margin_deg": None, "branches": [
    ...     {"reading": [9.5, 10.5], "next": leaf}, {"reading": [19.5, 20.5], "next": leaf}]}
    >>> data = {"parts": [{"stable_states": [{"diameter": 10.0}, {"diameter": 20.0}]}],
    ...         "root": node}
    >>> from feederkit.sensors import ToleranceSensor
    >>> widest, blocked = widen_readings(data, [[(0.0, 0.02), None]], ToleranceSensor(0.5))
    >>> round(widest, 9), blocked
    (0.02, set())
    >>> node["branches"][0]["reading"]
    [9.5, 10.52]
    """
    states = [
        (p, float(s["diameter"]), off)
        for p, part in enumerate(data["parts"])
        for s, off in zip(part["stable_states"], offsets[p], strict=True)
        if off is not None and (off[0] < 0.0 or off[1] > 0.0)
    ]
    widest, blocked = 0.0, set()
    if not states or not sensor.informative:
        return widest, blocked
    for node in _steps(data):
        readings = [b["reading"] for b in node["branches"]]
        if any(r is None for r in readings):
            continue
        wanted = []
        for lo, hi in readings:
            new_lo, new_hi, who = lo, hi, []
            for p, d, (off_lo, off_hi) in states:
                if sensor.reads_into(d, lo, hi):  # it may read in this branch
                    reach = sensor.reading_interval((d + off_lo, d + off_hi))
                    assert reach is not None  # an informative sensor reads
                    new_lo, new_hi = min(new_lo, reach[0]), max(new_hi, reach[1])
                    who.append(p)
            wanted.append((new_lo, new_hi, who))
        # Siblings in reading order: where two want the same gap (or more), they meet at
        # its middle and both may misread; else each takes what it wants.
        order = sorted(range(len(readings)), key=lambda k: readings[k][0])
        lows = {k: max(wanted[k][0], 0.0) for k in order}
        highs = {k: wanted[k][1] for k in order}
        for a, b in zip(order, order[1:], strict=False):
            if highs[a] > lows[b]:
                gap_lo, gap_hi = readings[a][1], readings[b][0]
                meet = min(max((highs[a] + lows[b]) / 2.0, gap_lo), gap_hi)
                highs[a], lows[b] = meet, meet
                blocked.update(wanted[a][2])
                blocked.update(wanted[b][2])
        for k, branch in enumerate(node["branches"]):
            lo, hi = readings[k]
            widest = max(widest, lo - lows[k], highs[k] - hi)
            branch["reading"] = [lows[k], highs[k]]
    return widest, blocked


def _steps(data: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The plan's step nodes, each once (shared subplans live in ``data["nodes"]``)."""
    out: list[dict[str, Any]] = []
    seen: set[int] = set()
    stack = [data["root"], *data.get("nodes", {}).values()]
    while stack:
        node = stack.pop()
        if id(node) in seen or "branches" not in node:
            continue
        seen.add(id(node))
        out.append(node)
        stack.extend(b["next"] for b in node["branches"])
    return out
