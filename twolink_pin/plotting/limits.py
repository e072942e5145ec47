"""Several runs against one joint's position range and one joint's effort limit: which law
keeps inside them (docs/control_within_limits.md)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import POSITION, JointLimits
from twolink_pin.plotting._panels import limit_lines
from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import LIMIT_COLOR, new_figure
from twolink_pin.simulation import SimulationResult

LIMITS_FIGSIZE = (9.0, 6.5)
"""Size of the limits figure (position above, torque below) [in]."""
RUN_STYLES = (("tab:red", "-"), ("tab:blue", "-"), ("tab:green", "--"), ("tab:purple", "-."))
"""Colour and line of each run, in the order given."""


def worst_joints(runs: Mapping[str, SimulationResult], limits: JointLimits) -> tuple[int, int]:
    """The joint whose position comes nearest its range (or goes furthest past it) over the
    runs, and the joint whose commanded torque is the largest share of its limit."""
    past = np.max([limits.excess(POSITION, r.q).max(axis=0) for r in runs.values()], axis=0)
    share = np.max([np.abs(r.tau_command).max(axis=0) / limits.effort for r in runs.values()], axis=0)
    reach, share = int(np.argmax(past)), int(np.argmax(share))
    return reach, share


def _limits_figure(
    runs: Mapping[str, SimulationResult],
    limits: JointLimits,
    position_joint: int,
    torque_joint: int,
    title: str,
) -> Figure:
    fig = new_figure(LIMITS_FIGSIZE)
    pos_ax, tau_ax = fig.subplots(2, 1, sharex=True)
    pos_ax.set_label("position")
    tau_ax.set_label("torque")
    j, k = position_joint, torque_joint
    name_j, name_k = limits.joint_names[j], limits.joint_names[k]
    for (label, result), (colour, line) in zip(runs.items(), RUN_STYLES, strict=False):
        q, tau = result.q[:, j], result.tau_command[:, k]
        past = float(np.max(limits.excess(POSITION, result.q)[:, j]))
        peak = float(np.max(np.abs(tau)))
        where = f"past the range by {past:.3g} rad" if past > 0 else f"inside it by {-past:.3g} rad at least"
        pos_label = f"{label}: {where}"
        pos_ax.plot(result.t, q, color=colour, ls=line, lw=1.3, label=pos_label)
        tau_ax.plot(result.t, tau, color=colour, ls=line, lw=1.3, label=f"{label}: peak {peak:.3g} N·m")
    low, high = pos_ax.get_ylim()
    for bound in (limits.position_lower[j], limits.position_upper[j]):
        if np.isfinite(bound) and low - (high - low) <= bound <= high + (
            high - low
        ):  # the bounds near the data
            pos_ax.axhline(bound, color=LIMIT_COLOR, ls=":", lw=1.5)
            low, high = min(low, bound), max(high, bound)
    span = high - low
    pos_ax.set_ylim(low - 0.08 * span, high + 0.35 * span)
    pos_ax.set_ylabel(f"q{j + 1} [rad]")
    pos_ax.set_title(
        f"joint {j + 1} ({name_j}) and its range [{limits.position_lower[j]:.4g}, {limits.position_upper[j]:.4g}] rad "
        "(dotted)",
        fontsize=10,
    )
    pos_ax.legend(loc="upper right", fontsize=8)
    pos_ax.grid(True, alpha=0.3)
    peak = max(float(np.max(np.abs(r.tau_command[:, k]))) for r in runs.values())
    limit_lines(tau_ax, float(limits.effort[k]), peak, label=True)
    tau_ax.set_ylabel(f"commanded τ{k + 1} [N·m]")
    tau_ax.set_xlabel("t [s]")
    tau_ax.set_title(f"joint {k + 1} ({name_k}): the torque each law asks for", fontsize=10)
    tau_ax.legend(loc="upper right", fontsize=8)
    tau_ax.grid(True, alpha=0.3)
    fig.suptitle(title, fontsize=11)
    return fig


def save_limits_figure(
    runs: Mapping[str, SimulationResult],
    limits: JointLimits,
    path: str | os.PathLike[str],
    *,
    position_joint: int | None = None,
    torque_joint: int | None = None,
    title: str | None = None,
) -> Path:
    """Write the limits figure of ``runs`` (label → run of one robot) to ``path`` (PNG).

    Above: joint ``position_joint``'s position [rad] in every run, with its range; below: joint
    ``torque_joint``'s commanded torque [N·m] in every run, with its effort limit. Default
    joints (0-based): :func:`worst_joints`. The legend says by how much each run went past the
    range (or stayed inside it) and its peak torque.

    Raises:
        InvalidParameterError: no runs, runs of another number of joints than ``limits``, or a
            joint index out of range.
    """
    if not runs or any(r.q.shape[1] != limits.nv for r in runs.values()):
        raise InvalidParameterError(
            "runs", list(runs), f"one or more runs of a robot with {limits.nv} joints (the limits')"
        )
    worst = worst_joints(runs, limits)
    j = worst[0] if position_joint is None else position_joint
    k = worst[1] if torque_joint is None else torque_joint
    for name, index in (("position_joint", j), ("torque_joint", k)):
        if not 0 <= index < limits.nv:
            raise InvalidParameterError(name, index, f"a joint index 0 … {limits.nv - 1}")
    shown = title or " against ".join(runs) + ": the joint limits"
    return save_figure(_limits_figure(runs, limits, j, k, shown), Path(path))
