"""What every figure shares: sizes, colours, the non-GUI figure, atomic saving, titles,
and the helpers that place limit lines, notes, annotations and legends.

Figures are :class:`matplotlib.figure.Figure` objects with their own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg` (never ``pyplot``): no GUI
backend is selected, no global registry holds a figure, and a figure is freed as soon as
it is no longer referenced. Sizes [in], resolution [dots per inch], torques [N·m].
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import matplotlib
import matplotlib.image
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.text import Text
from matplotlib.ticker import LogFormatter
from matplotlib.transforms import Bbox

from twolink_pin.errors import InvalidParameterError
from twolink_pin.files import atomic_write
from twolink_pin.plotting.titles import shown_title


@dataclass(frozen=True)
class Margins:
    """Fixed room around and between a figure's panels [in], set once per figure type instead
    of a layout engine (constrained layout measures every tick label of every panel, twice,
    on each save: half of a figure's CPU time).

    Attributes:
        left, right, bottom, top: Room between the panels and the figure's edges [in]
            (tick labels, axis labels, the suptitle).
        wspace, hspace: Room between neighbouring columns and rows [in].
    """

    left: float
    right: float
    bottom: float
    top: float
    wspace: float = 0.0
    hspace: float = 0.0


DPI = 110
"""Resolution of every saved figure [dots per inch]."""
PNG_COMPRESS_LEVEL = 1
"""zlib level of the PNG writer: 1 encodes a figure in about half the time of the default 6
for files about 7 % larger."""
JOINT_FIGSIZE = (8.0, 8.0)
"""Size of a trajectory joint figure (four stacked panels) [in]."""
WORKSPACE_FIGSIZE = (12.0, 5.5)
"""Size of the workspace figure (full view and zoom on the path) [in]."""
TORQUE_FIGSIZE = (8.0, 6.0)
"""Size of the desired-torque figure of a two-joint arm [in]; see :data:`TORQUE_ROW_HEIGHT`."""
TORQUE_ROW_HEIGHT = 2.7
"""Height each further (or fewer) joint adds to (takes from) a torque figure [in]."""
STATE_FIGSIZE = (8.0, 7.5)
"""Size of a simulation state figure (actual/desired, error, log |error|) [in]."""
SIM_TORQUE_FIGSIZE = (12.0, 6.5)
"""Size of a simulation torque figure of a two-joint arm (whole run and last period) [in]."""
PARAM_FIGSIZE = (8.0, 5.0)
"""Size of a parameter-error figure with one panel and a legend inside it [in]."""
PARAM_ROW_HEIGHT = 2.2
"""Height each further panel adds to a parameter-error figure [in]."""
SUMMARY_WIDTH = 10.0
"""Width of a parameter-error figure of many parameters (norms over time, bars) [in]."""
NORM_PANEL_HEIGHT = 2.2
"""Height of a panel of error norms over time in a many-parameter figure [in]."""
BAR_HEIGHT = 0.2
"""Height each parameter's bar pair takes in a many-parameter figure [in]."""
PANEL_DECORATION_HEIGHT = 0.85
"""Height of a panel's title, tick labels and x label, beside its drawing area [in]."""
SUPTITLE_HEIGHT = 0.75
"""Height of a figure's (two- or three-line) title [in]."""
WORKSPACE_3D_FIGSIZE = (16.0, 5.8)
"""Size of the workspace figure of an arm moving in 3-D (a 3-D view, two projections) [in]."""

STATE_MARGINS = Margins(left=0.9, right=0.15, bottom=0.5, top=0.58, wspace=0.85, hspace=0.55)
"""A run's state figure: a two-line suptitle; between rows a panel title above, tick labels
and an x label below; the late-error panel's tick labels between the columns."""
SIM_TORQUE_MARGINS = Margins(left=0.8, right=0.22, bottom=0.5, top=0.75, wspace=0.75, hspace=0.25)
"""A run's torque figure: a two-line suptitle and the column titles above."""
JOINT_MARGINS = Margins(left=0.92, right=0.18, bottom=0.5, top=0.36, hspace=0.16)
"""A trajectory joint figure: one suptitle line, four panels sharing t."""
TORQUE_MARGINS = Margins(left=0.8, right=0.18, bottom=0.5, top=0.36, hspace=0.2)
"""The desired-torque figure: one suptitle line, a panel per joint sharing t."""
PARAM_MARGINS = Margins(left=0.95, right=0.15, bottom=0.5, top=0.6, hspace=0.2)
"""A parameter-error figure with its legends inside the panels: a two-line suptitle."""

OFF_SCALE_RATIO = 3.0
"""A torque limit more than this many times the plotted peak is noted, not drawn in view."""
ENVELOPE_WINDOWS = 300
"""Number of windows of the max-|error| envelope drawn on the log-scale panel."""
LOG_FLOOR = 1e-16
"""Smallest value shown on a log-scale error panel (exact zeros are drawn there)."""

ACTUAL_COLOR = "tab:blue"
DESIRED_COLOR = "black"
ERROR_COLOR = "tab:red"
LIMIT_COLOR = "tab:red"
COMMAND_COLOR = "tab:orange"
REACH_COLOR = "tab:green"

LEGEND_BOX = (0.62, 0.78, 1.0, 1.0)
"""Region of an "upper right" legend, kept free of annotations [axes fraction]."""
NOTE_BOX = (0.0, 0.0, 0.75, 0.12)
"""Region of the off-scale limit note, kept free of annotations [axes fraction]."""
LegendPlace = Literal[
    "upper right", "center right", "upper left", "center left", "lower right", "upper center"
]
LEGEND_PLACES: tuple[LegendPlace, ...] = (
    "upper right",
    "center right",
    "upper left",
    "center left",
    "lower right",
    "upper center",
)
"""Where a torque panel's legend may go, in order of preference; the first is where it is
made (see :func:`unblock_legends`)."""


# ------------------------------------------------------------------ figures and files


def new_figure(figsize: tuple[float, float]) -> Figure:
    """A non-GUI figure with its own Agg canvas and constrained layout (a figure type with
    fixed :class:`Margins` replaces it with :func:`fix_margins` once its panels exist)."""
    fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def fix_margins(fig: Figure, margins: Margins) -> None:
    """Place the panels of ``fig`` (one grid) with ``margins`` [in] instead of constrained
    layout. :func:`save_figure` checks after drawing that the tick and axis labels fit and falls
    back to constrained layout when they do not (an unusually long tick label)."""
    width, height = fig.get_size_inches()
    spec = fig.axes[0].get_subplotspec()
    assert spec is not None  # every fixed-margin figure is a grid of subplots
    rows, cols = spec.get_gridspec().get_geometry()
    panel_w = (width - margins.left - margins.right - (cols - 1) * margins.wspace) / cols
    panel_h = (height - margins.bottom - margins.top - (rows - 1) * margins.hspace) / rows
    fig.set_layout_engine(None)
    fig.subplots_adjust(
        left=margins.left / width,
        right=1.0 - margins.right / width,
        bottom=margins.bottom / height,
        top=1.0 - margins.top / height,
        wspace=margins.wspace / panel_w,
        hspace=margins.hspace / panel_h,
    )
    fig._twolink_margins = margins  # type: ignore[attr-defined]  # read by save_figure


def rows_figsize(base: tuple[float, float], rows: int, row_height: float) -> tuple[float, float]:
    """``base`` (the size for two rows) grown or shrunk by ``row_height`` per row [in]."""
    return (base[0], base[1] + row_height * (rows - 2))


def _drawn_labels(ax: Axes) -> list[Text]:
    """The texts around ``ax`` whose size depends on the data or the caller: its drawn tick
    labels, its axis labels, the axis offsets (``1e−3``) and its title."""
    texts = [ax.xaxis.label, ax.yaxis.label, ax.xaxis.offsetText, ax.yaxis.offsetText, ax.title]
    for axis, (lo, hi) in ((ax.xaxis, sorted(ax.get_xlim())), (ax.yaxis, sorted(ax.get_ylim()))):
        index = 0 if axis is ax.xaxis else 1
        for tick in axis.majorTicks:
            for label in (tick.label1, tick.label2):
                if label.get_visible() and lo <= label.get_position()[index] <= hi:
                    texts.append(label)
    return [t for t in texts if t.get_visible() and t.get_text()]


def _labels_fit(fig: Figure) -> bool:
    """After a draw: every tick label, axis label, offset and panel title lies inside the
    figure and outside every other panel's plotting area, and the suptitle overlaps none of
    them (1 px of rounding allowed)."""
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]  # the Agg canvas has one
    areas = [ax.get_window_extent() for ax in fig.axes]
    box = fig.bbox
    suptitle = fig._suptitle  # type: ignore[attr-defined]  # the Text of fig.suptitle, or None
    top = None
    if suptitle is not None and suptitle.get_text():
        top = suptitle.get_window_extent(renderer)
        areas.append(top)  # no panel's text may reach into it
    for k, ax in enumerate(fig.axes):
        for text in _drawn_labels(ax):
            extent = text.get_window_extent(renderer)
            if not (
                box.x0 - 1 <= extent.x0
                and extent.x1 <= box.x1 + 1
                and box.y0 - 1 <= extent.y0
                and extent.y1 <= box.y1 + 1
            ):
                return False
            inner = Bbox.from_extents(extent.x0 + 1, extent.y0 + 1, extent.x1 - 1, extent.y1 - 1)
            if any(i != k and inner.overlaps(area) for i, area in enumerate(areas)):
                return False
    return top is None or not any(top.overlaps(area) for area in areas[:-1])


