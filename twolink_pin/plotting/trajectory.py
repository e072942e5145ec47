"""Figures of the desired trajectory: each joint's motion, the arm in the workspace, and
the torque the motion demands.

:func:`save_trajectory_figures` writes ``trajectory_theta1.png``, ``trajectory_theta2.png``,
… (one per joint), ``trajectory_workspace.png`` and ``trajectory_desired_torque.png``;
:func:`_trajectory_figures` returns the figures keyed ``theta1``, …, ``workspace``,
``desired_torque`` (the keys of ``figure_numbers``). Time [s], angles [rad], positions [m],
torques [N·m].
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.feasibility import TorqueCheck
from twolink_pin.kinematics import joint_positions, workspace
from twolink_pin.model import RobotModel
from twolink_pin.plotting._panels import LEGEND_BOX, NOTE_BOX, free_spot, limit_lines, unblock_legends
from twolink_pin.plotting._save import save_figures
from twolink_pin.plotting._style import (
    ACTUAL_COLOR,
    ERROR_COLOR,
    JOINT_FIGSIZE,
    JOINT_MARGINS,
    REACH_COLOR,
    TORQUE_FIGSIZE,
    TORQUE_MARGINS,
    TORQUE_ROW_HEIGHT,
    WORKSPACE_3D_FIGSIZE,
    WORKSPACE_FIGSIZE,
    check_figure_numbers,
    figure_title,
    fix_margins,
    new_figure,
    rows_figsize,
)
from twolink_pin.trajectory import JointTrajectory

PLANAR_TOLERANCE = 1e-9
"""Largest spread of the arm's z [m] for which it counts as moving in the x-y plane."""
VIEW_ELEVATION = 25.0
"""Elevation of the 3-D view of an arm moving in 3-D [deg]."""
VIEW_TURN = 35.0
"""How far the 3-D view turns from looking straight at the end-effector path [deg]."""
MOTION_PLANE_TOLERANCE = 1e-6
"""Largest motion [m] of any point of the arm along an axis for which the arm counts as moving
in the plane of the other two (drawn in 2-D there); beyond it on every axis, it moves in 3-D."""


def _joint_trajectory_figure(
    trajectory: JointTrajectory, j: int, samples: int, figure_numbers: Mapping[str, int]
) -> Figure:
    """Joint ``j``'s desired position, velocity, acceleration and jerk over one period."""
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, samples)
    ref = trajectory.sample(t)
    fig = new_figure(JOINT_FIGSIZE)
    axes = fig.subplots(4, 1, sharex=True)
    name = rf"$\theta_{{{j + 1}}}$"
    rows = (
        (ref.q[:, j], f"{name} [rad]", "position"),
        (ref.v[:, j], rf"$\dot\theta_{{{j + 1}}}$ [rad/s]", "velocity"),
        (ref.a[:, j], rf"$\ddot\theta_{{{j + 1}}}$ [rad/s²]", "acceleration"),
        (ref.jerk[:, j], rf"$\dddot\theta_{{{j + 1}}}$ [rad/s³]", "jerk"),
    )
    for ax, (y, ylabel, label) in zip(axes, rows):
        ax.set_label(label)
        ax.plot(t, y, color=ACTUAL_COLOR, lw=1.6, label=label)
        for tv in trajectory.times:
            ax.axvline(tv, color="0.6", ls=":", lw=0.9)
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[0].plot(
        trajectory.times, trajectory.via_q[:, j], "o", color=ERROR_COLOR, ms=6, zorder=3, label="via points"
    )
    last = len(trajectory.times) - 1
    for k, (tv, qv) in enumerate(zip(trajectory.times, trajectory.via_q[:, j])):
        ha, dx = ("left", 4) if k == 0 else ("right", -4) if k == last else ("center", 0)
        axes[0].annotate(f"{qv:.4f}", (tv, qv), textcoords="offset points", xytext=(dx, 8), ha=ha, fontsize=8)
    margin = 0.12 * float(np.ptp(ref.q[:, j]) or 1.0)
    axes[0].set_ylim(ref.q[:, j].min() - margin, ref.q[:, j].max() + 2 * margin)
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(t[0], t[-1])
    what = f"desired {name} and its derivatives over one period (T = {trajectory.period:g} s)"
    fig.suptitle(figure_title(what, f"theta{j + 1}", figure_numbers))
    fix_margins(fig, JOINT_MARGINS)
    return fig


