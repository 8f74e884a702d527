"""Strong plans: every outcome and every reading (design.md, "Uncertainty"; docs/planning.md).

The brute-force reference here shares no code with the planner or the mechanics: its own
convex hull, radius and width functions, its own quasi-static push (descend the radius
function from the fence orientation to a local minimum, section 3.1), rotation errors
sampled within the bound applied to it (half at the bound's ends), vertices moved within the
shape tolerance and the COM within the COM tolerance, readings sampled inside the sensor's
open interval. It executes the plan file's JSON and checks that every run ends in a result
naming the state the part rests in. A second reference searches exhaustively over outcome
sets for the minimum worst-case length on small machines.
"""

from __future__ import annotations

import math
import random
from functools import cache

import pytest
from shared import outcome_mask, read_alike_sets, rotation_mids

from feederkit.cli.app import main
from feederkit.errors import CheckFailed, PlanningError
from feederkit.machine import build_machine, inseparable
from feederkit.mechanics import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.plans.make import make_plan
from feederkit.plans.strong import strong_holds, verify_strong
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

# --- the reference's own geometry -----------------------------------------------------------


def convex_hull(pts):
    """Andrew's monotone chain, counter-clockwise (also tests/test_strong_machine.py's)."""
    pts = sorted(map(tuple, pts))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def support(poly, com, phi):
    u = (math.cos(phi), math.sin(phi))
    return max((x - com[0]) * u[0] + (y - com[1]) * u[1] for x, y in poly)


def width(poly, phi):
    return support(poly, (0.0, 0.0), phi) + support(poly, (0.0, 0.0), phi + math.pi)


def edge_normals(poly):
    n = len(poly)
    out = []
    for k in range(n):
        (ax, ay), (bx, by) = poly[k], poly[(k + 1) % n]
        out.append(math.atan2(-(bx - ax), by - ay) % (2 * math.pi))
    return out


def push(poly, com, theta):
    """Quasi-static push from fence orientation ``theta`` (rad): the resting edge's normal.

    The radius function is r(phi) = rho_j cos(phi - alpha_j) on vertex j's normal cone; the
    part turns downhill until an edge normal where the next vertex is uphill both ways.
    """
    n = len(poly)
    normals = edge_normals(poly)

    def cone_of(phi):  # vertex j supports directions between normal(e_{j-1}) and normal(e_j)
        for j in range(n):
            lo, hi = normals[(j - 1) % n], normals[j]
            if (phi - lo) % (2 * math.pi) < (hi - lo) % (2 * math.pi):
                return j
        return min(
            range(n), key=lambda j: abs(((phi - normals[j]) + math.pi) % (2 * math.pi) - math.pi)
        )

    def downhill(j, phi):  # +1: r decreases as phi increases
        ax, ay = poly[j][0] - com[0], poly[j][1] - com[1]
        return 1 if math.sin(phi - math.atan2(ay, ax)) > 0 else -1

    j = cone_of(theta % (2 * math.pi))
    d = downhill(j, theta)
    for _ in range(4 * n):
        if d > 0:
            e, nxt = j, (j + 1) % n  # leave through edge j's normal
        else:
            e, nxt = (j - 1) % n, (j - 1) % n
        phi = normals[e]
        if downhill(nxt, phi) != d:
            return phi  # both sides uphill: the part rests on edge e
        j = nxt
    raise AssertionError("the push did not settle")


def perturbed(poly, com, t, c, rng):
    def move(p, r):
        a = rng.uniform(0, 2 * math.pi)
        rad = r if rng.random() < 0.5 else r * math.sqrt(rng.random())
        return (p[0] + rad * math.cos(a), p[1] + rad * math.sin(a))

    moved = convex_hull([move(p, t) for p in poly]) if t > 0 else list(poly)
    return moved, move(com, c) if c > 0 else com


