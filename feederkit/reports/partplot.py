"""The part plot (the paper's figs. 3-6 for the user's own part), drawn with matplotlib (Agg).

Top: the outline with its holes, the contact hull (dashed), the COM and the stable edges, each
marked in its state's colour and numbered ``s<state> e<edge>`` as ``part analyze`` numbers them.
Below, over fence orientations theta in [0, 360): the radius function, the push function and
the push-diameter function, with resting ranges shaded, divergent orientations dotted and the
stable orientations marked. In SVG output each stable orientation's cross on the push-diameter
panel is the group ``stable-orientation-<id>`` (and ``stable-edge-<id>`` marks its edge).

matplotlib is imported inside the functions, never when feederkit is imported.
"""

from __future__ import annotations

import functools
import io
import re
import warnings
from typing import TYPE_CHECKING

import numpy as np

from feederkit.angles import norm360
from feederkit.mechanics.push import PushFunction, edge_normals, radius
from feederkit.outline import Outline

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.font_manager import FontProperties

STATE_COLOURS = (
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#17becf",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
)
"""Colour of stable state ``i`` (cycled) in every panel."""

FORMATS = ("png", "svg")

TITLE_SIZE = 11
"""The title's font size (pt)."""

UNDRAWN_NOTE = "(\\uXXXX: a character of the name the plot's font cannot draw)"
"""The title's second line when :func:`drawable` replaced characters of the part's name."""


def state_colour(sid: int) -> str:
    """The colour of stable state ``sid``."""
    return STATE_COLOURS[sid % len(STATE_COLOURS)]


@functools.lru_cache(maxsize=8)
def _charmaps(fonts: tuple[str, ...]) -> tuple[frozenset[int], ...]:
    """The code points each font file has a glyph for."""
    from matplotlib.font_manager import get_font

    return tuple(frozenset(get_font(f).get_charmap()) for f in fonts)


def _fonts(prop: FontProperties) -> tuple[str, ...]:
    """The font files matplotlib draws ``prop``'s text with, its fallbacks in order
    (``_find_fonts_by_props``, matplotlib >= 3.6; else the one ``findfont`` gives)."""
    from matplotlib import font_manager

    find = getattr(font_manager.fontManager, "_find_fonts_by_props", None)
    found = find(prop) if find is not None else [font_manager.findfont(prop)]
    return tuple(found)  # FontPath (3.11) keeps its face index in a collection


def drawable(text: str, prop: FontProperties | None = None) -> tuple[str, bool]:
    """``text`` with each character the plot's fonts have no glyph for written as its
    escape (``\\u65e5``), and whether any was. A part name is any printable Unicode
    (docs/catalog.md) and the plot's bundled font (DejaVu Sans) has no CJK glyphs: matplotlib
    would draw empty boxes and print a raw ``UserWarning`` on stderr for each."""
    from matplotlib.font_manager import FontProperties

    maps = _charmaps(_fonts(prop if prop is not None else FontProperties(size=TITLE_SIZE)))
    out = [c if c.isspace() or any(ord(c) in m for m in maps) else _escape(c) for c in text]
    return "".join(out), out != list(text)


def _escape(c: str) -> str:
    """A character as Python writes it escaped: ``\\u65e5``, ``\\U0001f600``."""
    n = ord(c)
    return f"\\u{n:04x}" if n <= 0xFFFF else f"\\U{n:08x}"


def _arcs(lo: float, hi: float) -> list[tuple[float, float]]:
    """The arc from lo to hi (hi - lo <= 360) as pieces inside [0, 360]."""
    a = norm360(lo)
    b = a + (hi - lo)
    if b <= 360.0:
        return [(a, b)]
    return [(a, 360.0), (0.0, b - 360.0)]


def _shade_ranges(ax: Axes, pf: PushFunction, label: bool) -> None:
    """Shade each state's resting range and dot the divergent orientations."""
    for s in pf.states:
        for a, b in _arcs(*s.resting_range_deg):
            ax.axvspan(a, b, color=state_colour(s.id), alpha=0.10, lw=0)
            if label and b - a > 12.0:
                ax.text(
                    (a + b) / 2,
                    1.0,
                    f"s{s.id}",
                    transform=ax.get_xaxis_transform(),
                    ha="center",
                    va="bottom",
                    fontsize=8,
                    color=state_colour(s.id),
                )
    for d in pf.divergent_deg:
        ax.axvline(d, color="#555", lw=0.8, ls=":")