def _draw_annulus(ax: Axes, robot: RobotModel, centre: np.ndarray) -> None:
    """The reachable annulus of a planar 2R arm around its first joint ``centre`` [m]."""
    r_min, r_max = workspace(robot)
    theta = np.linspace(0.0, 2.0 * np.pi, 361)
    cx, cy = float(centre[0]), float(centre[1])
    ring = np.concatenate([r_max * np.exp(1j * theta), r_min * np.exp(-1j * theta)])
    ax.fill(cx + ring.real, cy + ring.imag, color=REACH_COLOR, alpha=0.08, lw=0)
    for r, label in ((r_max, "reachable annulus"), (r_min, None)):
        ax.plot(cx + r * np.cos(theta), cy + r * np.sin(theta), color=REACH_COLOR, lw=1.2, label=label)
    for r in (r_max, r_min):
        ax.text(
            cx - r * math.sqrt(0.5),
            cy - r * math.sqrt(0.5),
            f"r = {r:.2f} m",
            color=REACH_COLOR,
            ha="right",
            va="top",
            fontsize=8,
        )


def _motion_plane(points: np.ndarray) -> list[int] | None:
    """The coordinate plane an arm moves in, as two axis indices, or None if it moves in 3-D.

    ``points`` (samples, njoints, 3) [m] are the arm's joint origins and end effector over
    the motion. The arm moves in a coordinate plane when along one axis no point moves by
    more than :data:`MOTION_PLANE_TOLERANCE` (z for the twolink, x for the double pendulum
    swinging in y-z); that axis is dropped, z on a tie (an arm moving in x-y is drawn in x-y).
    """
    excursion = np.ptp(points, axis=0).max(axis=0)  # largest motion of any point along x, y, z
    if float(excursion.min()) > MOTION_PLANE_TOLERANCE:
        return None
    dropped = 2 if excursion[2] <= excursion[:2].min() else int(np.argmin(excursion[:2]))
    return [k for k in range(3) if k != dropped]


def _via_groups(ee: np.ndarray, times: np.ndarray) -> dict[tuple[float, ...], list[float]]:
    """The via points' end-effector positions ``ee`` (n_via, d) [m] rounded to 1 µm → the
    times [s] at which the path passes there (coinciding points share one entry)."""
    groups: dict[tuple[float, ...], list[float]] = {}
    for xyz, tv in zip(ee, times):
        # "+ 0.0" turns a rounded -0.0 into 0.0 for the label.
        groups.setdefault(tuple(round(float(c), 6) + 0.0 for c in xyz), []).append(float(tv))
    return groups