def run_plan(plan_data, part_index, poly, com, r, e, rng):
    """One run of a plan file on a (perturbed) part; returns the failures (empty: fine)."""
    part = plan_data["parts"][part_index]
    name = part["name"]
    states = part["stable_states"]
    theta = rng.uniform(0, 2 * math.pi)
    failures = []
    todo = [(plan_data["root"], theta, 0)]
    shared = plan_data.get("nodes") or {}
    while todo:
        node, theta, depth = todo.pop()
        while "ref" in node:  # a shared subplan, stored once (design.md plan file v2)
            node = shared[node["ref"]]
        if "result" in node:
            rest = theta
            nearest = min(
                states,
                key=lambda s: abs(
                    (math.radians(s["normal_deg"]) - rest + math.pi) % (2 * math.pi) - math.pi
                ),
            )
            named = {x["state"] for x in node["result"] if x["part"] == name}
            if nearest["id"] not in named:
                failures.append(f"ended in state {nearest['id']}, result names {sorted(named)}")
            continue
        if node["action_deg"] is not None:
            err = rng.choice([-r, r, rng.uniform(-r, r), rng.uniform(-r, r)])
            theta = theta - math.radians(node["action_deg"] + err)
        theta = push(poly, com, theta)
        reading = width(poly, theta) + (rng.uniform(-e, e) * 0.999 if e else 0.0)
        nexts = [
            b["next"]
            for b in node["branches"]
            if b["reading"] is None or b["reading"][0] <= reading <= b["reading"][1]
        ]
        if not nexts:
            failures.append(f"reading {reading:.6g} in no branch at depth {depth}")
        todo.extend((nxt, theta, depth + 1) for nxt in nexts)
    return failures


# --- random parts ----------------------------------------------------------------------------


def random_polygon(seed):
    rng = random.Random(seed)
    while True:
        k = rng.randint(4, 10)
        pts = []
        for _ in range(k):  # near a circle, so most points are hull vertices
            a, rad = rng.uniform(0, 2 * math.pi), rng.uniform(6, 10)
            pts.append((rad * math.cos(a), rad * math.sin(a) * rng.uniform(0.5, 1.0)))
        hull = convex_hull(pts)
        if len(hull) >= 3:
            cx = sum(p[0] for p in hull) / len(hull)
            cy = sum(p[1] for p in hull) / len(hull)
            vx, vy = rng.choice(hull)  # a convex combination: strictly inside
            f = rng.uniform(0.0, 0.3)
            com = (cx + f * (vx - cx), cy + f * (vy - cy))
            return hull, com


@cache
def random_pf(seed):
    hull, com = random_polygon(seed)
    return push_function(make_part(make_outline(f"rnd{seed}", [list(p) for p in hull]), list(com)))


def _usable(pf, unc):
    """Parts whose resting states the uncertainty does not merge (the reference pushes the
    ideal part: vibration, which the model adds, is not simulated) and whose edges are long
    enough for the tolerance."""
    try:
        mech = uncertain_mechanics(pf.part, unc)
    except Exception:
        return False
    return mech.n == pf.n and all(s is not None for s in mech.state_of)


CASES = [
    (Uncertainty(1.0), None),
    (Uncertainty(1.0), 0.05),
    (Uncertainty(2.5), 0.2),
    (Uncertainty(1.0, 0.003, 0.003), 0.1),
]


def _sampled_runs(parts: int, trials: int, start: int = 0) -> None:
    """``parts`` random parts, each planned under one declared uncertainty and executed
    ``trials`` times by the reference with sampled rotation errors, shapes and readings."""
    planned = 0
    seed = start
    while planned < parts:
        seed += 1
        unc, tol = CASES[seed % len(CASES)]
        pf = random_pf(seed)
        if not _usable(pf, unc):
            continue
        sensor = NoSensor() if tol is None else ToleranceSensor(tol)
        try:
            made = make_plan([pf], sensor, uncertainty=unc, certify=False)
        except PlanningError:
            continue  # no strong plan: tested separately
        planned += 1
        hull = [tuple(v) for v in made.plan["parts"][0]["hull"]]
        com = tuple(made.plan["parts"][0]["com"])
        rng = random.Random(seed)
        e = 0.0 if tol is None else tol
        for _ in range(trials):
            poly, c = perturbed(hull, com, unc.shape_tolerance_mm, unc.com_tolerance_mm, rng)
            fails = run_plan(made.plan, 0, poly, c, unc.rotation_error_deg, e, rng)
            assert not fails, (seed, unc, tol, fails)
    assert seed - start < 4 * parts  # most random parts are usable


@pytest.mark.parametrize("chunk", range(6))
def test_strong_plans_succeed_for_every_sampled_outcome_on_random_parts(chunk):
    """120 random parts in all (six chunks of 20), 8 sampled runs each."""
    _sampled_runs(20, 8, start=10_000 * chunk)


@pytest.mark.slow
def test_strong_plans_succeed_for_every_sampled_outcome_on_many_random_parts():
    _sampled_runs(600, 60)


