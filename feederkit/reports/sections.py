"""The text sections of the changeover report: mix and sensor, statistics, look-alikes, conventions.

Each function returns an HTML fragment; every value that comes from outside is escaped.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from feederkit.errors import InputError
from feederkit.reports.planview import PlanView, leaves
from feederkit.reports.svgkit import esc, num
from feederkit.reports.trace import Confusion, plan_depth
from feederkit.reports.tree_html import Drawing, path_text
from feederkit.sensors import LedSensor, ToleranceSensor, sensor_from_dict

CONVENTIONS = (
    "Part frame: the outline's own coordinates, in millimetres; the contact polygon is the "
    "convex hull of the outline, counter-clockwise, vertex 0 its lowest-then-leftmost vertex, "
    "edge i joining vertex i to vertex i+1. The COM is the area centroid of the plate with its "
    "holes unless one was given. theta is the direction, in the part frame, of the fence's "
    "contact normal pointing from the COM toward the fence; edge e rests on the fence when theta "
    "equals its outward normal. An action a rotates the part counter-clockwise seen from above "
    "before the next push (theta' = theta - a), reported in [0, 360). The belt moves toward "
    "world -y and the fence lies below the part; a part's pose is the counter-clockwise rotation "
    "of its part frame into the world, pose = -90 - normal(e). A plan's length is its worst-case "
    "number of push-align operations, the first alignment counting as operation 1. Readings are "
    "diameters in mm; a branch's range [lo, hi] is closed."
)
"""The conventions paragraph (design.md), used when the plan file carries none."""


def sensor_text(sensor: Mapping[str, Any]) -> str:
    """The sensor model and its parameters, for people."""
    model = sensor_from_dict(dict(sensor))
    if isinstance(model, ToleranceSensor):
        return f"diameter sensor: a reading lies within \u00b1{num(model.tolerance, 4)} mm of it"
    if isinstance(model, LedSensor):
        return (
            f"LED array: beams every {num(model.pitch, 4)} mm, alignment noise "
            f"{num(model.noise, 4)} mm; the reading is the blocked beams times the pitch"
        )
    return "no sensor: a sensorless plan"


def mix_section(view: PlanView, draw: Drawing) -> str:
    """The parts of the mix (with their colours), the sensor and the plan's verdict in brief."""
    items = "".join(
        f'<li><span class="swatch" style="background:{draw.colours[p.name]}"></span>'
        f'<a href="#part-{i}">{esc(p.name)}</a>'
        + (f' <span class="muted">rev {esc(p.revision)}</span>' if p.revision else "")
        + f' <span class="muted">\u00b7 {len(p.states)} stable states</span></li>'
        for i, p in enumerate(view.parts)
    )
    return (
        f'<section id="mix"><h2>Mix and sensor</h2><ul class="mix">{items}</ul>'
        f"<p><strong>Sensor:</strong> {esc(sensor_text(view.sensor))}</p></section>"
    )


def _stat(stats: Mapping[str, Any], key: str) -> float | None:
    v = stats.get(key)
    if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
        return float(v)
    return None


def _row(label: str, value: str) -> str:
    return f"<tr><th>{esc(label)}</th><td>{value}</td></tr>"


def stats_section(
    view: PlanView,
    seconds_per_op: float | None,
    simulation: Mapping[str, Any] | None,
) -> str:
    """Length, expected length, smallest margin, optimality, cycle time, simulation results."""
    stats = view.stats
    length = _stat(stats, "length")
    if length is None:
        length = float(plan_depth(view.root))
    expected = _stat(stats, "expected_length")
    margin = _stat(stats, "min_margin_deg")
    bound = _stat(stats, "lower_bound")
    optimal = stats.get("optimal")
    rows = [
        _row("worst-case length", f"{num(length)} push-align operations"),
        _row("expected length", "not given" if expected is None else f"{num(expected)} operations"),
        _row("smallest margin", "none" if margin is None else f"\u00b1{num(margin, 2)}\u00b0"),
    ]
    opt = {True: "yes: no shorter plan exists", False: "not proven"}.get(optimal, "not stated")
    if bound is not None:
        opt += f" (lower bound {num(bound)})"
    rows.append(_row("optimal", esc(opt)))
    if seconds_per_op is None:
        rows.append(_row("cycle time", "give seconds per operation to see it"))
    else:
        worst = f"{num(length * seconds_per_op, 2)} s worst case"
        mean = "" if expected is None else f"{num(expected * seconds_per_op, 2)} s expected, "
        rows.append(
            _row("cycle time", f"{mean}{worst} at {num(seconds_per_op, 3)} s per operation")
        )
    if simulation is not None:
        rows.append(_row("simulation", esc(simulation_text(simulation))))
    table = f'<table class="kv">{"".join(rows)}</table>'
    return f'<section id="stats"><h2>Statistics</h2>{table}</section>'


