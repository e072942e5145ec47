"""Tests of twolink_pin.trajectory: the report's 11 conditions per joint, periodic
smoothness, consistency of sample() with its coefficients, and the report's printed
polynomials (eqs. 6–7) with their two misprints.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.polynomial import polynomial as P

from twolink_pin.errors import InvalidParameterError, UnreachableTargetError
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.trajectory import JointTrajectory, ViaPoints, build_trajectory, default_via_points
from twolink_pin.twolink.reference import REPORT_TIMES, REPORT_VIA_XY

ROBOT: RobotModel = load_robot()
TRAJ: JointTrajectory = build_trajectory(ROBOT)
PERIOD = 4.0

# Report eqs. 6–7, coefficients of t^0 .. t^10 as printed (t^1..t^3 absent: zero).
REPORT_ALPHA = np.array([-0.2936, 0, 0, 0, -2.04, 3.11, 1.95, 0.65, -0.12, 0.01, -0.00048])
REPORT_BETA = np.array([1.3587, 0, 0, 0, 3.19, -4.4, 2.32, -0.54, 0.04, 0.003, -0.00051])
# Decimal places printed for each coefficient (None: the term is absent from the report).
REPORT_ALPHA_DECIMALS = (4, None, None, None, 2, 2, 2, 2, 2, 2, 5)
REPORT_BETA_DECIMALS = (4, None, None, None, 2, 1, 2, 2, 2, 3, 5)
MISPRINTS = {(0, 6), (1, 4)}  # (joint, power): alpha6 and beta4


def _ik_via_points() -> np.ndarray:
    """Branch-0 IK of the report's via points [rad], shape (5, 2)."""
    return np.array([inverse_kinematics(ROBOT, xy)[0] for xy in REPORT_VIA_XY])


def test_report_defaults() -> None:
    """The twolink's default via points are the report's set: (0.48, 0.1), (0.38, 0), (0.48, −0.1), (0.58, 0), back
    to the start, at 0, 1, 2, 3, 4 s, branch 0, jerk-free ends; the period is 4 s."""
    via = default_via_points(ROBOT)
    assert via is not None
    assert via.xy == ((0.48, 0.1), (0.38, 0.0), (0.48, -0.1), (0.58, 0.0), (0.48, 0.1))
    assert via.times == REPORT_TIMES == (0.0, 1.0, 2.0, 3.0, 4.0)
    assert (via.branch, via.period, via.boundary_order) == (0, None, 3)
    assert TRAJ.period == PERIOD
    assert TRAJ.coefficients.shape == (2, 11)


def test_all_eleven_conditions_per_joint() -> None:
    """Each joint meets the report's 11 conditions to 1e-9: positions at 0, 1, 2, 3, 4 s
    equal the IK via points, and velocity, acceleration and jerk are zero at 0 and 4 s."""
    via_q = _ik_via_points()
    np.testing.assert_allclose(TRAJ.via_q, via_q, rtol=0, atol=0)
    for k, t in enumerate(REPORT_TIMES):
        # Sample 4 s just before the wrap so the end condition is that of the polynomial itself.
        sample = TRAJ.sample(t if t < PERIOD else np.nextafter(PERIOD, 0.0))
        np.testing.assert_allclose(sample.q, via_q[k], rtol=0, atol=1e-9)
    for t in (0.0, np.nextafter(PERIOD, 0.0), PERIOD):
        sample = TRAJ.sample(t)
        for derivative in (sample.v, sample.a, sample.jerk):
            np.testing.assert_allclose(derivative, [0.0, 0.0], rtol=0, atol=1e-9)


def test_continuity_across_the_period_boundary() -> None:
    """q, q̇, q̈ and jerk are continuous across t = 4 s (compare 4 − ε with 4 + ε, ε = 1e-7 s).

    q, q̇, q̈ agree to 1e-9; jerk to 2 ε max|snap| <= 2e-7 × 100 rad/s⁴ = 2e-5 rad/s³.
    """
    eps = 1e-7
    before, after = TRAJ.sample(PERIOD - eps), TRAJ.sample(PERIOD + eps)
    for name, atol in (("q", 1e-9), ("v", 1e-9), ("a", 1e-9), ("jerk", 2e-5)):
        np.testing.assert_allclose(
            getattr(before, name), getattr(after, name), rtol=0, atol=atol, err_msg=name
        )


@settings(max_examples=60, deadline=None)
@given(t=st.floats(min_value=0.0, max_value=PERIOD), k=st.integers(min_value=-3, max_value=5))
def test_periodicity(t: float, k: int) -> None:
    """sample(t + 4 k) = sample(t) for every field, k an integer number of periods."""
    base, shifted = TRAJ.sample(t), TRAJ.sample(t + k * PERIOD)
    for name in ("q", "v", "a", "jerk"):
        np.testing.assert_allclose(
            getattr(shifted, name), getattr(base, name), rtol=0, atol=1e-8, err_msg=name
        )