def _lay_out_once(fig: Figure) -> None:
    """Run ``fig``'s layout engine once, then remove it: with a layout engine set, savefig
    draws the whole figure twice (a first pass with drawing disabled that runs the layout,
    then the real one). Same layout, same pixels (checked byte for byte)."""
    engine = fig.get_layout_engine()
    if engine is not None and fig.axes:
        engine.execute(fig)
        with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
            fig.set_layout_engine(None)  # None (not "none", a placeholder savefig still pre-draws for)


def save_figure(fig: Figure, path: Path) -> Path:
    """Render ``fig`` into ``path`` atomically (format from the suffix, PNG by default).

    The figure is drawn once on its Agg canvas; a figure with fixed :class:`Margins` whose
    labels do not fit (:func:`_labels_fit`) is then laid out by constrained layout and drawn
    again. A PNG's pixels are written as drawn (zlib level :data:`PNG_COMPRESS_LEVEL`); other
    formats go through ``savefig``. The file carries the figure's title
    (:func:`~twolink_pin.plotting.titles.shown_title`) as its ``Title``."""
    fmt = path.suffix[1:].lower() or "png"
    _lay_out_once(fig)
    canvas = fig.canvas
    assert isinstance(canvas, FigureCanvasAgg)  # every figure here has its own (new_figure)
    canvas.draw()
    if getattr(fig, "_twolink_margins", None) is not None and fig.axes and not _labels_fit(fig):
        fig.set_layout_engine("constrained")
        _lay_out_once(fig)
        canvas.draw()
    title = shown_title(fig)
    if fmt != "png":
        with atomic_write(path, "wb") as f:
            fig.savefig(f, format=fmt, dpi=DPI, metadata={"Title": title} if fmt in ("pdf", "svg") else None)
        return path
    with atomic_write(path, "wb") as f:
        matplotlib.image.imsave(
            f,  # type: ignore[arg-type]  # a binary file (mode "wb")
            canvas.buffer_rgba(),
            format="png",
            origin="upper",
            dpi=fig.dpi,
            metadata={"Title": title},
            pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL},
        )
    return path


