"""Several runs against one joint's velocity limit and its effort limit: which law keeps its
speed and torque within them (docs/control_within_limits.md, demo (a))."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import EFFORT, VELOCITY, JointLimits
from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import LIMIT_COLOR, new_figure
from twolink_pin.plotting.limits import LIMITS_FIGSIZE, RUN_STYLES
from twolink_pin.simulation import SimulationResult


def _panel(
    ax: Axes, runs: Mapping[str, SimulationResult], limit: float, values: str, j: int, unit: str
) -> None:
    """One joint's ``values`` (``"v"`` or ``"tau_command"``) in every run, ``±limit`` dotted."""
    top = limit if np.isfinite(limit) else 0.0
    for (label, result), (colour, line) in zip(runs.items(), RUN_STYLES, strict=False):
        x = getattr(result, values)[:, j]
        top = max(top, float(np.max(np.abs(x))))
        peak = float(np.max(np.abs(x)))
        past = peak - limit
        where = f"past it by {past:.3g} {unit}" if past > 0 else f"peak {peak:.4g} {unit}"
        ax.plot(result.t, x, color=colour, ls=line, lw=1.2, label=f"{label}: {where}")
    if np.isfinite(limit):
        for bound in (limit, -limit):
            ax.axhline(bound, color=LIMIT_COLOR, ls=":", lw=1.5)
    ax.set_ylim(-1.15 * top, 1.5 * top)  # every run in view, room for the legend above
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(True, alpha=0.3)


def _figure(runs: Mapping[str, SimulationResult], limits: JointLimits, joint: int, title: str) -> Figure:
    fig = new_figure(LIMITS_FIGSIZE)
    v_ax, tau_ax = fig.subplots(2, 1, sharex=True)
    v_ax.set_label("velocity")
    tau_ax.set_label("torque")
    name = limits.joint_names[joint]
    v_limit, tau_limit = float(limits.velocity[joint]), float(limits.effort[joint])
    _panel(v_ax, runs, v_limit, "v", joint, VELOCITY.unit)
    v_ax.set_ylabel(f"q̇{joint + 1} [rad/s]")
    v_ax.set_title(
        f"joint {joint + 1} ({name}): velocity and its limit ±{v_limit:g} rad/s (dotted)", fontsize=10
    )
    _panel(tau_ax, runs, tau_limit, "tau_command", joint, EFFORT.unit)
    tau_ax.set_ylabel(f"commanded τ{joint + 1} [N·m]")
    tau_ax.set_xlabel("t [s]")
    tau_ax.set_title(
        f"the torque each law asks for, and the effort limit ±{tau_limit:g} N·m (dotted)", fontsize=10
    )
    fig.suptitle(title, fontsize=11)
    return fig


def save_velocity_limits_figure(
    runs: Mapping[str, SimulationResult],
    limits: JointLimits,
    path: str | os.PathLike[str],
    *,
    joint: int,
    title: str | None = None,
) -> Path:
    """Write the figure of ``runs`` (label → run of one robot) to ``path`` (PNG): joint
    ``joint``'s (0-based) velocity [rad/s] in every run with its velocity limit above, its
    commanded torque [N·m] with its effort limit below; the legend gives each run's peak, or by
    how much it went past the limit.

    Raises:
        InvalidParameterError: no runs, runs of another number of joints than ``limits``, or a
            joint index out of range.
    """
    if not runs or any(r.q.shape[1] != limits.nv for r in runs.values()):
        raise InvalidParameterError(
            "runs", list(runs), f"one or more runs of a robot with {limits.nv} joints (the limits')"
        )
    if not 0 <= joint < limits.nv:
        raise InvalidParameterError("joint", joint, f"a joint index 0 … {limits.nv - 1}")
    shown = title or " against ".join(runs) + ": velocity and effort limits"
    return save_figure(_figure(runs, limits, joint, shown), Path(path))
