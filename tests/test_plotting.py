"""Tests of twolink_pin.plotting: the figures show the data they are given (lines equal
the trajectory, its forward kinematics, the run's errors, torques and estimates; limit
lines at the motor limits), parameters go to the figure and panel their result declares
(kind and unit, never the name), report figure numbers appear only when the caller passes
them, every figure works for any number of joints, the PNGs decode at the stated pixel
size and are not blank, every write is atomic, no pyplot state is touched, and no figure
outlives its save.

Simulations are short (0.3–2 s) so the module runs in seconds.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import re
import subprocess
import sys
import types
import warnings
import weakref
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.image import imread
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, LogFormatterSciNotation
from matplotlib.transforms import Bbox

from twolink_pin import plotting
from twolink_pin.errors import InvalidParameterError, OutputError
from twolink_pin.feasibility import TorqueCheck, check_torques
from twolink_pin.kinematics import joint_positions
from twolink_pin.model import RobotModel, example_robot_urdf, load_robot
from twolink_pin.plotting import _panels, _save, _style
from twolink_pin.plotting.distribution import _distribution_figure
from twolink_pin.plotting.parameters import (
    MANY_PARAMETERS,
    RELATIVE_FLOOR,
    _relative_columns,
    parameter_figures,
)
from twolink_pin.plotting.run import _simulation_figures, _torque_figure
from twolink_pin.plotting.trajectory import _motion_plane, _trajectory_figures
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import JointTrajectory, default_trajectory
from twolink_pin.twolink import closed_form
from twolink_pin.twolink.reference import REPORT_FIGURES

ROBOT: RobotModel = load_robot()
TRAJ: JointTrajectory = default_trajectory(ROBOT)
LIMITS = (240.0, 40.0)
TRAJECTORY_KEYS = ["theta1", "theta2", "workspace", "desired_torque"]
RUN_SUFFIXES = ["theta1", "theta2", "theta1dot", "theta2dot", "torque"]


def _run(
    name: str, duration: float = 2.0, saturate: bool = False, robot: RobotModel = ROBOT
) -> SimulationResult:
    controller, plant = make_scenario(name, robot, saturate=saturate)
    return simulate(controller, plant, default_trajectory(robot), SimulationConfig(duration=duration))


@pytest.fixture(scope="module")
def check() -> TorqueCheck:
    return check_torques(ROBOT, TRAJ, samples=801)


@pytest.fixture(scope="module")
def trajectory_figures(check: TorqueCheck) -> dict[str, Figure]:
    return _trajectory_figures(ROBOT, TRAJ, check)


@pytest.fixture(scope="module")
def pd() -> SimulationResult:
    return _run("pd")


@pytest.fixture(scope="module")
def pd_figures(pd: SimulationResult) -> dict[str, Figure]:
    return _simulation_figures(pd)


@pytest.fixture(scope="module")
def adaptive() -> SimulationResult:
    return _run("adaptive")


@pytest.fixture(scope="module")
def friction() -> SimulationResult:
    return _run("adaptive-friction")


# ------------------------------------------------------------------------ helpers


def _axes(fig: Figure, label: str):  # type: ignore[no-untyped-def]  # matplotlib Axes
    found = [ax for ax in fig.axes if ax.get_label() == label]
    assert len(found) == 1, f"expected one axes labelled {label!r}, got {[a.get_label() for a in fig.axes]}"
    return found[0]


def _line(ax, label: str) -> Line2D:  # type: ignore[no-untyped-def]
    found = [ln for ln in ax.get_lines() if label in str(ln.get_label())]
    assert len(found) == 1, (
        f"expected one line labelled {label!r}, got {[ln.get_label() for ln in ax.get_lines()]}"
    )
    return found[0]


def _data_lines(ax) -> list[Line2D]:  # type: ignore[no-untyped-def]
    """The labelled lines of an axes (not the zero line or limit lines)."""
    return [ln for ln in ax.get_lines() if not str(ln.get_label()).startswith("_")]


def _limit_levels(ax) -> list[float]:  # type: ignore[no-untyped-def]
    """y of the dashed horizontal limit lines of an axes."""
    levels = []
    for ln in ax.get_lines():
        y = np.asarray(ln.get_ydata(), dtype=float)
        if ln.get_linestyle() == "--" and ln.get_color() == _style.LIMIT_COLOR and np.ptp(y) == 0:
            levels.append(float(y[0]))
    return sorted(levels)


def _assert_png(path: Path, figsize: tuple[float, float]) -> None:
    """The file is a PNG that decodes at figsize × DPI pixels and is not a blank canvas."""
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", path.name
    image = imread(path)
    w, h = figsize
    expected = (h * _style.DPI, w * _style.DPI)  # matplotlib truncates a fractional pixel
    assert all(abs(n - x) < 1 for n, x in zip(image.shape[:2], expected)), (path.name, image.shape, expected)
    gray = image[..., :3].mean(axis=2)
    assert gray.std() > 0.05, f"{path.name} looks blank (std {gray.std():.4f})"
    assert (gray < 0.5).mean() > 0.005, f"{path.name} has almost no dark pixels (no text or lines)"


def _final_bars(ax) -> list:  # type: ignore[no-untyped-def]  # matplotlib Axes → Rectangle patches
    """The bars of the final error p̂(T) − p of a bar panel (its second bar container)."""
    assert len(ax.containers) == 2, [c.get_label() for c in ax.containers]
    return list(ax.containers[1])


def _assert_inside_figure(fig: Figure) -> None:
    """After a draw, every legend, drawn tick label, axis label and title lies within the
    figure (1 px of rounding allowed)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    box = fig.bbox
    for ax in fig.axes:
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        artists = [ax.get_legend(), ax.title, ax.xaxis.label, ax.yaxis.label]
        artists += [t for t in ax.get_xticklabels() if x0 <= t.get_position()[0] <= x1]  # drawn ones
        artists += [t for t in ax.get_yticklabels() if y0 <= t.get_position()[1] <= y1]
        for artist in artists:
            if artist is None or not artist.get_visible() or getattr(artist, "get_text", lambda: "x")() == "":
                continue
            extent = artist.get_window_extent(renderer)
            inside = box.x0 - 1 <= extent.x0 and extent.x1 <= box.x1 + 1
            inside = inside and box.y0 - 1 <= extent.y0 and extent.y1 <= box.y1 + 1
            assert inside, (ax.get_label(), type(artist).__name__, getattr(artist, "get_text", str)(), extent)