class PowerOfTenFormatter(LogFormatter):
    """Log-axis tick labels as ``10⁻⁸`` (``2×10⁻³`` between decades) in plain Unicode text,
    where matplotlib's default writes mathtext (``$10^{-8}$``), parsed by pyparsing on each
    first draw: the labels look the same and cost nothing to lay out. Which ticks get a label
    is :class:`~matplotlib.ticker.LogFormatter`'s choice."""

    _SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")

    def __call__(self, x: float, pos: int | None = None) -> str:
        if not super().__call__(x, pos) or x <= 0 or not math.isfinite(x):
            return ""
        exponent = math.floor(math.log10(x) + 1e-9)
        mantissa = round(x / 10.0**exponent, 6)
        power = "10" + str(exponent).translate(self._SUPERSCRIPT)
        return power if mantissa == 1 else f"{mantissa:g}×{power}"


def plain_log_ticks(ax: Axes, axis: Literal["x", "y"] = "y") -> None:
    """Label ``ax``'s log ``axis`` with :class:`PowerOfTenFormatter` (major and minor ticks)."""
    target = ax.yaxis if axis == "y" else ax.xaxis
    target.set_major_formatter(PowerOfTenFormatter())
    target.set_minor_formatter(PowerOfTenFormatter(labelOnlyBase=False))  # as matplotlib's default