def test_derivatives_match_finite_differences_of_sample() -> None:
    """v, a, jerk from sample() equal central differences (step 1e-4 s) of q, v, a.

    The error is truncation h² f⁽³⁾/6 (about 2e-8, 2e-7, 1.3e-6 here: the derivatives of
    q reach 11 rad/s³, 100 rad/s⁴, 780 rad/s⁵); smaller steps meet rounding, the
    polynomial in normalised time having coefficients up to 1e4 rad.
    """
    h = 1e-4
    t = np.linspace(0.05, 3.95, 79)
    mid, plus, minus = TRAJ.sample(t), TRAJ.sample(t + h), TRAJ.sample(t - h)
    for low, high, atol in (("q", "v", 1e-7), ("v", "a", 5e-7), ("a", "jerk", 5e-6)):
        numeric = (getattr(plus, low) - getattr(minus, low)) / (2 * h)
        np.testing.assert_allclose(getattr(mid, high), numeric, rtol=0, atol=atol, err_msg=high)


def test_vectorised_sample_shapes() -> None:
    """sample() of N times gives (N, 2) arrays; of one time, (2,) arrays."""
    assert TRAJ.sample(np.linspace(0, 8, 7)).q.shape == (7, 2)
    assert TRAJ.sample(1.5).jerk.shape == (2,)


def test_coefficients_reproduce_sample_in_powers_of_t() -> None:
    """Σ_k c_k t^k and its derivatives equal sample(t) over one period (t0 = 0)."""
    t = np.linspace(0.0, PERIOD, 401)[:-1]
    sample = TRAJ.sample(t)
    for joint, c in enumerate(TRAJ.coefficients):
        for order, name in enumerate(("q", "v", "a", "jerk")):
            np.testing.assert_allclose(
                P.polyval(t, P.polyder(c, order) if order else c),
                getattr(sample, name)[:, joint],
                rtol=0,
                atol=1e-9,
                err_msg=f"joint {joint + 1} {name}",
            )


def test_coefficients_t1_to_t3_vanish() -> None:
    """Zero velocity, acceleration and jerk at t = 0 make the t, t², t³ coefficients zero."""
    np.testing.assert_allclose(TRAJ.coefficients[:, 1:4], np.zeros((2, 3)), rtol=0, atol=1e-10)


def _agrees_to_printed_precision(ours: float, printed: float, decimals: int) -> bool:
    """Whether ``printed`` is ``ours`` rounded or truncated to ``decimals`` places."""
    scale = 10.0**decimals
    candidates = (round(ours, decimals), math.trunc(ours * scale) / scale)
    return any(abs(c - printed) < 0.01 / scale for c in candidates)


@pytest.mark.parametrize(
    ("joint", "power"),
    [
        (j, k)
        for j, decs in enumerate((REPORT_ALPHA_DECIMALS, REPORT_BETA_DECIMALS))
        for k, d in enumerate(decs)
        if d is not None
    ],
)
def test_report_coefficients_agree_except_two_misprints(joint: int, power: int) -> None:
    """Each printed coefficient of eqs. 6–7 is ours rounded or truncated to its printed
    decimals, except alpha6 and beta4, which are misprints."""
    printed = (REPORT_ALPHA, REPORT_BETA)[joint][power]
    decimals = (REPORT_ALPHA_DECIMALS, REPORT_BETA_DECIMALS)[joint][power]
    ours = float(TRAJ.coefficients[joint, power])
    agrees = _agrees_to_printed_precision(ours, printed, decimals)
    assert agrees == ((joint, power) not in MISPRINTS), (ours, printed)


def test_report_misprint_alpha6_sign() -> None:
    """alpha6 is printed +1.95 but is −1.95854: the sign is wrong (|alpha6| truncates to 1.95)."""
    ours = TRAJ.coefficients[0, 6]
    np.testing.assert_allclose(ours, -1.958540, rtol=0, atol=1e-6)
    assert REPORT_ALPHA[6] == 1.95
    assert _agrees_to_printed_precision(-ours, REPORT_ALPHA[6], 2)


def test_report_misprint_beta4() -> None:
    """beta4 is printed 3.19 but is 3.10971 (3.11 rounded, 3.10 truncated)."""
    ours = TRAJ.coefficients[1, 4]
    np.testing.assert_allclose(ours, 3.109710, rtol=0, atol=1e-6)
    assert REPORT_BETA[4] == 3.19
    assert abs(ours - REPORT_BETA[4]) > 0.08