def test_the_reference_catches_an_ideal_plan_failing_under_rotation_error():
    """The reference can fail: the t-clip's ideal sensorless plan (margin ±0.044°) fails
    under a 1° rotation error, its strong plan does not."""
    from pathlib import Path

    from feederkit.outline import load_outline_json

    path = Path(__file__).resolve().parent.parent / "catalog" / "t-clip.json"
    pf = push_function(make_part(load_outline_json(path)))
    failed = {}
    for unc in (IDEAL, Uncertainty(1.0)):
        made = make_plan([pf], NoSensor(), uncertainty=unc, certify=False)
        hull = [tuple(v) for v in made.plan["parts"][0]["hull"]]
        com = tuple(made.plan["parts"][0]["com"])
        rng = random.Random(0)
        failed[unc.is_ideal] = sum(
            bool(run_plan(made.plan, 0, hull, com, 1.0, 0.0, rng)) for _ in range(100)
        )
    assert failed[True] > 10 and failed[False] == 0


def test_the_reference_push_agrees_with_the_plan_files_states():
    """Sanity of the reference itself: its pushes end on the file's stable normals and its
    widths are the file's diameters."""
    pf = random_pf(5)
    made = make_plan([pf], ToleranceSensor(0.1), uncertainty=IDEAL, certify=False)
    part = made.plan["parts"][0]
    hull, com = [tuple(v) for v in part["hull"]], tuple(part["com"])
    normals = {round(s["normal_deg"], 6) % 360 for s in part["stable_states"]}
    for s in part["stable_states"]:
        rest = push(hull, com, math.radians(s["normal_deg"]))
        assert round(math.degrees(rest), 6) % 360 in normals
        assert width(hull, math.radians(s["normal_deg"])) == pytest.approx(s["diameter"], abs=1e-9)


# --- exhaustive minimal length ---------------------------------------------------------------


def strong_search(machine, tol, pairs):
    """``within(mask, k)``: whether a strong plan of at most ``k`` operations takes the set
    ``mask`` to one whose every pair ``(i, j)``, ``i < j``, is in ``pairs``; and
    ``children(mask)``: its reading branches (own code, shared with tests/test_lumping.py).

    Rotations: the middle of every cell between all action-range boundaries of all states;
    outcomes looked up in the maps; reading branches: the sets of states that can give one
    reading through their open reading intervals (``tol``; None: sensorless); plain
    depth-bounded recursion over outcome sets, memoised.
    """
    n = machine.n
    mids = rotation_mids(machine)

    def out(i, a):
        return outcome_mask(machine, i, a)

    def members(mask):
        return [i for i in range(n) if mask >> i & 1]

    def sensed(i):
        d = machine.states[i].sensed
        return (d, d) if isinstance(d, float) else d

    def children(mask):
        if tol is None:
            return [mask]
        return read_alike_sets({i: (sensed(i)[0] - tol, sensed(i)[1] + tol) for i in members(mask)})

    def goal(mask):
        idx = members(mask)
        return all((i, j) in pairs for k, i in enumerate(idx) for j in idx[k + 1 :])

    memo: dict[tuple[int, int], bool] = {}

    def within(mask, k):
        if goal(mask):
            return True
        if k == 0:
            return False
        key = (mask, k)
        if key not in memo:
            memo[key] = False
            for a in mids:
                img = 0
                for i in members(mask):
                    img |= out(i, a)
                if all(within(c, k - 1) for c in children(img)):
                    memo[key] = True
                    break
        return memo[key]

    return within, children


def exhaustive_length(machine, tol, lumped=()):
    """Minimum worst-case length by exhaustive search over outcome sets (:func:`strong_search`);
    goal: one state (the machines used have no inseparable pairs), or a set whose every pair
    is in ``lumped`` (the pairs the planner lumps: planning.lumping, checked by brute force in
    tests/test_lumping.py)."""
    n = machine.n
    within, children = strong_search(machine, tol, {tuple(sorted(p)) for p in lumped})
    worst = 0
    for root in children((1 << n) - 1):
        k = 0
        while not within(root, k):
            k += 1
            assert k < 12
        worst = max(worst, k)
    return 1 + worst


@pytest.mark.parametrize("seed", range(24))
def test_strong_plan_length_is_minimal_by_exhaustive_search(seed):
    pf = random_pf(1000 + seed)
    unc = Uncertainty([1.0, 2.0, 4.0][seed % 3])
    tol = [None, 0.1, 0.4][seed % 3]
    sensor = NoSensor() if tol is None else ToleranceSensor(tol)
    m = build_machine([pf], sensor, unc)
    if any(inseparable(m)):
        pytest.skip("a part with inseparable states")
    try:
        result = plan(m)
    except PlanningError:
        with pytest.raises(AssertionError):
            exhaustive_length(m, tol)
        return
    assert result.length == exhaustive_length(m, tol, result.lumped_pairs)


