"""Figures of the report: the desired trajectory (Figures 3–6) and each controller's run.

The only module of the package that imports matplotlib. It never touches ``pyplot``:
every figure is a :class:`matplotlib.figure.Figure` drawn by its own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`, so no GUI backend is selected,
no global figure registry holds on to anything, and a figure is freed as soon as it is
no longer referenced. Every file is written atomically (:func:`twolink_pin.io.atomic_write`).

Public functions write PNG files and return their paths:

* :func:`save_trajectory_figures` — ``fig03_theta1.png``, ``fig04_theta2.png`` (one per
  joint), ``fig05_workspace.png``, ``fig06_desired_torque.png``;
* :func:`save_simulation_figures` — ``<prefix>_theta1.png``, ``_theta2.png``,
  ``_theta1dot.png``, ``_theta2dot.png``, ``_torque.png`` and, for adaptive runs,
  ``_param_error.png`` (and ``_friction_error.png`` with friction estimates);
* :func:`save_distribution_figure` — histograms of Monte Carlo metrics.

The private builders :func:`_trajectory_figures`, :func:`_simulation_figures` and
:func:`_distribution_figure` return the :class:`Figure` objects (keyed by file stem or
suffix) so tests can check what is drawn. Units: time [s], angles [rad], rates [rad/s],
torques [N·m].
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.feasibility import TorqueCheck
from twolink_pin.files import atomic_write
from twolink_pin.kinematics import workspace
from twolink_pin.model import RobotModel
from twolink_pin.simulation import SimulationResult
from twolink_pin.trajectory import JointTrajectory

DPI = 110
"""Resolution of every saved figure [dots per inch]."""
JOINT_FIGSIZE = (8.0, 8.0)
"""Size of a trajectory joint figure (four stacked panels) [in]."""
WORKSPACE_FIGSIZE = (12.0, 5.5)
"""Size of the workspace figure (full view and zoom on the path) [in]."""
TORQUE_FIGSIZE = (8.0, 6.0)
"""Size of the desired-torque figure [in]."""
STATE_FIGSIZE = (8.0, 7.5)
"""Size of a simulation state figure (actual/desired, error, log |error|) [in]."""
SIM_TORQUE_FIGSIZE = (12.0, 6.5)
"""Size of a simulation torque figure (whole run and last period, per joint) [in]."""
PARAM_FIGSIZE = (8.0, 5.0)
"""Size of a parameter-error figure [in]."""

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

REPORT_FIGURES: dict[str, dict[str, int]] = {
    "pd": {"theta1": 7, "theta2": 8, "theta1dot": 9, "theta2dot": 10, "torque": 11},
    "computed-torque": {"theta1": 12, "theta2": 13, "theta1dot": 14, "theta2dot": 15, "torque": 16},
    "robust": {"theta1": 17, "theta2": 18, "theta1dot": 19, "theta2dot": 20, "torque": 21},
    "adaptive": {
        "theta1": 22,
        "theta2": 23,
        "theta1dot": 24,
        "theta2dot": 25,
        "torque": 26,
        "param_error": 27,
    },
    "adaptive-friction": {
        "theta1": 28,
        "theta2": 29,
        "theta1dot": 30,
        "theta2dot": 31,
        "param_error": 32,
        "friction_error": 33,
        "torque": 34,
    },
}
"""The report's figure number of each controller's figure (shown in the titles)."""

CONTROLLER_TITLES = {
    "pd": "PD + model feedforward",
    "computed-torque": "modified computed torque, Slotine–Li",
    "robust": "Slotine–Li law with M̂ = 0.5 M, Ĉ = 0.5 C",
    "adaptive": "Slotine–Li adaptive, p̂(0) = 0.5 p",
    "adaptive-friction": "adaptive, friction estimated too",
}
"""Long names of the report's controllers for figure titles."""


# --------------------------------------------------------------------------- helpers


