"""Tests of twolink_pin.dynamics: Pinocchio's terms against the report's closed form and
the identities of rigid-body dynamics; the polarised regressor; joint friction.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.dynamics import (
    Friction,
    coriolis_matrix,
    forward_dynamics,
    friction_regressor,
    inverse_dynamics,
    inverse_dynamics_rows,
    mass_matrix,
    model_torque,
    polarisation_pair,
    regressor,
)
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel, example_robot_urdf, load_robot
from twolink_pin.model.parameters import inertial_parameters
from twolink_pin.twolink import closed_form

ROBOT: RobotModel = load_robot()
MODEL = ROBOT.model
DATA = ROBOT.create_data()
P_TRUE = np.asarray(ROBOT.p)
PI = inertial_parameters(MODEL)

angles = st.lists(st.floats(min_value=-math.pi, max_value=math.pi), min_size=2, max_size=2).map(np.array)
rates = st.lists(st.floats(min_value=-10.0, max_value=10.0), min_size=2, max_size=2).map(np.array)
EXAMPLES = settings(max_examples=60, deadline=None)


@EXAMPLES
@given(q=angles)
def test_crba_mass_matrix_equals_closed_form(q: np.ndarray) -> None:
    """M(q) from CRBA equals the report's [[p1 + 2 p3 c2, p2 + p3 c2], [p2 + p3 c2, p2]]."""
    np.testing.assert_allclose(
        mass_matrix(MODEL, DATA, q), closed_form.mass_matrix(q, P_TRUE), rtol=0, atol=1e-12
    )


@EXAMPLES
@given(q=angles, v=rates)
def test_coriolis_matrix_equals_closed_form(q: np.ndarray, v: np.ndarray) -> None:
    """C(q, v) from Pinocchio equals the report's p3 sin q2 [[−v2, −(v1 + v2)], [v1, 0]]."""
    np.testing.assert_allclose(
        coriolis_matrix(MODEL, DATA, q, v), closed_form.coriolis_matrix(q, v, P_TRUE), rtol=0, atol=1e-12
    )


@EXAMPLES
@given(q=angles)
def test_mass_matrix_is_symmetric_positive_definite(q: np.ndarray) -> None:
    """M(q) is exactly symmetric and its smallest eigenvalue is positive.

    For this arm det M = p1 p2 − p2² − p3² cos² q2 >= 1.11 (kg·m²)², so the bound
    λ_min > 0.1 kg·m² holds everywhere.
    """
    M = mass_matrix(MODEL, DATA, q)
    np.testing.assert_array_equal(M, M.T)
    assert np.linalg.eigvalsh(M).min() > 0.1


@EXAMPLES
@given(q=angles, v=rates)
def test_mdot_minus_2c_is_skew_symmetric(q: np.ndarray, v: np.ndarray) -> None:
    """Ṁ − 2C is skew-symmetric, Ṁ = dM/dt along q̇ = v by central finite difference.

    Step h = 1e-6 s: truncation <= h² p3 |v|³ / 3 ~ 1e-10 and rounding ~ eps |M| / h ~ 1e-9,
    so the tolerance 1e-7 kg·m²/s is loose by two orders of magnitude.
    """
    h = 1e-6
    m_dot = (mass_matrix(MODEL, DATA, q + h * v) - mass_matrix(MODEL, DATA, q - h * v)) / (2 * h)
    N = m_dot - 2 * coriolis_matrix(MODEL, DATA, q, v)
    np.testing.assert_allclose(N + N.T, np.zeros((2, 2)), rtol=0, atol=1e-7)