def save_figures(figures: Mapping[str, Figure], out_dir: str | os.PathLike[str], prefix: str) -> list[Path]:
    """Save each figure as ``out_dir/<prefix><key>.png`` in order, then clear them all."""
    out = Path(out_dir)
    try:
        return [save_figure(fig, out / f"{prefix}{key}.png") for key, fig in figures.items()]
    finally:
        for fig in figures.values():
            fig.clear()


# ---------------------------------------------------------------------------- titles


def check_figure_numbers(figure_numbers: Mapping[str, int] | None) -> Mapping[str, int]:
    """``figure_numbers`` or an empty mapping; each value a positive integer.

    Raises:
        InvalidParameterError: not a mapping of figure key → positive integer.
    """
    if figure_numbers is None:
        return {}
    if not isinstance(figure_numbers, Mapping):
        raise InvalidParameterError(
            "figure_numbers", figure_numbers, "a mapping figure key → report figure number, or None"
        )
    for key, number in figure_numbers.items():
        if not isinstance(key, str) or isinstance(number, bool) or not isinstance(number, int) or number < 1:
            raise InvalidParameterError(
                f"figure_numbers[{key!r}]", number, "a positive integer (the report's figure number)"
            )
    return figure_numbers


def figure_title(what: str, key: str, figure_numbers: Mapping[str, int], heading: str | None = None) -> str:
    """A figure title: ``heading`` on its own line (if any), then ``what``.

    When ``figure_numbers`` has ``key``, "— cf. report Fig. N" ends the first line.
    """
    number = figure_numbers.get(key)
    cite = f" — cf. report Fig. {number}" if number is not None else ""
    return f"{heading}{cite}\n{what}" if heading else f"{what}{cite}"


# ------------------------------------------------------------- helpers on the axes