def test_printed_polynomials_miss_the_via_points_ours_hit_them() -> None:
    """The printed theta1(t) gives 3.27, 248, 2814, 15553 rad at t = 1, 2, 3, 4 s instead of
    −0.6426, −0.7044, −0.2835, −0.2936 rad; printed theta2(1) = 1.971 rad instead of 1.8921.
    Our coefficients hit every via point to 1e-9 rad."""
    via_q = _ik_via_points()
    times = np.array(REPORT_TIMES)
    printed1, printed2 = P.polyval(times, REPORT_ALPHA), P.polyval(times, REPORT_BETA)
    np.testing.assert_allclose(printed1[1:], [3.26592, 248.49488, 2814.46288, 15552.70992], rtol=1e-6)
    np.testing.assert_allclose(printed2[1], 1.97119, rtol=1e-6)
    assert np.all(np.abs(printed1[1:] - via_q[1:, 0]) > 3.0)
    assert np.all(np.abs(printed2[1:] - via_q[1:, 1]) > 0.07)
    for joint in (0, 1):
        np.testing.assert_allclose(
            P.polyval(times, TRAJ.coefficients[joint]), via_q[:, joint], rtol=0, atol=1e-9
        )


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [
        (
            {"times": (0.0, 1.0, 1.0, 3.0, 4.0)},
            "times = (0.0, 1.0, 1.0, 3.0, 4.0) is invalid: expected finite, strictly increasing times [s]",
        ),
        (
            {"times": (0.0, 2.0, 1.0, 3.0, 4.0)},
            "times = (0.0, 2.0, 1.0, 3.0, 4.0) is invalid: expected finite, strictly increasing times [s]",
        ),
        (
            {"times": (0.0, 1.0, 2.0)},
            "times = (0.0, 1.0, 2.0) is invalid: expected one time per via point (5 from xy)",
        ),
        ({"branch": 2}, "branch = 2 is invalid: expected 0 (q2 >= 0) or 1 (q2 <= 0)"),
        ({"period": 3.5}, "period = 3.5 is invalid: expected a finite period >= the via-point span 4 s"),
        (
            {"period": float("nan")},
            "period = nan is invalid: expected a finite period >= the via-point span 4 s",
        ),
    ],
)
def test_invalid_via_points_raise_with_clear_messages(kwargs: dict, text: str) -> None:
    """Non-increasing times, a time count that differs from the points, a bad branch or a
    period shorter than the via-point span raise InvalidParameterError with that text."""
    with pytest.raises(InvalidParameterError) as info:
        ViaPoints(**{"xy": REPORT_VIA_XY, "times": REPORT_TIMES, **kwargs})
    assert str(info.value) == text


def test_unreachable_via_point_raises_when_building() -> None:
    """A via point outside the annulus raises UnreachableTargetError naming it."""
    via = ViaPoints(xy=((0.48, 0.1), (0.70, 0.0), (0.48, 0.1)), times=(0.0, 1.0, 2.0))
    with pytest.raises(UnreachableTargetError, match=r"target \(0\.7, 0\) m .* 0\.14 <= r <= 0\.62 m"):
        build_trajectory(ROBOT, via)


def test_branch_1_uses_the_other_elbow() -> None:
    """With branch = 1 every via point is the q2 <= 0 IK solution (Table 1's second pair)."""
    traj = build_trajectory(ROBOT, ViaPoints(xy=REPORT_VIA_XY, times=REPORT_TIMES, branch=1))
    expected = np.array([inverse_kinematics(ROBOT, xy)[1] for xy in REPORT_VIA_XY])
    np.testing.assert_allclose(traj.via_q, expected, rtol=0, atol=0)
    assert np.all(traj.via_q[:, 1] <= 0)


def test_longer_period_rests_at_the_last_via_point() -> None:
    """With period 5 s > span 4 s the arm rests at the last via point from 4 s to 5 s
    (q = last via point, v = a = jerk = 0), then repeats the motion."""
    traj = build_trajectory(ROBOT, ViaPoints(xy=REPORT_VIA_XY, times=REPORT_TIMES, period=5.0))
    assert traj.period == 5.0
    rest = traj.sample(np.array([4.0, 4.25, 4.5, 4.999]))
    np.testing.assert_allclose(rest.q, np.tile(traj.via_q[-1], (4, 1)), rtol=0, atol=1e-9)
    for name in ("v", "a", "jerk"):
        np.testing.assert_allclose(getattr(rest, name), np.zeros((4, 2)), rtol=0, atol=1e-9, err_msg=name)
    np.testing.assert_allclose(traj.sample(6.0).q, traj.via_q[1], rtol=0, atol=1e-9)
