"""The text sections of the changeover report: mix and sensor, statistics, look-alikes, conventions.

Each function returns an HTML fragment; every value that comes from outside is escaped.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from feederkit.cell import expectation_words
from feederkit.errors import InputError
from feederkit.plans.model import (
    REJECTED_WORDS,
    UNRECOGNIZED_WORDS,
    Member,
    Plan,
    member_label,
    member_name,
    pairs_words,
    robust_ideal_words,
)
from feederkit.reports.svgkit import esc, num
from feederkit.reports.trace import Confusion
from feederkit.reports.tree_html import Drawing, path_text
from feederkit.reports.twins import TwinLeaf

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


def mix_section(plan: Plan, draw: Drawing) -> str:
    """The members of the mix (a part, or a part in one landing: design.md "Landings") with
    their colours and prior shares, the sensor."""
    shares = plan.shares() if all(p.share is not None for p in plan.parts) else None
    items = "".join(
        f'<li><span class="swatch" style="background:{draw.colours[i]}"></span>'
        f'<a href="#part-{i}">{esc(p.label)}</a>'
        + (f' <span class="muted">rev {esc(str(p.revision))}</span>' if p.revision else "")
        + f' <span class="muted">\u00b7 {len(p.states)} stable states</span>'
        + (
            ""
            if shares is None
            else f' <span class="muted">\u00b7 share {num(100.0 * shares[i], 3)}%</span>'
        )
        + "</li>"
        for i, p in enumerate(plan.parts)
    )
    return (
        f'<section id="mix"><h2>Mix and sensor</h2><ul class="mix">{items}</ul>'
        f"<p><strong>Sensor:</strong> {esc(plan.sensor.describe())}</p></section>"
    )


def _row(label: str, value: str) -> str:
    return f"<tr><th>{esc(label)}</th><td>{value}</td></tr>"


def stats_section(
    plan: Plan,
    seconds_per_op: float | None,
    simulation: Mapping[str, Any] | None,
    cycle_time: Mapping[str, Any] | None = None,
) -> str:
    """Length, expected length, smallest margin, the declared uncertainty and the certificate
    (design.md, "Uncertainty"), optimality, cycle time, simulation results.

    ``cycle_time`` is the plan's ``stats.cycle_time`` (:func:`feederkit.cell.cycle_time_dict`:
    seconds per part in the cell profile it names); without it, ``seconds_per_op`` gives a
    flat cycle time (the same seconds for every operation)."""
    stats = plan.stats
    length = float(stats.length)
    expected = stats.expected_length
    margin = stats.min_margin_deg
    shown_margin = "none (no rotation)" if margin is None else f"\u00b1{num(margin, 2)}\u00b0"
    if margin is not None and margin < 0.005:
        shown_margin = f"\u00b1{margin:.2g}\u00b0"  # never round a tiny margin to 0
    rows = [
        _row("worst-case length", f"{num(length)} push-align operations"),
        _row(
            "expected length", f"{num(expected)} operations ({esc(expectation_words(plan.parts))})"
        ),
        _row("smallest margin", esc(shown_margin)),
        _row("declared uncertainty", esc(plan.uncertainty_words())),
    ]
    cert = stats.certificate
    if cert is not None:
        rows += [
            _row(
                "certified rotation error",
                f"up to \u00b1{num(cert.max_rotation_error_deg, 3)}\u00b0",
            ),
            _row("certified shape tolerance", f"up to {num(cert.max_shape_tolerance_mm, 4)} mm"),
            _row(
                "length: robust / ideal model",
                esc(robust_ideal_words(stats.length, cert.ideal_length)),
            ),
        ]
    opt = "yes: no shorter plan exists" if stats.optimal else "not proven"
    opt += f" (lower bound {stats.lower_bound})"
    rows.append(_row("optimal", esc(opt)))
    if cycle_time is not None:
        rows += _cycle_rows(cycle_time)
    elif seconds_per_op is None:
        rows.append(_row("cycle time", "not known: give a cell profile with timing (docs/cell.md)"))
    else:
        worst = f"{num(length * seconds_per_op, 2)} s worst case"
        mean = f"{num(expected * seconds_per_op, 2)} s expected, "
        rows.append(
            _row("cycle time", f"{mean}{worst} at {num(seconds_per_op, 3)} s per operation")
        )
    if simulation is not None:
        rows.append(_row("simulation", esc(simulation_text(simulation))))
    table = f'<table class="kv">{"".join(rows)}</table>'
    return f'<section id="stats"><h2>Statistics</h2>{table}</section>'


def _cycle_rows(cycle: Mapping[str, Any]) -> list[str]:
    """Expected and worst seconds per part and parts per minute, naming the profile."""
    try:
        exp, worst = float(cycle["expected_s"]), float(cycle["worst_s"])
        profile = str(cycle["profile"])
    except (KeyError, TypeError, ValueError):
        raise InputError(
            "stats cycle_time needs expected_s, worst_s and profile (docs/cell.md)"
        ) from None

    def rate(seconds: float) -> str:
        return "" if seconds <= 0.0 else f", {num(60.0 / seconds, 1)} parts per minute"

    return [
        _row("cycle time, expected", f"{num(exp, 2)} s per part{rate(exp)}"),
        _row("cycle time, worst case", f"{num(worst, 2)} s per part{rate(worst)}"),
        _row("cell profile", esc(profile)),
    ]


def _count(value: object) -> int | None:
    if isinstance(value, list | tuple):
        return len(value)
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    return None


def _int(value: object) -> int | None:
    return value if isinstance(value, int) and not isinstance(value, bool) else None


def simulation_text(simulation: Mapping[str, Any]) -> str:
    """The simulator's result in words, from the summary ``feederkit simulate --json`` prints
    (``SimulationSummary.to_dict``, docs/simulation.md), in the command line's words: the
    successes with their 95 % Wilson interval (the rightly rejected and the unrecognized
    counted apart), what
    was sampled and the seed, the failures by cause, the model errors, per part, the push
    agreement, and the notes on what the plan certifies, the simulator's width accuracy, a
    part simulated at another size than its own and a part simulated beyond the plan's
    declared shape tolerance."""
    trials, successes = _int(simulation.get("trials")), _int(simulation.get("successes"))
    if trials is None or successes is None:
        raise InputError("simulation results need integer 'trials' and 'successes'")
    rate = f" ({num(100.0 * successes / trials, 1)}%)" if trials > 0 else ""
    shown = simulation.get("success_words")
    success = shown if isinstance(shown, str) else f"{successes} of {trials}{rate}"
    rejects = _int(simulation.get("rejects")) or 0
    unrecognized = _int(simulation.get("unrecognized")) or 0
    if rejects or unrecognized:
        kinds = [f"{successes - rejects - unrecognized} oriented correctly"]
        kinds += [f"{rejects} {REJECTED_WORDS}"] if rejects else []
        kinds += [f"{unrecognized} {UNRECOGNIZED_WORDS}"] if unrecognized else []
        words = [f"successes: {success}, " + " and ".join(kinds)]
    else:
        words = [f"successes (oriented correctly): {success}"]
    settings = simulation.get("settings")
    if isinstance(settings, Mapping):
        sampled, seed = settings.get("sampled"), _int(settings.get("seed"))
        if isinstance(sampled, str):
            words.append(sampled)
        if seed is not None:
            words.append(f"seed {seed}")
    failed, unsettled = _count(simulation.get("failures")), _count(simulation.get("unsettled"))
    if failed is not None or unsettled is not None:
        went = f"failures {failed or 0}, never settled {unsettled or 0}"
        by_cause = simulation.get("by_cause")
        if isinstance(by_cause, Mapping) and by_cause:
            went += " (" + ", ".join(f"{c}: {n}" for c, n in by_cause.items()) + ")"
        wrong = _int(simulation.get("wrong_accepts"))
        if wrong:
            went += f", of them {wrong} wrong accepts (accepted, landing or state wrong)"
        words.append(went)
    model_errors = _int(simulation.get("model_errors"))
    if model_errors is not None:
        words.append(f"{model_errors} went where the plan's model did not predict (model errors)")
    per_part = simulation.get("per_part")
    if isinstance(per_part, list) and len(per_part) > 1:
        words.append(
            ", ".join(
                f"{p.get('part')}: {p.get('successes')} of {p.get('trials')}"
                for p in per_part
                if isinstance(p, Mapping)
            )
        )
    agree, settled = simulation.get("push_agreements"), simulation.get("settled_pushes")
    pushes = simulation.get("push_words")
    if isinstance(pushes, str) and pushes:
        words.append(pushes)
    elif isinstance(agree, int) and isinstance(settled, int) and settled > 0:
        words.append(f"{agree} of {settled} settled pushes ended where the push function says")
    for key, label in (("beyond_certified", "note"), ("width_accuracy_warning", "warning")):
        text = simulation.get(key)
        if isinstance(text, str) and text:
            words.append(f"{label}: {text}")
    scaled = simulation.get("scale_notes")  # a part simulated at another size than its own
    if isinstance(scaled, list):
        words += [f"note: {n}" for n in scaled if isinstance(n, str) and n]
    geometry = simulation.get("warnings")  # with --part: a part beyond the shape tolerance
    if isinstance(geometry, list):
        words += [f"warning: {w}" for w in geometry if isinstance(w, str) and w]
    return "; ".join(words)


def _states(ids: Sequence[object]) -> str:
    return ", ".join(f"s{i}" for i in ids) if ids else "-"


def _pairing(a: str, b: str, states_a: Sequence[object], states_b: Sequence[object]) -> str:
    """``a s0 ~ b s2, ...`` when the states pair up one to one, else both lists."""
    if states_a and len(states_a) == len(states_b):
        return ", ".join(f"{a} s{i} ~ {b} s{j}" for i, j in zip(states_a, states_b, strict=True))
    return f"{a}: {_states(states_a)}; {b}: {_states(states_b)}"


def _unique(items: Sequence[str]) -> list[str]:
    return list(dict.fromkeys(items))


@dataclass
class PairRow:
    """A pair of members no plan tells apart, as the report shows it: the members (``a``,
    ``b``: ``(part, landing)``), where the row comes from (``plan``: a leaf holds both;
    ``mix``: the mix analysis alone), the inseparable state pairings (the mix analysis's
    witness when it has one, as the terminal and ``--json`` give it; else the states a leaf
    lists together), the leaves that hold both (each a witness) and the reasons."""

    a: Member
    b: Member
    source: str
    listed: list[str] = field(default_factory=list)
    witness: list[str] = field(default_factory=list)
    paths: list[str] = field(default_factory=list)
    why: list[str] = field(default_factory=list)

    @property
    def states(self) -> str:
        """The inseparable states in words (the witness's, else the leaves')."""
        if self.witness:
            return "; ".join(_unique(self.witness))
        return "listed together: " + "; ".join(_unique(self.listed)) if self.listed else ""

    def reason(self, plan: Plan) -> str:
        """The mix analysis's reason; for a pair only a strong plan's results list together
        (the ideal model tells it apart), what holds of it."""
        if self.why:
            return "; ".join(_unique(self.why))
        if plan.uncertainty.is_ideal:
            return ""
        return (
            "told apart on the ideal model, but this plan, strong for its declared uncertainty "
            f"({plan.uncertainty_words()}), lists them together: no strong plan tells them apart"
        )


def pair_rows(
    plan: Plan, confusions: Sequence[Confusion], given: Sequence[Mapping[str, Any]]
) -> list[PairRow]:
    """One row per pair of members, whichever order they are named in: the plan's leaves
    that hold both (:func:`~feederkit.reports.trace.confusions`) and the mix analysis's
    pairs ``given`` (``PART/LANDING`` names, :func:`member_name`), no pairing listed twice."""
    by_label = {p.label: p.key for p in plan.parts}
    by_name = {member_name(*p.key): p.key for p in plan.parts}
    rows: dict[frozenset[Member], PairRow] = {}

    def row(a: Member, b: Member, source: str) -> PairRow:
        key = frozenset((a, b))
        if key not in rows:
            rows[key] = PairRow(a, b, source)
        return rows[key]

    for c in confusions:
        r = row(by_label[c.part_a], by_label[c.part_b], "plan")
        r.listed.append(_pairing(c.part_a, c.part_b, c.states_a, c.states_b))
        r.paths.append(f"leaf {c.node_id}: {path_text(c.path)}")
    for i, pair in enumerate(given):
        if not isinstance(pair, Mapping):
            raise InputError(f"unrecognizable pair {i} must be a mapping")
        names = (str(pair.get("part_a", "?")), str(pair.get("part_b", "?")))
        a, b = (by_name.get(n, (n, None)) for n in names)
        r = row(a, b, "mix")
        sa, sb = list(pair.get("states_a") or []), list(pair.get("states_b") or [])
        if r.a != a:  # named the other way round: keep the row's order
            a, b, sa, sb = b, a, sb, sa
        r.witness.append(_pairing(member_label(*a), member_label(*b), sa, sb))
        if pair.get("reason"):
            r.why.append(str(pair["reason"]))
    return list(rows.values())


def unrecognized_words(plan: Plan, rows: Sequence[PairRow]) -> str | None:
    """The pairs no plan tells apart in the words of ``plan`` and ``changeover compile``
    (:func:`~feederkit.plans.model.pairs_words`); None when there are none."""
    if not rows:
        return None
    return pairs_words("this plan", [(r.a, r.b, r.reason(plan) or "no reason given") for r in rows])


def _row_html(plan: Plan, r: PairRow) -> str:
    witness = ""
    if r.paths:
        items = "".join(f"<li>{esc(p)}</li>" for p in _unique(r.paths))
        witness = f"the plan ends with both at<ul>{items}</ul>"
    why = r.reason(plan)
    return (
        f'<tr class="pair" data-source="{r.source}"><td>{esc(member_label(*r.a))}</td>'
        f"<td>{esc(member_label(*r.b))}</td><td>{esc(r.states)}</td>"
        f"<td>{esc(why)}{' ' if why and witness else ''}{witness}</td></tr>"
    )


_SIDES = (
    " Two landings of one part: the part is known, but not which side is up (or which pose it "
    "lies in), so it is not oriented."
)


def lookalike_section(
    plan: Plan,
    confusions: Sequence[Confusion],
    given: Sequence[Mapping[str, Any]],
    twins: Sequence[TwinLeaf] = (),
) -> str:
    """Pairs of parts that cannot be told apart, with their witnesses, then the leaves that
    list several poses of one part (``twins``): those that look alike, each a correct answer,
    apart from those that do not, between which the part is not oriented."""
    found = pair_rows(plan, confusions, given)
    rows = [_row_html(plan, r) for r in found]
    sides = any(r.a[0] == r.b[0] for r in found)
    if rows:
        body = (
            "<p>No plan tells these apart with this sensor"
            f"{'' if plan.uncertainty.is_ideal else ' at the declared uncertainty'}: whatever "
            "push-align operations follow, their readings may agree (they behave alike, or "
            "differ by less than the sensor resolves), so a result lists both, each with its "
            "state and pose, and the controller does not know which it holds."
            f"{_SIDES if sides else ''}</p>"
            '<table class="grid"><tr><th>part</th><th>look-alike</th>'
            f"<th>inseparable states</th><th>why, and witness</th></tr>{''.join(rows)}</table>"
        )
    elif len(plan.parts) > 1:
        what = "member (part and landing)" if plan.over_landings else "part"
        body = (
            f"<p>Every {what} of the mix is recognized: no accepting leaf of the plan holds "
            f"two.</p>"
        )
    else:
        body = "<p>One part only: nothing to recognize.</p>"
    body += _alike_poses(plan, [t for t in twins if t.oriented and not t.merged])
    body += _merged_poses(plan, [t for t in twins if t.oriented and t.merged])
    body += _unoriented_poses(plan, [t for t in twins if not t.oriented])
    return f'<section id="lookalikes"><h2>Parts the plan cannot tell apart</h2>{body}</section>'


def _twin_items(plan: Plan, twins: Sequence[TwinLeaf]) -> str:
    """One list item per leaf: the member, its states and the leaf (and, of more than two
    poses, which do not look alike)."""
    return "".join(
        f"<li>{esc(plan.parts[t.member].label)}: states {esc(_states(t.states))} at leaf "
        f"{t.node_id}{esc(_unlike_words(t))}</li>"
        for t in twins
    )


def _alike_poses(plan: Plan, twins: Sequence[TwinLeaf]) -> str:
    """The leaves whose listed poses of one part look alike: each is a correct answer.
    Compared on the contact hull alone (no outline given: a plan file records none), they
    are a correct answer only if the holes and notches look alike too, which is not known
    here."""
    seen = [t for t in twins if t.outline]
    hull = [t for t in twins if not t.outline]
    out = ""
    if seen:
        out += (
            '<p id="alike-poses">Poses no plan tells apart that look alike (symmetric or '
            f"nearly so; each is a correct answer):</p><ul>{_twin_items(plan, seen)}</ul>"
        )
    if hull:
        out += (
            '<p id="alike-hulls">Poses no plan tells apart whose contact hulls look alike '
            "(symmetric or nearly so): each is a correct answer if the outlines, holes and "
            "notches included, look alike too. The plan file records only the hull; plan and "
            "changeover compile compare the outlines, name the poses that do not look alike "
            f"and exit 1:</p><ul>{_twin_items(plan, hull)}</ul>"
        )
    return out


def _unlike_words(twin: TwinLeaf) -> str:
    """Which of a leaf's poses do not look alike, when it lists more than two."""
    if len(twin.states) < 3 or not twin.unlike:  # all alike: nothing to name
        return ""
    return ", not alike: " + ", ".join(f"s{a} and s{b}" for a, b in twin.unlike)


