"""Pictures: part plots (the paper's figs. 3-6) and the self-contained HTML changeover report.

Both take the one plan model (:class:`feederkit.plans.model.Plan`). matplotlib is imported
only by the functions that draw, never when feederkit is imported.
"""

from feederkit.reports.files import (
    REPORT_SUFFIXES,
    check_report_path,
    plot_format,
    write_part_plot,
    write_report,
)
from feederkit.reports.partplot import part_figure, part_plot_bytes
from feederkit.reports.report import render_report

__all__ = [
    "REPORT_SUFFIXES",
    "check_report_path",
    "part_figure",
    "part_plot_bytes",
    "plot_format",
    "render_report",
    "write_part_plot",
    "write_report",
]