# --- monotone, certificate -------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(10))
def test_a_larger_uncertainty_never_gives_a_shorter_plan(seed):
    pf = random_pf(2000 + seed)
    sensor = ToleranceSensor(0.1) if seed % 2 else NoSensor()
    last = 0
    for r in (0.25, 1.0, 2.0, 3.0):
        try:
            length = plan(build_machine([pf], sensor, Uncertainty(r))).length
        except PlanningError:
            last = math.inf  # and then no larger uncertainty has a plan either
            continue
        assert length >= last
        last = length


@pytest.mark.parametrize("seed", range(8))
def test_certificate_covers_the_declared_error_and_is_tight(seed):
    pf = random_pf(3000 + seed)
    unc = Uncertainty(1.0 + seed % 3)
    sensor = ToleranceSensor(0.2) if seed % 2 else NoSensor()
    try:
        made = make_plan([pf], sensor, uncertainty=unc)
    except PlanningError:
        pytest.skip("no strong plan")
    cert = made.plan["stats"]["certificate"]
    r_max = cert["max_rotation_error_deg"]
    assert r_max >= unc.rotation_error_deg
    assert made.result.certificate is not None
    assert made.result.certificate.max_rotation_error_deg == r_max
    assert cert["ideal_length"] == plan(build_machine([pf], sensor, IDEAL)).length
    if r_max < 90.0:
        below = Uncertainty(max(unc.rotation_error_deg, r_max - 1e-6))
        assert strong_holds(made.plan, below)
        assert not strong_holds(made.plan, Uncertainty(r_max + 1e-3))
    t_max = cert["max_shape_tolerance_mm"]
    assert strong_holds(made.plan, Uncertainty(unc.rotation_error_deg, t_max))


def test_ideal_plans_carry_a_certificate_too():
    pf = random_pf(7)
    made = make_plan([pf], NoSensor(), uncertainty=IDEAL)
    cert = made.plan["stats"]["certificate"]
    assert made.plan["uncertainty"] == IDEAL.to_dict()
    assert list(made.plan)[list(made.plan).index("sensor") + 1] == "uncertainty"
    assert cert["ideal_length"] == made.plan["stats"]["length"]
    assert 0.0 <= cert["max_rotation_error_deg"] <= made.plan["stats"]["min_margin_deg"] + 1e-6


def _holds_declared_at(plan_data: dict, rotation_deg: float) -> bool:
    """Whether the plan holds once declared at ``rotation_deg``: the model ``plan
    --rotation-error`` plans and verifies on (with the feeder's vibration)."""
    unc = {**plan_data["uncertainty"], "rotation_error_deg": rotation_deg}
    return strong_holds({**plan_data, "uncertainty": unc}, Uncertainty(rotation_deg))


@pytest.mark.parametrize("seed", [2, 7, 11, 19])
@pytest.mark.parametrize("tolerance", [None, 0.2])
def test_an_ideal_plans_certificate_is_what_it_holds_under_that_rotation_error(seed, tolerance):
    """The certificate of a plan made on the ideal model speaks of the feeder the planner
    models under any rotation error (its vibration: fragile states merged, a push band at
    each hilltop), not of the ideal model's margins: the plan declared at 0.9 times it
    holds, and a little past it fails (an ideal plan may hold none)."""
    sensor = NoSensor() if tolerance is None else ToleranceSensor(tolerance)
    made = make_plan([random_pf(seed)], sensor, uncertainty=IDEAL)
    held = made.plan["stats"]["certificate"]["max_rotation_error_deg"]
    margin = made.plan["stats"]["min_margin_deg"]
    if held > 1e-6:
        assert _holds_declared_at(made.plan, 0.9 * held)
    if 1.1 * held + 1e-3 < 90.0:  # 90: no rotation error reaches the plan
        assert not _holds_declared_at(made.plan, 1.1 * held + 1e-3)
    if margin is not None and margin < 90.0:
        assert held <= margin + 1e-6
        # The ideal model alone (no vibration) holds up to the margin: the old, larger figure.
        assert strong_holds(made.plan, Uncertainty(0.9 * margin))


# --- verification refuses wrong plans -------------------------------------------------------


def _leaves(node):
    stack, out = [node], []
    while stack:
        n = stack.pop()
        if "result" in n:
            out.append(n)
        else:
            stack.extend(b["next"] for b in n["branches"])
    return out