@EXAMPLES
@given(q=angles, v=rates, a=rates)
def test_rnea_equals_m_a_plus_c_v(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
    """RNEA's τ equals M(q) a + C(q, v) v (no gravity torque: the arm is horizontal)."""
    expected = mass_matrix(MODEL, DATA, q) @ a + coriolis_matrix(MODEL, DATA, q, v) @ v
    np.testing.assert_allclose(inverse_dynamics(MODEL, DATA, q, v, a), expected, rtol=0, atol=1e-10)


@EXAMPLES
@given(q=angles, v=rates, a=rates)
def test_aba_inverts_rnea(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
    """ABA(q, v, RNEA(q, v, a)) = a."""
    tau = inverse_dynamics(MODEL, DATA, q, v, a)
    np.testing.assert_allclose(forward_dynamics(MODEL, DATA, q, v, tau), a, rtol=0, atol=1e-10)


@EXAMPLES
@given(q=angles, v=rates, w=rates, a=rates)
def test_polarised_regressor_times_pi_equals_m_a_plus_c_w(
    q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> None:
    """regressor(q, v, w, a) π = M(q) a + C(q, v) w, with π Pinocchio's inertial parameters."""
    Y = regressor(MODEL, DATA, q, v, w, a)
    assert Y.shape == (2, 20)
    expected = mass_matrix(MODEL, DATA, q) @ a + coriolis_matrix(MODEL, DATA, q, v) @ w
    np.testing.assert_allclose(Y @ PI, expected, rtol=0, atol=1e-10)


@EXAMPLES
@given(q=angles, v=rates, w=rates, a=rates)
def test_regressor_times_p_matrix_equals_corrected_closed_form(
    q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> None:
    """Y_π P equals closed_form.regressor: [Y1 Y2 Y3] with Y3's lower-left +q̇1 sin q2."""
    Yp = regressor(MODEL, DATA, q, v, w, a) @ ROBOT.parameter_map.matrix
    np.testing.assert_allclose(Yp, closed_form.regressor(q, v, w, a), rtol=0, atol=1e-10)
    expected = closed_form.mass_matrix(q, P_TRUE) @ a + closed_form.coriolis_matrix(q, v, P_TRUE) @ w
    np.testing.assert_allclose(Yp @ P_TRUE, expected, rtol=0, atol=1e-10)


def _report_printed_regressor(q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
    """[Y1 Y2 Y3] exactly as the report prints them: Y3's lower-left Coriolis entry −q̇1 sin q2."""
    Y = closed_form.regressor(q, v, w, a)
    Y[1, 2] -= 2 * math.sin(q[1]) * v[0] * w[0]
    return Y


def test_report_printed_y3_sign_does_not_match_pinocchio() -> None:
    """The report's printed Y3 (lower-left −q̇1 sin q2) does not match Pinocchio: at a state
    with q̇1 sin q2 ≠ 0 and w1 ≠ 0 its p3 column differs by 2 q̇1 sin q2 w1 in row 2, so
    Y_report p ≠ M a + C w, while the corrected Y (+q̇1 sin q2) matches."""
    q, v, w, a = np.array([0.3, 1.1]), np.array([1.5, -0.4]), np.array([2.0, 0.7]), np.array([0.2, -0.3])
    assert abs(v[0] * math.sin(q[1])) > 1 and abs(w[0]) > 1
    Y_pin = regressor(MODEL, DATA, q, v, w, a) @ ROBOT.parameter_map.matrix
    Y_report = _report_printed_regressor(q, v, w, a)
    difference = Y_pin - Y_report
    np.testing.assert_allclose(
        difference, [[0, 0, 0], [0, 0, 2 * math.sin(q[1]) * v[0] * w[0]]], rtol=0, atol=1e-12
    )
    assert abs(difference[1, 2]) > 5.0
    tau = mass_matrix(MODEL, DATA, q) @ a + coriolis_matrix(MODEL, DATA, q, v) @ w
    assert abs((Y_report @ P_TRUE - tau)[1]) > 1.0  # off by 2 p3 sin q2 v1 w1 ≈ 1.60 N·m
    np.testing.assert_allclose(Y_pin @ P_TRUE, tau, rtol=0, atol=1e-12)


@EXAMPLES
@given(q=angles, v=rates, a=rates)
def test_polarised_regressor_with_w_equal_v_is_pinocchios(
    q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> None:
    """regressor(q, v, v, a) equals pin.computeJointTorqueRegressor(q, v, a)."""
    expected = pin.computeJointTorqueRegressor(MODEL, ROBOT.create_data(), q, v, a)
    np.testing.assert_allclose(regressor(MODEL, DATA, q, v, v, a), expected, rtol=0, atol=1e-10)


@EXAMPLES
@given(q=angles, v=rates, w=rates)
def test_coriolis_bilinear_form_is_symmetric(q: np.ndarray, v: np.ndarray, w: np.ndarray) -> None:
    """C(q, v) w = C(q, w) v (Christoffel form), the property the polarised regressor uses."""
    np.testing.assert_allclose(
        coriolis_matrix(MODEL, DATA, q, v) @ w, coriolis_matrix(MODEL, DATA, q, w) @ v, rtol=0, atol=1e-12
    )


@EXAMPLES
@given(v=rates, smoothing=st.sampled_from([0.0, 0.01, 0.5]))
def test_friction_torque_equals_regressor_times_parameters(v: np.ndarray, smoothing: float) -> None:
    """Friction.torque(v) = friction_regressor(v) (V1, V2, C1, C2) for exact and smooth sign."""
    friction = Friction((0.4, 0.2), (0.2, 0.1), smoothing=smoothing)
    np.testing.assert_allclose(
        friction.torque(v), friction_regressor(v, smoothing) @ friction.parameters, rtol=0, atol=1e-14
    )


def test_report_friction_values() -> None:
    """The twolink profile's friction is the report's: V = (0.4, 0.2) N·m·s/rad, C = (0.2, 0.1) N·m."""
    friction = Friction(*ROBOT.profile.friction)
    np.testing.assert_array_equal(friction.parameters, [0.4, 0.2, 0.2, 0.1])
    np.testing.assert_allclose(friction.torque(np.array([2.0, -1.0])), [1.0, -0.3], rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [
        (
            {"viscous": (-0.4, 0.2), "coulomb": (0.2, 0.1)},
            "viscous = (-0.4, 0.2) is invalid: expected finite values >= 0",
        ),
        (
            {"viscous": (0.4, 0.2), "coulomb": (0.2, -0.1)},
            "coulomb = (0.2, -0.1) is invalid: expected finite values >= 0",
        ),
        (
            {"viscous": (0.4, 0.2), "coulomb": (0.2, 0.1), "smoothing": -0.01},
            "smoothing = -0.01 is invalid: expected a finite velocity >= 0 rad/s",
        ),
    ],
)
def test_friction_rejects_negative_values_naming_them(kwargs: dict, text: str) -> None:
    """A negative friction coefficient or smoothing raises InvalidParameterError whose
    message names the parameter and its values."""
    with pytest.raises(InvalidParameterError) as info:
        Friction(**kwargs)
    assert str(info.value) == text


# -- the polarisation pair of the fast simulator ------------------------------------------------

PAIR_ROBOTS = [
    None,  # the twolink: gravity along the joint axes, so no gravity torque
    "double_pendulum_description/urdf/double_pendulum.urdf",  # gravity torque
    "asr_twodof_description/urdf/TwoDofs.urdf",
]


@pytest.mark.parametrize("relative", PAIR_ROBOTS)
@pytest.mark.parametrize("armature", [0.0, 0.3])
def test_polarisation_pair_gives_the_model_term_in_one_call(relative: str | None, armature: float) -> None:
    """One RNEA / regressor call on the pair (copy B upside down, half gravity) equals the
    two-call model term ``M a + C(q, v) w + g`` (RNEA + Coriolis matrix) and the polarised
    regressor, including gravity and armature, to 1e-12 relative."""
    robot = load_robot(str(example_robot_urdf(relative))) if relative else load_robot()
    model = pin.Model(robot.model)
    model.armature = np.full(model.nv, armature)
    data = model.createData()
    pair = polarisation_pair(model)
    pair_data = pair.createData()
    nv, n_pi = model.nv, 10 * (model.njoints - 1)
    rng = np.random.default_rng(7)
    gravity_seen = 0.0
    for _ in range(100):
        q, v, w, a = (rng.uniform(-3.0, 3.0, nv) for _ in range(4))
        Q, V, A = np.r_[q, q], np.r_[(v + w) / 2, (v - w) / 2], np.r_[a, np.zeros(nv)]
        expected = model_torque(model, data, q, v, w, a)
        tau = pin.rnea(pair, pair_data, Q, V, A)
        scale = max(1.0, float(np.abs(expected).max()))
        assert np.abs(tau[:nv] - tau[nv:] - expected).max() <= 1e-12 * scale
        Y = pin.computeJointTorqueRegressor(pair, pair_data, Q, V, A)
        expected_y = regressor(model, data, q, v, w, a)
        scale = max(1.0, float(np.abs(expected_y).max()))
        assert np.abs(Y[:nv, :n_pi] - Y[nv:, n_pi:] - expected_y).max() <= 1e-12 * scale
        gravity_seen = max(gravity_seen, float(np.abs(pin.computeGeneralizedGravity(model, data, q)).max()))
    if relative and "double_pendulum" in relative:
        assert gravity_seen > 0.1  # the identity was really exercised with gravity


def test_polarisation_pair_refuses_nq_different_from_nv() -> None:
    """A free-flyer model (nq = nv + 1) is refused with both sizes in the message."""
    model = pin.buildSampleModelHumanoidRandom()
    with pytest.raises(ValueError, match=rf"nq = {model.nq}, nv = {model.nv}"):
        polarisation_pair(model)


def test_friction_regressor_of_a_batch_is_the_regressor_of_each_row() -> None:
    """friction_regressor on (N, nv) velocities stacks the (nv, 2 nv) regressors of the rows."""
    v = np.array([[0.3, -2.0], [0.0, 1e-4], [-1.0, 0.5]])
    batch = friction_regressor(v, 1e-3)
    for i in range(3):
        np.testing.assert_array_equal(batch[i], friction_regressor(v[i], 1e-3))


@pytest.mark.parametrize("name", ["twolink", "ur5"])
def test_inverse_dynamics_rows_is_pinocchios_rnea_row_by_row(name: str) -> None:
    """One ``rneaInParallel`` call over K rows gives ``pin.rnea`` of each row (a second call
    path of Pinocchio) to rounding, and refuses a row of the wrong width naming it."""
    robot = load_robot(name)
    rng = np.random.default_rng(3)
    q, v, a = (rng.uniform(-2.0, 2.0, (37, robot.nv)) for _ in range(3))
    data = robot.model.createData()
    expected = np.array([pin.rnea(robot.model, data, *row) for row in zip(q, v, a)])
    np.testing.assert_allclose(inverse_dynamics_rows(robot.model, q, v, a), expected, rtol=0, atol=1e-10)
    with pytest.raises(InvalidParameterError, match="v"):
        inverse_dynamics_rows(robot.model, q, v[:, :-1], a)
    with pytest.raises(InvalidParameterError, match="the same number of rows"):
        inverse_dynamics_rows(robot.model, q, v[:-1], a)
