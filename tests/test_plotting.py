"""Tests of twolink_pin.plotting: the figures show the data they are given (lines equal
the trajectory, the run's errors, torques and estimates; limit lines at the motor limits),
the PNGs have the stated pixel size and are not blank, every write is atomic, and no
figure outlives its save.

Simulations are short (2 s) so the module runs in seconds.
"""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.image import imread
from matplotlib.lines import Line2D

from twolink_pin import plotting
from twolink_pin.errors import InvalidParameterError, OutputError
from twolink_pin.feasibility import TorqueCheck, check_torques
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.scenarios import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import JointTrajectory, build_trajectory
from twolink_pin.twolink import closed_form

ROBOT: RobotModel = load_robot()
TRAJ: JointTrajectory = build_trajectory(ROBOT)
LIMITS = (240.0, 40.0)
TRAJECTORY_FILES = ["fig03_theta1.png", "fig04_theta2.png", "fig05_workspace.png", "fig06_desired_torque.png"]
RUN_SUFFIXES = ["theta1", "theta2", "theta1dot", "theta2dot", "torque"]


def _run(name: str, duration: float = 2.0, saturate: bool = False) -> SimulationResult:
    controller, plant = make_scenario(name, ROBOT, saturate=saturate)
    return simulate(controller, plant, TRAJ, SimulationConfig(duration=duration))


@pytest.fixture(scope="module")
def check() -> TorqueCheck:
    return check_torques(ROBOT, TRAJ, samples=801)


@pytest.fixture(scope="module")
def trajectory_figures(check: TorqueCheck) -> dict[str, Figure]:
    return plotting._trajectory_figures(ROBOT, TRAJ, check)


@pytest.fixture(scope="module")
def pd() -> SimulationResult:
    return _run("pd")


@pytest.fixture(scope="module")
def pd_figures(pd: SimulationResult) -> dict[str, Figure]:
    return plotting._simulation_figures(pd)


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


def _limit_levels(ax) -> list[float]:  # type: ignore[no-untyped-def]
    """y of the dashed horizontal limit lines of an axes."""
    levels = []
    for ln in ax.get_lines():
        y = np.asarray(ln.get_ydata(), dtype=float)
        if ln.get_linestyle() == "--" and ln.get_color() == plotting.LIMIT_COLOR and np.ptp(y) == 0:
            levels.append(float(y[0]))
    return sorted(levels)


def _assert_png(path: Path, figsize: tuple[float, float]) -> None:
    """The PNG's pixel size is figsize × DPI and it is not a blank canvas."""
    image = imread(path)
    w, h = figsize
    assert image.shape[:2] == (round(h * plotting.DPI), round(w * plotting.DPI)), path.name
    gray = image[..., :3].mean(axis=2)
    assert gray.std() > 0.05, f"{path.name} looks blank (std {gray.std():.4f})"
    assert (gray < 0.5).mean() > 0.005, f"{path.name} has almost no dark pixels (no text or lines)"


# --------------------------------------------------------------------- trajectory


def test_trajectory_figures_written_with_size_and_content(
    tmp_path: Path, check: TorqueCheck, trajectory_figures: dict[str, Figure]
) -> None:
    """Figures 3–6 land in a new nested directory, in order, at figsize × DPI pixels, not
    blank, and nothing else (no temporary file) is left in the directory."""
    out = tmp_path / "new" / "figs"
    sizes = {f"{k}.png": tuple(fig.get_size_inches()) for k, fig in trajectory_figures.items()}
    paths = plotting.save_trajectory_figures(ROBOT, TRAJ, check, out)
    assert [p.name for p in paths] == TRAJECTORY_FILES
    assert sorted(p.name for p in out.iterdir()) == sorted(TRAJECTORY_FILES)
    assert sizes["fig03_theta1.png"] == plotting.JOINT_FIGSIZE
    assert sizes["fig05_workspace.png"] == plotting.WORKSPACE_FIGSIZE
    for path in paths:
        _assert_png(path, sizes[path.name])


