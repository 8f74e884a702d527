"""Writing the pictures: a part plot file (PNG or SVG by suffix) and the HTML report, atomically."""

from __future__ import annotations

import os
from pathlib import Path

from feederkit.errors import InputError
from feederkit.jsonio import write_bytes_atomic, write_text_atomic
from feederkit.mechanics.push import push_function
from feederkit.part import Part
from feederkit.reports.partplot import FORMATS, part_plot_bytes


def plot_format(path: str | os.PathLike[str]) -> str:
    """``png`` or ``svg`` from the file's suffix; any other suffix is bad input."""
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise InputError(f"{path}: the plot file must end in .png or .svg")
    return fmt


def write_part_plot(part: Part, path: str | os.PathLike[str]) -> None:
    """Draw ``part``'s plot and write it as PNG or SVG, chosen by the file's suffix."""
    fmt = plot_format(path)
    write_bytes_atomic(path, part_plot_bytes(push_function(part), fmt))


REPORT_SUFFIXES = (".html", ".htm")
"""The report is one HTML page; a PDF is printed from a browser (the page prints on A4)."""


def check_report_path(path: str | os.PathLike[str]) -> None:
    """A report file must end in .html (or .htm): a .pdf would hold HTML, so it is refused."""
    if Path(path).suffix.lower() not in REPORT_SUFFIXES:
        raise InputError(
            f"{path}: the report is an HTML page: name it .html (a browser prints it to PDF on A4)"
        )


def write_report(path: str | os.PathLike[str], html_text: str) -> None:
    """Write the HTML report atomically; an unwritable destination or a name that does not
    end in .html is bad input."""
    check_report_path(path)
    write_text_atomic(path, html_text, what="report")