def _path_view(
    ax: Axes,
    t: np.ndarray,
    path: np.ndarray,
    mid_t: np.ndarray,
    labels: Sequence[tuple[tuple[float, float], str]],
    centre: np.ndarray,
    names: tuple[str, str],
) -> None:
    """The end-effector ``path`` (samples, 2) [m] in a plane whose axes are ``names``:
    arrows of the motion at ``mid_t`` [s], a square view on the path, and each via point of
    ``labels`` ((h, v) [m], text) marked and labelled, the label pushed away from ``centre``."""
    ax.plot(path[:, 0], path[:, 1], color=ERROR_COLOR, lw=1.8, label="end-effector path", zorder=4)
    ax.plot(0.0, 0.0, "ks", ms=7, zorder=5)  # the world origin
    ax.set_aspect("equal")
    ax.set_xlabel(f"{names[0]} [m]")
    ax.set_ylabel(f"{names[1]} [m]")
    ax.grid(True, alpha=0.3)
    # Direction of motion: arrows at the middle of each segment.
    for tm in mid_t:
        k = int(np.argmin(np.abs(t - tm)))
        ax.annotate(
            "",
            xy=path[min(k + 3, len(path) - 1)],
            xytext=path[k],
            arrowprops={"arrowstyle": "-|>", "color": ERROR_COLOR, "lw": 1.5},
            zorder=6,
        )
    # A square view on the path (equal aspect fills the panel), padded for the labels.
    span = float(np.ptp(path, axis=0).max()) or 0.05 * (float(np.abs(path).max()) or 1.0)
    middle = 0.5 * (path.min(axis=0) + path.max(axis=0))
    ax.set_xlim(middle[0] - 0.85 * span, middle[0] + 0.85 * span)
    ax.set_ylim(middle[1] - 0.85 * span, middle[1] + 0.85 * span)
    for (x, y), text in labels:
        ax.plot(x, y, "o", color="black", mfc="yellow", ms=8, zorder=7)
        direction = np.array([x, y]) - centre
        norm = float(np.linalg.norm(direction))
        direction = direction / norm if norm > 1e-3 * span else np.array([0.0, 1.0])
        ax.annotate(
            text,
            (x, y),
            textcoords="offset points",
            xytext=tuple(46 * direction),
            ha="center",
            va="center",
            fontsize=9,
            bbox={"boxstyle": "round,pad=0.25", "fc": "lightyellow", "ec": "0.5"},
            zorder=8,
        )


def _times(times: Sequence[float]) -> str:
    """``t = 0, 2, 4 s``."""
    return f"t = {', '.join(f'{tv:g}' for tv in times)} s"


def _view_azimuth(path: np.ndarray) -> float:
    """Azimuth [deg] of a 3-D view from in front of the arm: from the horizontal direction
    of the end-effector ``path``'s centre (samples, 3) [m] seen from the base, turned by
    :data:`VIEW_TURN` so that the arm's depth shows (matplotlib's −60° if the path is
    centred above the base)."""
    cx, cy = (float(c) for c in path[:, :2].mean(axis=0))
    if math.hypot(cx, cy) < 1e-3:
        return -60.0
    return math.degrees(math.atan2(cy, cx)) - VIEW_TURN


