"""Simulation summaries made by hand, for the tests of what the simulator's outputs say (the
command line, the report, the JSON) without running MuJoCo."""

from __future__ import annotations

from feederkit.sim.summary import SimSettings, SimulationSummary, TrialResult


def sim_summary(
    parts: dict[str, tuple[int, int]],
    *,
    seed: int = 0,
    min_margin_deg: float | None = 2.0,
    failures: tuple[TrialResult, ...] = (),
    pushes: int = 0,
    rejects: int = 0,
    **settings: object,
) -> SimulationSummary:
    """The summary of a run over ``parts`` (per member's name: its successes of its trials)
    as the simulator makes it: the run's trials and successes are the members' sums, every
    push settled and agreed with the plan, no time spent. ``settings`` are further
    :class:`SimSettings` fields (``sampled``, ...)."""
    successes = tuple(s for s, _ in parts.values())
    trials = tuple(t for _, t in parts.values())
    return SimulationSummary(
        settings=SimSettings(sum(trials), seed, 1.0, 0.1, 0.5, 0.2, 0.002, **settings),
        parts=tuple(parts),
        part_trials=trials,
        part_successes=successes,
        scales=(1.0,) * len(parts),
        min_margin_deg=min_margin_deg,
        successes=sum(successes),
        failures=failures,
        unsettled=(),
        pushes=pushes,
        settled_pushes=pushes,
        push_agreements=pushes,
        push_misses=(),
        wall_time_s=0.0,
        sim_time_s=0.0,
        rejects=rejects,
    )