def test_joint_figure_plots_the_trajectory_and_its_via_points(trajectory_figures: dict[str, Figure]) -> None:
    """Each panel of Figure 3/4 is the trajectory's q, q̇, q̈, jerk over exactly one period,
    and the via-point markers sit at (times, via_q)."""
    for j, key in enumerate(("fig03_theta1", "fig04_theta2")):
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
    """The end-effector path equals the closed-form FK of the trajectory, the annulus
    circles have radii |L1 − L2| and L1 + L2, the axes are equal-aspect, and the via points
    are labelled with their times (the start and end point share one label)."""
    fig = trajectory_figures["fig05_workspace"]
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
        if ln.get_color() == "tab:green"
    )
    np.testing.assert_allclose(radii, [abs(l1 - l2), l1 + l2], rtol=0, atol=1e-12)
    assert full.get_aspect() == 1.0 and zoom.get_aspect() == 1.0
    labels = [text.get_text() for text in zoom.texts]
    assert any(s.startswith("t = 0, 4 s") for s in labels), labels
    for tv in ("1", "2", "3"):
        assert any(s.startswith(f"t = {tv} s") for s in labels), labels


def test_desired_torque_figure_data_limits_and_peaks(
    check: TorqueCheck, trajectory_figures: dict[str, Figure]
) -> None:
    """Figure 6 plots check.tau, dashed lines at ±240 and ±40 N·m, a marker at each peak,
    and (the peaks being a few % of the limits) a note that the limit is off scale."""
    fig = trajectory_figures["fig06_desired_torque"]
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


def test_trajectory_figures_reject_a_mismatched_trajectory(check: TorqueCheck) -> None:
    three = JointTrajectory.from_via_q((0.0, 1.0), np.zeros((2, 3)))
    with pytest.raises(InvalidParameterError, match="trajectory"):
        plotting._trajectory_figures(ROBOT, three, check)


# --------------------------------------------------------------------- simulation


