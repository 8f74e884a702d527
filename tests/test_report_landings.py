"""The HTML report of plans over landings (design.md "Landings") and of plans that share
subplans (design.md, plan file ``"nodes"``): each member named by its label, its outline and
share shown, reject leaves said as such, and each distinct node drawn once.

The default tests check the plan section and the trace (fast); the whole page, with a
matplotlib part plot per member, is checked under ``-m slow``.
"""

from __future__ import annotations

import re
import time
from itertools import product
from pathlib import Path

import pytest
from test_plan_graph import layered
from test_report import parse

from feederkit.landing.plan import load_landings, plan_landings
from feederkit.plans import plan_from_dict, plan_to_dict
from feederkit.plans.model import Leaf, Step
from feederkit.reports import render_report
from feederkit.reports.report import member_rings, plan_section
from feederkit.reports.sections import lookalike_section, mix_section
from feederkit.reports.trace import StateKey, places, pushed, trace_plan
from feederkit.reports.tree_html import drawing_for
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

BRACKET = Path(__file__).resolve().parent.parent / "catalog" / "l-bracket.json"


@pytest.fixture(scope="module")
def bracket():
    landings = load_landings([str(BRACKET)]).all
    return landings, {x.label: x.part.outline for x in landings}  # as the CLI passes them


@pytest.fixture(scope="module", params=["ideal", "default"])
def both(bracket, request):
    """The l-bracket planned over up and down, on the ideal model and at the default
    declared uncertainty."""
    unc = IDEAL if request.param == "ideal" else None
    return plan_landings(bracket[0], ToleranceSensor(0.2), uncertainty=unc).made.plan


@pytest.fixture(scope="module")
def up_only(bracket):
    return plan_landings(bracket[0], ToleranceSensor(0.2), accept={"up"}).made.plan


def plan_tree_of(doc):
    return next(a for _, a in doc.tags if a.get("id") == "plan-tree")


def test_a_plan_over_landings_names_both_landings_and_draws_their_outlines(both, bracket):
    plan = plan_from_dict(both)
    html = plan_section(plan, bracket[1])
    doc = parse(html)
    text = "".join(doc.text)
    assert "l-bracket (up)" in text and "l-bracket (down)" in text
    finals = {f["data-landing"] for f in doc.with_class("final-pose")}
    assert finals == {"up", "down"}
    assert not doc.with_class("reject")
    tree = plan_tree_of(doc)
    assert tree["data-rejects"] == "0" and int(tree["data-accepts"]) == len(plan.leaves())
    # the outline keyed PART/LANDING is the one drawn: every pose shows the plate's two holes
    assert {len(o.holes) for o in bracket[1].values()} == {2}
    drawn = re.findall(r'<svg class="pose".*?<path d="([^"]*)"', html)
    assert drawn and all(d.count("M") == 3 for d in drawn)
    mix = mix_section(plan, drawing_for(plan, member_rings(plan, bracket[1])))
    assert "l-bracket (up)" in mix and "l-bracket (down)" in mix and mix.count("share 50%") == 2


def test_the_trace_keys_states_by_member(both):
    plan = plan_from_dict(both)
    numbered = places(plan)
    trace = trace_plan(plan, numbered)
    every = {(m, s.id) for m, p in enumerate(plan.parts) for s in p.states}
    assert set(trace.states[0]) == every
    for place in numbered:
        if isinstance(place.node, Leaf):  # a verified plan: exactly the listed states arrive
            listed = {(plan.part_index(r.part, r.landing), r.state) for r in place.node.results}
            assert set(trace.states[place.node_id]) == listed


def test_accepting_one_landing_shows_reject_leaves(up_only, bracket):
    plan = plan_from_dict(up_only)
    doc = parse(plan_section(plan, bracket[1]))
    rejects = doc.with_class("reject")
    assert rejects and all("result" in r["class"].split() for r in rejects)
    assert "reject (recirculate or re-drop): l-bracket (down)" in "".join(doc.text)
    written = plan.leaves()
    tree = plan_tree_of(doc)
    assert int(tree["data-rejects"]) == sum(leaf.reject for leaf in written) == len(rejects)
    assert int(tree["data-accepts"]) == len(written) - len(rejects) > 0
    assert not doc.with_class("warn")  # every leaf holds exactly the states that reach it
    for leaf in written:  # the accepting leaves hold the up side only
        assert leaf.reject == all(r.landing == "down" for r in leaf.results)


