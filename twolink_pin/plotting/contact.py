"""Runs against a surface, side by side: the normal force with the desired force, the end
effector's position along the surface with the reference's, the penetration."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.contact_metrics import SETTLE, contact_metrics
from twolink_pin.errors import InvalidParameterError
from twolink_pin.frame_poses import frame_positions
from twolink_pin.model import RobotModel
from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import DESIRED_COLOR, new_figure
from twolink_pin.simulation import SimulationResult

CONTACT_FIGSIZE = (9.0, 8.5)
"""Size of the contact figure [in]."""
COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink")
"""One colour per run, in order."""


def along_axis(normal: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """The unit direction along the surface of normal ``normal`` (3,) in which the reference's
    positions ``reference`` (K, 3) [m] move the most (the first principal axis of their
    projection on the surface; the surface's first in-plane axis if they do not move)."""
    n = np.asarray(normal, dtype=float)
    projected = reference - np.outer(reference @ n, n)
    centred = projected - projected.mean(axis=0)
    _, s, vt = np.linalg.svd(centred, full_matrices=False)
    if s[0] <= 1e-12:
        e = np.eye(3)[int(np.argmin(np.abs(n)))]
        u = e - (e @ n) * n
        return u / np.linalg.norm(u)
    u = vt[0] - (vt[0] @ n) * n
    u /= np.linalg.norm(u)
    return u if u[int(np.argmax(np.abs(u)))] > 0 else -u


def _contact_figure(results: Mapping[str, SimulationResult], robot: RobotModel, title: str | None) -> Figure:
    first = next(iter(results.values()))
    normal = np.asarray(first.contact_normal, dtype=float)
    t0 = np.asarray(first.t)
    reference = frame_positions(robot, np.asarray(first.q_des), int(robot.ee_frame_id))
    u = along_axis(normal, reference)
    fig = new_figure(CONTACT_FIGSIZE)
    force_ax, along_ax, depth_ax = fig.subplots(3, 1, sharex=True)
    if first.force_des is not None:
        force_ax.plot(t0, first.force_des, color=DESIRED_COLOR, ls="--", lw=1.2, label="desired f_d")
    along_ax.plot(t0, reference @ u, color=DESIRED_COLOR, ls="--", lw=1.2, label="reference")
    for (name, result), color in zip(results.items(), COLORS * len(results), strict=False):
        t = np.asarray(result.t)
        m = contact_metrics(result, robot)
        assert m is not None and result.normal_force is not None and result.penetration is not None
        rms = "" if not np.isfinite(m.force_rms_error) else f", RMS error {m.force_rms_error:.3g} N"
        force_ax.plot(
            t,
            result.normal_force,
            color=color,
            lw=1.0,
            label=f"{name} (peak {m.peak_impact_force:.3g} N{rms})",
        )
        p = frame_positions(robot, np.asarray(result.q), int(robot.ee_frame_id))
        along_ax.plot(t, p @ u, color=color, lw=1.0, label=f"{name} (RMS error {m.tangent_rms_mm:.3g} mm)")
        depth_ax.plot(t, 1e3 * np.asarray(result.penetration), color=color, lw=1.0, label=name)
        if np.isfinite(m.first_contact):
            force_ax.axvspan(m.first_contact, m.first_contact + SETTLE, color=color, alpha=0.08, lw=0)
    force_ax.set_ylabel("normal force f_n [N]")
    force_ax.set_title(
        f"force pressed on the surface (shaded: the impact, {SETTLE:g} s after the first contact)",
        fontsize=10,
    )
    axis = ", ".join(f"{c:.3g}" for c in np.round(u, 6) + 0.0)
    along_ax.set_ylabel("along the surface [m]")
    along_ax.set_title(f"end effector's position along ({axis})", fontsize=10)
    depth_ax.set_ylabel("penetration [mm]")
    depth_ax.set_title("penetration into the surface", fontsize=10)
    depth_ax.set_xlabel("t [s]")
    for ax in (force_ax, along_ax, depth_ax):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    fig.suptitle(title or f"contact on {robot.name}: {', '.join(results)}", fontsize=11)
    return fig


def save_contact_figure(
    results: Mapping[str, SimulationResult],
    robot: RobotModel,
    path: str | os.PathLike[str],
    title: str | None = None,
) -> Path:
    """Write the contact figure of ``results`` (runs of ``robot`` against a scene, by name, drawn
    together) to ``path`` (PNG): the normal force each pressed with and the desired force, the
    end effector's position along the surface (the direction the reference moves most) with the
    reference's, and the penetration [mm]; the legends carry the contact metrics
    (:mod:`twolink_pin.contact_metrics`).

    Raises:
        InvalidParameterError: no run, or a run without a scene.
    """
    if not results or any(r.wrench is None or r.contact_normal is None for r in results.values()):
        raise InvalidParameterError("results", list(results), "runs against a scene (--scene or --wall)")
    return save_figure(_contact_figure(results, robot, title), Path(path))


__all__ = ["save_contact_figure"]