def simulation_text(simulation: Mapping[str, Any]) -> str:
    """``successes of trials (rate)`` and any other plain values the simulator reported."""
    trials, successes = simulation.get("trials"), simulation.get("successes")
    if (
        not isinstance(trials, int)
        or not isinstance(successes, int)
        or isinstance(trials, bool)
        or isinstance(successes, bool)
    ):
        raise InputError("simulation results need integer 'trials' and 'successes'")
    rate = f" ({num(100.0 * successes / trials, 1)}%)" if trials > 0 else ""
    extra = [
        f"{k} {num(v, 4) if isinstance(v, float) else v}"
        for k, v in simulation.items()
        if k not in ("trials", "successes") and isinstance(v, str | int | float | bool)
    ]
    return f"{successes} of {trials} trials oriented correctly{rate}" + (
        f"; {', '.join(extra)}" if extra else ""
    )


def _states(ids: Sequence[object]) -> str:
    return ", ".join(f"s{i}" for i in ids) if ids else "-"


def _pairing(a: str, b: str, states_a: Sequence[object], states_b: Sequence[object]) -> str:
    """``a s0 ~ b s2, ...`` when the states pair up one to one, else both lists."""
    if states_a and len(states_a) == len(states_b):
        return ", ".join(f"{a} s{i} ~ {b} s{j}" for i, j in zip(states_a, states_b, strict=True))
    return f"{a}: {_states(states_a)}; {b}: {_states(states_b)}"


def _plan_rows(confusions: Sequence[Confusion]) -> list[str]:
    """One row per pair of parts the plan's leaves hold together, every such leaf a witness."""
    grouped: dict[tuple[str, str], list[Confusion]] = {}
    for c in confusions:
        grouped.setdefault((c.part_a, c.part_b), []).append(c)
    rows = []
    for (a, b), cs in grouped.items():
        states = "; ".join(_pairing(a, b, c.states_a, c.states_b) for c in cs)
        paths = "".join(f"<li>leaf {c.node_id}: {esc(path_text(c.path))}</li>" for c in cs)
        rows.append(
            f'<tr class="pair" data-source="plan"><td>{esc(a)}</td><td>{esc(b)}</td>'
            f"<td>{esc(states)}</td><td>the plan ends with both at<ul>{paths}</ul></td></tr>"
        )
    return rows


def _given_rows(given: Sequence[Mapping[str, Any]]) -> list[str]:
    """Rows for the pairs the mix analysis found, with its reason."""
    rows = []
    for i, pair in enumerate(given):
        if not isinstance(pair, Mapping):
            raise InputError(f"unrecognizable pair {i} must be a mapping")
        a, b = str(pair.get("part_a", "?")), str(pair.get("part_b", "?"))
        states = _pairing(a, b, list(pair.get("states_a") or []), list(pair.get("states_b") or []))
        rows.append(
            f'<tr class="pair" data-source="mix"><td>{esc(a)}</td><td>{esc(b)}</td>'
            f"<td>{esc(states)}</td><td>{esc(pair.get('reason', ''))}</td></tr>"
        )
    return rows


def lookalike_section(
    view: PlanView, confusions: Sequence[Confusion], given: Sequence[Mapping[str, Any]]
) -> str:
    """Pairs of parts that cannot be told apart, with their witnesses, and symmetric leaves."""
    rows = _plan_rows(confusions) + _given_rows(given)
    if rows:
        body = (
            "<p>These parts behave alike under every push-align operation the sensor can "
            "tell apart; a plan can orient them but not say which part it holds.</p>"
            '<table class="grid"><tr><th>part</th><th>look-alike</th>'
            f"<th>inseparable states</th><th>witness</th></tr>{''.join(rows)}</table>"
        )
    elif len(view.parts) > 1:
        body = "<p>Every part of the mix is recognized: no leaf of the plan holds two parts.</p>"
    else:
        body = "<p>One part only: nothing to recognize.</p>"
    sym = [
        leaf
        for leaf in leaves(view.root)
        if len({r.part for r in leaf.results}) == 1 and len(leaf.results) > 1
    ]
    if sym:
        items = "".join(
            f"<li>{esc(leaf.results[0].part)}: states "
            f"{esc(_states([r.state for r in leaf.results]))} at leaf {leaf.node_id}</li>"
            for leaf in sym
        )
        body += (
            "<p>Oriented up to symmetry (poses no plan tells apart; each is a correct answer):"
            f"</p><ul>{items}</ul>"
        )
    return f'<section id="lookalikes"><h2>Parts the plan cannot tell apart</h2>{body}</section>'


def conventions_section(view: PlanView) -> str:
    """The conventions in one paragraph, and how the drawings show them."""
    text = view.conventions or CONVENTIONS
    return (
        f'<section id="conventions"><h2>Conventions</h2><p>{esc(text)}</p>'
        "<p>Drawings: each part is seen from above, resting on the fence (the dark bar) with the "
        "belt moving down the page; the dot is the COM; all parts of the mix share one scale."
        "</p></section>"
    )