def _synthetic_result(
    names: tuple[str, ...],
    units: tuple[str, ...],
    kinds: tuple[str, ...],
    p_true: np.ndarray,
    nv: int = 6,
    samples: int = 201,
    tau: np.ndarray | None = None,
) -> SimulationResult:
    """A 1 s "run" of an nv-joint arm whose estimates start at half the true values (at
    0.1 where the true value is 0) and wander; τ [N·m] sinusoidal unless given."""
    t = np.linspace(0.0, 1.0, samples)
    rng = np.random.default_rng(3)
    start = np.where(p_true != 0, 0.5 * p_true, 0.1)
    drift = rng.normal(scale=0.3, size=len(p_true)) * (np.abs(p_true) + 0.05)
    p_hat = start + np.outer(np.sin(2.0 * t), drift)
    q = 0.1 * np.sin(np.outer(t, np.arange(1, nv + 1)))
    torque = 5.0 * np.cos(np.outer(t, np.arange(1, nv + 1))) if tau is None else tau
    return SimulationResult(
        controller="adaptive",
        method="rk4",
        dt=float(t[1] - t[0]),
        t=t,
        q=q,
        v=np.gradient(q, t, axis=0),
        tau_command=torque,
        tau=torque,
        q_des=0.9 * q,
        v_des=0.9 * np.gradient(q, t, axis=0),
        a_des=np.zeros_like(q),
        torque_limits=np.full(nv, 100.0),
        saturate=False,
        reference_period=0.5,
        p_hat=p_hat,
        p_true=p_true,
        parameter_names=names,
        parameter_units=units,
        parameter_kinds=kinds,
        robot="synthetic",
    )


def _base_parameters(n: int = 36) -> tuple[tuple[str, ...], tuple[str, ...], np.ndarray]:
    """``n`` base-parameter-like names (long combinations and single terms), units (kg·m²,
    and kg·m for every third), and true values with exact zeros and one negligible value."""
    units = tuple("kg·m" if k % 3 == 1 else "kg·m²" for k in range(n))
    names = tuple(
        f"link{k // 6 + 1}.{'mcx' if units[k] == 'kg·m' else 'Ixx'}"
        + (
            f" - 1 link{k // 6 + 1}.Izz + 0.1806 link{k // 6 + 2}.m + 0.1806 link{k // 6 + 3}.m"
            if k % 2 == 0
            else ""
        )
        for k in range(n)
    )
    p_true = np.array([0.0 if k % 5 == 3 else (-1.0) ** k * (0.2 + 0.1 * k) for k in range(n)])
    p_true[7] = 1e-6  # a kg·m² value far below 1 % of the largest one
    return names, units, p_true


def _chain_urdf(path: Path, n: int, effort: float = 200.0) -> Path:
    """An n-joint arm in gravity: a yaw joint, then pitch joints 0.3 m apart, and an
    ``ee_link`` 0.25 m beyond the last joint (so nothing is planar for n >= 2)."""
    parts = ['<?xml version="1.0"?>\n<robot name="chain"><link name="l0"/>']
    for i in range(1, n + 1):
        axis, xyz = ("0 0 1", "0 0 0.1") if i == 1 else ("0 1 0", "0.3 0 0")
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            f'<limit lower="-3.14" upper="3.14" effort="{effort}" velocity="10"/></joint>'
            f'<link name="l{i}"><inertial><origin xyz="0.1 0.01 0.02"/><mass value="{2.0 / i}"/>'
            f'<inertia ixx="0.05" ixy="0.001" ixz="0" iyy="0.04" iyz="0" izz="0.03"/></inertial></link>'
        )
    parts.append(
        f'<joint name="ee" type="fixed"><parent link="l{n}"/><child link="ee_link"/>'
        '<origin xyz="0.25 0 0"/></joint><link name="ee_link"/></robot>\n'
    )
    path.write_text("".join(parts))
    return path


# --------------------------------------------------------------------- trajectory


def test_trajectory_figures_written_with_size_and_content(
    tmp_path: Path, check: TorqueCheck, trajectory_figures: dict[str, Figure]
) -> None:
    """trajectory_<key>.png land in a new nested directory, in order (no report figure
    number in a name), at figsize × DPI pixels, not blank, and nothing else (no temporary
    file) is left in the directory."""
    assert list(trajectory_figures) == TRAJECTORY_KEYS
    out = tmp_path / "new" / "figs"
    sizes = {f"trajectory_{k}.png": tuple(fig.get_size_inches()) for k, fig in trajectory_figures.items()}
    paths = plotting.save_trajectory_figures(ROBOT, TRAJ, check, out)
    assert [p.name for p in paths] == [f"trajectory_{k}.png" for k in TRAJECTORY_KEYS]
    assert sorted(p.name for p in out.iterdir()) == sorted(sizes)
    assert sizes["trajectory_theta1.png"] == _style.JOINT_FIGSIZE
    assert sizes["trajectory_workspace.png"] == _style.WORKSPACE_FIGSIZE
    assert sizes["trajectory_desired_torque.png"] == _style.TORQUE_FIGSIZE
    for path in paths:
        _assert_png(path, sizes[path.name])


def test_joint_figure_plots_the_trajectory_and_its_via_points(trajectory_figures: dict[str, Figure]) -> None:
    """Each panel of a joint figure is the trajectory's q, q̇, q̈, jerk over exactly one
    period, and the via-point markers sit at (times, via_q)."""
    for j, key in enumerate(("theta1", "theta2")):
        fig = trajectory_figures[key]
        for label, field in (("position", "q"), ("velocity", "v"), ("acceleration", "a"), ("jerk", "jerk")):
            line = _line(_axes(fig, label), label)
            t = np.asarray(line.get_xdata())
            np.testing.assert_allclose([t[0], t[-1]], [TRAJ.t0, TRAJ.t0 + TRAJ.period], rtol=0, atol=1e-12)
            expected = getattr(TRAJ.sample(t), field)[:, j]
            np.testing.assert_allclose(line.get_ydata(), expected, rtol=0, atol=1e-12)
        via = _line(_axes(fig, "position"), "via points")
        np.testing.assert_allclose(via.get_xdata(), TRAJ.times, rtol=0, atol=0)
        np.testing.assert_allclose(via.get_ydata(), TRAJ.via_q[:, j], rtol=0, atol=0)


def test_workspace_figure_path_annulus_and_labels(trajectory_figures: dict[str, Figure]) -> None:
    """The end-effector path equals the closed-form FK of the trajectory (a second method
    beside Pinocchio's), the annulus circles have radii |L1 − L2| and L1 + L2, the axes are
    equal-aspect x-y, and the via points are labelled with their times (the start and end
    point share one label)."""
    fig = trajectory_figures["workspace"]
    full, zoom = _axes(fig, "workspace"), _axes(fig, "path")
    path = _line(zoom, "end-effector path")
    xy = np.column_stack([path.get_xdata(), path.get_ydata()])
    l1, l2 = (float(x) for x in ROBOT.link_lengths)
    t = TRAJ.t0 + np.linspace(0.0, TRAJ.span, len(xy))
    np.testing.assert_allclose(
        xy, closed_form.forward_kinematics(TRAJ.sample(t).q, l1, l2), rtol=0, atol=1e-12
    )
    radii = sorted(
        float(np.hypot(ln.get_xdata(), ln.get_ydata()).mean())
        for ln in full.get_lines()
        if ln.get_color() == _style.REACH_COLOR
    )
    np.testing.assert_allclose(radii, [abs(l1 - l2), l1 + l2], rtol=0, atol=1e-12)
    assert full.get_aspect() == 1.0 and zoom.get_aspect() == 1.0
    assert (zoom.get_xlabel(), zoom.get_ylabel()) == ("x [m]", "y [m]")
    labels = [text.get_text() for text in zoom.texts]
    assert any(s.startswith("t = 0, 4 s") for s in labels), labels
    for tv in ("1", "2", "3"):
        assert any(s.startswith(f"t = {tv} s") for s in labels), labels


