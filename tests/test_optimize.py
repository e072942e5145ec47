"""Optimal trajectories through via points, checked independently of the optimiser: ∫τᵀτ by
pin.rnea and the trapezoid on a fine grid, the limits on a grid finer than the optimiser's,
the via points (and poses, by forward kinematics) from the saved file read back."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.errors import InvalidParameterError, OptimizationError
from twolink_pin.limits import joint_limits
from twolink_pin.model import catalog, load_robot
from twolink_pin.trajectory import (
    JointTrajectory,
    default_trajectory,
    optimize,
    read_trajectory_file,
    time_optimal,
    write_trajectory_file,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LIMIT_TOLERANCE = 1e-9
"""How far beyond a limit (a fraction of it) the motion may go on the test's grid: 40 points
per spline piece, 10× the 4 the optimiser constrains (it checks 100 and keeps 1e-5 free)."""
TEST_GRID = 40
"""Points per spline piece (sample interval) of the test's grid."""


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


@pytest.fixture(scope="module")
def least_effort(twolink):
    return optimize(twolink, default_trajectory(twolink), "effort")


def effort(robot, trajectory, samples: int = 40001) -> float:
    """∫τᵀτ dt over one period: pin.rnea on ``samples`` instants, the trapezoid."""
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, samples)
    ref = trajectory.sample(t)
    data = robot.model.createData()
    tau = np.array([pin.rnea(robot.model, data, q, v, a) for q, v, a in zip(ref.q, ref.v, ref.a)])
    return float(np.trapezoid((tau**2).sum(axis=1), t))


def worst_excess(robot, trajectory, per_interval: int = TEST_GRID) -> float:
    """The largest |q̇|/limit − 1, |τ|/limit − 1 and position excess (a fraction of the range)
    on ``per_interval`` points per sample interval, τ by pin.rnea."""
    limits = joint_limits(robot)
    _, sample = trajectory.dense(per_interval)
    data = robot.model.createData()
    tau = np.array([pin.rnea(robot.model, data, q, v, a) for q, v, a in zip(sample.q, sample.v, sample.a)])
    with np.errstate(invalid="ignore"):
        parts = [
            np.abs(sample.v) / limits.velocity - 1.0,
            np.abs(tau) / limits.effort - 1.0,
            (sample.q - limits.position_upper) / (limits.position_upper - limits.position_lower),
            (limits.position_lower - sample.q) / (limits.position_upper - limits.position_lower),
        ]
    return float(max(np.nanmax(np.where(np.isfinite(p), p, -np.inf)) for p in parts))


def test_least_effort_beats_the_course_polynomial_with_the_same_via_times(twolink, least_effort) -> None:
    """∫τᵀτ dt of the result ≤ the report's polynomial's, both recomputed here (RNEA, trapezoid
    on 40 001 instants), the result's over the same 4 s."""
    reference = default_trajectory(twolink)
    assert least_effort.trajectory.period == pytest.approx(reference.period)
    mine, theirs = effort(twolink, least_effort.trajectory), effort(twolink, reference)
    assert mine <= theirs
    assert mine == pytest.approx(least_effort.effort, rel=1e-4)


def test_least_effort_keeps_every_limit_on_a_grid_finer_than_its_own(twolink, least_effort) -> None:
    assert worst_excess(twolink, least_effort.trajectory) <= LIMIT_TOLERANCE
    assert least_effort.max_violation is not None and least_effort.max_violation <= 0


def test_the_saved_file_passes_each_via_point_within_1e_6_rad(tmp_path, twolink, least_effort) -> None:
    """The via points measured from the file written (and read back by read_trajectory_file),
    at the reference's via times; its feedforward torque is RNEA's at its samples."""
    write_trajectory_file(tmp_path / "optimal.toml", least_effort.trajectory)
    back = read_trajectory_file(tmp_path / "optimal.toml", twolink)
    reference = default_trajectory(twolink)
    q = back.sample(reference.times).q
    assert np.abs(q - reference.via_q).max() <= 1e-6
    data = twolink.model.createData()
    rnea = np.array([pin.rnea(twolink.model, data, *z) for z in zip(back.q, back.v, back.a)])
    np.testing.assert_allclose(back.tau, rnea, atol=1e-9)


def test_the_time_cost_is_no_longer_than_the_retiming_and_keeps_the_limits(twolink) -> None:
    reference = default_trajectory(twolink)
    fastest = optimize(twolink, reference, "time")
    retimed = time_optimal(twolink, reference)
    assert fastest.duration <= retimed.duration
    q = fastest.trajectory.sample(fastest.trajectory.via_times).q
    assert np.abs(q - reference.via_q).max() <= 1e-6
    assert worst_excess(twolink, fastest.trajectory) <= LIMIT_TOLERANCE


