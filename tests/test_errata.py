"""The errata's evidence, checked by independent computations."""

from __future__ import annotations

import numpy as np
import pytest

from twolink_pin import build_trajectory, load_robot, make_scenario, simulate
from twolink_pin.twolink.errata import (
    REPORT_COEFFICIENTS,
    parameter_convergence,
    printed_coefficients,
    third_via_point,
    y3_sign,
)


@pytest.fixture(scope="module")
def robot():
    return load_robot()


def test_table1_row3_is_the_ik_of_048_minus_01(robot) -> None:
    e = third_via_point(robot)
    assert e.evidence["max_abs_diff_corrected_rad"] == 0.0
    assert e.evidence["max_abs_diff_printed_rad"] > 0.4


def test_printed_polynomials_miss_the_via_points(robot) -> None:
    """Evaluate the printed eqs. 6–7 by plain powers (a second method) at t = 4 s."""
    traj = build_trajectory(robot)
    e = printed_coefficients(traj)
    by_hand = [sum(c * 4.0**k for k, c in enumerate(coeffs)) for coeffs in REPORT_COEFFICIENTS]
    np.testing.assert_allclose(e.evidence["printed_polynomial_at_via_times_rad"][-1], by_hand, rtol=1e-12)
    assert e.evidence["printed_max_miss_rad"] > 1000  # theta1(4) ≈ 15553 rad instead of −0.2936
    assert e.evidence["ours_max_miss_rad"] < 1e-9
    assert e.evidence["ours_coefficients"][0][6] == pytest.approx(-1.9585, abs=1e-4)  # printed +1.95
    assert e.evidence["ours_coefficients"][1][4] == pytest.approx(3.1097, abs=1e-4)  # printed 3.19


def test_printed_y3_sign_is_wrong_and_pinocchio_is_right(robot) -> None:
    e = y3_sign(robot)
    assert e.evidence["max_error_pinocchio_regressor_Nm"] < 1e-12
    assert e.evidence["max_error_printed_Y3_Nm"] > 0.1


@pytest.mark.slow
def test_parameter_drift_matches_the_averaged_adaptation_rates(robot) -> None:
    """After the fast transient, |p̃| decays between the two slowest averaged rates.

    Averaging theory (once s ≈ K⁻¹ Y p̃) predicts dp̃/dt ≈ −Γ G p̃; the simulated decay of
    |p̃| from 10 s to 30 s must lie between exp(−r_2 · 20 s) and exp(−r_1 · 20 s), r_1 < r_2
    the two slowest rates (with 3 % slack for the approximation).
    """
    traj = build_trajectory(robot)
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, traj)
    e = parameter_convergence(result, controller, traj)
    r1, r2 = e.evidence["averaged_adaptation_rates_per_s"][:2]
    norms = e.evidence["p_error_norm_at_t"]
    ratio = norms["30"] / norms["10"]
    assert np.exp(-r2 * 20) * 0.97 < ratio < np.exp(-r1 * 20) * 1.03
    assert min(e.evidence["excitation_gram_eigenvalues"]) > 0  # persistently exciting
    assert e.evidence["slowest_time_constant_s"] > 30  # so 30 s cannot show convergence
