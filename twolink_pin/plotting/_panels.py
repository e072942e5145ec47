"""Helpers that draw on a panel: the max-|e| envelope, a free spot for an annotation, legends
moved off the curves, ±limit lines with their note, shaded time spans, plain log-axis labels.
Torques [N·m], times [s], positions in axes fraction where said.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Literal

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.ticker import LogFormatter
from matplotlib.transforms import Bbox

from twolink_pin.plotting._save import figure_renderer
from twolink_pin.plotting._style import LIMIT_COLOR, LOG_FLOOR

OFF_SCALE_RATIO = 3.0
"""A torque limit more than this many times the plotted peak is noted, not drawn in view."""
ENVELOPE_WINDOWS = 300
"""Number of windows of the max-|error| envelope drawn on the log-scale panel."""
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
    renderer = figure_renderer(fig)
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
