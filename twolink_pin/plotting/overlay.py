"""Several runs of one law on the same axes: the variants of a comparison overlaid
(``compare pd pd@kp=200,150``, :mod:`twolink_pin.law_variant`).

:func:`save_overlay_figure` writes one figure: for each joint, the tracking error's envelope
``max |e_j|`` per window over the whole run [rad] (log scale: an error that decays to 1e-10
stays visible) and the applied torque ``τ_j`` over the last reference period [N·m]; one colour
per run, named in the legend by its row's name.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.plotting._panels import envelope, plain_log_ticks, shade_spans
from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import LOG_FLOOR, Margins, fix_margins, new_figure, rows_figsize
from twolink_pin.simulation import SimulationResult

OVERLAY_FIGSIZE = (12.0, 5.0)
"""Size of the overlay figure of a 2-joint arm [in]; each further joint adds a row."""
OVERLAY_ROW_HEIGHT = 2.1
"""Height each further (or fewer) joint adds to (takes from) the figure [in]."""
OVERLAY_MARGINS = Margins(left=1.05, right=0.2, bottom=0.55, top=0.95, wspace=0.85, hspace=0.35)
"""Margins [in]: the top holds the title and the legend of the runs."""
COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:gray")
"""One colour per run, in order (then again, dashed)."""


def _overlay_figure(results: Mapping[str, SimulationResult], title: str) -> Figure:
    first = next(iter(results.values()))
    nv = first.nv
    fig = new_figure(rows_figsize(OVERLAY_FIGSIZE, nv, OVERLAY_ROW_HEIGHT))
    axes = fig.subplots(nv, 2, squeeze=False, width_ratios=(1.6, 1.0))
    period = first.reference_period
    for k, (name, result) in enumerate(results.items()):
        style = {"color": COLORS[k % len(COLORS)], "ls": "-" if k < len(COLORS) else "--", "lw": 1.2}
        t = np.asarray(result.t)
        last = t >= max(t[0], t[-1] - period)
        for j in range(nv):
            te, env = envelope(t, np.asarray(result.e[:, j]))
            axes[j, 0].semilogy(te, np.maximum(env, LOG_FLOOR), drawstyle="steps-post", label=name, **style)
            axes[j, 1].plot(t[last], np.asarray(result.tau[last, j]), **style)
    for j in range(nv):
        left, right = axes[j]
        left.set_label(f"e{j + 1}")
        right.set_label(f"tau{j + 1}-last")
        plain_log_ticks(left)
        left.set_ylabel(f"max $|e_{{{j + 1}}}|$ [rad]")
        right.set_ylabel(rf"$\tau_{{{j + 1}}}$ [N·m]")
        for ax in (left, right):
            ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].set_title("tracking error: max |e| per window, whole run", fontsize=10)
    shorter = float(first.t[-1] - first.t[0]) <= period
    window = (
        f"whole run (shorter than one {period:g}-s period)"
        if shorter
        else f"last reference period ({period:g} s)"
    )
    axes[0, 1].set_title(f"applied torque, {window}", fontsize=10)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    height = fig.get_size_inches()[1]
    fig.legend(  # below the title, in the top margin whatever the figure's height
        handles,
        labels,
        loc="upper center",
        ncols=min(3, len(labels)),
        fontsize=9,
        bbox_to_anchor=(0.5, 1.0 - 0.4 / height),
    )
    fig.suptitle(title, fontsize=11)
    fix_margins(fig, OVERLAY_MARGINS)
    return fig


def save_overlay_figure(
    results: Mapping[str, SimulationResult],
    path: str | os.PathLike[str],
    title: str | None = None,
    spans: Sequence[tuple[float, float]] = (),
) -> Path:
    """Write the runs ``results`` (row name → run, at least two, of one robot and one
    reference) overlaid to ``path`` (PNG): per joint the tracking error's envelope over the
    run [rad] and the torque over the last reference period [N·m], one colour per run;
    ``spans`` (a wrench's window [s]) shaded.

    Raises:
        InvalidParameterError: fewer than two runs, or runs of different arms or grids.
    """
    if len(results) < 2:
        raise InvalidParameterError("results", list(results), "at least two runs to overlay")
    shapes = {(r.nv, r.t.shape) for r in results.values()}
    if len(shapes) != 1:
        raise InvalidParameterError("results", sorted(shapes), "runs of one arm on one time grid")
    names = list(results)
    heading = title or f"{len(names)} runs overlaid: {', '.join(names)}"
    fig = _overlay_figure(results, heading)
    shade_spans(fig, spans, np.asarray(next(iter(results.values())).t))
    return save_figure(fig, Path(path))