def test_state_figures_plot_actual_desired_and_error(
    pd: SimulationResult, pd_figures: dict[str, Figure]
) -> None:
    """Position and velocity figures: top panel q (v) and q_d (v_d); both error panels hold
    e (ė) exactly; the log panel is the window-wise max |e|, so it bounds |e| from above
    and reaches max |e|."""
    figures = pd_figures
    assert list(figures) == RUN_SUFFIXES
    for j in range(2):
        for key, actual, desired, error in (
            (f"theta{j + 1}", pd.q, pd.q_des, pd.e),
            (f"theta{j + 1}dot", pd.v, pd.v_des, pd.edot),
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
            assert "pd" in fig.get_suptitle()


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


def test_saturated_run_shows_commanded_and_applied_torque() -> None:
    """With saturation the figure shows the commanded torque beside the applied (clipped)
    one and says the plant clipped it; without, it flags the excess as unsaturated."""
    sat = _run("adaptive", duration=0.3, saturate=True)
    assert sat.limit_exceeded[1], "the adaptive run's initial τ2 should exceed 40 N·m"
    ax = _axes(plotting._torque_figure(sat), "tau2")
    np.testing.assert_array_equal(_line(ax, "commanded").get_ydata(), sat.tau_command[:, 1])
    np.testing.assert_array_equal(_line(ax, "applied").get_ydata(), sat.tau[:, 1])
    assert np.abs(_line(ax, "applied").get_ydata()).max() <= 40.0
    assert any("clipped by the plant" in t.get_text() for t in ax.texts)
    free = _run("adaptive", duration=0.3)
    ax = _axes(plotting._torque_figure(free), "tau2")
    assert any("not saturated" in t.get_text() for t in ax.texts)


def test_parameter_figures_only_for_adaptive_runs(
    pd_figures: dict[str, Figure], adaptive: SimulationResult, friction: SimulationResult
) -> None:
    """pd has no parameter figure, adaptive has param_error only, adaptive-friction has both;
    the lines are p̂ − p (absolute) and 100 (p̂ − p)/p (relative)."""
    assert "param_error" not in pd_figures
    figs = plotting._simulation_figures(adaptive)
    assert list(figs) == [*RUN_SUFFIXES, "param_error"]
    assert adaptive.p_error is not None and adaptive.p_true is not None
    absolute = _axes(figs["param_error"], "absolute")
    for i in range(3):
        np.testing.assert_array_equal(absolute.get_lines()[i].get_ydata(), adaptive.p_error[:, i])
    relative = _axes(figs["param_error"], "relative")
    np.testing.assert_allclose(
        relative.get_lines()[0].get_ydata(), 100 * adaptive.p_error[:, 0] / adaptive.p_true[0], rtol=1e-12
    )
    figs = plotting._simulation_figures(friction)
    assert list(figs) == [*RUN_SUFFIXES, "param_error", "friction_error"]
    assert friction.p_error is not None
    names = list(friction.parameter_names)
    viscous = _axes(figs["friction_error"], "V")
    coulomb = _axes(figs["friction_error"], "C")
    for ax, group in ((viscous, ("V1", "V2")), (coulomb, ("C1", "C2"))):
        for line, name in zip(ax.get_lines(), group):
            np.testing.assert_array_equal(line.get_ydata(), friction.p_error[:, names.index(name)])
    assert len(_axes(figs["param_error"], "absolute").get_lines()) == 3 + 1  # p1..p3 and the zero line


def test_save_simulation_figures_sizes_and_no_leftovers(
    tmp_path: Path, pd: SimulationResult, pd_figures: dict[str, Figure]
) -> None:
    """Files are <controller>_<suffix>.png by default, at figsize × DPI, not blank, and
    nothing else (no temporary file) is left in the directory."""
    sizes = {k: tuple(f.get_size_inches()) for k, f in pd_figures.items()}
    assert sizes["theta1"] == plotting.STATE_FIGSIZE and sizes["torque"] == plotting.SIM_TORQUE_FIGSIZE
    paths = plotting.save_simulation_figures(pd, tmp_path / "a")
    assert [p.name for p in paths] == [f"pd_{k}.png" for k in RUN_SUFFIXES]
    for path, key in zip(paths, RUN_SUFFIXES):
        _assert_png(path, sizes[key])
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == sorted(p.name for p in paths)


def test_custom_prefix_and_every_friction_figure(
    tmp_path: Path, friction: SimulationResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A given prefix replaces the controller's name (the default, see the test above) and
    every figure of an adaptive-friction run is saved."""
    written: list[str] = []
    monkeypatch.setattr(plotting, "_save", lambda fig, path: written.append(path.name) or path)
    suffixes = [*RUN_SUFFIXES, "param_error", "friction_error"]
    paths = plotting.save_simulation_figures(friction, tmp_path, prefix="run7")
    assert written == [p.name for p in paths] == [f"run7_{k}.png" for k in suffixes]


# -------------------------------------------------------------------- distribution


def test_distribution_figure_histograms(tmp_path: Path) -> None:
    """One histogram per metric whose counts add up to the finite values; the title counts
    the non-finite ones; the PNG has the figure's pixel size."""
    rng = np.random.default_rng(0)
    a = rng.normal(size=200)
    a[:3] = np.nan
    rows = {"RMS e1 [rad]": a, "RMS e2 [rad]": rng.lognormal(size=50), "peak τ1 [N·m]": np.full(10, 3.0)}
    fig = plotting._distribution_figure(rows)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 3
    heights = sum(p.get_height() for p in visible[0].patches)
    assert heights == 197
    assert "3 non-finite" in visible[0].get_title()
    assert sum(p.get_height() for p in visible[2].patches) == 10
    path = plotting.save_distribution_figure(rows, tmp_path / "mc" / "dist.png")
    assert path == tmp_path / "mc" / "dist.png"
    _assert_png(path, tuple(fig.get_size_inches()))


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

    monkeypatch.setattr(Figure, "savefig", broken_savefig)
    with pytest.raises(RuntimeError, match="disk full"):
        plotting.save_distribution_figure({"x": np.arange(5.0)}, target)
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == ["dist.png"]


def test_output_directory_that_is_a_file_is_reported(tmp_path: Path, pd: SimulationResult) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="cannot create the directory"):
        plotting.save_simulation_figures(pd, blocker / "figs")


def test_figures_are_freed_after_saving(
    tmp_path: Path, check: TorqueCheck, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No figure survives a save (no pyplot registry, nothing cached)."""
    refs: list[weakref.ref[Figure]] = []
    monkeypatch.setattr(plotting, "_save", lambda fig, path: refs.append(weakref.ref(fig)) or path)
    plotting.save_trajectory_figures(ROBOT, TRAJ, check, tmp_path)
    gc.collect()
    assert len(refs) == 4
    assert all(ref() is None for ref in refs)