def test_workspace_arms_come_from_joint_positions(trajectory_figures: dict[str, Figure]) -> None:
    """The blue arms are the x-y of kinematics.joint_positions at the via points: joint
    origins, then the end effector."""
    full = _axes(trajectory_figures["workspace"], "workspace")
    arms = [ln for ln in full.get_lines() if ln.get_color() == "tab:blue"]
    assert len(arms) == len(TRAJ.times)
    expected = joint_positions(ROBOT, TRAJ.via_q)[:, :, :2]
    for line, arm in zip(arms, expected):
        np.testing.assert_allclose(np.column_stack([line.get_xdata(), line.get_ydata()]), arm, rtol=0, atol=0)


def test_desired_torque_figure_data_limits_and_peaks(
    check: TorqueCheck, trajectory_figures: dict[str, Figure]
) -> None:
    """The desired-torque figure plots check.tau, dashed lines at ±240 and ±40 N·m, a
    marker at each peak, and (the peaks being a few % of the limits) a note that the limit
    is off scale."""
    fig = trajectory_figures["desired_torque"]
    for j, limit in enumerate(LIMITS):
        ax = _axes(fig, f"tau{j + 1}")
        line = _line(ax, "desired")
        np.testing.assert_array_equal(line.get_xdata(), check.t)
        np.testing.assert_array_equal(line.get_ydata(), check.tau[:, j])
        assert _limit_levels(ax) == [-limit, limit]
        peak_markers = [
            ln for ln in ax.get_lines() if ln.get_marker() == "o" and len(np.atleast_1d(ln.get_xdata())) == 1
        ]
        assert len(peak_markers) == 1
        np.testing.assert_allclose(
            abs(float(np.ravel(peak_markers[0].get_ydata())[0])), check.peak[j], rtol=0, atol=0
        )
        assert any(f"±{limit:g} N·m limit off scale" in t.get_text() for t in ax.texts)
        assert ax.get_ylim()[1] < limit  # the curve is not squashed against a far-away limit
        assert "[N·m]" in ax.get_ylabel()


def test_trajectory_figures_reject_a_mismatched_trajectory(check: TorqueCheck) -> None:
    three = JointTrajectory.from_via_q((0.0, 1.0), np.zeros((2, 3)))
    with pytest.raises(InvalidParameterError, match="trajectory"):
        _trajectory_figures(ROBOT, three, check)


def test_arm_without_torque_limits_and_in_another_plane() -> None:
    """The double pendulum swings in the y-z plane and its URDF gives no effort limits:
    the workspace figure is drawn in y-z (its path is joint_positions' y-z, no annulus),
    and the torque figures draw no limit line and say there is no limit."""
    robot = load_robot(str(example_robot_urdf("double_pendulum_description/urdf/double_pendulum.urdf")))
    trajectory = default_trajectory(robot)
    check = check_torques(robot, trajectory, samples=201)
    assert not np.isfinite(check.limits).any()
    figures = _trajectory_figures(robot, trajectory, check, samples=201)
    zoom = _axes(figures["workspace"], "path")
    assert (zoom.get_xlabel(), zoom.get_ylabel()) == ("y [m]", "z [m]")
    path = _line(zoom, "end-effector path")
    t = trajectory.t0 + np.linspace(0.0, trajectory.span, 201)
    expected = joint_positions(robot, trajectory.sample(t).q)[:, -1, 1:]
    np.testing.assert_allclose(np.column_stack([path.get_xdata(), path.get_ydata()]), expected, atol=0)
    full = _axes(figures["workspace"], "workspace")
    assert [ln for ln in full.get_lines() if ln.get_color() == _style.REACH_COLOR] == []
    assert "y-z plane" in figures["workspace"].get_suptitle()
    for j in range(2):
        ax = _axes(figures["desired_torque"], f"tau{j + 1}")
        assert _limit_levels(ax) == []
        assert any("no limit in the URDF" in text.get_text() for text in ax.texts)
    assert "no motor limits" in figures["desired_torque"].get_suptitle()
    torque = _torque_figure(_run("pd", duration=0.3, robot=robot))
    assert all(_limit_levels(_axes(torque, f"tau{j + 1}")) == [] for j in range(2))


# ----------------------------------------------------------------------- titles


def test_report_figure_numbers_only_when_given(
    check: TorqueCheck, pd: SimulationResult, trajectory_figures: dict[str, Figure]
) -> None:
    """With figure_numbers every title cites its own number ("cf. report Fig. N"), with a
    partial mapping only the figures it names do, and without none does; ``title`` goes
    beside the controller's name. A read-only mapping is accepted and left as it was."""
    assert all("cf. report" not in fig.get_suptitle() for fig in trajectory_figures.values())
    numbers = REPORT_FIGURES["trajectory"]
    cited = _trajectory_figures(ROBOT, TRAJ, check, samples=201, figure_numbers=numbers)
    for key, fig in cited.items():
        assert f"cf. report Fig. {numbers[key]}" in fig.get_suptitle(), key

    run_numbers = types.MappingProxyType(dict(REPORT_FIGURES["pd"]))
    figs = _simulation_figures(pd, run_numbers, "PD + model feedforward")
    assert dict(run_numbers) == REPORT_FIGURES["pd"]
    for key, fig in figs.items():
        title = fig.get_suptitle()
        assert title.startswith("controller pd (PD + model feedforward) — cf. report Fig. "), title
        assert title.splitlines()[0].endswith(f"Fig. {run_numbers[key]}"), title
    partial = _simulation_figures(pd, {"torque": 11, "friction_error": 33})
    assert "cf. report Fig. 11" in partial["torque"].get_suptitle()
    assert all("cf. report" not in f.get_suptitle() for k, f in partial.items() if k != "torque")
    assert all(f.get_suptitle().startswith("controller pd\n") for k, f in partial.items() if k != "torque")


@pytest.mark.parametrize(
    ("numbers", "match"),
    [
        ([("torque", 11)], "figure_numbers.*a mapping"),
        ({"torque": 0}, r"figure_numbers\['torque'\].*positive integer"),
        ({"torque": True}, r"figure_numbers\['torque'\].*positive integer"),
        ({"torque": "11"}, r"figure_numbers\['torque'\].*positive integer"),
    ],
)
def test_bad_figure_numbers_are_refused(pd: SimulationResult, numbers: object, match: str) -> None:
    with pytest.raises(InvalidParameterError, match=match):
        _simulation_figures(pd, numbers)  # type: ignore[arg-type]


# --------------------------------------------------------------------- simulation