def _workspace_figure_3d(
    robot: RobotModel, trajectory: JointTrajectory, samples: int, figure_numbers: Mapping[str, int]
) -> Figure:
    """An arm moving in 3-D: a 3-D view of the arm at the via points and between them with
    the end-effector path, then the path seen from above (x-y) and from the side (z against
    the horizontal axis along which the path spreads most) [m]."""
    t = trajectory.t0 + np.linspace(0.0, trajectory.span, samples)
    points = joint_positions(robot, trajectory.sample(t).q)  # (samples, njoints, 3)
    path = points[:, -1]
    via_arms = joint_positions(robot, trajectory.via_q)
    mid_t = 0.5 * (trajectory.times[:-1] + trajectory.times[1:])
    quarter_t = np.concatenate([trajectory.times[:-1] + 0.25 * np.diff(trajectory.times), mid_t])
    mid_arms = joint_positions(robot, trajectory.sample(np.sort(quarter_t)).q)
    groups = _via_groups(via_arms[:, -1], trajectory.times)
    across = 0 if np.ptp(path[:, 0]) >= np.ptp(path[:, 1]) else 1
    side_plane = [across, 2]

    fig = new_figure(WORKSPACE_3D_FIGSIZE)
    grid = fig.add_gridspec(1, 3, width_ratios=(1.3, 1.0, 1.0))
    view = fig.add_subplot(grid[0], projection="3d")
    top, side = fig.add_subplot(grid[1]), fig.add_subplot(grid[2])
    view.set_label("workspace")
    top.set_label("path")
    side.set_label("path-side")
    base = np.vstack([np.zeros(3), via_arms[0, 0]])
    view.plot(*base.T, color="black", lw=3.0, alpha=0.6, label="base: origin → joint 1")
    for k, arm in enumerate(mid_arms):
        label = "intermediate poses" if k == 0 else None
        view.plot(*arm.T, "-o", color="0.7", lw=1.5, ms=3, label=label)
    for k, arm in enumerate(via_arms):
        label = "arm at via points" if k == 0 else None
        view.plot(*arm.T, "-o", color="tab:blue", lw=2.2, ms=4, label=label)
    view.plot(*path.T, color=ERROR_COLOR, lw=1.8, label="end-effector path")
    ends = np.array(list(groups))
    view.plot(*ends.T, "o", color="black", mfc="yellow", ms=7, ls="none")
    view.plot(0.0, 0.0, 0.0, "ks", ms=6)
    view.set_xlabel("x [m]")
    view.set_ylabel("y [m]")
    view.set_zlabel("z [m]")
    view.set_aspect("equal")
    view.view_init(elev=VIEW_ELEVATION, azim=_view_azimuth(path))
    view.set_box_aspect(None, zoom=0.85)  # room for the z label
    view.locator_params(nbins=5)
    view.tick_params(labelsize=8)
    view.legend(loc="upper left", fontsize=8)
    view.set_title("arm poses in 3-D (joint origins, end effector)", fontsize=10)

    for ax, plane in ((top, [0, 1]), (side, side_plane)):
        for arm in via_arms[:, :, plane]:
            ax.plot(arm[:, 0], arm[:, 1], "-o", color="tab:blue", lw=1.5, ms=3, alpha=0.35)
        if ax is top:  # the label says where the via point is in 3-D
            labels = [
                ((x, y), f"{_times(times)}\n({x:.2f}, {y:.2f}, {z:.2f}) m")
                for (x, y, z), times in groups.items()
            ]
        else:
            labels = [((xyz[plane[0]], xyz[plane[1]]), _times(times)) for xyz, times in groups.items()]
        centre = via_arms[:, -1, plane].mean(axis=0)
        _path_view(ax, t, path[:, plane], mid_t, labels, centre, ("xyz"[plane[0]], "xyz"[plane[1]]))
    top.set_title("end-effector path from above (x-y), arrows: direction of motion", fontsize=10)
    side.set_title(f"from the side ({'xy'[across]}-z)", fontsize=10)
    what = f"arm and end-effector path in 3-D over one period (T = {trajectory.period:g} s)"
    fig.suptitle(figure_title(what, "workspace", figure_numbers))
    return fig


def _workspace_figure(
    robot: RobotModel, trajectory: JointTrajectory, samples: int, figure_numbers: Mapping[str, int]
) -> Figure:
    """The arm at the via points and between them, and the end-effector path [m], drawn
    in the coordinate plane the arm moves in (x-y for the twolink); an arm moving in 3-D gets
    :func:`_workspace_figure_3d`."""
    t = trajectory.t0 + np.linspace(0.0, trajectory.span, samples)
    points = joint_positions(robot, trajectory.sample(t).q)  # (samples, njoints, 3)
    plane = _motion_plane(points)
    if plane is None:
        return _workspace_figure_3d(robot, trajectory, samples, figure_numbers)
    h_name, v_name = ("xyz"[k] for k in plane)
    path = points[:, -1][:, plane]
    via_arms = joint_positions(robot, trajectory.via_q)[:, :, plane]
    mid_t = 0.5 * (trajectory.times[:-1] + trajectory.times[1:])
    quarter_t = np.concatenate([trajectory.times[:-1] + 0.25 * np.diff(trajectory.times), mid_t])
    mid_arms = joint_positions(robot, trajectory.sample(np.sort(quarter_t)).q)[:, :, plane]
    in_xy = plane == [0, 1] and float(np.ptp(points[:, :, 2])) <= PLANAR_TOLERANCE

    fig = new_figure(WORKSPACE_FIGSIZE)
    full, zoom = fig.subplots(1, 2, width_ratios=(1.0, 1.15))
    full.set_label("workspace")
    zoom.set_label("path")
    annulus = False
    if in_xy:  # the annulus lies in the plane the arm moves in
        try:
            _draw_annulus(full, robot, points[0, 0, :2])
            annulus = True
        except InvalidParameterError:  # not a 2R arm: no closed-form workspace
            pass
    for ax, alpha in ((full, 1.0), (zoom, 0.45)):
        for k, arm in enumerate(mid_arms):
            label = "intermediate poses" if k == 0 else None
            ax.plot(arm[:, 0], arm[:, 1], "-o", color="0.7", lw=1.5, ms=3, alpha=alpha, label=label)
        for k, arm in enumerate(via_arms):
            label = "arm at via points" if k == 0 else None
            ax.plot(arm[:, 0], arm[:, 1], "-o", color="tab:blue", lw=2.2, ms=4, alpha=alpha, label=label)
    full.plot(path[:, 0], path[:, 1], color=ERROR_COLOR, lw=1.8, label="end-effector path", zorder=4)
    full.plot(0.0, 0.0, "ks", ms=7, zorder=5)  # the world origin
    full.set_aspect("equal")
    full.set_xlabel(f"{h_name} [m]")
    full.set_ylabel(f"{v_name} [m]")
    full.grid(True, alpha=0.3)
    # Via points, labelled with their times and positions (coinciding points share one label).
    ee = via_arms[:, -1]
    groups = _via_groups(ee, trajectory.times)
    labels = [((x, y), f"{_times(times)}\n({x:.2f}, {y:.2f}) m") for (x, y), times in groups.items()]
    _path_view(zoom, t, path, mid_t, labels, ee.mean(axis=0), (h_name, v_name))
    for (x, y), _ in labels:
        full.plot(x, y, "o", color="black", mfc="yellow", ms=8, zorder=7)
    zoom.set_title("zoom on the end-effector path (arrows: direction of motion)", fontsize=10)
    where = "in the reachable workspace" if annulus else f"projected on the {h_name}-{v_name} plane"
    full.set_title(f"arm poses {where}", fontsize=10)
    full.legend(loc="upper left" if annulus else "best", fontsize=8)
    what = f"arm and end-effector path in the {h_name}-{v_name} plane over one period (T = {trajectory.period:g} s)"
    fig.suptitle(figure_title(what, "workspace", figure_numbers))
    return fig


