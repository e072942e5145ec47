"""Figures of a motion against its limits: velocity, acceleration and torque, one panel per
joint, the limits dashed and the stretches where a limit is active shaded.

:func:`save_limit_figures` writes ``<prefix>velocity.png``, ``<prefix>acceleration.png`` and
``<prefix>torque.png`` (what ``trajectory --time-optimal --plot`` and ``optimize --plot``
draw); :func:`limit_figures` returns the figures keyed ``velocity``, ``acceleration``,
``torque``. A reference drawn beside it (the motion before retiming or optimisation) is a
thin grey line on its own time axis, stretched to the motion's duration and labelled so.
:func:`save_references_figures` draws several references overlaid, each on its own time
axis scaled to its duration (the report's section "The reference within the limits").
Time [s], rates [rad/s], accelerations [rad/s²], torques [N·m].
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from twolink_pin.limits import ACCELERATION, EFFORT, VELOCITY, JointLimits, LimitKind, Motion
from twolink_pin.limits.active import ActiveLimit
from twolink_pin.plotting._save import save_figures
from twolink_pin.plotting._style import (
    ACTUAL_COLOR,
    LIMIT_COLOR,
    TORQUE_FIGSIZE,
    TORQUE_ROW_HEIGHT,
    new_figure,
    rows_figsize,
)

PANELS = ((VELOCITY, "velocity", "q̇"), (ACCELERATION, "acceleration", "q̈"), (EFFORT, "torque", "τ"))
"""The figures: kind, file key, symbol."""
REFERENCE_COLOR = "0.55"
"""Colour of the reference drawn beside the motion."""
ACTIVE_COLOR = "tab:orange"
"""Shade of the stretches where the panel's limit is active."""


OFF_SCALE = 4.0
"""A limit more than this many times the peak is not drawn to scale: a note gives it."""


def _limit(ax: Axes, limit: float, peak: float, unit: str) -> None:
    """``±limit`` dashed, in view unless far beyond ``peak``: then the axis stays on the data and
    a note gives the limit and the peak as a fraction of it."""
    if not math.isfinite(limit):
        return
    if limit <= OFF_SCALE * max(peak, 1e-300):
        ax.axhline(limit, color=LIMIT_COLOR, ls="--", lw=1.1, label=f"±limit ({limit:.4g} {unit})")
        ax.axhline(-limit, color=LIMIT_COLOR, ls="--", lw=1.1)
        ax.set_ylim(-1.15 * limit, 1.45 * limit)  # room for the legend above the +limit line
        return
    ax.text(
        0.005, 0.03, f"±{limit:.4g} {unit} limit off scale: the peak is {100 * peak / limit:.1f} % of it",
        transform=ax.transAxes, fontsize=8, color=LIMIT_COLOR, va="bottom",
    )  # fmt: skip