def _merged_poses(plan: Plan, twins: Sequence[TwinLeaf]) -> str:
    """The leaves whose listed poses of one part are one resting state of the declared
    uncertainty's model (:attr:`TwinLeaf.merged`): oriented only as far as that state."""
    if not twins:
        return ""
    return (
        '<p id="merged-poses">Resting states made of several stable states, shallow wells a '
        "breath of vibration crosses (docs/uncertainty.md): the part rests anywhere over "
        f"those poses, oriented only that far:</p><ul>{_twin_items(plan, twins)}</ul>"
    )


def _unoriented_poses(plan: Plan, twins: Sequence[TwinLeaf]) -> str:
    """The leaves whose listed poses of one part do not look alike: not oriented between
    them."""
    if not twins:
        return ""
    items = _twin_items(plan, twins)
    return (
        '<p id="unoriented-poses" class="warn">Poses no plan tells apart that do not look '
        "alike (holes, slots or notches placed otherwise, or a push function that repeats): "
        "the part is not oriented between them; check its pose by other means, or take it "
        f"either way:</p><ul>{items}</ul>"
    )


def conventions_section(plan: Plan) -> str:
    """The conventions in one paragraph, and how the drawings show them."""
    text = plan.conventions or CONVENTIONS
    return (
        f'<section id="conventions"><h2>Conventions</h2><p>{esc(text)}</p>'
        "<p>Drawings: each part is seen from above, resting on the fence (the dark bar) with the "
        "belt moving down the page; the dot is the COM; all parts of the mix share one scale."
        "</p></section>"
    )
