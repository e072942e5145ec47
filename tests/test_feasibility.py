"""Tests of twolink_pin.feasibility: the desired torques along the report's trajectory,
their peaks and margins against the motor limits (the report's Figure 6 check).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.feasibility import TorqueCheck, check_torques
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.trajectory import JointTrajectory, build_trajectory
from twolink_pin.twolink import closed_form

ROBOT: RobotModel = load_robot()
TRAJ: JointTrajectory = build_trajectory(ROBOT)


@pytest.fixture(scope="module")
def check() -> TorqueCheck:
    return check_torques(ROBOT, TRAJ)


def test_torques_and_peaks_equal_closed_form(check: TorqueCheck) -> None:
    """τ(t) from RNEA equals the report's closed form M(q) q̈ + C(q, q̇) q̇ at every sample,
    and the peaks |τ_i| and their times equal those of the closed-form torques."""
    ref = TRAJ.sample(check.t)
    p = np.asarray(ROBOT.p)
    tau = np.array(
        [
            closed_form.mass_matrix(q, p) @ a + closed_form.coriolis_matrix(q, v, p) @ v
            for q, v, a in zip(ref.q, ref.v, ref.a)
        ]
    )
    np.testing.assert_allclose(check.tau, tau, rtol=0, atol=1e-10)
    idx = np.argmax(np.abs(tau), axis=0)
    np.testing.assert_allclose(check.peak, np.abs(tau[idx, [0, 1]]), rtol=0, atol=1e-10)
    np.testing.assert_allclose(check.peak_time, check.t[idx], rtol=0, atol=0)


def test_samples_cover_one_period(check: TorqueCheck) -> None:
    """The default 4001 samples span one 4 s period, both ends included."""
    assert check.t.shape == (4001,) and check.tau.shape == (4001, 2)
    np.testing.assert_allclose([check.t[0], check.t[-1]], [0.0, 4.0], rtol=0, atol=0)


def test_report_trajectory_is_within_limits(check: TorqueCheck) -> None:
    """The report's trajectory needs at most 4.09 N·m at the base (limit 240) and 1.12 N·m
    at the elbow (limit 40): within limits, margins limit − peak positive."""
    assert check.within_limits is True
    np.testing.assert_allclose(check.limits, [240.0, 40.0], rtol=0, atol=0)
    np.testing.assert_allclose(check.peak, [4.0933, 1.1245], rtol=0, atol=1e-4)
    np.testing.assert_allclose(check.margin, check.limits - check.peak, rtol=0, atol=0)
    assert np.all(check.margin > 0)


def test_small_limits_are_not_within_limits(check: TorqueCheck) -> None:
    """With 1 N·m motors the same trajectory is infeasible: within_limits False and each
    margin negative (1 − peak)."""
    weak = dataclasses.replace(ROBOT, torque_limits=np.array([1.0, 1.0]))
    weak_check = check_torques(weak, TRAJ)
    assert weak_check.within_limits is False
    np.testing.assert_allclose(weak_check.peak, check.peak, rtol=0, atol=0)
    np.testing.assert_allclose(weak_check.margin, 1.0 - check.peak, rtol=0, atol=1e-15)
    assert np.all(weak_check.margin < 0)


def test_one_joint_over_its_limit_is_enough_to_fail(check: TorqueCheck) -> None:
    """A limit just below one joint's peak makes the check fail, only that margin negative."""
    limits = np.array([240.0, check.peak[1] - 1e-6])
    result = check_torques(dataclasses.replace(ROBOT, torque_limits=limits), TRAJ)
    assert result.within_limits is False
    assert result.margin[0] > 0 > result.margin[1]


def test_verdict_text_feasible(check: TorqueCheck) -> None:
    """The verdict names the tightest joint (largest peak / limit): the elbow, 2.8 % of 40 N·m."""
    j = 1
    assert check.peak[1] / 40.0 > check.peak[0] / 240.0
    assert check.verdict() == (
        f"FEASIBLE: peak |tau{j + 1}| = {check.peak[j]:.2f} N·m at t = {check.peak_time[j]:.3f} s "
        f"is {100 * check.peak[j] / check.limits[j]:.1f}% of its 40 N·m limit"
    )
    assert check.verdict().startswith("FEASIBLE: peak |tau2| = 1.12 N·m at t = ")
    assert check.verdict().endswith(" s is 2.8% of its 40 N·m limit")


def test_verdict_text_not_feasible() -> None:
    """With 1 N·m motors the verdict says NOT FEASIBLE and names the base joint at 409 %."""
    weak = check_torques(dataclasses.replace(ROBOT, torque_limits=np.array([1.0, 1.0])), TRAJ)
    assert weak.verdict().startswith("NOT FEASIBLE: peak |tau1| = 4.09 N·m at t = ")
    assert weak.verdict().endswith(" s is 409.3% of its 1 N·m limit")


@pytest.mark.parametrize("samples", [1, 0, 2.5])
def test_bad_sample_count_raises(samples: object) -> None:
    """samples must be an integer >= 2; the message names the value."""
    with pytest.raises(
        InvalidParameterError, match=rf"^samples = {samples!r} is invalid: expected an integer >= 2$"
    ):
        check_torques(ROBOT, TRAJ, samples=samples)  # type: ignore[arg-type]