def _desired_torque_figure(check: TorqueCheck, figure_numbers: Mapping[str, int]) -> Figure:
    """Each joint's desired torque with its ``±limit`` lines and its peak annotated."""
    nv = check.tau.shape[1]
    fig = new_figure(rows_figsize(TORQUE_FIGSIZE, nv, TORQUE_ROW_HEIGHT))
    axes = fig.subplots(nv, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        ax.set_label(f"tau{j + 1}")
        limit = float(check.limits[j])
        ax.plot(check.t, check.tau[:, j], color=ACTUAL_COLOR, lw=1.6, label=rf"desired $\tau_{{{j + 1}}}$")
        limit_lines(ax, limit, float(check.peak[j]))
        k = int(np.argmin(np.abs(check.t - check.peak_time[j])))
        tp, yp = float(check.t[k]), float(check.tau[k, j])
        ax.plot(tp, yp, "o", color=ERROR_COLOR, ms=6, zorder=4)
        ax.set_xlim(check.t[0], check.t[-1])
        share = (
            f"{100 * check.peak[j] / limit:.1f} % of limit"
            if math.isfinite(limit)
            else "no limit in the URDF"
        )
        spot = free_spot(ax, check.t, check.tau[:, j], (0.36, 0.2), (tp, yp), (LEGEND_BOX, NOTE_BOX))
        ax.annotate(
            f"peak |τ{j + 1}| = {check.peak[j]:.3g} N·m\nat t = {tp:.2f} s ({share})",
            (tp, yp),
            textcoords="axes fraction",
            xytext=spot,
            ha="center",
            va="center",
            fontsize=8.5,
            arrowprops={"arrowstyle": "->", "color": "0.3"},
            bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": "0.6"},
        )
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.set_ylabel(rf"$\tau_{{{j + 1}}}$ [N·m]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    if not np.isfinite(check.limits).any():
        verdict = "the URDF gives no motor limits"
    else:
        verdict = ("within" if check.within_effort_limits else "EXCEEDS") + " the motor limits"
    what = f"desired torques M q̈ + C q̇ + g along one period: {verdict}"
    fig.suptitle(figure_title(what, "desired_torque", figure_numbers))
    fix_margins(fig, TORQUE_MARGINS)
    unblock_legends(fig, [(ax, check.t, check.tau[:, j]) for j, ax in enumerate(axes)])
    return fig


def _trajectory_figures(
    robot: RobotModel,
    trajectory: JointTrajectory,
    check: TorqueCheck,
    samples: int = 2001,
    figure_numbers: Mapping[str, int] | None = None,
) -> dict[str, Figure]:
    """Build the desired trajectory's figures (one per joint, then workspace, torques).

    Returns:
        Key → figure: ``theta1``, ``theta2``, … (one per joint), ``workspace``,
        ``desired_torque``.

    Raises:
        InvalidParameterError: the trajectory's or the check's joint count is not the
            robot's, ``samples`` is not an integer >= 2, or ``figure_numbers`` is not a
            mapping of key → positive integer.
    """
    if trajectory.nv != robot.nv:
        raise InvalidParameterError(
            "trajectory", f"nv = {trajectory.nv}", f"a trajectory for nv = {robot.nv}"
        )
    if check.tau.ndim != 2 or check.tau.shape[1] != robot.nv:
        raise InvalidParameterError("check", f"tau shape {check.tau.shape}", f"shape (N, {robot.nv})")
    if isinstance(samples, bool) or not (isinstance(samples, int) and samples >= 2):
        raise InvalidParameterError("samples", samples, "an integer >= 2")
    numbers = check_figure_numbers(figure_numbers)
    figures: dict[str, Figure] = {}
    for j in range(robot.nv):
        figures[f"theta{j + 1}"] = _joint_trajectory_figure(trajectory, j, samples, numbers)
    figures["workspace"] = _workspace_figure(robot, trajectory, samples, numbers)
    figures["desired_torque"] = _desired_torque_figure(check, numbers)
    return figures


def save_trajectory_figures(
    robot: RobotModel,
    trajectory: JointTrajectory,
    check: TorqueCheck,
    out_dir: str | os.PathLike[str],
    figure_numbers: Mapping[str, int] | None = None,
) -> list[Path]:
    """Write the desired trajectory's figures as PNG into ``out_dir``.

    * ``trajectory_theta1.png``, ``trajectory_theta2.png``, … (one per joint): ``θ_i``
      [rad], ``θ̇_i`` [rad/s], ``θ̈_i`` [rad/s²] and jerk [rad/s³] over one period, via
      points marked;
    * ``trajectory_workspace.png``: the arm (joint origins and end effector,
      :func:`twolink_pin.kinematics.joint_positions`) at the via points and at
      intermediate poses, and the end-effector path with the via points labelled by time
      [s]. An arm moving in a coordinate plane (every point keeps its coordinate along one
      axis: the twolink in x-y, a pendulum swinging in y-z) is drawn in that plane [m],
      beside a zoom on the path; a planar 2R arm moving in x-y gets its reachable annulus
      too. An arm moving in 3-D (the UR5, the Panda) gets a 3-D view of its poses and the
      path, seen from in front of the arm, then the path from above (x-y) and from the
      side (z against x or y, whichever the path spans more), the via points labelled
      with their times and (x, y, z);
    * ``trajectory_desired_torque.png``: each ``τ_i`` [N·m] of ``check`` with the
      ``±limit`` lines and the peaks annotated; a legend that would cover the curve moves
      to a free corner or side.

    Args:
        robot: The arm (forward kinematics for the workspace figure).
        trajectory: The desired joint trajectory.
        check: Its torque check (:func:`twolink_pin.feasibility.check_torques`).
        out_dir: Output directory, created if missing.
        figure_numbers: Figure key (``theta1``, …, ``workspace``, ``desired_torque``) →
            the number of the matching figure in a report, cited in the title as
            "cf. report Fig. N"; keys of no figure are ignored. Default: no citation.

    Returns:
        The paths written, in figure order.

    Raises:
        InvalidParameterError: see :func:`_trajectory_figures`.
        OutputError: ``out_dir`` cannot be created or written.
    """
    figures = _trajectory_figures(robot, trajectory, check, figure_numbers=figure_numbers)
    return save_figures(figures, out_dir, "trajectory_")