def test_state_figures_plot_actual_desired_and_error(
    pd: SimulationResult, pd_figures: dict[str, Figure]
) -> None:
    """Position and velocity figures: top panel q (v) and q_d (v_d); both error panels hold
    e (ė) exactly; the log panel is the window-wise max |e|, so it bounds |e| from above
    and reaches max |e|; every y label has its unit."""
    figures = pd_figures
    assert list(figures) == RUN_SUFFIXES
    for j in range(2):
        for key, actual, desired, error, unit in (
            (f"theta{j + 1}", pd.q, pd.q_des, pd.e, "[rad]"),
            (f"theta{j + 1}dot", pd.v, pd.v_des, pd.edot, "[rad/s]"),
        ):
            fig = figures[key]
            top = _axes(fig, "signal")
            np.testing.assert_array_equal(_line(top, "actual").get_ydata(), actual[:, j])
            np.testing.assert_array_equal(_line(top, "desired").get_ydata(), desired[:, j])
            for panel in ("error", "error-late"):
                err_line = _axes(fig, panel).get_lines()[0]
                np.testing.assert_array_equal(err_line.get_xdata(), pd.t)
                np.testing.assert_array_equal(err_line.get_ydata(), error[:, j])
            env = _line(_axes(fig, "error-log"), "max")
            te, ye = np.asarray(env.get_xdata()), np.asarray(env.get_ydata())
            window = np.searchsorted(te, pd.t, side="right") - 1
            assert np.all(ye[window] >= np.abs(error[:, j]))
            np.testing.assert_allclose(ye.max(), np.abs(error[:, j]).max(), rtol=0, atol=0)
            assert _axes(fig, "error-log").get_yscale() == "log"
            for label in ("signal", "error", "error-log"):
                assert _axes(fig, label).get_ylabel().endswith(unit), (key, label)
            assert fig.get_suptitle().startswith("controller pd")


def test_torque_figure_data_and_limit_lines(pd: SimulationResult, pd_figures: dict[str, Figure]) -> None:
    """The torque figure plots result.tau for the whole run and the last period, with
    dashed limit lines at ±240 and ±40 N·m in every panel."""
    fig = pd_figures["torque"]
    for j, limit in enumerate(LIMITS):
        whole = _axes(fig, f"tau{j + 1}")
        np.testing.assert_array_equal(_line(whole, "applied").get_ydata(), pd.tau[:, j])
        last = _axes(fig, f"tau{j + 1}-last")
        line = _line(last, "applied")
        t0 = pd.t[-1] - pd.reference_period
        np.testing.assert_array_equal(line.get_xdata(), pd.t[pd.t >= max(pd.t[0], t0)])
        for ax in (whole, last):
            assert _limit_levels(ax) == [-limit, limit]
            assert [ln for ln in ax.get_lines() if "commanded" in str(ln.get_label())] == []
        assert whole.get_ylabel() == rf"$\tau_{{{j + 1}}}$ [N·m]"


def test_saturated_run_shows_commanded_and_applied_torque() -> None:
    """With saturation the figure shows the commanded torque beside the applied (clipped)
    one and says the plant clipped it; without, it flags the excess as unsaturated."""
    sat = _run("adaptive", duration=0.3, saturate=True)
    assert sat.limit_exceeded[1], "the adaptive run's initial τ2 should exceed 40 N·m"
    ax = _axes(_torque_figure(sat), "tau2")
    np.testing.assert_array_equal(_line(ax, "commanded").get_ydata(), sat.tau_command[:, 1])
    np.testing.assert_array_equal(_line(ax, "applied").get_ydata(), sat.tau[:, 1])
    assert np.abs(_line(ax, "applied").get_ydata()).max() <= 40.0
    assert any("clipped by the plant" in t.get_text() for t in ax.texts)
    free = _run("adaptive", duration=0.3)
    ax = _axes(_torque_figure(free), "tau2")
    assert any("not saturated" in t.get_text() for t in ax.texts)


# --------------------------------------------------------------------- parameters


def test_parameter_figures_only_for_adaptive_runs(
    pd_figures: dict[str, Figure], adaptive: SimulationResult, friction: SimulationResult
) -> None:
    """pd has no parameter figure, adaptive has param_error only, adaptive-friction has both;
    the lines are p̂ − p (absolute, one panel per unit: kg·m²; N·m·s/rad and N·m) and
    100 (p̂ − p)/p (relative), with the units on the y axes."""
    assert "param_error" not in pd_figures
    figs = _simulation_figures(adaptive)
    assert list(figs) == [*RUN_SUFFIXES, "param_error"]
    assert adaptive.p_error is not None and adaptive.p_true is not None
    absolute = _axes(figs["param_error"], "absolute [kg·m²]")
    assert absolute.get_ylabel() == "estimate − true [kg·m²]"
    for i, line in enumerate(_data_lines(absolute)):
        np.testing.assert_array_equal(line.get_ydata(), adaptive.p_error[:, i])
    assert len(absolute.get_lines()) == 3 + 1  # p1..p3 and the zero line
    relative = _axes(figs["param_error"], "relative")
    assert relative.get_ylabel().endswith("[%]")
    np.testing.assert_allclose(
        _data_lines(relative)[0].get_ydata(), 100 * adaptive.p_error[:, 0] / adaptive.p_true[0], rtol=1e-12
    )
    figs = _simulation_figures(friction)
    assert list(figs) == [*RUN_SUFFIXES, "param_error", "friction_error"]
    assert friction.p_error is not None
    names = list(friction.parameter_names)
    for unit, group in (("N·m·s/rad", ("V1", "V2")), ("N·m", ("C1", "C2"))):
        ax = _axes(figs["friction_error"], f"absolute [{unit}]")
        assert ax.get_ylabel() == f"estimate − true [{unit}]"
        lines = _data_lines(ax)
        assert len(lines) == len(group)
        for line, name in zip(lines, group):
            np.testing.assert_array_equal(line.get_ydata(), friction.p_error[:, names.index(name)])
    assert len(_data_lines(_axes(figs["param_error"], "absolute [kg·m²]"))) == 3


def test_parameters_go_where_their_kind_says_not_their_name(friction: SimulationResult) -> None:
    """Renamed so that an inertial parameter is called "Vz" and a friction one "Cx" or
    "p9", each still lands in the figure of its declared kind; re-declaring p3 as friction
    moves it (with its own unit panel) to friction_error; declaring all friction leaves no
    param_error figure."""
    assert friction.p_error is not None
    names = ("Vz", "p2", "p3", "Cx", "p9", "C1", "C2")
    renamed = dataclasses.replace(friction, parameter_names=names)
    figs = _simulation_figures(renamed)
    inertial = _data_lines(_axes(figs["param_error"], "absolute [kg·m²]"))
    assert [str(ln.get_label()).split(" (")[0] for ln in inertial] == [
        "Vz",
        r"$\hat{p}_{2} - p_{2}$",
        r"$\hat{p}_{3} - p_{3}$",
    ]
    np.testing.assert_array_equal(inertial[0].get_ydata(), friction.p_error[:, 0])
    viscous = _data_lines(_axes(figs["friction_error"], "absolute [N·m·s/rad]"))
    assert [str(ln.get_label()).split(" (")[0] for ln in viscous] == ["Cx", r"$\hat{p}_{9} - p_{9}$"]
    np.testing.assert_array_equal(viscous[1].get_ydata(), friction.p_error[:, 4])

    kinds = ("inertial", "inertial", "friction", "friction", "friction", "friction", "friction")
    moved = _simulation_figures(dataclasses.replace(friction, parameter_kinds=kinds))
    assert len(_data_lines(_axes(moved["param_error"], "absolute [kg·m²]"))) == 2
    p3 = _data_lines(_axes(moved["friction_error"], "absolute [kg·m²]"))
    assert len(p3) == 1
    np.testing.assert_array_equal(p3[0].get_ydata(), friction.p_error[:, 2])

    only = _simulation_figures(dataclasses.replace(friction, parameter_kinds=("friction",) * 7))
    assert list(only) == [*RUN_SUFFIXES, "friction_error"]


