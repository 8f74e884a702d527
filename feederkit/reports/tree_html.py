"""The plan as a tree in HTML: each node the possible states drawn as parts in their poses.

Markup contract (tests and scripts rely on it): every distinct plan node is one element of
class ``tree-node`` with ``data-node-id`` (pre-order of distinct nodes, root 0); operation
nodes also have class ``op``, leaves class ``result`` and their kind: ``known``,
``symmetric`` (poses of one part that look alike), ``unoriented`` (poses of one part that do
not: :mod:`feederkit.reports.twins`), ``confused`` or ``reject``; a node
several branches lead to (design.md's ``"nodes"``) is drawn once, at its first place (a shared
subplan with ``data-shared``: ``S1``, ``S2``, ... in the order drawn, as ``plan_tree`` names
them), and each other place is one ``div.tree-ref`` with ``data-ref`` (the node id); each
drawn state is a figure with ``data-part``, ``data-landing`` (empty when the plan is not over
landings) and ``data-state``, a final pose of a leaf a ``figure.final-pose`` also with
``data-pose-deg``; each edge is one ``div.edge`` with ``data-action-deg`` (empty at the root)
and ``data-reading`` (``lo..hi``, empty when sensorless). A drawing stopped by its size
ends with one ``li.tree-stop`` with ``data-operations`` and ``data-results`` (left out).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from feederkit.plans.model import Branch, Leaf, Plan, Step, side_words
from feederkit.reports.svgkit import Ring, esc, num, part_colour, pose_svg, reach
from feederkit.reports.trace import Place, StateKey, Trace, TraceStep, leaf_members
from feederkit.reports.twins import TwinLeaf

STATE_PX = 56
"""Drawn size of a possible state inside an operation node."""

FINAL_PX = 72
"""Drawn size of a final pose in a leaf."""

TREE_FIGURES = 10_000
"""The tree stops drawing nodes once it has drawn this many states (about 1.4 KB of SVG
each): the plan of a 50-part mix drew 111,656 of them, a 151 MB page no browser shows well.
Its last item says how much it left out; the plan file has all of it."""


SMALLEST_DRAWN = 0.25
"""A member is drawn at least this share of the mix's scale across: a part of a mix whose
largest is a hundred times its size was a fence bar and no part (sub-pixel); such a member
is magnified to this share, and its caption says how much."""


@dataclass(frozen=True)
class Drawing:
    """What the tree needs to draw each member (by index in ``plan.parts``): its rings
    (outline and holes, or hull), colour, the one scale of the mix (``radius_mm``) and each
    member's own (``radii``: the mix's, or smaller for a member magnified,
    :data:`SMALLEST_DRAWN`)."""

    rings: Sequence[Sequence[Ring]]
    colours: Sequence[str]
    radius_mm: float
    radii: Sequence[float] = ()

    def radius(self, m: int) -> float:
        """The scale member ``m`` is drawn at (mm from the centre to the box's edge)."""
        return self.radii[m] if self.radii else self.radius_mm

    def magnified(self, m: int) -> str:
        """`` ×N`` for a member drawn larger than the mix's scale, else ``""``."""
        times = self.radius_mm / self.radius(m)
        return f" \u00d7{times:.2g}" if times > 1.0 + 1e-9 else ""


def drawing_for(plan: Plan, rings: Sequence[Sequence[Ring]]) -> Drawing:
    """One common scale for the whole mix (small members magnified to
    :data:`SMALLEST_DRAWN` of it), a colour per member in plan order."""
    reaches = [reach(p.hull, p.com) for p in plan.parts]
    scale = max(reaches)
    return Drawing(
        rings=tuple(rings),
        colours=tuple(part_colour(i) for i in range(len(plan.parts))),
        radius_mm=scale,
        radii=tuple(min(scale, r / SMALLEST_DRAWN) for r in reaches),
    )


def reading_text(reading: tuple[float, float] | None) -> str:
    """A reading range for people: one value when the ends agree, ``lo-hi mm`` otherwise."""
    if reading is None:
        return "no reading (sensorless)"
    lo, hi = reading
    if num(lo) == num(hi):
        return f"reads {num(lo)} mm"
    return f"reads {num(lo)}\u2013{num(hi)} mm"


def action_text(action_deg: float | None) -> str:
    """An operation's rotation for people."""
    if action_deg is None:
        return "first alignment"
    return f"rotate {num(action_deg, 2)}\u00b0 ccw"


def path_text(path: Sequence[TraceStep]) -> str:
    """The operations and readings that lead to a node, as one line."""
    if not path:
        return "before the first alignment"
    return " \u2192 ".join(f"{action_text(s.action_deg)}, {reading_text(s.reading)}" for s in path)


def _state_figure(
    plan: Plan, draw: Drawing, key: StateKey, cls: str, px: int, pose: float | None = None
) -> str:
    """A state drawn on the fence; ``pose`` (deg) overrides the state's own pose."""
    m, sid = key
    part = plan.parts[m]
    state = part.state(sid)
    pose_deg = state.pose_deg if pose is None else pose
    label = part.label
    title = f"{label}, state {sid} (edge {state.edge}) on the fence, pose {num(pose_deg, 1)} deg"
    svg = pose_svg(
        draw.rings[m],
        part.hull,
        part.com,
        pose_deg,
        radius_mm=draw.radius(m),
        colour=draw.colours[m],
        px=px,
        title=title,
    )
    return (
        f'<figure class="{cls}" data-part="{esc(part.name)}" '
        f'data-landing="{esc(part.landing or "")}" data-state="{sid}" '
        f'data-pose-deg="{num(pose_deg, 4)}">{svg}'
        f'<figcaption>{esc(label)} s{sid}<span class="pose-deg"> {num(pose_deg, 1)}\u00b0</span>'
        f"{esc(draw.magnified(m))}</figcaption></figure>"
    )


def _edge(parent: Step, branch: Branch) -> str:
    action = "" if parent.action_deg is None else num(parent.action_deg, 6)
    reading = ""
    if branch.reading is not None:
        reading = f"{num(branch.reading[0], 6)}..{num(branch.reading[1], 6)}"
    return (
        f'<div class="edge" data-action-deg="{action}" data-reading="{reading}">'
        f'<span class="act">{esc(action_text(parent.action_deg))}</span>'
        f'<span class="read">{esc(reading_text(branch.reading))}</span></div>'
    )


def _shared_tag(name: str | None) -> tuple[str, str]:
    """The attribute and the head note of a shared subplan's one drawing."""
    if name is None:
        return "", ""
    note = f' <span class="shared-tag">shared subplan {esc(name)}</span>'
    return f' data-shared="{esc(name)}"', note


def unreached_words(plan: Plan) -> str:
    """An operation node the trace reaches with no state, in words. In a strong plan that is
    a branch for the declared uncertainty (design.md, "Uncertainty"): on the nominal push no
    start reaches it, as its leaves say; on the ideal model no state should."""
    if plan.uncertainty.is_ideal:
        return "following the plan, no state reaches it"
    return (
        "on the nominal push (no rotation error) no start reaches it: the declared "
        "uncertainty can bring states here"
    )


def _op_node(plan: Plan, trace: Trace, draw: Drawing, place: Place, shared: str | None) -> str:
    node = place.node
    assert isinstance(node, Step)
    here = trace.states[place.node_id]
    figures = "".join(_state_figure(plan, draw, k, "state", STATE_PX) for k in here)
    count = f"{len(here)} possible state{'s' if len(here) != 1 else ''}"
    if place.node_id == 0:
        count = f"any orientation: {len(here)} stable states after the first alignment"
    elif not here:
        count = unreached_words(plan)
    margin = "" if node.margin_deg is None else f" (margin \u00b1{num(node.margin_deg, 2)}\u00b0)"
    read = ", read" if any(b.reading is not None for b in node.branches) else ""
    if node.action_deg is None:
        step = f"next: align from an unknown orientation{read}"
    else:
        step = f"next: {action_text(node.action_deg)}{margin}, align{read}"
    attr, note = _shared_tag(shared)
    cls = "warn" if not here and plan.uncertainty.is_ideal else "muted"
    return (
        f'<div class="tree-node op" data-node-id="{place.node_id}" data-depth="{place.depth}" '
        f'data-states="{len(here)}"{attr}><div class="node-head">'
        f"<strong>operation {place.depth + 1}</strong> "
        f'<span class="{cls}">node {place.node_id} \u00b7 {esc(count)}</span>{note}</div>'
        f'<div class="poses">{figures}</div>'
        f'<div class="node-op">{esc(step)}</div></div>'
    )


REJECT_WORDS = "reject (recirculate or re-drop)"
"""A reject leaf in words: the next station cannot take these landings (docs/plans.md)."""


def _result_node(
    plan: Plan,
    trace: Trace,
    draw: Drawing,
    place: Place,
    shared: str | None,
    twin: TwinLeaf | None = None,
) -> str:
    node = place.node
    assert isinstance(node, Leaf)
    keys = [(plan.part_index(r.part, r.landing), r.state) for r in node.results]
    figures = "".join(
        _state_figure(plan, draw, k, "final-pose", FINAL_PX, r.pose_deg)
        for k, r in zip(keys, node.results, strict=True)
    )
    members = leaf_members(plan, node)
    if node.reject:
        labels = ", ".join(plan.parts[m].label for m in members)
        head = f"{REJECT_WORDS}: {labels}"
        kind = "reject"
    elif len(node.results) == 1:
        head = f"done: {plan.parts[keys[0][0]].label} in state {keys[0][1]}"
        kind = "known"
    elif len(members) == 1 and twin is not None and not twin.oriented:
        label = plan.parts[next(iter(members))].label
        head = (
            f"not oriented: {label}, one of {len(node.results)} poses that no plan tells "
            "apart and that do not look alike"
        )
        kind = "unoriented"
    elif len(members) == 1 and twin is not None and twin.merged:
        label = plan.parts[next(iter(members))].label
        head = (
            f"done: {label}, resting anywhere over {len(node.results)} poses (one resting "
            "state: shallow wells a breath of vibration crosses), oriented only that far"
        )
        kind = "symmetric"
    elif len(members) == 1:
        label = plan.parts[next(iter(members))].label
        head = f"done: {label}, one of {len(node.results)} poses that no plan tells apart"
        kind = "symmetric"
    elif len({plan.parts[m].name for m in members}) == 1:
        part = plan.parts[next(iter(members))].name
        how = side_words(plan.parts[m].landing for m in members)
        head = f"not oriented: {part} recognized, but not {how} ({len(members)} landings)"
        kind = "confused"
    else:
        what = "landings" if plan.over_landings else "parts"
        head = f"not recognized: {len(members)} {what} end here together"
        kind = "confused"
    note = ""
    reached = set(trace.states[place.node_id])
    if reached != set(keys):
        got = ", ".join(f"{plan.parts[m].label} s{s}" for m, s in sorted(reached))
        if not plan.uncertainty.is_ideal:
            # The trace follows the nominal push; a strong plan's leaf also lists the states
            # that the declared uncertainty can bring here (design.md, "Uncertainty").
            nominal = f"the states that reach it are {got}" if got else "no start reaches it"
            note = (
                f'<p class="muted">On the nominal push (no rotation error) {esc(nominal)}; '
                "the leaf lists every state the declared uncertainty can bring here.</p>"
            )
        else:
            note = (
                f'<p class="warn">Following the plan, the states that reach this leaf are: '
                f"{esc(got or 'none')}.</p>"
            )
    attr, tag = _shared_tag(shared)
    return (
        f'<div class="tree-node result {kind}" data-node-id="{place.node_id}" '
        f'data-depth="{place.depth}" data-states="{len(node.results)}"{attr}>'
        f'<div class="node-head"><strong>{esc(head)}</strong> '
        f'<span class="muted">node {place.node_id}</span>{tag}</div>'
        f'<div class="poses">{figures}</div>{note}</div>'
    )


def _stop_item(numbered: Sequence[Place], drawn: set[int], figures: int) -> str:
    """The last item of a drawing that stopped after ``figures`` states: what it left out."""
    left = [p for p in numbered if p.node_id not in drawn]
    ops = sum(1 for p in left if isinstance(p.node, Step))
    results = len(left) - ops
    return (
        f'<li class="tree-stop" data-operations="{ops}" data-results="{results}">'
        f"... the drawing stops after {figures:,} drawn states: {ops:,} more "
        f"operation{'s' if ops != 1 else ''} and {results:,} more "
        f"result{'s' if results != 1 else ''} are in the plan file (feederkit run PLAN --all "
        "walks every path)</li>"
    )


def _ref(place: Place, name: str | None) -> str:
    """Another place of a shared node: its name (a shared subplan) and node, drawn above."""
    what = "the result" if name is None else f"the shared subplan {esc(name)}"
    return (
        f'<div class="tree-ref" data-ref="{place.node_id}">{what} '
        f"(node {place.node_id}, drawn above)</div>"
    )


def tree_html(
    plan: Plan,
    numbered: Sequence[Place],
    trace: Trace,
    draw: Drawing,
    max_figures: int | None = None,
    twins: Mapping[int, TwinLeaf] | None = None,
) -> str:
    """The plan as nested lists: operation nodes, labelled edges, leaves; each distinct
    node drawn once (at its first place; a shared subplan named ``S1``, ``S2``, ... and
    referred to by name elsewhere, as ``plan_tree`` does), without recursion. After
    ``max_figures`` (default ``TREE_FIGURES``) drawn states the drawing stops (the nodes
    begun are closed) and a last item (``li.tree-stop``) says how many operations and
    results it left out. ``twins`` (by node id, :func:`~feederkit.reports.twins.twin_leaves`)
    marks the leaves whose poses of one part do not look alike: the part is not oriented."""
    twins = twins or {}
    max_figures = TREE_FIGURES if max_figures is None else max_figures
    out: list[str] = ['<ul class="tree">']
    figures = 0
    stack: list[str | tuple[int, str]] = [(0, "")]
    names: dict[int, str | None] = {}
    drawn: set[int] = set()
    subplans = 0
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            out.append(item)
            continue
        number, edge = item
        place = numbered[number]
        if number in drawn:
            out.append(f"<li>{edge}{_ref(place, names[number])}</li>")
            continue
        drawn.add(number)
        shared = None
        if place.shared and isinstance(place.node, Step):
            subplans += 1
            shared = f"S{subplans}"
        names[number] = shared
        if figures >= max_figures:
            drawn.discard(number)
            stack = [x for x in stack if isinstance(x, str)]  # close the nodes begun
            out.append(_stop_item(numbered, drawn, figures))
            continue
        if isinstance(place.node, Leaf):
            html = _result_node(plan, trace, draw, place, shared, twins.get(number))
            figures += html.count("<svg")
            out.append(f"<li>{edge}{html}</li>")
            continue
        html = _op_node(plan, trace, draw, place, shared)
        figures += html.count("<svg")
        out.append(f"<li>{edge}{html}<ul>")
        stack.append("</ul></li>")
        step = place.node
        stack.extend(
            reversed(
                [(k, _edge(step, b)) for b, k in zip(step.branches, place.children, strict=True)]
            )
        )
    out.append("</ul>")
    return "".join(out)
