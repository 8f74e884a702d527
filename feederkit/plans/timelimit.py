"""How a plan's time limit is shared: the planner, then the plan file and its verification,
then the certificate, then the caller's writing and showing of the plan.

The limit is the command's, counted from its start; the planner stops early enough
(``POST_SHARE``, ``POST_S_PER_PAIR`` or ``POST_S_STRONG_PER_PAIR``) for the verified file to
follow, and the certificate leaves ``OUTPUT_SHARE`` and ``OUTPUT_S_PER_NODE`` per node to the
output.
"""

from __future__ import annotations

import time
from typing import Any

from feederkit.planning.budget import Deadline
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import result_nodes

POST_SHARE = 0.15
"""With a time limit, the share of it a certified plan keeps after the planner: the plan file
and its verification (always made) and the certificate (its largest rotation error and shape
tolerance, then the ideal length, each only while time is left). The limit is the command's,
so the planner gets the rest; ``certify=False`` callers (a design's many plans, under their
own clock) give the planner the whole limit."""


POST_MIN_S = 1.5
"""With a time limit, at least this many seconds (up to ``POST_MAX_SHARE`` of the limit) are
kept after the planner, however short the limit: what the work after it costs whatever the
plan's size (the plan's own verification and file are committed by the planner as it builds
the plan, ``POST_S_PER_PAIR``)."""

POST_MAX_SHARE = 0.25
"""The most of a short time limit ``POST_MIN_S`` may take from the planner."""

OUTPUT_SHARE = 0.05
"""With a time limit, the share of it the certificate (whose ideal length may take all the
time left) leaves to the caller for writing and showing the plan, besides
``OUTPUT_S_PER_NODE`` per node of the plan file."""

POST_S_PER_PAIR = 4e-5
"""Seconds per (node, state) pair of a plan on the ideal model (a state that can reach a
node) of the work after the planner: the file, its verification (``check_plan``, one path
per start, outcome and reading) and the command's output. The planner's deadline comes this
much earlier per pair of the nodes it makes (``Deadline.per_pair_s``), so a large plan leaves
time for its own verification and file. Measured 3.2e-5 s on a 1000-point outline's plan
over both landings (265,000 pairs in 8.5 s; ``python benchmarks/bench_command_deadline.py``)
and, traced in process, 4.1e-5 s on a 200-part mix's at 1 % (203,000 pairs; 5.5e-5 s before
the plan file's writer and reader were sped up), the high end covered by the certificate's
reserve (``Deadline.reserve_s``). Measured idle, so scaled by the planner's
budget's slowness (``Deadline.slowness``: wall over CPU seconds since it began) on a loaded
machine."""

POST_S_STRONG_PER_PAIR = 2.7e-5
"""``POST_S_PER_PAIR`` for a strong plan (under uncertainty), whose verifier
(``verify_strong``) walks each (node, state) pair once with its outcome sets memoised per
rotation: measured 1.95-2.7e-5 s on a 50-part mix's plan at 5 % (857,000 pairs, on two days),
2.9e-5 s on a 20-part mix's over both landings (283,000) and 3.1e-5 s on a 50-part mix's at
3 % (111,000, whose fixed costs weigh more: the certificate's reserve covers them; a caller
that does not certify, with no reserve, may end a fraction of a second late). At 4e-5 the 50-part
mix's first plan, found at 29 s of 60, was dropped as too slow to verify ("no plan found"
at 47 s); at 3e-5 it was kept in two runs, then dropped again in the one run after the limit
counted Python's start too."""

OUTPUT_S_PER_NODE = 7e-5
"""Seconds per node of the plan file (each shared step once, each result in place) of what
comes after the certificate: writing the file, reading it back and drawing it (2.5 s for the
44,000 nodes of the 100-part mix's plan above); scaled by the planner's budget's slowness as
``POST_S_PER_PAIR`` is."""


def planner_budget(
    options: PlanningOptions, started: float, certify: bool, strong: bool = False
) -> Deadline:
    """The planner's budget: the options' time limit from ``started`` less, when certifying,
    ``POST_SHARE`` of it or ``POST_MIN_S`` (at most ``POST_MAX_SHARE`` of it), whichever is
    more (at least a tenth of the limit is left to plan), and their memory limit; the
    deadline comes ``POST_S_PER_PAIR`` (``POST_S_STRONG_PER_PAIR`` for a ``strong`` plan,
    one under uncertainty) earlier per pair of the plan made, whose verification follows
    whether certified or not. What is kept past ``POST_MIN_S`` is the
    certificate's, which takes only the time left: the plan in hand's verification may take
    it first (``Deadline.reserve_s``; a plan with its certificate cut beats none)."""
    limit = options.time_limit_s
    if limit is None:
        return Deadline(None, options.memory_limit_mb)
    left = seconds_left(options, started) or 0.0
    keep = max(POST_SHARE * limit, min(POST_MIN_S, POST_MAX_SHARE * limit)) if certify else 0.0
    span = max(left - keep, 0.1 * limit)
    # A design's plan of 11,559 nodes took 7.6 s to verify past a 5 s limit uncommitted.
    return Deadline(
        span,
        options.memory_limit_mb,
        per_pair_s=POST_S_STRONG_PER_PAIR if strong else POST_S_PER_PAIR,
        reserve_s=max(left - span - POST_MIN_S, 0.0),
    )


def seconds_left(
    options: PlanningOptions, started: float, keep: float = 0.0, keep_s: float = 0.0
) -> float | None:
    """Seconds left of the options' time limit since ``started``, less ``keep`` of the limit
    and ``keep_s`` seconds (None: no limit)."""
    if options.time_limit_s is None:
        return None
    return (1.0 - keep) * options.time_limit_s - keep_s - (time.monotonic() - started)


def output_seconds(data: dict[str, Any]) -> float:
    """Seconds the caller needs to write and show the plan file's object ``data``:
    ``OUTPUT_S_PER_NODE`` per node (each shared step once, each result in place)."""
    return OUTPUT_S_PER_NODE * (len(data.get("nodes") or {}) + sum(1 for _ in result_nodes(data)))