def test_parameter_panels_follow_the_declared_units(adaptive: SimulationResult) -> None:
    """The absolute panels group the parameters by ``parameter_units`` (in order of first
    use) and each y axis names that unit."""
    assert adaptive.p_error is not None
    result = dataclasses.replace(adaptive, parameter_units=("kg", "kg·m", "kg"))
    fig = _simulation_figures(result)["param_error"]
    assert [ax.get_label() for ax in fig.axes] == ["absolute [kg]", "absolute [kg·m]", "relative"]
    kg = _data_lines(_axes(fig, "absolute [kg]"))
    np.testing.assert_array_equal(kg[0].get_ydata(), adaptive.p_error[:, 0])
    np.testing.assert_array_equal(kg[1].get_ydata(), adaptive.p_error[:, 2])
    assert _axes(fig, "absolute [kg·m]").get_ylabel() == "estimate − true [kg·m]"


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (
            {"parameter_kinds": ()},
            r"result\.parameter_kinds.*one entry per estimated parameter \(3\) but got 0",
        ),
        ({"parameter_units": ("kg·m²",)}, r"result\.parameter_units.*\(3\) but got 1"),
        ({"parameter_kinds": ("inertial", "payload", "inertial")}, r"parameter_kinds.*not \['payload'\]"),
    ],
)
def test_undeclared_parameters_are_refused(adaptive: SimulationResult, change: dict, match: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(InvalidParameterError, match=match):
        _simulation_figures(dataclasses.replace(adaptive, **change))


# ------------------------------------------------------------------ generality in nv


@pytest.mark.parametrize("nv", [1, 3, 6])
def test_any_number_of_joints(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, nv: int) -> None:
    """An nv-joint arm gets one trajectory figure and two state figures per joint, a torque
    panel pair per joint at least 1.5 in tall (the figure grows with nv), the workspace
    without an annulus (no closed form for nv != 2; a 3-D view for the chains that leave
    every plane), and its base parameters: the single yaw joint's one inertia as a curve
    (kg·m²), the 15 and 36 of the longer chains as norms and one bar pair each, a bar
    panel per unit (kg·m² and kg·m); every file is written, and matplotlib warns of
    nothing (no collapsed constrained layout)."""
    robot = load_robot(_chain_urdf(tmp_path / f"chain{nv}.urdf", nv))
    assert robot.nv == nv
    trajectory = default_trajectory(robot)
    check = check_torques(robot, trajectory, samples=201)
    figures = _trajectory_figures(robot, trajectory, check, samples=201)
    assert list(figures) == [*(f"theta{j + 1}" for j in range(nv)), "workspace", "desired_torque"]
    full = _axes(figures["workspace"], "workspace")
    assert [ln for ln in full.get_lines() if ln.get_color() == _style.REACH_COLOR] == []
    assert full.name == ("rectilinear" if nv == 1 else "3d")
    assert len([ax for ax in figures["desired_torque"].axes if ax.get_label().startswith("tau")]) == nv

    result = _run("adaptive", duration=0.2, robot=robot)
    assert set(result.parameter_units) == ({"kg·m²"} if nv == 1 else {"kg·m", "kg·m²"})
    run = _simulation_figures(result)
    suffixes = [f"theta{j + 1}" for j in range(nv)] + [f"theta{j + 1}dot" for j in range(nv)]
    assert list(run) == [*suffixes, "torque", "param_error"]
    torque = run["torque"]
    torque.canvas.draw()
    height = torque.get_size_inches()[1]
    for j in range(nv):
        for label in (f"tau{j + 1}", f"tau{j + 1}-last"):
            ax = _axes(torque, label)
            assert ax.get_position().height * height >= 1.5, (label, ax.get_position().height * height)
        np.testing.assert_array_equal(
            _line(_axes(torque, f"tau{j + 1}"), "applied").get_ydata(), result.tau[:, j]
        )
    param = run["param_error"]
    labels = [ax.get_label() for ax in param.axes]
    n_p = len(result.parameter_names)
    if nv == 1:
        assert n_p <= MANY_PARAMETERS
        assert labels == ["absolute [kg·m²]", "relative"]
        assert len(_data_lines(param.axes[0])) == n_p
    else:
        assert n_p == {3: 15, 6: 36}[nv] > MANY_PARAMETERS
        units = ["kg·m²", "kg·m"]  # in order of first use
        assert labels == ["normalised", *(f"final [{u}]" for u in units), *(f"relative [{u}]" for u in units)]
        assert sum(len(_final_bars(param.axes[1 + k])) for k in range(len(units))) == n_p

    real_save = _save.save_figure
    rendered = ("trajectory_workspace.png", "adaptive_torque.png", "adaptive_param_error.png")
    monkeypatch.setattr(  # render the three largest figures, only name the others (speed)
        _save, "save_figure", lambda fig, path: real_save(fig, path) if path.name in rendered else path
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        paths = plotting.save_trajectory_figures(robot, trajectory, check, tmp_path)
        paths += plotting.save_simulation_figures(result, tmp_path)
    expected = [f"trajectory_{k}.png" for k in figures] + [f"adaptive_{k}.png" for k in run]
    assert [p.name for p in paths] == expected
    for name in rendered:
        _assert_png(tmp_path / name, tuple((figures | run)[name.split("_", 1)[1][:-4]].get_size_inches()))


# ---------------------------------------------------- many joints, many parameters


@pytest.fixture(scope="module")
def many() -> SimulationResult:
    """A 6-joint run estimating 36 base-parameter-like inertial parameters."""
    names, units, p_true = _base_parameters()
    return _synthetic_result(names, units, ("inertial",) * 36, p_true)


def _unit_columns(result: SimulationResult, unit: str) -> list[int]:
    return [i for i, u in enumerate(result.parameter_units) if u == unit]


def test_many_parameters_show_norms_and_one_bar_pair_each(many: SimulationResult) -> None:
    """36 parameters (more than MANY_PARAMETERS): one panel of ‖p̂ − p‖ / ‖p‖ per unit over
    time, equal to the norms computed here (from p̂(0) at t = 0), and one bar panel per unit
    with an initial and a final bar per parameter (36 final bars in all), their widths
    p̂(0) − p and p̂(T) − p, labelled β<k> with the first term of the k-th name."""
    fig = parameter_figures(many, {}, "controller adaptive")["param_error"]
    units = ("kg·m²", "kg·m")
    assert [ax.get_label() for ax in fig.axes] == [
        "normalised",
        *(f"final [{u}]" for u in units),
        *(f"relative [{u}]" for u in units),
    ]
    assert many.p_hat is not None and many.p_true is not None
    err = many.p_hat - many.p_true
    for unit in units:
        group = _unit_columns(many, unit)
        line = _line(_axes(fig, "normalised"), f"[{unit}]")
        first = math.sqrt(sum((many.p_hat[0, i] - many.p_true[i]) ** 2 for i in group))
        first /= math.sqrt(sum(many.p_true[i] ** 2 for i in group))
        np.testing.assert_allclose(np.asarray(line.get_ydata())[0], first, rtol=1e-12)
        expected = np.sqrt((err[:, group] ** 2).sum(axis=1) / (many.p_true[group] ** 2).sum())
        np.testing.assert_allclose(line.get_ydata(), expected, rtol=1e-12)
        bars = _axes(fig, f"final [{unit}]")
        initial, final = list(bars.containers[0]), _final_bars(bars)
        assert len(initial) == len(final) == len(group)
        np.testing.assert_allclose([b.get_width() for b in initial], err[0, group], rtol=0, atol=0)
        np.testing.assert_allclose([b.get_width() for b in final], err[-1, group], rtol=0, atol=0)
        expected_labels = []
        for i in group:
            head, *rest = many.parameter_names[i].split(" - ", 1)
            expected_labels.append(f"β{i + 1}: {head}" + (" + …" if rest else ""))
        assert [text.get_text() for text in bars.get_yticklabels()] == expected_labels
    assert sum(len(_final_bars(_axes(fig, f"final [{u}]"))) for u in units) == len(many.parameter_names) == 36


def test_relative_errors_only_where_the_true_value_is_not_negligible(many: SimulationResult) -> None:
    """Beside each bar: the final 100 (p̂ − p)/p [%] where |p| >= RELATIVE_FLOOR (1 %) of the
    largest |p| of its unit, "p = 0" for a true zero and "|p| ≈ 0" for the 1e-6 kg·m² value
    (no division by a value near 0). The few-parameter figure applies the same floor: the
    double pendulum's 5.8e-7 kg·m and 6.4e-11 kg·m get no relative curve, the twolink's
    p1, p2, p3 all do."""
    assert RELATIVE_FLOOR == 0.01
    fig = parameter_figures(many, {}, "controller adaptive")["param_error"]
    assert many.p_hat is not None and many.p_true is not None
    err = many.p_hat - many.p_true
    seen = set()
    for unit in ("kg·m²", "kg·m"):
        group = _unit_columns(many, unit)
        scale = max(abs(many.p_true[i]) for i in group)
        texts = [text.get_text() for text in _axes(fig, f"relative [{unit}]").get_yticklabels()]
        assert len(texts) == len(group)
        for i, text in zip(group, texts):
            p = float(many.p_true[i])
            if p == 0:
                assert text == "p = 0", (i, text)
            elif abs(p) < 0.01 * scale:
                assert text == "|p| ≈ 0", (i, text)
            else:
                assert text == f"{100 * err[-1, i] / p:+.1f} %", (i, text)
            seen.add(text if not text.endswith("%") else "%")
    assert seen == {"p = 0", "|p| ≈ 0", "%"}
    assert _relative_columns(many.p_true, many.parameter_units, range(36)).count(7) == 0

    pendulum = np.array([5.8018e-07, 4.2854e-02, 4.0784e-03, 6.4385e-11, 3.3530e-02, 4.5579e-03])
    units = ("kg·m", "kg·m", "kg·m²", "kg·m", "kg·m", "kg·m²")
    result = _synthetic_result(tuple(f"p{k}" for k in range(1, 7)), units, ("inertial",) * 6, pendulum, nv=2)
    relative = _axes(parameter_figures(result, {}, "controller adaptive")["param_error"], "relative")
    assert [str(ln.get_label()).split(":")[0] for ln in _data_lines(relative)] == [
        rf"$p_{{{k}}}$" for k in (2, 3, 5, 6)
    ]


def test_friction_the_plant_lacks_gets_error_norms() -> None:
    """14 friction parameters whose true values are all 0 (a plant without friction): no
    normalised panel (‖p‖ = 0) but ‖p̂ − p‖ per unit [N·m·s/rad], [N·m], bars labelled
    V₁…C₇ in mathtext, "p = 0" beside every bar, and everything inside the figure."""
    names = tuple(f"V{j}" for j in range(1, 8)) + tuple(f"C{j}" for j in range(1, 8))
    units = ("N·m·s/rad",) * 7 + ("N·m",) * 7
    result = _synthetic_result(names, units, ("friction",) * 14, np.zeros(14), nv=7)
    fig = parameter_figures(result, {}, "controller adaptive")["friction_error"]
    assert [ax.get_label() for ax in fig.axes] == [
        "norm [N·m·s/rad]",
        "norm [N·m]",
        "final [N·m·s/rad]",
        "final [N·m]",
        "relative [N·m·s/rad]",
        "relative [N·m]",
    ]
    assert result.p_hat is not None
    (line,) = _data_lines(_axes(fig, "norm [N·m]"))
    np.testing.assert_allclose(line.get_ydata(), np.sqrt((result.p_hat[:, 7:] ** 2).sum(axis=1)), rtol=1e-12)
    ticks = [text.get_text() for text in _axes(fig, "final [N·m·s/rad]").get_yticklabels()]
    assert ticks == [rf"$V_{{{j}}}$" for j in range(1, 8)]
    assert {text.get_text() for text in _axes(fig, "relative [N·m]").get_yticklabels()} == {"p = 0"}
    _assert_inside_figure(fig)


def test_six_joints_and_36_parameters_fit_in_their_figures(many: SimulationResult) -> None:
    """With nv = 6 and 36 parameters, building and drawing the run's figures raises no
    matplotlib UserWarning (constrained layout is applied, no axes collapse), and no legend,
    tick label, axis label or title extends beyond the figure."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        figures = _simulation_figures(many)
        assert list(figures)[-2:] == ["torque", "param_error"]
        for key in ("theta6", "theta6dot", "torque", "param_error"):
            _assert_inside_figure(figures[key])
    assert figures["param_error"].get_size_inches()[1] >= 36 * _style.BAR_HEIGHT


def test_the_report_figures_fit_their_fixed_margins(
    trajectory_figures: dict[str, Figure], pd_figures: dict[str, Figure], friction: SimulationResult
) -> None:
    """The twolink's figures drawn with fixed margins (no layout engine: the report's state,
    torque, trajectory and parameter-error figures) keep every legend, drawn tick label, axis
    label and title inside the figure, and no panel's decorations (matplotlib's own tight
    box of each axes) reach into another panel's or into the suptitle: saving them never
    needs the constrained-layout fallback."""
    figures = {f"trajectory_{k}": fig for k, fig in trajectory_figures.items()}
    figures |= {f"pd_{k}": fig for k, fig in pd_figures.items()}
    figures |= {f"friction_{k}": fig for k, fig in _simulation_figures(friction).items()}
    fixed = {k for k, fig in figures.items() if getattr(fig, "_twolink_margins", None) is not None}
    assert fixed == set(figures) - {"trajectory_workspace"}, sorted(set(figures) - fixed)
    for key in sorted(fixed):
        fig = figures[key]
        _assert_inside_figure(fig)  # draws it
        renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
        boxes = [ax.get_tightbbox(renderer) for ax in fig.axes]
        suptitle = fig._suptitle.get_window_extent(renderer)  # type: ignore[attr-defined]
        for i, box in enumerate(boxes):
            assert not box.overlaps(suptitle), (key, fig.axes[i].get_label())
            for k in range(i + 1, len(boxes)):
                overlap = Bbox.intersection(box, boxes[k])
                assert overlap is None or min(overlap.width, overlap.height) < 1.0, (
                    key,
                    fig.axes[i].get_label(),
                    fig.axes[k].get_label(),
                    overlap,
                )
        assert _save._labels_fit(fig), key


def test_a_label_wider_than_the_fixed_margins_gets_constrained_layout(tmp_path: Path) -> None:
    """Fixed margins too narrow for a panel's tick labels (they would be cut at the left edge)
    are replaced by constrained layout when the figure is saved: the labels then lie inside
    the figure and the PNG has the figure's size."""
    fig = _style.new_figure((4.0, 3.0))
    ax = fig.subplots()
    ax.plot([0.0, 1.0], [0.0, 1.0])
    ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:.1f} rad, a wide tick label"))
    _style.fix_margins(fig, _style.Margins(left=0.3, right=0.1, bottom=0.4, top=0.2))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    assert min(t.get_window_extent(renderer).x0 for t in ax.get_yticklabels()) < 0  # cut off
    path = _save.save_figure(fig, tmp_path / "wide.png")
    _assert_inside_figure(fig)
    assert ax.get_position().x0 * 4.0 > 1.0  # room made for the labels
    _assert_png(path, (4.0, 3.0))


