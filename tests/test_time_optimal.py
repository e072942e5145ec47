"""Time-optimal retiming (TOPP-RA) and the sampled trajectory it returns, checked against
Pinocchio's RNEA on grids finer than the ones the retiming used, exact polynomials, and the
saved file read back."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from numpy.polynomial import polynomial as P

from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import joint_limits
from twolink_pin.model import load_robot
from twolink_pin.trajectory import (
    JointTrajectory,
    SampledTrajectory,
    default_trajectory,
    read_trajectory_file,
    time_optimal,
    write_trajectory_file,
)

TORQUE_TOLERANCE = 1e-9
"""How far beyond a limit (a fraction of it) the recomputed motion may go between the retiming's
check points: the check grid has 10 points per sample interval, this test 100."""


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


@pytest.fixture(scope="module")
def retimed(twolink):
    return time_optimal(twolink, default_trajectory(twolink))


def _rnea(robot, q, v, a):
    data = robot.model.createData()
    return np.array([pin.rnea(robot.model, data, x, y, z) for x, y, z in zip(q, v, a)])


def _worst(robot, sample, limits) -> float:
    """The largest |q̇|/limit, |τ|/limit over a motion (τ by pin.rnea)."""
    tau = _rnea(robot, sample.q, sample.v, sample.a)
    return max(float((np.abs(sample.v) / limits.velocity).max()), float((np.abs(tau) / limits.effort).max()))


def test_the_retimed_report_path_is_faster_and_within_every_limit_on_a_finer_grid(twolink, retimed) -> None:
    """The report's path, retimed: far shorter than its 4 s, and pin.rnea on 100 points per
    sample interval (10× the retiming's own check) keeps |τ| and |q̇| within their limits."""
    assert retimed.duration < 0.6 < default_trajectory(twolink).period
    _, sample = retimed.trajectory.dense(100)
    assert _worst(twolink, sample, joint_limits(twolink)) <= 1.0 + TORQUE_TOLERANCE


def test_a_limit_is_active_the_motion_scaled_to_099_of_its_duration_exceeds_one(twolink, retimed) -> None:
    """Time-optimal: played 1 % faster (q̇ / 0.99, q̈ / 0.99²), the same path needs more than
    some limit allows."""
    _, sample = retimed.trajectory.dense(20)
    faster = sample._replace(v=sample.v / 0.99, a=sample.a / 0.99**2)
    assert _worst(twolink, faster, joint_limits(twolink)) > 1.0
    assert retimed.active  # and the result names where


def test_the_retiming_keeps_the_path_and_passes_the_via_points_at_its_via_times(twolink, retimed) -> None:
    """At the retimed via times the motion is at the reference's via points (to the samples'
    interpolation); between them it traces the reference's path (every retimed q lies on it)."""
    reference = default_trajectory(twolink)
    q = retimed.trajectory.sample(retimed.trajectory.via_times).q
    assert np.abs(q - reference.via_q).max() < 1e-6
    path = reference.sample(np.linspace(0.0, reference.period, 40001)).q
    _, sample = retimed.trajectory.dense(3)
    distance = np.min(np.linalg.norm(sample.q[:, None, :] - path[None, ::20, :], axis=2), axis=1)
    assert distance.max() < 2e-3  # the reference path sampled every 2 ms: its chords' sagitta


def test_the_saved_retiming_reads_back_as_the_same_motion(tmp_path, twolink, retimed) -> None:
    """--save's file (JSON and TOML) read by read_trajectory_file: the same samples, torque and
    via times; a repeated time keeps its acceleration jump."""
    for name in ("retimed.json", "retimed.toml"):
        write_trajectory_file(tmp_path / name, retimed.trajectory)
        back = read_trajectory_file(tmp_path / name, twolink)
        assert isinstance(back, SampledTrajectory)
        for field in ("times", "q", "v", "a", "tau", "via_times"):
            np.testing.assert_array_equal(getattr(back, field), getattr(retimed.trajectory, field))
    assert np.any(np.diff(back.times) == 0)


def test_headroom_and_friction_lengthen_the_retiming(twolink, retimed) -> None:
    """Half of each limit takes longer; the plant's friction, which the torque must also
    overcome, takes no less, and its torque (RNEA + friction) stays within the limits."""
    reference = default_trajectory(twolink)
    half = time_optimal(twolink, reference, limit_scale=0.5)
    assert half.duration > 1.2 * retimed.duration
    friction = Friction((2.0, 1.0), (3.0, 1.5))
    rubbed = time_optimal(twolink, reference, friction=friction)
    assert rubbed.duration >= retimed.duration
    _, sample = rubbed.trajectory.dense(30)
    tau = _rnea(twolink, sample.q, sample.v, sample.a) + friction.torque(sample.v)
    assert (np.abs(tau) / joint_limits(twolink).effort).max() <= 1.0 + TORQUE_TOLERANCE


def test_a_retiming_needs_velocity_limits_and_a_scale_in_zero_one() -> None:
    """The double pendulum's URDF has no velocity limits: refused, naming the joint."""
    pendulum = load_robot("double_pendulum")
    with pytest.raises(InvalidParameterError, match="velocity limit of joint 'joint1'"):
        time_optimal(pendulum, default_trajectory(pendulum))
    twolink = load_robot("twolink")
    for scale in (0.0, -0.5, 1.5, math.nan):
        with pytest.raises(InvalidParameterError, match="limit scale"):
            time_optimal(twolink, default_trajectory(twolink), limit_scale=scale)


def test_a_path_that_gravity_alone_overloads_at_rest_is_refused_naming_the_joint() -> None:
    """The UR5 at a tenth of its effort limits cannot even hold its start against gravity."""
    ur5 = load_robot("ur5")
    limits = joint_limits(ur5)
    weak = type(limits)(
        limits.joint_names, limits.position_lower, limits.position_upper, limits.velocity, limits.acceleration,
        limits.effort * 0.1,
    )  # fmt: skip
    with pytest.raises(
        InvalidParameterError,
        match=r"effort limit of joint 3 \(elbow_joint\).*gravity needs at rest.*even at rest",
    ):
        time_optimal(ur5, default_trajectory(ur5), limits=weak)


# -- the sampled trajectory -------------------------------------------------------------------


def test_quintic_hermite_samples_reproduce_a_quintic_exactly() -> None:
    """Samples of a periodic quintic-per-piece motion (a closed polynomial) at a few times: q,
    q̇, q̈ and the jerk between them equal the polynomial's."""
    rng = np.random.default_rng(0)
    c = rng.normal(size=(6, 2))
    t = np.array([0.0, 0.3, 0.7, 1.2, 2.0])
    derivative = [c]
    for _ in range(3):
        derivative.append(P.polyder(derivative[-1]))
    rows = [P.polyval(t, d).T for d in derivative]
    rows[0][-1], rows[1][-1] = rows[0][0], rows[1][0]  # closes (only the last sample is moved)
    traj = SampledTrajectory(t, rows[0], rows[1], rows[2])
    s = np.linspace(0.0, 1.19, 60)  # the pieces before the moved sample
    sample = traj.sample(s)
    for got, d in zip(sample, derivative, strict=True):
        np.testing.assert_allclose(got, P.polyval(s, d).T, atol=1e-9)


def test_a_sampled_trajectory_refuses_what_cannot_repeat() -> None:
    t = np.array([0.0, 1.0, 2.0])
    q = np.array([[0.0], [1.0], [0.5]])
    with pytest.raises(InvalidParameterError, match="repeats every period"):
        SampledTrajectory(t, q, np.zeros((3, 1)), np.zeros((3, 1)))
    with pytest.raises(InvalidParameterError, match="at most twice"):
        SampledTrajectory(np.array([0.0, 0.0, 1.0]), np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((3, 1)))
    with pytest.raises(InvalidParameterError, match=r"only the\s+acceleration may jump"):
        SampledTrajectory(
            np.array([0.0, 1.0, 1.0, 2.0]),
            np.array([[0.0], [1.0], [1.1], [0.0]]),
            np.zeros((4, 1)),
            np.zeros((4, 1)),
        )


def test_a_joint_trajectory_round_trip_through_a_retiming_keeps_its_period_contract(twolink, retimed) -> None:
    """The engine's periodic contract: the retimed reference repeats from rest to rest, with
    period = duration (sampled one period later, the same motion)."""
    traj = retimed.trajectory
    t = np.linspace(0.0, traj.period, 37)[:-1]
    a, b = traj.sample(t), traj.sample(t + traj.period)
    np.testing.assert_allclose(a.q, b.q, atol=1e-12)
    np.testing.assert_allclose(traj.sample(0.0).v, 0.0, atol=1e-12)
    assert isinstance(default_trajectory(twolink), JointTrajectory)


def test_reading_a_samples_file_rechecks_the_position_range(tmp_path, twolink, retimed) -> None:
    """A saved retiming edited to carry joint 1 past its range is refused when read, naming the
    joint and its limits, as every trajectory file is."""
    import json

    write_trajectory_file(tmp_path / "fast.json", retimed.trajectory)
    document = json.loads((tmp_path / "fast.json").read_text())
    document["samples"]["q"][5][0] = 3.5
    (tmp_path / "edited.json").write_text(json.dumps(document))
    with pytest.raises(
        InvalidParameterError, match=r"samples\.q\[5\]\[0\].*joint 1 \(joint1\) within its limits"
    ):
        read_trajectory_file(tmp_path / "edited.json", twolink)