def _oriented(ring: tuple[tuple[float, float], ...], ccw: bool) -> list[tuple[float, float]]:
    """The ring counter-clockwise (``ccw``) or clockwise, so holes stay empty when filled."""
    nxt = ring[1:] + ring[:1]
    area2 = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(ring, nxt, strict=True))
    return list(ring) if (area2 > 0) == ccw else list(reversed(ring))


def _draw_outline(ax: Axes, pf: PushFunction, outline: Outline | None = None) -> None:
    """The outline (``outline`` when given, for its holes; else the part's), its contact hull,
    and the stable edges labelled by state and edge, fragile ones marked.

    Only stable edges are labelled: a CAD arc flattened into many short edges would otherwise
    bury the part under "unstable" labels.
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    from feederkit.mechanics.analysis import fragile_states

    part = pf.part
    shape = outline if outline is not None else part.outline
    rings = [_oriented(shape.vertices, True)]
    rings += [_oriented(h, False) for h in shape.holes]
    verts: list[tuple[float, float]] = []
    codes: list[int] = []
    for ring in rings:
        verts.extend([*ring, ring[0]])
        codes.extend([MplPath.MOVETO] + [MplPath.LINETO] * (len(ring) - 1) + [MplPath.CLOSEPOLY])
    ax.add_patch(PathPatch(MplPath(verts, codes), facecolor="#d9d9d9", edgecolor="#333", lw=1.0))
    hull = np.array([*part.hull, part.hull[0]])
    ax.plot(hull[:, 0], hull[:, 1], color="#666", lw=0.9, ls="--", label="contact hull")
    normals = edge_normals(part.hull)
    size = part.size
    n = len(part.hull)
    fragile = set(fragile_states(pf))
    for s in pf.states:
        p0, p1 = np.array(part.hull[s.edge]), np.array(part.hull[(s.edge + 1) % n])
        (line,) = ax.plot(
            [p0[0], p1[0]],
            [p0[1], p1[1]],
            color=state_colour(s.id),
            lw=3.2,
            solid_capstyle="butt",
            ls=":" if s.id in fragile else "-",
        )
        line.set_gid(f"stable-edge-{s.id}")
        mid = (p0 + p1) / 2
        u = np.array([np.cos(np.radians(normals[s.edge])), np.sin(np.radians(normals[s.edge]))])
        tx, ty = mid + 0.09 * size * u
        ax.text(
            tx,
            ty,
            f"s{s.id} e{s.edge}" + (" fragile" if s.id in fragile else ""),
            ha="center",
            va="center",
            fontsize=8,
            color=state_colour(s.id),
            fontweight="bold",
        )
    ax.plot([part.com[0]], [part.com[1]], "o", color="black", ms=5, label="COM")
    xs = [p[0] for p in part.hull]
    ys = [p[1] for p in part.hull]
    pad = 0.2 * size
    ax.set_xlim(min(xs) - pad, max(xs) + pad)
    ax.set_ylim(min(ys) - pad, max(ys) + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (mm, part frame)")
    ax.set_ylabel("y (mm)")
    ax.legend(loc="upper right", fontsize=7, framealpha=0.8)


def _draw_radius(ax: Axes, pf: PushFunction) -> None:
    grid = np.union1d(
        np.linspace(0.0, 360.0, 1441),
        np.array([*pf.divergent_deg, *(norm360(s.normal_deg) for s in pf.states)]),
    )
    ax.plot(grid, radius(pf.part, grid), color="#222", lw=1.2)
    for s in pf.states:
        x = norm360(s.normal_deg)
        (m,) = ax.plot([x], [radius(pf.part, x)], "o", color=state_colour(s.id), ms=5)
        m.set_gid(f"radius-minimum-{s.id}")
    _shade_ranges(ax, pf, label=True)
    ax.set_ylabel("radius r (mm)")
    ax.set_title("radius function: COM to fence distance", fontsize=9, loc="left", pad=12)


def _draw_push(ax: Axes, pf: PushFunction) -> None:
    ax.plot([0, 360], [0, 360], color="#bbb", lw=0.7, ls="--")
    for s in pf.states:
        y = norm360(s.normal_deg)
        for a, b in _arcs(*s.resting_range_deg):
            ax.plot([a, b], [y, y], color=state_colour(s.id), lw=2.2, solid_capstyle="butt")
        ax.plot([y], [y], "o", color=state_colour(s.id), ms=4, mfc="white")
    _shade_ranges(ax, pf, label=False)
    ax.set_ylim(-10, 370)
    ax.set_yticks(range(0, 361, 90))
    ax.set_ylabel("after push (deg)")
    ax.set_title("push function: where each fence orientation settles", fontsize=9, loc="left")


def _draw_push_diameter(ax: Axes, pf: PushFunction) -> None:
    for s in pf.states:
        for a, b in _arcs(*s.resting_range_deg):
            ax.plot(
                [a, b],
                [s.diameter, s.diameter],
                color=state_colour(s.id),
                lw=2.2,
                solid_capstyle="butt",
            )
        (m,) = ax.plot([norm360(s.normal_deg)], [s.diameter], "x", color="black", ms=7, mew=1.6)
        m.set_gid(f"stable-orientation-{s.id}")
    _shade_ranges(ax, pf, label=False)
    ds = [s.diameter for s in pf.states]
    spread = max(ds) - min(ds)
    pad = max(0.15 * spread, 0.05 * max(ds))
    ax.set_ylim(min(ds) - pad, max(ds) + pad)
    ax.set_ylabel("diameter (mm)")
    ax.set_xlabel("fence orientation theta (deg, part frame; x: stable orientations)")
    ax.set_title("push-diameter function: the sensor's reading", fontsize=9, loc="left")


def part_figure(
    pf: PushFunction, title: str | None = None, outline: Outline | None = None
) -> Figure:
    """The part plot of a push function's part as a matplotlib figure (Agg canvas).

    Every state, edge and function is the push function's; ``outline`` only draws the plate
    (its holes) around that part's hull. Characters of the title the fonts cannot draw are
    shown escaped, under a line that says so (:func:`drawable`).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # A fixed layout: the constrained one cost a third of a plot's time (a report draws one
    # per member) for margins these four panels always need.
    fig = Figure(figsize=(7.0, 10.0))
    FigureCanvasAgg(fig)
    label, replaced = drawable(title if title is not None else pf.part.name)
    grid = fig.add_gridspec(
        4,
        1,
        height_ratios=[3.2, 1.5, 1.5, 1.5],
        left=0.11,
        right=0.97,
        bottom=0.06,
        top=0.945 if replaced else 0.96,  # room for the title's second line
        hspace=0.42,
    )
    ax0 = fig.add_subplot(grid[0])
    _draw_outline(ax0, pf, outline)
    heading = f"{label}: {pf.n} stable state{'s' if pf.n != 1 else ''}"
    ax0.set_title(
        f"{heading}\n{UNDRAWN_NOTE}" if replaced else heading,
        fontsize=TITLE_SIZE,
        parse_math=False,
    )
    axes = [fig.add_subplot(grid[i]) for i in (1, 2, 3)]
    for ax in axes[1:]:
        ax.sharex(axes[0])
    _draw_radius(axes[0], pf)
    _draw_push(axes[1], pf)
    _draw_push_diameter(axes[2], pf)
    for ax in axes:
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 45))
        ax.grid(True, axis="y", color="#eee", lw=0.6)
    return fig