def test_log_tick_labels_read_as_matplotlibs(pd_figures: dict[str, Figure]) -> None:
    """The plain-text log labels (10⁻⁸, 2×10⁻³) say what matplotlib's mathtext ones say, tick
    for tick, and the state figure's log panel uses them."""
    fig = _style.new_figure((4.0, 3.0))
    ax = fig.subplots()
    ax.set_yscale("log")
    ax.set_ylim(1e-16, 1e6)
    ours, theirs = _panels.PowerOfTenFormatter(), LogFormatterSciNotation()
    ours.set_axis(ax.yaxis)
    theirs.set_axis(ax.yaxis)
    digits = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
    for x in (1e-16, 1e-8, 1e-3, 0.1, 1.0, 10.0, 1e5):
        text = theirs(x)
        exponent = re.search(r"10\^\{(-?\d+)\}", text)
        expected = exponent.group(1) if exponent else {"1": "0", "10": "1"}[re.sub(r"[^0-9]", "", text)]
        got = ours(x)
        assert got.startswith("10") and "$" not in got, (x, got)
        assert got[2:].translate(digits) == expected, (x, got, text)
    between = _panels.PowerOfTenFormatter(labelOnlyBase=False)
    between.set_axis(ax.yaxis)
    assert between(2e-3) == "2×10⁻³"
    log = _axes(pd_figures["theta1"], "error-log")
    assert isinstance(log.yaxis.get_major_formatter(), _panels.PowerOfTenFormatter)


