"""Histograms of metrics over many runs (a sweep or a Monte Carlo study).

:func:`save_distribution_figure` writes one figure with a histogram per metric;
:func:`_distribution_figure` returns it. Values are in each metric's own unit, which its
name carries (``"RMS e1 [rad]"``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.plotting import _save
from twolink_pin.plotting._style import ACTUAL_COLOR, ERROR_COLOR, new_figure

DEFAULT_TITLE = "Distribution of metrics over the sweep"
"""Title of a distribution figure when none is given."""


def _bins(x: np.ndarray) -> np.ndarray:
    """numpy's ``"auto"`` bin edges of ``x``; or, when its spread is rounding (a metric equal
    in every run but for the last bits, whose range numpy cannot cut into finite bins), one
    bin of ±5 % about the value, wide enough to be seen."""
    scale = float(np.max(np.abs(x)))
    if float(np.ptp(x)) > 1e-9 * scale:
        try:
            return np.histogram_bin_edges(x, bins="auto")
        except ValueError:  # "too many bins for data range"
            pass
    centre = float(np.median(x))
    half = max(0.05 * abs(centre), float(np.ptp(x)), 1e-12)
    return np.array([centre - half, centre + half])


def _distribution_figure(rows: Mapping[str, np.ndarray], title: str | None = None) -> Figure:
    """Histograms of each metric in ``rows`` (one subplot each), median and mean marked.

    Raises:
        InvalidParameterError: ``rows`` is empty or a metric has no finite value.
    """
    if not rows:
        raise InvalidParameterError("rows", {}, "at least one metric name → array of values")
    values: dict[str, np.ndarray] = {}
    for name, raw in rows.items():
        x = np.asarray(raw, dtype=float).ravel()
        if not np.isfinite(x).any():
            raise InvalidParameterError(f"rows[{name!r}]", raw, "at least one finite value")
        values[name] = x
    n = len(values)
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    fig = new_figure((4.0 * ncols + 0.5, 3.2 * nrows + 0.6))
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax, (name, x) in zip(axes, values.items()):
        finite = x[np.isfinite(x)]
        edges = _bins(finite)
        ax.hist(finite, bins=edges, color=ACTUAL_COLOR, alpha=0.75, edgecolor="white")
        if edges.size == 2:  # one value: no offset notation for its tiny spread
            ax.ticklabel_format(axis="x", useOffset=False)
        median, mean = float(np.median(finite)), float(np.mean(finite))
        ax.axvline(median, color="black", lw=1.4, label=f"median {median:.3g}")
        ax.axvline(mean, color=ERROR_COLOR, lw=1.2, ls="--", label=f"mean {mean:.3g}")
        dropped = x.size - finite.size
        ax.set_title(f"{name} (n = {finite.size}{f', {dropped} non-finite' if dropped else ''})", fontsize=10)
        ax.set_xlabel(name)
        ax.set_ylabel("count")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(title if title is not None else DEFAULT_TITLE)
    return fig


def save_distribution_figure(
    rows: Mapping[str, np.ndarray], out_path: str | os.PathLike[str], title: str | None = None
) -> Path:
    """Write histograms of several metrics (one subplot each) to ``out_path``, atomically.

    Args:
        rows: Metric name (with its unit, e.g. ``"RMS e1 [rad]"``) → values, any shape
            (flattened; non-finite values are counted and left out). Read only.
        out_path: Output file; its suffix picks the format (``.png`` if none); the
            directory is created if missing.
        title: Figure title; default "Distribution of metrics over the sweep".

    Returns:
        ``out_path`` as a :class:`Path`.

    Raises:
        InvalidParameterError: ``rows`` is empty or a metric has no finite value.
        OutputError: ``out_path`` cannot be written.
    """
    fig = _distribution_figure(rows, title)
    return _save.save_figure(fig, Path(out_path))
