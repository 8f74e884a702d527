"""Pictures: part plots (the paper's figs. 3-6) and the self-contained HTML changeover report.

matplotlib is imported only by the functions that draw, never when feederkit is imported.
"""

from feederkit.reports.files import plot_format, write_part_plot, write_report
from feederkit.reports.partplot import part_figure, part_plot_bytes
from feederkit.reports.planview import plan_view, read_plan_file
from feederkit.reports.report import render_report

__all__ = [
    "part_figure",
    "part_plot_bytes",
    "plan_view",
    "plot_format",
    "read_plan_file",
    "render_report",
    "write_part_plot",
    "write_report",
]