def test_a_dag_plan_draws_each_distinct_node_once_and_fast():
    plan = plan_from_dict(plan_to_dict(layered(30)))
    distinct = list(plan.walk())
    start = time.perf_counter()
    doc = parse(plan_section(plan))
    took = time.perf_counter() - start
    assert took < 1.5, f"{took:.2f} s for {len(distinct)} distinct nodes (2**30 paths)"
    nodes = doc.with_class("tree-node")
    assert len(nodes) == len(distinct) < 1000
    assert [int(n["data-node-id"]) for n in nodes] == list(range(len(distinct)))
    refs = doc.with_class("tree-ref")
    edges = sum(len(n.branches) for n, _ in distinct if isinstance(n, Step))
    assert len(nodes) - 1 + len(refs) == edges  # every other arrival is a reference
    assert {int(r["data-ref"]) for r in refs} <= {int(n["data-node-id"]) for n in nodes}
    shared = [n["data-shared"] for n in nodes if n.get("data-shared")]
    assert shared and shared == [f"S{k}" for k in range(1, len(shared) + 1)]
    assert plan_tree_of(doc)["data-shared"] == str(len(shared))


def _by_paths(plan, node, states: set[StateKey], out: dict[int, set[StateKey]]) -> None:
    """The oracle: every path of a small plan followed on its own, unions collected by node."""
    out.setdefault(id(node), set()).update(states)
    if isinstance(node, Leaf):
        return
    part = plan.parts[0]
    image = {
        (m, sid if node.action_deg is None else pushed(part, part.state(sid), node.action_deg).id)
        for m, sid in states
    }
    for b in node.branches:
        into = {
            k
            for k in image
            if b.reading is None or plan.sensor.reads_into(part.state(k[1]).diameter, *b.reading)
        }
        _by_paths(plan, b.next, into, out)


@pytest.mark.parametrize(("layers", "width"), list(product([2, 4], [3, 4])))
def test_a_shared_node_holds_the_union_of_what_every_path_brings(layers, width):
    plan = layered(layers, width=width)
    numbered = places(plan)
    trace = trace_plan(plan, numbered)
    oracle: dict[int, set[StateKey]] = {}
    _by_paths(plan, plan.root, {(0, s.id) for s in plan.parts[0].states}, oracle)
    assert any(p.shared for p in numbered)
    for place in numbered:
        assert set(trace.states[place.node_id]) == oracle[id(place.node)]


@pytest.mark.slow
@pytest.mark.parametrize("accept", ["both", "up"])
def test_the_whole_page_of_a_landing_plan(accept, both, up_only, bracket):
    plan = both if accept == "both" else up_only
    doc = parse(render_report(plan, outlines=bracket[1]))
    sections = doc.with_class("part")
    assert [(p["data-part"], p["data-landing"]) for p in sections] == [
        ("l-bracket", "up"),
        ("l-bracket", "down"),
    ]
    assert [float(p["data-share"]) for p in sections] == pytest.approx([0.5, 0.5])
    assert not doc.with_class("pair")  # up and down are told apart: no look-alike row
    assert bool(doc.with_class("reject")) == (accept == "up")


def test_a_pair_of_landings_from_the_mix_analysis_is_named_by_label(both):
    plan = plan_from_dict(both)
    pair = {"part_a": "l-bracket/up", "part_b": "l-bracket/down", "reason": "alike"}
    html = lookalike_section(plan, [], [pair])
    assert "l-bracket (up)" in html and "l-bracket (down)" in html and "/up" not in html


@pytest.mark.slow
def test_the_whole_page_of_a_dag_plan():
    plan = plan_from_dict(plan_to_dict(layered(30)))
    start = time.perf_counter()
    doc = parse(render_report(plan))
    took = time.perf_counter() - start
    assert took < 10.0, f"{took:.2f} s"  # one part plot and the tree of ~300 distinct nodes
    assert len(doc.with_class("tree-node")) == len(list(plan.walk()))


def test_a_strong_plans_leaf_is_not_called_wrong_for_states_only_uncertainty_brings(tmp_path):
    """The d-washer's strong plan (1 degree) has a leaf that the nominal push reaches with
    fewer states than it lists: the report says why, not that the plan is wrong."""
    from feederkit.mechanics.push import push_function
    from feederkit.plans.make import make_plan
    from feederkit.reports import render_report
    from feederkit.sensors import ToleranceSensor
    from feederkit.sources import load_part

    washer = Path(__file__).resolve().parents[1] / "catalog" / "d-washer.json"
    pf = push_function(load_part(str(washer)))
    made = make_plan([pf], ToleranceSensor(0.3))
    html = render_report(made.plan)
    assert "On the nominal push (no rotation error)" in html
    assert "Following the plan, the states that reach this leaf" not in html
