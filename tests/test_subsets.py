"""The hardest subsets' lower bound (``feederkit.planning.subsets``) against the independent
exhaustive planner of test_planners_bruteforce: never above the optimum, at least the
hardest pair, and a subset's bound never above that subset's own optimum."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_beam import _case, _problem, _random_part_machine

from feederkit.machine import members
from feederkit.planning.andor import WorstCase
from feederkit.planning.budget import Deadline
from feederkit.planning.subsets import SubsetBound, subset_lower_bound


@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.002, 0.08))
def test_the_subset_bound_never_exceeds_the_optimum(seed, n, rel):
    machine, optimum = _case(seed, n, rel)
    problem, _branches, roots = _problem(machine)
    bound = subset_lower_bound(problem, roots, 0, Deadline(), 2 * machine.n + 1)
    assert 1 + bound <= optimum
    exact = WorstCase(problem)
    hardest_pair = max(
        (
            exact.length((1 << a) | (1 << b))
            for r in roots
            for a in members(r)
            for b in members(r)
            if a < b
        ),
        default=0,
    )
    assert bound >= hardest_pair
    # On each root: the bound is a length of a subset, so at most the root's own length.
    bounds = SubsetBound(problem, Deadline(), 2 * machine.n + 1)
    for r in roots:
        assert bounds.bound(r, 2 * machine.n) <= exact.length(r)


def test_a_bound_already_at_the_plans_length_costs_nothing():
    problem, _branches, roots = _problem(_random_part_machine())
    # A passed deadline: the search would stop at once; a proven bound at the goal skips it.
    assert subset_lower_bound(problem, roots, 5, Deadline(0.0), 5) == 5
    assert subset_lower_bound(problem, roots, 1, Deadline(0.0), 5) == 1