def test_verification_refuses_a_wrong_result_and_a_missing_reading():
    pf = random_pf(11)
    made = make_plan([pf], ToleranceSensor(0.2), uncertainty=Uncertainty(1.0), certify=False)
    verify_strong(made.plan)
    import copy

    wrong = copy.deepcopy(made.plan)
    leaf = _leaves(wrong["root"])[0]
    leaf["result"] = [dict(leaf["result"][0], state=(leaf["result"][0]["state"] + 1) % pf.n)]
    with pytest.raises(CheckFailed, match="does not name"):
        verify_strong(wrong)
    narrow = copy.deepcopy(made.plan)
    b = narrow["root"]["branches"][0]
    b["reading"] = [b["reading"][0] + 0.05, b["reading"][1]]
    with pytest.raises(CheckFailed, match="no branch"):
        verify_strong(narrow)
    longer = copy.deepcopy(made.plan)
    longer["stats"]["length"] += 1
    with pytest.raises(CheckFailed, match="length"):
        verify_strong(longer)


def test_no_strong_plan_names_the_largest_rotation_error_with_one():
    """A part no strong plan orients at 15 deg, even lumping the pairs none resolves (at 6
    deg lumping already rescues the random parts that fail: planning.lumping)."""
    pf = None
    for seed in range(200):
        cand = random_pf(5000 + seed)
        try:
            plan(build_machine([cand], NoSensor(), Uncertainty(15.0)))
        except PlanningError:
            pf = cand
            break
    assert pf is not None
    with pytest.raises(PlanningError, match="largest rotation error with a strong plan is") as exc:
        make_plan([pf], NoSensor(), uncertainty=Uncertainty(15.0))
    text = str(exc.value)
    r = float(text.split("strong plan is at least ")[1].split(" deg")[0])
    width = float(text.split("(bisected to ")[1].split(" deg")[0])
    assert 0.0 <= r < 15.0 and 0.0 < width < 15.0
    if r > 0.0:
        plan(build_machine([pf], NoSensor(), Uncertainty(r)))  # printed rounded down: a plan
    assert "\n" not in text


# --- the command line -----------------------------------------------------------------------


@pytest.fixture
def tri(tmp_path):
    import json

    path = tmp_path / "tri.json"
    path.write_text(json.dumps({"name": "tri", "vertices": [[0, 0], [4, 0], [0, 3]]}))
    return str(path)


@pytest.mark.parametrize(
    ("flag", "value", "words"),
    [
        ("--rotation-error", "-1", "rotation error"),
        ("--rotation-error", "nan", "rotation error"),
        ("--rotation-error", "90", "rotation error"),
        ("--shape-tolerance", "-0.1", "shape tolerance"),
        ("--shape-tolerance", "nan", "shape tolerance"),
        ("--shape-tolerance", "2", "smallest hull edge"),
        ("--com-tolerance", "-1", "COM tolerance"),
        ("--com-tolerance", "inf", "COM tolerance"),
    ],
)
def test_bad_uncertainty_is_one_line_and_exit_2(tri, tmp_path, capsys, flag, value, words):
    rc = main(["plan", tri, flag, value, "-o", str(tmp_path / "p.json")])
    err = capsys.readouterr().err
    assert rc == 2
    assert len(err.strip().splitlines()) == 1 and words in err and "Traceback" not in err


def test_plan_command_says_which_uncertainty_and_shows_the_certificate(tri, tmp_path, capsys):
    import json

    out = tmp_path / "p.json"
    rc = main(["plan", tri, "--tolerance", "0.1", "--rotation-error", "2", "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    assert "uncertainty: rotation error ±2°" in text
    data = json.loads(out.read_text())
    assert data["uncertainty"]["rotation_error_deg"] == 2.0
    assert set(data["stats"]["certificate"]) == {
        "max_rotation_error_deg",
        "max_shape_tolerance_mm",
        "ideal_length",
    }


def test_a_part_whose_states_all_merge_is_oriented_by_the_first_alignment():
    """The 1.8 mm octagon at shape 0.01, COM 0.02 mm: one physical state (docs/uncertainty.md)."""
    from pathlib import Path

    from feederkit.outline import load_outline_json

    path = Path(__file__).resolve().parent.parent / "catalog" / "octagon.json"
    pf = push_function(make_part(load_outline_json(path)))
    made = make_plan([pf], NoSensor(), uncertainty=Uncertainty(1.0, 0.01, 0.02))
    assert made.result.machine.n == 1 and made.result.length == 1
    (leaf,) = _leaves(made.plan["root"])
    assert sorted(e["state"] for e in leaf["result"]) == list(range(pf.n))  # every member named