def _panel_figure(
    motion: Motion,
    limits: JointLimits,
    kind: LimitKind,
    symbol: str,
    title: str,
    active: Sequence[ActiveLimit],
    reference: Motion | None,
) -> Figure:
    """One figure: the quantity ``kind`` bounds, per joint, against its limit."""
    values = kind.of(motion)
    assert values is not None
    nv = values.shape[1]
    fig = new_figure(rows_figsize(TORQUE_FIGSIZE, nv, 0.55 * TORQUE_ROW_HEIGHT))
    axes = fig.subplots(nv, 1, sharex=True, squeeze=False)[:, 0]
    _, upper = limits.bounds(kind)
    duration = float(motion.t[-1] - motion.t[0])
    for j, ax in enumerate(axes):
        ref_values = None if reference is None else kind.of(reference)
        if reference is not None and ref_values is not None:
            span = float(reference.t[-1] - reference.t[0]) or 1.0
            t_ref = motion.t[0] + (reference.t - reference.t[0]) * duration / span
            ax.plot(
                t_ref,
                ref_values[:, j],
                color=REFERENCE_COLOR,
                lw=0.9,
                label="the reference, its time scaled to this one",
            )
        ax.plot(motion.t, values[:, j], color=ACTUAL_COLOR, lw=1.3, label=f"{symbol}{j + 1}")
        _limit(ax, float(upper[j]), float(np.abs(values[:, j]).max()), kind.unit)
        for stretch in active:
            if stretch.kind is kind and stretch.joint == j:
                ax.axvspan(
                    stretch.start,
                    max(stretch.end, stretch.start + 1e-3 * duration),
                    color=ACTIVE_COLOR,
                    alpha=0.18,
                    lw=0,
                )
        ax.set_ylabel(f"{symbol}{j + 1} [{kind.unit}]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7.5)
    axes[-1].set_xlabel("t [s]")
    what = "torque" if kind is EFFORT else kind.name
    fig.suptitle(f"{title}: {what} against its limits (shaded: a limit active)", fontsize=10)
    return fig


def limit_figures(
    motion: Motion,
    limits: JointLimits,
    title: str,
    active: Sequence[ActiveLimit] = (),
    reference: Motion | None = None,
) -> dict[str, Figure]:
    """The figures keyed ``velocity``, ``acceleration``, ``torque`` (those the motion carries)."""
    figures = {}
    for kind, key, symbol in PANELS:
        if kind.of(motion) is not None:
            figures[key] = _panel_figure(motion, limits, kind, symbol, title, active, reference)
    return figures


def save_limit_figures(
    motion: Motion,
    limits: JointLimits,
    out_dir: str | os.PathLike[str],
    prefix: str,
    title: str,
    active: Sequence[ActiveLimit] = (),
    reference: Motion | None = None,
) -> list[Path]:
    """Write :func:`limit_figures` as ``out_dir/<prefix><key>.png``; returns the paths."""
    return save_figures(limit_figures(motion, limits, title, active, reference), out_dir, prefix)


REFERENCE_COLORS = ("0.2", "tab:blue", "tab:green", "tab:purple", "tab:brown")
"""Colours of the references overlaid by :func:`save_references_figures`, in order."""


def _references_figure(
    motions: dict[str, Motion], limits: JointLimits, kind: LimitKind, symbol: str, title: str
) -> Figure:
    """One figure: ``kind``'s quantity of every motion per joint against ``t / duration``, the
    limit dashed (its value on the axis), one legend below the panels; a limit far beyond every
    motion's peak is not drawn, its panel's title says so."""
    nv = limits.nv
    fig = new_figure(rows_figsize(TORQUE_FIGSIZE, nv, 0.55 * TORQUE_ROW_HEIGHT))
    axes = fig.subplots(nv, 1, sharex=True, squeeze=False)[:, 0]
    _, upper = limits.bounds(kind)
    for j, ax in enumerate(axes):
        peak = 0.0
        for (label, motion), color in zip(motions.items(), REFERENCE_COLORS, strict=False):
            values = kind.of(motion)
            assert values is not None
            duration = float(motion.t[-1] - motion.t[0]) or 1.0
            ax.plot((motion.t - motion.t[0]) / duration, values[:, j], color=color, lw=1.1, label=label)
            peak = max(peak, float(np.abs(values[:, j]).max()))
        limit = float(upper[j])
        if math.isfinite(limit) and limit <= OFF_SCALE * max(peak, 1e-300):
            ax.axhline(limit, color=LIMIT_COLOR, ls="--", lw=1.0, label="±limit")
            ax.axhline(-limit, color=LIMIT_COLOR, ls="--", lw=1.0)
            ax.set_ylim(-1.15 * limit, 1.15 * limit)
            ax.set_title(f"joint {j + 1}: limit ±{limit:.4g} {kind.unit}", fontsize=8)
        elif math.isfinite(limit):
            ax.set_title(
                f"joint {j + 1}: the ±{limit:.4g} {kind.unit} limit is off scale (largest peak "
                f"{100 * peak / limit:.1f} % of it)",
                fontsize=8, color=LIMIT_COLOR,
            )  # fmt: skip
        else:
            ax.set_title(f"joint {j + 1}: no {kind.name} limit given", fontsize=8)
        ax.set_ylabel(f"{symbol}{j + 1} [{kind.unit}]")
        ax.grid(alpha=0.3)
    # one legend for every panel, below them: it never covers a curve
    handles, labels = max((ax.get_legend_handles_labels() for ax in axes), key=lambda hl: len(hl[1]))
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=7.5, frameon=False)
    axes[-1].set_xlabel("t / duration (each reference on its own time scale)")
    what = "torque" if kind is EFFORT else kind.name
    fig.suptitle(f"{title}: {what} against the limits", fontsize=10)
    return fig


def save_references_figures(
    motions: dict[str, Motion],
    limits: JointLimits,
    out_dir: str | os.PathLike[str],
    prefix: str,
    title: str,
) -> list[Path]:
    """The velocity, torque and (where some joint has one) acceleration of several references
    overlaid against their limits (``motions``: label → one period of each, the labels saying
    the durations), as ``out_dir/<prefix><key>.png``; a kind no joint limits is not drawn."""
    figures = {}
    for kind, key, symbol in PANELS:
        if limits.given(kind).any() and all(kind.of(m) is not None for m in motions.values()):
            figures[key] = _references_figure(motions, limits, kind, symbol, title)
    return save_figures(figures, out_dir, prefix)


__all__ = ["limit_figures", "save_limit_figures", "save_references_figures"]