def _stable_clip_ids(svg: str) -> str:
    """Renumber matplotlib's hashed clip-path ids (they vary between runs) as ``clip1``, ..."""
    names = dict.fromkeys(re.findall(r'<clipPath id="([^"]+)"', svg))
    for k, old in enumerate(names, start=1):
        svg = svg.replace(f'id="{old}"', f'id="clip{k}"').replace(f"#{old})", f"#clip{k})")
    return svg


def part_plot_bytes(
    pf: PushFunction, fmt: str, title: str | None = None, outline: Outline | None = None
) -> bytes:
    """The part plot encoded as ``png`` or ``svg`` (SVG: UTF-8, fonts drawn as paths, the same
    bytes on every run); ``outline`` as in :func:`part_figure`. matplotlib's warnings are
    kept off stderr (design.md: one clear line, never raw Python output)."""
    import matplotlib

    if fmt not in FORMATS:
        raise ValueError(f"unsupported plot format {fmt!r}")
    with (
        warnings.catch_warnings(),
        matplotlib.rc_context({"svg.hashsalt": "feederkit", "svg.fonttype": "path"}),
    ):
        warnings.simplefilter("ignore")
        fig = part_figure(pf, title, outline)
        buf = io.BytesIO()
        meta = {"Date": None} if fmt == "svg" else {"Software": "feederkit"}
        fig.savefig(buf, format=fmt, dpi=120, metadata=meta)
    if fmt == "svg":
        return _stable_clip_ids(buf.getvalue().decode("utf-8")).encode("utf-8")
    return buf.getvalue()