def _new_figure(figsize: tuple[float, float]) -> Figure:
    """A non-GUI figure with its own Agg canvas and constrained layout."""
    fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: Path) -> Path:
    """Render ``fig`` into ``path`` atomically (format from the suffix, PNG by default)."""
    fmt = path.suffix[1:].lower() or "png"
    with atomic_write(path, "wb") as f:
        fig.savefig(f, format=fmt, dpi=DPI)
    return path


def _save_all(figures: Mapping[str, Figure], out_dir: str | os.PathLike[str], prefix: str) -> list[Path]:
    out = Path(out_dir)
    paths = [_save(fig, out / f"{prefix}{key}.png") for key, fig in figures.items()]
    for fig in figures.values():
        fig.clear()
    return paths


def _sub(j: int) -> str:
    """``θ_{j+1}`` in mathtext."""
    return rf"$\theta_{{{j + 1}}}$"


def _run_title(controller: str, key: str, what: str) -> str:
    """Two-line title: the controller (long name, report figure), then what is shown."""
    long = CONTROLLER_TITLES.get(controller)
    first = f"controller {controller}" + (f" ({long})" if long and long != controller else "")
    number = REPORT_FIGURES.get(controller, {}).get(key)
    if number is not None:
        first += f" — cf. report Fig. {number}"
    return f"{first}\n{what}"


