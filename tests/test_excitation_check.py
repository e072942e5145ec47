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
    excitation_verdict,
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


def test_a_feasible_excitation_says_so_even_when_the_optimiser_stopped_at_its_limit() -> None:
    """The issue's case: every peak within limits, SLSQP at its iteration limit: the verdict
    says feasible (never "NOT converged to a feasible point") and names the closest limit:
    positions use 1 of their 2-rad half range (50 %), speeds 2 of 5 (40 %), accelerations 3 of
    10 (30 %), torque 7 of 192 (3.6 %)."""
    verdict = excitation_verdict(peaks(), LIMITS, False, "Iteration limit reached")
    assert verdict.startswith("feasible: every peak within its limit")
    assert "(closest: position of joint 1 at 50.0 % of its half range)" in verdict
    assert "SLSQP stopped before converging (Iteration limit reached)" in verdict
    tight = excitation_verdict(
        peaks(tau_max=[190.08, 1.0]), LIMITS, True, "Optimization terminated successfully"
    )
    assert (
        tight
        == "feasible: every peak within its limit (closest: torque of joint 1 at 99.0 % of 192 N·m); SLSQP converged"
    )


def test_an_infeasible_excitation_names_the_limit_and_by_how_much() -> None:
    verdict = excitation_verdict(
        peaks(v_max=[2.0, 6.0]), LIMITS, True, "Optimization terminated successfully"
    )
    assert verdict == (
        "peak speed of joint 2 is 6 rad/s, beyond its limit 5 rad/s, over by 1 rad/s (20 % of the limit) (infeasible)"
    )
    position = excitation_verdict(peaks(q_min=[-2.5, -1.0]), LIMITS, False, "Iteration limit reached")
    assert (
        "joint 1 reaches [-2.5, 1] rad, beyond its range [-2, 2] rad, over by 0.5 rad (25 % of the limit)"
        in position
    )


def test_the_ur5_has_a_stored_excitation_and_identify_uses_it_without_optimising(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """identify --robot ur5's default reads the packaged excitation (the one the docs measure,
    tests/fixtures/ur5_excitation.json) instead of optimising one for minutes; a loaded UR5
    (another robot) has none."""
    from pathlib import Path

    import numpy as np

    from twolink_pin.identification import excitation
    from twolink_pin.model import load_robot
    from twolink_pin.trajectory import read_trajectory_file

    def refuse(*_: object, **__: object) -> None:
        raise AssertionError("optimise_excitation called")

    monkeypatch.setattr(excitation, "optimise_excitation", refuse)
    ur5 = load_robot("ur5")
    stored = excitation.excitation_trajectory(ur5)
    fixture = read_trajectory_file(Path(__file__).parent / "fixtures" / "ur5_excitation.json", ur5)
    t = np.linspace(0.0, 10.0, 101)
    np.testing.assert_array_equal(stored.sample(t).q, fixture.sample(t).q)
    assert excitation.stored_excitation(load_robot("ur5", payload=1.0)) is None


def test_identify_robot_ur5_takes_the_stored_excitation_and_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """The CLI's choice of excitation for `identify --robot ur5` (what took 2 min 9 s when it
    optimised one first): the stored file, named as such, no optimisation."""
    from twolink_pin.cli.commands import identify as command
    from twolink_pin.identification import excitation
    from twolink_pin.model import load_robot

    def refuse(*_: object, **__: object) -> None:
        raise AssertionError("optimise_excitation called")

    monkeypatch.setattr(excitation, "optimise_excitation", refuse)
    trajectory, where = command._excitation(load_robot("ur5"))
    assert where == "stored excitation" and trajectory.period == 10.0
