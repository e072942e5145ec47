"""excite's verdict on an optimised excitation (infeasible or motionless is a failure) and
its bound on work, checked on hand-made peaks against limits."""

from __future__ import annotations

import math

import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.identification.excitation_check import (
    MAX_EXCITATION_WORK,
    check_excitation_work,
    excitation_problem,
    excitation_work,
)

LIMITS = {
    "lower": [-2.0, -2.0],
    "upper": [2.0, 2.0],
    "velocity": [5.0, 5.0],
    "acceleration": [10.0, 10.0],
    "torque": [192.0, math.inf],
}


def peaks(**change: list[float]) -> dict[str, list[float]]:
    base = {
        "q_min": [-1.0, -1.0],
        "q_max": [1.0, 1.0],
        "v_max": [2.0, 2.0],
        "a_max": [3.0, 3.0],
        "tau_max": [7.0, 1e6],
    }
    return base | change


def test_within_limits_is_usable_and_no_torque_limit_bounds_nothing() -> None:
    assert excitation_problem(peaks(), LIMITS) is None


def test_the_issue_s_peak_torque_is_a_failure_naming_joint_and_value() -> None:
    problem = excitation_problem(peaks(tau_max=[1.7e17, 1.0]), LIMITS)
    assert problem is not None and "joint 1" in problem and "1.7e+17" in problem and "192" in problem


def test_a_position_beyond_the_range_and_a_non_finite_peak_are_failures() -> None:
    assert "joint 2" in str(excitation_problem(peaks(q_max=[1.0, 2.5]), LIMITS))
    assert "speed of joint 1" in str(excitation_problem(peaks(v_max=[math.nan, 1.0]), LIMITS))


def test_a_joint_that_does_not_move_is_a_failure() -> None:
    problem = excitation_problem(peaks(v_max=[2.0, 0.0]), LIMITS)
    assert problem is not None and "joint 2" in problem and "not move" in problem


def test_work_is_the_product_and_is_bounded() -> None:
    # default design of a 2-joint arm: 3 starts x 200 iterations x 100 samples x 2 (2 * 5 + 1) unknowns
    assert excitation_work(2, 5, 100, 3, 200) == 3 * 200 * 100 * 22
    check_excitation_work(2, 5, 100, 3, 200)
    with pytest.raises(InvalidParameterError, match=r"1\.1e\+13"):
        check_excitation_work(2, 5, 100_000, 50, 100_000)
    assert excitation_work(2, 5, 100_000, 50, 100_000) > MAX_EXCITATION_WORK