def test_a_torque_legend_moves_off_a_curve_near_the_top(pd_figures: dict[str, Figure]) -> None:
    """A torque that stays near its peak (like the Panda's τ4, 20–24 N·m) would run under
    the "upper right" legend: the legend goes where it covers no point of the curve. The
    twolink's legends stay in the upper right corner and cover no point either."""
    t = np.linspace(0.0, 1.0, 201)
    tau = np.column_stack([5.0 * np.cos(3.0 * t), 22.0 + 2.0 * np.sin(10.0 * t)])
    result = _synthetic_result(
        ("p1", "p2", "p3"), ("kg·m²",) * 3, ("inertial",) * 3, np.ones(3), nv=2, tau=tau
    )
    for fig, run in ((_torque_figure(result), result), (pd_figures["torque"], None)):
        fig.canvas.draw()
        for j in range(2):
            ax = _axes(fig, f"tau{j + 1}")
            legend = ax.get_legend()
            assert legend is not None
            box = legend.get_window_extent()
            line = _line(ax, "applied")
            points = ax.transData.transform(np.column_stack([line.get_xdata(), line.get_ydata()]))
            covered = (points[:, 0] >= box.x0) & (points[:, 0] <= box.x1)
            covered &= (points[:, 1] >= box.y0) & (points[:, 1] <= box.y1)
            assert not covered.any(), (j, int(covered.sum()))
            corner = ax.get_window_extent()
            at_corner = corner.x1 - box.x1 < 15 and corner.y1 - box.y1 < 15
            assert at_corner == (run is None or j == 0), (j, box, corner)


def test_workspace_of_an_arm_moving_in_3d(tmp_path: Path) -> None:
    """A chain that leaves every plane gets a 3-D view (its blue arms are joint_positions at
    the via points, in 3-D), the end-effector path seen from above (x-y) and from the side
    (z), and via labels with their three coordinates; the twolink moves in x-y and the
    double pendulum in y-z (their figures stay 2-D)."""
    robot = load_robot(_chain_urdf(tmp_path / "chain3.urdf", 3))
    trajectory = default_trajectory(robot)
    t = trajectory.t0 + np.linspace(0.0, trajectory.span, 201)
    points = joint_positions(robot, trajectory.sample(t).q)
    assert _motion_plane(points) is None
    assert _motion_plane(joint_positions(ROBOT, TRAJ.sample(t).q)) == [0, 1]
    pendulum = load_robot(str(example_robot_urdf("double_pendulum_description/urdf/double_pendulum.urdf")))
    assert _motion_plane(joint_positions(pendulum, default_trajectory(pendulum).sample(t).q)) == [1, 2]

    check = check_torques(robot, trajectory, samples=101)
    fig = _trajectory_figures(robot, trajectory, check, samples=201)["workspace"]
    view, top, side = _axes(fig, "workspace"), _axes(fig, "path"), _axes(fig, "path-side")
    assert view.name == "3d" and "3-D" in fig.get_suptitle()
    arms = [ln for ln in view.get_lines() if ln.get_color() == "tab:blue"]
    via = joint_positions(robot, trajectory.via_q)
    assert len(arms) == len(via)
    for line, arm in zip(arms, via):
        np.testing.assert_allclose(np.column_stack(line.get_data_3d()), arm, rtol=0, atol=0)
    ee = points[:, -1]
    path = _line(top, "end-effector path")
    np.testing.assert_allclose(np.column_stack([path.get_xdata(), path.get_ydata()]), ee[:, :2], atol=0)
    assert (top.get_xlabel(), top.get_ylabel()) == ("x [m]", "y [m]")
    assert side.get_xlabel() in ("x [m]", "y [m]") and side.get_ylabel() == "z [m]"
    np.testing.assert_allclose(_line(side, "end-effector path").get_ydata(), ee[:, 2], atol=0)
    labels = [text.get_text() for text in top.texts]
    for x, y, z in via[:, -1]:
        assert any(f"({x:.2f}, {y:.2f}, {z:.2f}) m" in s for s in labels), labels
    assert fig.get_size_inches().tolist() == list(_style.WORKSPACE_3D_FIGSIZE)


# ---------------------------------------------------------------------- saving