def test_via_poses_are_met_to_1e_6_by_forward_kinematics(tmp_path) -> None:
    """The UR5 through the four via poses of examples/ur5_square_pose.toml: after their IK the
    joint via points are kept exactly, and the saved file's end effector at the via times is
    at each pose to 1e-6 m and 1e-6 rad."""
    ur5 = load_robot("ur5")
    source = read_trajectory_file(EXAMPLES / "ur5_square_pose.toml", ur5)
    result = optimize(ur5, source, "effort")
    write_trajectory_file(tmp_path / "ur5.json", result.trajectory)
    back = read_trajectory_file(tmp_path / "ur5.json", ur5)
    data = ur5.model.createData()
    for q, p, R in zip(back.sample(source.times).q, source.positions, source.rotations, strict=True):
        pin.framesForwardKinematics(ur5.model, data, q)
        frame = data.oMf[ur5.ee_frame_id]
        assert np.linalg.norm(frame.translation - p) <= 1e-6
        assert np.linalg.norm(pin.log3(R.T @ frame.rotation)) <= 1e-6
    assert effort(ur5, back) <= effort(ur5, source)
    assert worst_excess(ur5, back) <= LIMIT_TOLERANCE


@pytest.mark.parametrize("name", [n for n in catalog.names() if n not in ("twolink", "ur5")])
def test_every_catalog_arm_gets_its_least_effort_trajectory(name: str) -> None:
    """Each arm's default reference: through its via points, within its limits, with no more
    effort than the reference (a cheap smoke run per arm)."""
    robot = load_robot(name)
    reference = default_trajectory(robot)
    result = optimize(robot, reference, "effort")
    assert isinstance(reference, JointTrajectory)
    assert np.abs(result.trajectory.sample(reference.times).q - reference.via_q).max() <= 1e-6
    assert result.effort <= result.reference_effort
    assert result.max_violation is None or result.max_violation <= 0


def test_bad_via_points_and_costs_are_refused_naming_what(twolink) -> None:
    """A via point beyond a joint's range, gravity beyond an effort limit at a via point, a
    reference without via points, an unknown cost: one message each, naming joint and limit."""
    outside = JointTrajectory.from_via_q((0.0, 1.0, 2.0), np.array([[0.0, 0.0], [3.5, 0.0], [0.0, 0.0]]))
    with pytest.raises(
        InvalidParameterError, match=r"via point 1, joint 1 \(joint1\).*range \[-3.14159, 3.14159\]"
    ):
        optimize(twolink, outside)
    ur5 = load_robot("ur5")
    limits = joint_limits(ur5)
    weak = type(limits)(
        limits.joint_names, limits.position_lower, limits.position_upper, limits.velocity, limits.acceleration,
        limits.effort * 0.1,
    )  # fmt: skip
    with pytest.raises(
        InvalidParameterError, match=r"effort limit of joint 3 \(elbow_joint\).*via point 0.*even at rest"
    ):
        optimize(ur5, default_trajectory(ur5), limits=weak)
    from twolink_pin.identification import excitation_trajectory

    with pytest.raises(InvalidParameterError, match="through via points"):
        optimize(twolink, excitation_trajectory(twolink))
    with pytest.raises(InvalidParameterError, match="one of effort, time"):
        optimize(twolink, default_trajectory(twolink), "speed")


def test_a_solver_that_does_not_converge_says_so(twolink) -> None:
    """One SQP iteration cannot reach the minimum: OptimizationError (exit 1) that says what
    did not converge — the cost, not the constraints, which hold — by how much (what the last
    step gained, what the model sees left, against the tolerance), and what to try (issue 45:
    "no convergence … violation 1.19e-09 (tolerance 1e-06)" read as a constraint failing)."""
    with pytest.raises(OptimizationError) as caught:
        optimize(twolink, default_trajectory(twolink), max_iterations=1)
    message = str(caught.value)
    assert re.search(
        r"the cost did not settle in 1 SQP iterations: the last accepted step lowered the cost by "
        r"\S+ of its starting value and the model sees \S+ more \(tolerance 1e-05\)",
        message,
    ), message
    assert (
        "the constraints hold (largest violation" in message
        and "try more iterations (--max-iterations" in message
    )
    left = float(re.search(r"the model sees (\S+) more", message).group(1))
    assert left > 1e-5  # really not settled: more than the tolerance left