def _envelope(t: np.ndarray, x: np.ndarray, windows: int = ENVELOPE_WINDOWS) -> tuple[np.ndarray, np.ndarray]:
    """Max ``|x|`` over consecutive windows: (window start times [s], maxima)."""
    n = len(t)
    width = max(1, n // windows)
    starts = np.arange(0, n, width)
    peaks = np.maximum.reduceat(np.abs(x), starts)
    return t[starts], np.maximum(peaks, LOG_FLOOR)


def _free_spot(
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


LEGEND_BOX = (0.62, 0.78, 1.0, 1.0)
"""Region of an "upper right" legend, kept free of annotations [axes fraction]."""
NOTE_BOX = (0.0, 0.0, 0.75, 0.12)
"""Region of the off-scale limit note, kept free of annotations [axes fraction]."""


def _limit_lines(ax: Axes, limit: float, peak: float, label: bool = True) -> bool:
    """Draw ``±limit`` dashed; keep them in view unless far beyond ``peak``.

    Returns whether the limit is in view. When it is not, the y range stays on the data and
    a note gives the limit and the peak as a fraction of it.
    """
    ax.axhline(limit, color=LIMIT_COLOR, ls="--", lw=1.2, label=f"±limit ({limit:g} N·m)" if label else None)
    ax.axhline(-limit, color=LIMIT_COLOR, ls="--", lw=1.2)
    in_view = limit <= OFF_SCALE_RATIO * max(peak, 1e-12)
    if in_view:
        top = max(limit, peak)
        ax.set_ylim(-1.12 * top, 1.5 * top)  # the legend goes above the +limit line
    else:
        ax.set_ylim(-1.4 * peak, 1.15 * peak)  # room for the note below the data
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


def _joint_positions(robot: RobotModel, q: np.ndarray, data: pin.Data) -> np.ndarray:
    """Planar points of the arm at ``q`` [m]: every joint origin, then the end effector."""
    pin.forwardKinematics(robot.model, data, q)
    pin.updateFramePlacements(robot.model, data)
    points = [data.oMi[j].translation[:2] for j in range(1, robot.model.njoints)]
    points.append(data.oMf[robot.ee_frame_id].translation[:2])
    return np.array(points)


# --------------------------------------------------------------------- trajectory


def _joint_trajectory_figure(trajectory: JointTrajectory, j: int, number: int, samples: int) -> Figure:
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, samples)
    ref = trajectory.sample(t)
    fig = _new_figure(JOINT_FIGSIZE)
    axes = fig.subplots(4, 1, sharex=True)
    name = _sub(j)
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
        trajectory.times,
        trajectory.via_q[:, j],
        "o",
        color=ERROR_COLOR,
        ms=6,
        zorder=3,
        label="via points",
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
    fig.suptitle(
        f"Figure {number}: desired {name} and its derivatives over one period (T = {trajectory.period:g} s)"
    )
    return fig


def _workspace_figure(robot: RobotModel, trajectory: JointTrajectory, samples: int) -> Figure:
    data = robot.create_data()
    t = trajectory.t0 + np.linspace(0.0, trajectory.span, samples)
    path = np.array([_joint_positions(robot, q, data)[-1] for q in trajectory.sample(t).q])
    via_arms = [_joint_positions(robot, q, data) for q in trajectory.via_q]
    mid_t = 0.5 * (trajectory.times[:-1] + trajectory.times[1:])
    quarter_t = np.concatenate([trajectory.times[:-1] + 0.25 * np.diff(trajectory.times), mid_t])
    mid_arms = [_joint_positions(robot, q, data) for q in trajectory.sample(np.sort(quarter_t)).q]

    fig = _new_figure(WORKSPACE_FIGSIZE)
    full, zoom = fig.subplots(1, 2, width_ratios=(1.0, 1.15))
    full.set_label("workspace")
    zoom.set_label("path")
    theta = np.linspace(0.0, 2.0 * np.pi, 361)
    if robot.nv == 2:
        r_min, r_max = workspace(robot)
        ring = np.concatenate([r_max * np.exp(1j * theta), r_min * np.exp(-1j * theta)])
        full.fill(ring.real, ring.imag, color="tab:green", alpha=0.08, lw=0)
        for r, lab in ((r_max, "reachable annulus"), (r_min, None)):
            full.plot(r * np.cos(theta), r * np.sin(theta), color="tab:green", lw=1.2, label=lab)
        for r in (r_max, r_min):
            full.text(
                -r * math.sqrt(0.5),
                -r * math.sqrt(0.5),
                f"r = {r:.2f} m",
                color="tab:green",
                ha="right",
                va="top",
                fontsize=8,
            )
    for ax, alpha in ((full, 1.0), (zoom, 0.45)):
        for k, arm in enumerate(mid_arms):
            pts = np.vstack([[0.0, 0.0], arm])
            label = "intermediate poses" if k == 0 else None
            ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.7", lw=1.5, ms=3, alpha=alpha, label=label)
        for k, arm in enumerate(via_arms):
            pts = np.vstack([[0.0, 0.0], arm])
            label = "arm at via points" if k == 0 else None
            ax.plot(pts[:, 0], pts[:, 1], "-o", color="tab:blue", lw=2.2, ms=4, alpha=alpha, label=label)
        ax.plot(path[:, 0], path[:, 1], color=ERROR_COLOR, lw=1.8, label="end-effector path", zorder=4)
        ax.plot(0.0, 0.0, "ks", ms=7, zorder=5)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(True, alpha=0.3)
    # Direction of motion: arrows at the middle of each segment.
    for tm in mid_t:
        k = int(np.argmin(np.abs(t - tm)))
        zoom.annotate(
            "",
            xy=path[min(k + 3, len(path) - 1)],
            xytext=path[k],
            arrowprops={"arrowstyle": "-|>", "color": ERROR_COLOR, "lw": 1.5},
            zorder=6,
        )
    # Via points, labelled with their times (coinciding points share one label).
    ee = np.array([arm[-1] for arm in via_arms])
    groups: dict[tuple[float, float], list[float]] = {}
    for xy, tv in zip(ee, trajectory.times):
        # "+ 0.0" turns a rounded -0.0 into 0.0 for the label.
        groups.setdefault((round(float(xy[0]), 6) + 0.0, round(float(xy[1]), 6) + 0.0), []).append(float(tv))
    centre = ee.mean(axis=0)
    for (x, y), times in groups.items():
        for ax in (full, zoom):
            ax.plot(x, y, "o", color="black", mfc="yellow", ms=8, zorder=7)
        direction = np.array([x, y]) - centre
        direction = direction / (np.linalg.norm(direction) or 1.0)
        zoom.annotate(
            f"t = {', '.join(f'{tv:g}' for tv in times)} s\n({x:.2f}, {y:.2f}) m",
            (x, y),
            textcoords="offset points",
            xytext=tuple(46 * direction),
            ha="center",
            va="center",
            fontsize=9,
            bbox={"boxstyle": "round,pad=0.25", "fc": "lightyellow", "ec": "0.5"},
            zorder=8,
        )
    pad = 0.35 * float(np.ptp(path, axis=0).max())
    zoom.set_xlim(path[:, 0].min() - pad, path[:, 0].max() + pad)
    zoom.set_ylim(path[:, 1].min() - pad, path[:, 1].max() + pad)
    zoom.set_title("zoom on the end-effector path (arrows: direction of motion)", fontsize=10)
    full.set_title("arm poses in the reachable workspace", fontsize=10)
    full.legend(loc="upper left", fontsize=8)
    fig.suptitle(
        f"Figure 5: arm and end-effector path in the x-y plane over one period (T = {trajectory.period:g} s)"
    )
    return fig


def _desired_torque_figure(check: TorqueCheck) -> Figure:
    fig = _new_figure(TORQUE_FIGSIZE)
    nv = check.tau.shape[1]
    axes = fig.subplots(nv, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        ax.set_label(f"tau{j + 1}")
        ax.plot(check.t, check.tau[:, j], color=ACTUAL_COLOR, lw=1.6, label=rf"desired $\tau_{{{j + 1}}}$")
        _limit_lines(ax, float(check.limits[j]), float(check.peak[j]))
        k = int(np.argmin(np.abs(check.t - check.peak_time[j])))
        tp, yp = float(check.t[k]), float(check.tau[k, j])
        ax.plot(tp, yp, "o", color=ERROR_COLOR, ms=6, zorder=4)
        ax.set_xlim(check.t[0], check.t[-1])
        spot = _free_spot(ax, check.t, check.tau[:, j], (0.36, 0.2), (tp, yp), (LEGEND_BOX, NOTE_BOX))
        ax.annotate(
            f"peak |τ{j + 1}| = {check.peak[j]:.3g} N·m\nat t = {tp:.2f} s "
            f"({100 * check.peak[j] / check.limits[j]:.1f} % of limit)",
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
    axes[-1].set_xlim(check.t[0], check.t[-1])
    verdict = "within" if check.within_limits else "EXCEEDS"
    fig.suptitle(f"Figure 6: desired torques M q̈ + C q̇ + g along one period — {verdict} the motor limits")
    return fig


def _trajectory_figures(
    robot: RobotModel, trajectory: JointTrajectory, check: TorqueCheck, samples: int = 2001
) -> dict[str, Figure]:
    """Build the report's Figures 3–6 (one joint figure per joint, then workspace, torques).

    Returns:
        File stem → figure: ``fig03_theta1``, ``fig04_theta2``, …, ``figNN_workspace``,
        ``figNN_desired_torque``.

    Raises:
        InvalidParameterError: the trajectory's or the check's joint count is not the robot's.
    """
    if trajectory.nv != robot.nv:
        raise InvalidParameterError(
            "trajectory", f"nv = {trajectory.nv}", f"a trajectory for nv = {robot.nv}"
        )
    if check.tau.ndim != 2 or check.tau.shape[1] != robot.nv:
        raise InvalidParameterError("check", f"tau shape {check.tau.shape}", f"shape (N, {robot.nv})")
    if not (isinstance(samples, int) and samples >= 2):
        raise InvalidParameterError("samples", samples, "an integer >= 2")
    figures: dict[str, Figure] = {}
    number = 3
    for j in range(robot.nv):
        figures[f"fig{number:02d}_theta{j + 1}"] = _joint_trajectory_figure(trajectory, j, number, samples)
        number += 1
    figures[f"fig{number:02d}_workspace"] = _workspace_figure(robot, trajectory, samples)
    figures[f"fig{number + 1:02d}_desired_torque"] = _desired_torque_figure(check)
    return figures


def save_trajectory_figures(
    robot: RobotModel,
    trajectory: JointTrajectory,
    check: TorqueCheck,
    out_dir: str | os.PathLike[str],
) -> list[Path]:
    """Write the report's Figures 3–6 for the desired trajectory as PNG into ``out_dir``.

    * ``fig03_theta1.png``, ``fig04_theta2.png``: ``θ_i`` [rad], ``θ̇_i`` [rad/s],
      ``θ̈_i`` [rad/s²] and jerk [rad/s³] over one period, via points marked;
    * ``fig05_workspace.png``: the arm at the via points and at intermediate poses, the
      end-effector path [m] with the via points labelled by time [s], the reachable annulus;
    * ``fig06_desired_torque.png``: ``τ_1``, ``τ_2`` [N·m] of ``check`` with the ``±limit``
      lines and the peaks annotated.

    Args:
        robot: The arm (link geometry for the workspace figure).
        trajectory: The desired joint trajectory.
        check: Its torque check (:func:`twolink_pin.feasibility.check_torques`).
        out_dir: Output directory, created if missing.

    Returns:
        The paths written, in figure order.

    Raises:
        OutputError: ``out_dir`` cannot be created or written.
    """
    return _save_all(_trajectory_figures(robot, trajectory, check), out_dir, "")


# --------------------------------------------------------------------- simulation


def _late_ylim(ax: Axes, y: np.ndarray) -> None:
    """y range of ``y`` padded by 12 % (symmetric and tiny if ``y`` is all zero)."""
    lo, hi = float(y.min()), float(y.max())
    pad = 0.12 * (hi - lo) or 0.12 * max(abs(lo), abs(hi)) or 1e-15
    ax.set_ylim(lo - pad, hi + pad)


def _state_figure(result: SimulationResult, j: int, derivative: bool) -> Figure:
    t = result.t
    if derivative:
        actual, desired, error = result.v[:, j], result.v_des[:, j], result.edot[:, j]
        base, ebase, unit = r"\dot\theta", r"\dot e", "rad/s"
    else:
        actual, desired, error = result.q[:, j], result.q_des[:, j], result.e[:, j]
        base, ebase, unit = r"\theta", "e", "rad"
    sym, sym_d, esym = f"{base}_{{{j + 1}}}", f"{base}_{{{j + 1},d}}", f"{ebase}_{{{j + 1}}}"
    duration = float(t[-1] - t[0])
    split = float(t[0] + min(result.reference_period, duration / 3.0))
    margin = 0.01 * duration  # keeps what happens at t = 0 off the axis spine

    fig = _new_figure(STATE_FIGSIZE)
    axd = fig.subplot_mosaic(
        [["signal", "signal"], ["error", "error-late"], ["error-log", "error-log"]],
        height_ratios=(1.5, 1.0, 1.0),
        width_ratios=(1.0, 2.0),
    )
    top, early, late, log = axd["signal"], axd["error"], axd["error-late"], axd["error-log"]
    top.sharex(log)
    top.tick_params(labelbottom=False)

    top.plot(t, actual, color=ACTUAL_COLOR, lw=2.6, alpha=0.75, label=f"actual ${sym}$")
    top.plot(t, desired, color=DESIRED_COLOR, lw=1.0, ls="--", label=f"desired ${sym_d}$")
    top.set_ylabel(f"${sym}$ [{unit}]")
    top.legend(loc="upper right", fontsize=8, ncols=2, framealpha=0.9)
    span = float(max(np.ptp(actual), np.ptp(desired)) or 1.0)
    lo, hi = float(min(actual.min(), desired.min())), float(max(actual.max(), desired.max()))
    top.set_ylim(lo - 0.08 * span, hi + 0.35 * span)  # head room for the legend

    for ax in (early, late):
        ax.plot(t, error, color=ERROR_COLOR, lw=1.2, label=f"${esym} = {sym} - {sym_d}$")
        ax.axhline(0.0, color="0.6", lw=0.7)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
    early.set_xlim(t[0] - margin / 3.0, split)
    _late_ylim(early, error[t <= split])
    early.set_ylabel(f"${esym}$ [{unit}]")
    early.set_title(f"${esym} = {sym} - {sym_d}$, first {split - t[0]:g} s", fontsize=9)
    after = t >= split
    late.set_xlim(split, t[-1])
    _late_ylim(late, error[after] if after.any() else error)
    late.set_title(f"${esym}$ for t ≥ {split:g} s (own scale)", fontsize=9)

    te, env = _envelope(t, error)
    log.semilogy(
        te, env, color=ERROR_COLOR, lw=1.2, drawstyle="steps-post", label=f"max $|{esym}|$ per window"
    )
    log.set_ylim(max(LOG_FLOOR, 0.3 * float(env.min())), 3.0 * float(env.max()))
    width = float(te[1] - te[0]) if len(te) > 1 else duration
    log.set_ylabel(f"$|{esym}|$ [{unit}]")
    log.legend(loc="upper right", fontsize=8, title=f"window {width:.3g} s", title_fontsize=8)
    log.set_xlabel("t [s]")
    log.set_xlim(t[0] - margin, t[-1])
    for ax in (top, early, late, log):
        ax.grid(True, alpha=0.3)
    for ax in (early, late):
        ax.set_xlabel("t [s]", fontsize=9)
    what = "velocity" if derivative else "position"
    key = f"theta{j + 1}{'dot' if derivative else ''}"
    fig.suptitle(
        _run_title(result.controller, key, f"joint {j + 1} {what}: actual vs desired, error"), fontsize=11
    )
    return fig


def _torque_figure(result: SimulationResult) -> Figure:
    t = result.t
    nv = result.tau.shape[1]
    fig = _new_figure(SIM_TORQUE_FIGSIZE)
    axes = fig.subplots(nv, 2, sharex="col", width_ratios=(1.6, 1.0), squeeze=False)
    period = result.reference_period
    last = t >= max(t[0], t[-1] - period)
    clipped = result.saturate and not np.array_equal(result.tau, result.tau_command)
    for j in range(nv):
        limit = float(result.torque_limits[j])
        for col, mask in ((0, np.ones_like(t, dtype=bool)), (1, last)):
            ax = axes[j, col]
            ax.set_label(f"tau{j + 1}" if col == 0 else f"tau{j + 1}-last")
            tt = t[mask]
            if clipped:
                ax.plot(
                    tt, result.tau_command[mask, j], color=COMMAND_COLOR, lw=1.0, ls="--", label="commanded"
                )
            ax.plot(tt, result.tau[mask, j], color=ACTUAL_COLOR, lw=1.3, label=rf"applied $\tau_{{{j + 1}}}$")
            peak_cmd = float(np.abs(result.tau_command[mask, j]).max())
            _limit_lines(ax, limit, peak_cmd)
            ax.axhline(0.0, color="0.8", lw=0.6)
            ax.grid(True, alpha=0.3)
            ax.set_xlim(tt[0] - (0.01 * (tt[-1] - tt[0]) if col == 0 else 0.0), tt[-1])
            over = np.abs(result.tau_command[mask, j]) > limit
            if over.any():
                k = int(np.argmax(np.abs(result.tau_command[mask, j])))
                tk, yk = float(tt[k]), float(result.tau_command[mask, j][k])
                note = "clipped by the plant" if result.saturate else "not saturated in this run"
                lines = np.linspace(tt[0], tt[-1], 200)
                spot = _free_spot(
                    ax,
                    np.concatenate([tt, lines, lines]),
                    np.concatenate([result.tau[mask, j], np.full(200, limit), np.full(200, -limit)]),
                    (0.5, 0.2),
                    (tk, yk),
                    (LEGEND_BOX, NOTE_BOX),
                )
                ax.annotate(
                    f"commanded |τ{j + 1}| up to {peak_cmd:.3g} N·m > {limit:g} N·m\n"
                    f"(first at t = {tt[np.argmax(over)]:.3f} s; {note})",
                    (tk, yk),
                    textcoords="axes fraction",
                    xytext=spot,
                    ha="center",
                    va="center",
                    fontsize=8,
                    color=LIMIT_COLOR,
                    arrowprops={"arrowstyle": "->", "color": LIMIT_COLOR},
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": LIMIT_COLOR},
                )
        axes[j, 0].set_ylabel(rf"$\tau_{{{j + 1}}}$ [N·m]")
        axes[j, 0].legend(loc="upper right", fontsize=8)
    axes[0, 0].set_title("whole run", fontsize=10)
    axes[0, 1].set_title(f"last reference period ({period:g} s), own scale", fontsize=10)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    sat = "saturated at the limits" if result.saturate else "no saturation"
    fig.suptitle(_run_title(result.controller, "torque", f"joint torques ({sat})"), fontsize=11)
    return fig


_UNITS = {"p": "kg·m²", "V": "N·m·s/rad", "C": "N·m"}


def _unit(name: str) -> str:
    return _UNITS.get(name[:1], "SI") if name[1:].isdigit() else "SI"


def _is_friction(name: str) -> bool:
    return name[:1] in ("V", "C")


def _parameter_label(name: str, true: float, err: np.ndarray) -> str:
    if name[1:].isdigit():
        sym = rf"$\hat{{{name[0]}}}_{{{name[1:]}}} - {name[0]}_{{{name[1:]}}}$"
    else:
        sym = name
    return f"{sym} (true {true:.3g}; {err[0]:+.3g} → {err[-1]:+.3g})"


def _parameter_figure(result: SimulationResult, names: list[str], friction: bool) -> Figure:
    """Absolute ``p̂ − p`` (one panel per unit group), then relative ``(p̂ − p)/p`` [%]."""
    assert result.p_error is not None and result.p_true is not None
    t = result.t
    p_error, p_true = result.p_error, result.p_true
    column = {n: result.parameter_names.index(n) for n in names}
    groups = [[n for n in names if n.startswith(k)] for k in ("V", "C")] if friction else [names]
    groups = [g for g in groups if g]
    relative = [n for n in names if abs(p_true[column[n]]) > 1e-12]
    rows = len(groups) + (1 if relative else 0)
    fig = _new_figure((PARAM_FIGSIZE[0], PARAM_FIGSIZE[1] + 2.2 * (rows - 1)))
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    color = {n: f"C{k % 10}" for k, n in enumerate(names)}  # same colour in every panel
    for ax, group in zip(axes, groups):
        ax.set_label("absolute" if not friction else group[0][0])
        for n in group:
            i = column[n]
            label = _parameter_label(n, float(p_true[i]), p_error[:, i])
            ax.plot(t, p_error[:, i], lw=1.5, color=color[n], label=label)
        units = {_unit(n) for n in group}
        unit = units.pop() if len(units) == 1 else "SI"
        ax.set_ylabel(f"estimate − true [{unit}]")
    if relative:
        ax = axes[-1]
        ax.set_label("relative")
        for n in relative:
            i = column[n]
            rel = 100.0 * p_error[:, i] / p_true[i]
            ax.plot(t, rel, lw=1.3, color=color[n], label=f"{n}: {rel[0]:+.0f} % → {rel[-1]:+.0f} %")
        ax.set_ylabel("(estimate − true) / true [%]")
    for ax in axes:
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8, ncols=1 if len(names) <= 4 else 2)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(t[0], t[-1])
    what = "friction" if friction else "inertial"
    key = "friction_error" if friction else "param_error"
    fig.suptitle(_run_title(result.controller, key, f"{what} parameter estimation error p̂ − p"), fontsize=11)
    return fig


def _simulation_figures(result: SimulationResult) -> dict[str, Figure]:
    """Build one run's figures.

    Returns:
        Suffix → figure: ``theta{i}`` for each joint, then ``theta{i}dot``, ``torque``, and
        for runs with parameter estimates ``param_error`` (and ``friction_error`` when some
        estimated parameters are friction coefficients, names starting with V or C).
    """
    nv = result.q.shape[1]
    figures: dict[str, Figure] = {}
    for j in range(nv):
        figures[f"theta{j + 1}"] = _state_figure(result, j, derivative=False)
    for j in range(nv):
        figures[f"theta{j + 1}dot"] = _state_figure(result, j, derivative=True)
    figures["torque"] = _torque_figure(result)
    if result.p_error is not None:
        inertial = [n for n in result.parameter_names if not _is_friction(n)]
        friction = [n for n in result.parameter_names if _is_friction(n)]
        if inertial:
            figures["param_error"] = _parameter_figure(result, inertial, friction=False)
        if friction:
            figures["friction_error"] = _parameter_figure(result, friction, friction=True)
    return figures


def save_simulation_figures(
    result: SimulationResult, out_dir: str | os.PathLike[str], prefix: str | None = None
) -> list[Path]:
    """Write one controller run's figures as PNG into ``out_dir``.

    * ``<prefix>_theta1.png``, ``_theta2.png`` (position [rad]) and ``_theta1dot.png``,
      ``_theta2dot.png`` (velocity [rad/s]): actual vs desired over the run; the error over
      the first reference period and, on its own scale, after it; the error's envelope
      ``max |e|`` per window on a log scale (errors decaying to 1e-10 stay visible);
    * ``<prefix>_torque.png``: ``τ_1``, ``τ_2`` [N·m] with the ``±limit`` lines (applied vs
      commanded when the plant saturates), for the whole run and the last reference period;
      a limit far beyond the data is noted instead of squashing the curve, and a commanded
      torque beyond its limit is annotated;
    * adaptive runs: ``<prefix>_param_error.png`` (``p̂ − p`` of the inertial parameters
      [kg·m²] and the relative error [%]) and, with friction estimates (names starting with
      V or C), ``<prefix>_friction_error.png`` (V [N·m·s/rad], C [N·m], relative [%]).

    Args:
        result: A simulation result.
        out_dir: Output directory, created if missing.
        prefix: File-name prefix; default ``result.controller``.

    Returns:
        The paths written, in figure order.

    Raises:
        OutputError: ``out_dir`` cannot be created or written.
    """
    prefix = result.controller if prefix is None else prefix
    return _save_all(_simulation_figures(result), out_dir, f"{prefix}_" if prefix else "")


# ------------------------------------------------------------------- distribution


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
        finite = x[np.isfinite(x)]
        if finite.size == 0:
            raise InvalidParameterError(f"rows[{name!r}]", raw, "at least one finite value")
        values[name] = x
    n = len(values)
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    fig = _new_figure((4.0 * ncols + 0.5, 3.2 * nrows + 0.6))
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax, (name, x) in zip(axes, values.items()):
        finite = x[np.isfinite(x)]
        bins = "auto" if np.ptp(finite) > 0 else 1
        ax.hist(finite, bins=bins, color=ACTUAL_COLOR, alpha=0.75, edgecolor="white")
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
    fig.suptitle(title if title is not None else "Distribution of metrics over the sweep")
    return fig


def save_distribution_figure(
    rows: Mapping[str, np.ndarray], out_path: str | os.PathLike[str], title: str | None = None
) -> Path:
    """Write histograms of several metrics (one subplot each) to ``out_path``, atomically.

    Args:
        rows: Metric name (with its unit, e.g. ``"RMS e1 [rad]"``) → values, any shape
            (flattened; non-finite values are counted and left out).
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
    path = _save(fig, Path(out_path))
    fig.clear()
    return path