def test_save_simulation_figures_sizes_and_no_leftovers(
    tmp_path: Path, pd: SimulationResult, pd_figures: dict[str, Figure]
) -> None:
    """Files are <controller>_<suffix>.png by default, at figsize × DPI, not blank, and
    nothing else (no temporary file) is left in the directory."""
    sizes = {k: tuple(f.get_size_inches()) for k, f in pd_figures.items()}
    assert sizes["theta1"] == _style.STATE_FIGSIZE and sizes["torque"] == _style.SIM_TORQUE_FIGSIZE
    paths = plotting.save_simulation_figures(pd, tmp_path / "a")
    assert [p.name for p in paths] == [f"pd_{k}.png" for k in RUN_SUFFIXES]
    for path, key in zip(paths, RUN_SUFFIXES):
        _assert_png(path, sizes[key])
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == sorted(p.name for p in paths)


def test_custom_prefix_and_every_friction_figure(
    tmp_path: Path, friction: SimulationResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A given prefix replaces the controller's name (the default, see the test above),
    every figure of an adaptive-friction run is saved, and the friction figure decodes."""
    written: list[str] = []
    real_save = _save.save_figure

    def record(fig: Figure, path: Path) -> Path:
        written.append(path.name)
        return real_save(fig, path) if path.name.endswith("friction_error.png") else path

    monkeypatch.setattr(_save, "save_figure", record)
    suffixes = [*RUN_SUFFIXES, "param_error", "friction_error"]
    paths = plotting.save_simulation_figures(friction, tmp_path, prefix="run7")
    assert written == [p.name for p in paths] == [f"run7_{k}.png" for k in suffixes]
    figure = _simulation_figures(friction)["friction_error"]
    _assert_png(tmp_path / "run7_friction_error.png", tuple(figure.get_size_inches()))


# -------------------------------------------------------------------- distribution


def test_distribution_figure_histograms(tmp_path: Path) -> None:
    """One histogram per metric whose counts add up to the finite values; the title counts
    the non-finite ones; the PNG has the figure's pixel size; the input is left as it was."""
    rng = np.random.default_rng(0)
    a = rng.normal(size=200)
    a[:3] = np.nan
    a.setflags(write=False)
    rows = {"RMS e1 [rad]": a, "RMS e2 [rad]": rng.lognormal(size=50), "peak τ1 [N·m]": np.full(10, 3.0)}
    fig = _distribution_figure(rows)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 3
    heights = sum(p.get_height() for p in visible[0].patches)
    assert heights == 197
    assert "3 non-finite" in visible[0].get_title()
    assert sum(p.get_height() for p in visible[2].patches) == 10
    assert visible[2].get_xlabel() == "peak τ1 [N·m]"
    path = plotting.save_distribution_figure(rows, tmp_path / "mc" / "dist.png")
    assert path == tmp_path / "mc" / "dist.png"
    _assert_png(path, tuple(fig.get_size_inches()))
    assert int(np.isnan(a).sum()) == 3


def test_distribution_figure_of_values_equal_but_for_rounding(tmp_path: Path) -> None:
    """A metric equal in every run but for the last bits (a UR5 sweep's peak torque: numpy's
    "auto" bins cannot cut a range of 1e-14 at 150 and raised): one bin holding every run;
    a tiny but real spread still gets numpy's bins."""
    rows = {
        "peak τ1 [N·m]": 150.0 + np.array([0.0, 2.8e-14, 5.7e-14, 0.0]),
        "RMS e1 [rad]": 1e-7 * np.array([1.0, 1.1, 1.3, 1.2]),
    }
    fig = _distribution_figure(rows)
    rounding, tiny = (ax for ax in fig.axes if ax.get_visible())
    assert len(rounding.patches) == 1 and rounding.patches[0].get_height() == 4
    assert len(tiny.patches) > 1 and sum(p.get_height() for p in tiny.patches) == 4
    _assert_png(plotting.save_distribution_figure(rows, tmp_path / "d.png"), tuple(fig.get_size_inches()))


def test_distribution_figure_rejects_empty_input(tmp_path: Path) -> None:
    with pytest.raises(InvalidParameterError, match="at least one metric"):
        plotting.save_distribution_figure({}, tmp_path / "x.png")
    with pytest.raises(InvalidParameterError, match=r"rows\['bad'\].*at least one finite value"):
        plotting.save_distribution_figure({"bad": np.array([np.nan, np.inf])}, tmp_path / "x.png")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------- atomicity and leaks


def test_failed_write_keeps_the_old_file_and_leaves_no_temp(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A render that fails midway leaves the previous file intact and no temporary file."""
    target = tmp_path / "dist.png"
    target.write_bytes(b"previous")

    def broken_savefig(self: Figure, f, **kwargs) -> None:  # type: ignore[no-untyped-def]
        f.write(b"\x89PNG partial")
        raise RuntimeError("disk full")

    def broken_imsave(f, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        f.write(b"\x89PNG partial")
        raise RuntimeError("disk full")

    monkeypatch.setattr(Figure, "savefig", broken_savefig)  # SVG, PDF
    monkeypatch.setattr(matplotlib.image, "imsave", broken_imsave)  # a PNG: the drawn canvas's pixels
    with pytest.raises(RuntimeError, match="disk full"):
        plotting.save_distribution_figure({"x": np.arange(5.0)}, target)
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == ["dist.png"]


def test_output_directory_that_is_a_file_is_reported(tmp_path: Path, pd: SimulationResult) -> None:
    """A file where the output folder should go is an OutputError naming a path under it
    (the wording is twolink_pin.files'), and the file is left as it was."""
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError) as caught:
        plotting.save_simulation_figures(pd, blocker / "figs")
    assert caught.value.path.startswith(str(blocker))
    assert blocker.read_text() == "x"


def test_figures_are_freed_after_saving(
    tmp_path: Path, check: TorqueCheck, pd: SimulationResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No figure survives a save (no pyplot registry, nothing cached)."""
    refs: list[weakref.ref[Figure]] = []
    monkeypatch.setattr(_save, "save_figure", lambda fig, path: refs.append(weakref.ref(fig)) or path)
    plotting.save_trajectory_figures(ROBOT, TRAJ, check, tmp_path)
    plotting.save_simulation_figures(pd, tmp_path)
    gc.collect()
    assert len(refs) == 4 + 5
    assert all(ref() is None for ref in refs)


def test_no_pyplot_and_only_the_public_names() -> None:
    """Building and saving figures never imports pyplot (checked in a fresh interpreter),
    and the package exports exactly its seven save functions (no report tables)."""
    code = (
        "import sys, tempfile, numpy as np\n"
        "import twolink_pin.plotting as p\n"
        "p.save_distribution_figure({'x [m]': np.arange(5.0)}, tempfile.mkdtemp() + '/d.png')\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert sorted(plotting.__all__) == [
        "save_distribution_figure",
        "save_end_effector_figure",
        "save_limits_figure",
        "save_simulation_figures",
        "save_task_error_figure",
        "save_trajectory_figures",
        "save_velocity_limits_figure",
    ]
    assert not hasattr(plotting, "REPORT_FIGURES") and not hasattr(plotting, "CONTROLLER_TITLES")