def envelope(t: np.ndarray, x: np.ndarray, windows: int = ENVELOPE_WINDOWS) -> tuple[np.ndarray, np.ndarray]:
    """Max ``|x|`` over consecutive windows: (window start times [s], maxima, >= LOG_FLOOR)."""
    n = len(t)
    width = max(1, n // windows)
    starts = np.arange(0, n, width)
    peaks = np.maximum.reduceat(np.abs(x), starts)
    return t[starts], np.maximum(peaks, LOG_FLOOR)


def free_spot(
    ax: Axes,
    x: np.ndarray,
    y: np.ndarray,
    size: tuple[float, float],
    near: tuple[float, float],
    avoid: tuple[tuple[float, float, float, float], ...] = (),
) -> tuple[float, float]:
    """Centre (axes fraction) of a ``size`` box over as few data points as possible.

    Candidates on a grid; ties go to the one nearest ``near`` (data coordinates). Boxes
    ``avoid`` (x0, y0, x1, y1 in axes fraction: legend, notes) are never used. Call after
    the axis limits are final.
    """
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    step = max(1, len(x) // 4000)
    fx, fy = (np.asarray(x)[::step] - x0) / (x1 - x0), (np.asarray(y)[::step] - y0) / (y1 - y0)
    nx, ny = (near[0] - x0) / (x1 - x0), (near[1] - y0) / (y1 - y0)
    w, h = size
    best: tuple[int, float, float, float] | None = None
    for cx in np.linspace(w / 2 + 0.02, 1 - w / 2 - 0.02, 11):
        for cy in np.linspace(h / 2 + 0.03, 1 - h / 2 - 0.03, 9):
            bx0, by0, bx1, by1 = cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2
            if any(bx0 < a1 and a0 < bx1 and by0 < b1 and b0 < by1 for a0, b0, a1, b1 in avoid):
                continue
            inside = int(
                np.count_nonzero(
                    (fx > bx0 - 0.02) & (fx < bx1 + 0.02) & (fy > by0 - 0.04) & (fy < by1 + 0.04)
                )
            )
            key = (inside, float(np.hypot(cx - nx, cy - ny)), float(cx), float(cy))
            if best is None or key < best:
                best = key
    return (0.5, 0.5) if best is None else (best[2], best[3])


def _legend_size(legend: Legend, dpi: float) -> tuple[float, float]:
    """An upper estimate of a one-column legend's width and height [px] from its labels'
    lengths and its spacings (in font sizes), without laying out its text (measuring a
    mathtext label from inside a figure builder keeps the figure alive for a second
    garbage-collection pass)."""
    em = legend.prop.get_size_in_points() * dpi / 72.0
    # A mathtext command (\tau) counts as one character; $ { } _ ^ as none.
    labels = [re.sub(r"[${}_^]", "", re.sub(r"\\[A-Za-z]+", "x", text.get_text())) for text in legend.texts]
    chars = max((len(label) for label in labels), default=0)
    width = legend.handlelength + legend.handletextpad + 2.0 * legend.borderpad + 0.6 * chars
    height = 1.25 * len(labels) + legend.labelspacing * max(len(labels) - 1, 0) + 2.0 * legend.borderpad
    return width * em, height * em


def _legend_box(ax: Axes, loc: LegendPlace, size: tuple[float, float], pad: float) -> Bbox:
    """Where a legend of ``size`` [px] at ``loc``, ``pad`` [px] from the axes edges, lies [px]."""
    box = ax.get_window_extent()
    w, h = size
    x0 = {"left": box.x0 + pad, "right": box.x1 - pad - w, "center": 0.5 * (box.x0 + box.x1 - w)}
    y0 = {"upper": box.y1 - pad - h, "center": 0.5 * (box.y0 + box.y1 - h), "lower": box.y0 + pad}
    vertical, horizontal = loc.split()
    return Bbox.from_bounds(x0[horizontal], y0[vertical], w, h)


def unblock_legends(fig: Figure, curves: Sequence[tuple[Axes, np.ndarray, np.ndarray]]) -> None:
    """Move each "upper right" legend that covers a point of its axes' curves to a free place.

    ``curves`` gives, per axes whose legend was made at ``loc="upper right"``, the points
    of its curves (x, y in data coordinates). A legend covering none of the points stays
    where it is (the twolink's legends do not move); else it goes to the first of
    :data:`LEGEND_PLACES` that covers no point and no text (annotation, note), else to the
    one covering fewest points, then fewest texts. Call once the figure is complete.

    The test is conservative: it runs on the axes as placed when it is called (their fixed
    :class:`Margins`, or the plain subplot grid, smaller than constrained layout makes them),
    with an upper estimate of the legend's size (:func:`_legend_size`), so a legend is
    judged at least as large as it will be drawn, and no layout pass is needed. Matplotlib's ``loc="best"`` does a similar search at each
    draw, but also avoids the ±limit lines the legend is meant to sit above, and it warns
    on long runs.
    """
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]  # the Agg canvas has one
    for ax, x, y in curves:
        legend = ax.get_legend()
        if legend is None:
            continue
        points = ax.transData.transform(np.column_stack([np.ravel(x), np.ravel(y)]))
        texts = [text.get_window_extent(renderer) for text in ax.texts]
        size = _legend_size(legend, fig.dpi)
        pad = legend.borderaxespad * legend.prop.get_size_in_points() * fig.dpi / 72.0
        scores: list[tuple[int, int]] = []
        for loc in LEGEND_PLACES:
            box = _legend_box(ax, loc, size, pad)
            (x0, y0), (x1, y1) = box.get_points()
            inside = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
            scores.append((int(np.count_nonzero(inside)), sum(1 for text in texts if box.overlaps(text))))
            if loc == LEGEND_PLACES[0] and scores[0][0] == 0:
                break  # where it was made, over no point: it stays
            if scores[-1] == (0, 0):
                break
        best = LEGEND_PLACES[min(range(len(scores)), key=lambda k: scores[k])]
        if best != LEGEND_PLACES[0]:
            legend.set_loc(best)


def limit_lines(ax: Axes, limit: float, peak: float, label: bool = True) -> bool:
    """Draw ``±limit`` [N·m] dashed; keep them in view unless far beyond ``peak`` [N·m].

    Returns whether the limit is in view. When it is not, the y range stays on the data and
    a note gives the limit and the peak as a fraction of it. An infinite limit (the URDF
    gives none) draws nothing and returns False.
    """
    top = max(peak, 1e-12)
    if not math.isfinite(limit):
        ax.set_ylim(-1.12 * top, 1.4 * top)  # room for the legend above the data
        return False
    ax.axhline(limit, color=LIMIT_COLOR, ls="--", lw=1.2, label=f"±limit ({limit:g} N·m)" if label else None)
    ax.axhline(-limit, color=LIMIT_COLOR, ls="--", lw=1.2)
    in_view = limit <= OFF_SCALE_RATIO * top
    if in_view:
        top = max(limit, top)
        ax.set_ylim(-1.12 * top, 1.5 * top)  # the legend goes above the +limit line
    else:
        ax.set_ylim(-1.4 * top, 1.15 * top)  # room for the note below the data
        ax.text(
            0.005,
            0.03,
            f"±{limit:g} N·m limit off scale: peak |τ| = {peak:.3g} N·m ({100 * peak / limit:.1f} % of it)",
            transform=ax.transAxes,
            fontsize=8.5,
            color=LIMIT_COLOR,
            va="bottom",
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        )
    return in_view


SPAN_COLOR = "tab:purple"
"""Colour of a shaded time span (a wrench acting)."""


def shade_spans(
    fig: Figure, spans: Sequence[tuple[float, float]], t: np.ndarray, label: str = "wrench"
) -> None:
    """Shade each time span ``(start, stop)`` [s] on every axis of ``fig`` (all time axes), clipped
    to the run ``t``; ``label`` is written once, at the top of the span on the top axis."""
    t0, t1 = float(t[0]), float(t[-1])
    clipped = [(max(a, t0), min(b, t1)) for a, b in spans if min(b, t1) > max(a, t0)]
    if not clipped or not fig.axes:
        return
    top = max(fig.axes, key=lambda ax: ax.get_position().y1)
    for ax in fig.axes:
        limits = ax.get_xlim()
        for a, b in clipped:
            ax.axvspan(a, b, color=SPAN_COLOR, alpha=0.12, lw=0, zorder=0)
        ax.set_xlim(limits)  # the span never widens an axis
    for a, b in clipped:
        top.text(
            0.5 * (a + b),
            0.98,
            f"{label} {a:g}–{b:g} s",
            transform=top.get_xaxis_transform(),
            ha="center",
            va="top",
            fontsize=7,
            color=SPAN_COLOR,
            clip_on=True,
        )
