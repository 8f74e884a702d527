"""Moved to :mod:`feederkit.cli.plan_render`: the library builds no rich renderables.

Transitional re-export for the command modules that still import from here; it goes once
they import ``feederkit.cli.plan_render``.
"""

from feederkit.cli.plan_render import (
    plan_tree,
    sensor_text,
    stats_table,
    trace_table,
    verification_table,
)

__all__ = ["plan_tree", "sensor_text", "stats_table", "trace_table", "verification_table"]
