"""The optimisation core (twolink_pin.optimal) and the dynamics callable it linearises, each
checked against something independent: SciPy's B-splines, finite differences, Pinocchio's
ABA derivatives and CRBA, closed-form least squares."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.dynamics import Friction
from twolink_pin.dynamics.derivatives import RneaDerivatives
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import EFFORT, POSITION, VELOCITY, joint_limits
from twolink_pin.model import load_robot
from twolink_pin.optimal.layout import SplineLayout
from twolink_pin.optimal.spline import BSplineBasis
from twolink_pin.optimal.sqp import SQPOptions, solve_sqp, sqp_step
from twolink_pin.optimal.transcription import Cost, Pin, TrajectoryProblem


@pytest.fixture(scope="module")
def ur5():
    return load_robot("ur5")


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


# -- splines ---------------------------------------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), pieces=st.integers(1, 7), degree=st.integers(2, 6))
def test_basis_matrices_equal_scipys_bspline_and_its_derivatives(seed: int, pieces: int, degree: int) -> None:
    """Random breakpoints and coefficients: ``B_r c`` equals ``scipy.interpolate.BSpline(..)(s, r)``
    for every derivative, the ends included."""
    from scipy.interpolate import BSpline

    rng = np.random.default_rng(seed)
    breaks = np.concatenate([[0.0], np.sort(rng.uniform(0.05, 1.95, pieces - 1)), [2.0]])
    breaks = np.unique(np.round(breaks, 6))
    basis = BSplineBasis(breaks, degree)
    c = rng.normal(size=basis.size)
    reference = BSpline(basis.knots, c, degree)
    s = np.concatenate([rng.uniform(0.0, 2.0, 40), [0.0, 2.0]])
    for r in range(degree + 1):
        np.testing.assert_allclose(basis.matrix(s, r) @ c, reference(s, r), rtol=1e-9, atol=1e-7 * 10.0**r)


def test_the_derivatives_coefficients_bound_the_derivative_everywhere() -> None:
    """Convex hull: on a fine grid, every derivative lies within its coefficients' range, and
    the bound is reached at the ends (a clamped spline meets its end coefficients)."""
    rng = np.random.default_rng(3)
    basis = BSplineBasis.uniform(0.0, 1.0, 6, 5)
    c = rng.normal(size=basis.size)
    s = np.linspace(0.0, 1.0, 4001)
    for r in range(4):
        values = basis.matrix(s, r) @ c
        hull = basis.derivative_coefficients(r) @ c
        assert hull.min() - 1e-9 <= values.min() and values.max() <= hull.max() + 1e-9
        np.testing.assert_allclose(values[[0, -1]], hull[[0, -1]], rtol=1e-9)


def test_quadrature_integrates_a_spline_product_exactly() -> None:
    """Gauss–Legendre with degree + 1 points per piece integrates y² (degree 10 per piece)
    exactly: against the antiderivative of the squared polynomial pieces."""
    basis = BSplineBasis(np.array([0.0, 0.3, 1.1, 2.0]), 5)
    c = np.random.default_rng(0).normal(size=basis.size)
    nodes, weights = basis.quadrature()
    approx = weights @ (basis.matrix(nodes) @ c) ** 2
    s = np.linspace(0.0, 2.0, 200_001)
    fine = np.trapezoid((basis.matrix(s) @ c) ** 2, s)
    assert approx == pytest.approx(fine, rel=1e-8)


def test_basis_refuses_bad_breakpoints_and_orders() -> None:
    with pytest.raises(InvalidParameterError, match="strictly increasing"):
        BSplineBasis(np.array([0.0, 1.0, 1.0]))
    with pytest.raises(InvalidParameterError, match="derivative from 0 to 5"):
        BSplineBasis.uniform(0.0, 1.0, 2).matrix(np.array([0.5]), 6)


# -- the dynamics callable -------------------------------------------------------------------


def test_rnea_derivatives_match_finite_differences_and_crba(ur5) -> None:
    """∂τ/∂q and ∂τ/∂q̇ against central differences of pin.rnea (1e-6 steps); ∂τ/∂q̈ = CRBA's M."""
    rng = np.random.default_rng(1)
    q, v, a = rng.normal(size=(3, 3, ur5.nv))
    terms = RneaDerivatives(ur5.model)(q, v, a)
    data = ur5.model.createData()
    h = 1e-6
    for k in range(3):
        np.testing.assert_allclose(terms.tau[k], pin.rnea(ur5.model, data, q[k], v[k], a[k]), atol=1e-12)
        for j in range(ur5.nv):
            e = np.eye(ur5.nv)[j] * h
            dq = (
                pin.rnea(ur5.model, data, q[k] + e, v[k], a[k])
                - pin.rnea(ur5.model, data, q[k] - e, v[k], a[k])
            ) / (2 * h)
            dv = (
                pin.rnea(ur5.model, data, q[k], v[k] + e, a[k])
                - pin.rnea(ur5.model, data, q[k], v[k] - e, a[k])
            ) / (2 * h)
            np.testing.assert_allclose(terms.dtau_dq[k][:, j], dq, atol=1e-6)
            np.testing.assert_allclose(terms.dtau_dv[k][:, j], dv, atol=1e-6)
        M = pin.crba(ur5.model, data, q[k])
        np.testing.assert_allclose(terms.mass[k], np.triu(M) + np.triu(M, 1).T, atol=1e-12)


def test_rnea_derivatives_agree_with_aba_derivatives(ur5) -> None:
    """A second Pinocchio algorithm: at τ = RNEA(q, q̇, q̈), ABA's derivatives satisfy
    ∂q̈/∂q = −M⁻¹ ∂τ/∂q, ∂q̈/∂q̇ = −M⁻¹ ∂τ/∂q̇ and ∂q̈/∂τ = M⁻¹ (the implicit function theorem)."""
    rng = np.random.default_rng(2)
    q, v, a = rng.normal(size=(3, 1, ur5.nv))
    terms = RneaDerivatives(ur5.model)(q, v, a)
    data = ur5.model.createData()
    ddq_dq, ddq_dv, minv = pin.computeABADerivatives(ur5.model, data, q[0], v[0], terms.tau[0])
    M_inv = np.linalg.inv(terms.mass[0])
    np.testing.assert_allclose(ddq_dq, -M_inv @ terms.dtau_dq[0], atol=1e-8)
    np.testing.assert_allclose(ddq_dv, -M_inv @ terms.dtau_dv[0], atol=1e-8)
    np.testing.assert_allclose(np.triu(minv) + np.triu(minv, 1).T, M_inv, atol=1e-8)


def test_friction_enters_the_torque_and_its_velocity_derivative(twolink) -> None:
    """With viscous V and smoothed Coulomb C tanh(q̇/ε): τ gains f(q̇), ∂τ/∂q̇ its derivative
    (central differences)."""
    friction = Friction((0.5, 0.3), (1.0, 0.7), smoothing=0.05)
    dyn, plain = RneaDerivatives(twolink.model, friction), RneaDerivatives(twolink.model)
    q, v, a = np.array([[0.3, -0.2]]), np.array([[0.02, -0.4]]), np.array([[1.0, 2.0]])
    with_f, without = dyn(q, v, a), plain(q, v, a)
    np.testing.assert_allclose(with_f.tau - without.tau, friction.torque(v), atol=1e-12)
    h = 1e-7
    for j in range(2):
        e = np.eye(2)[j] * h
        fd = (dyn(q, v + e, a).tau - dyn(q, v - e, a).tau) / (2 * h)
        np.testing.assert_allclose(with_f.dtau_dv[0][:, j], fd[0], atol=1e-5)


# -- the transcription ------------------------------------------------------------------------


def _problem(robot, free: bool, cost: Cost | None = None) -> tuple[TrajectoryProblem, np.ndarray]:
    """Two segments of a quintic spline through three via points of ``robot`` (random start)."""
    rng = np.random.default_rng(5)
    basis = BSplineBasis.uniform(0.0, 1.0, 3, 5)
    layout = SplineLayout(basis, 2, robot.nv, None if free else np.array([0.6, 0.9]))
    via = robot.home + 0.2 * rng.normal(size=(3, robot.nv))
    pins = (Pin("via", layout.points(np.array([0, 1, 1]), np.array([0.0, 0.0, 1.0])), 0, via),)
    problem = TrajectoryProblem(
        layout, RneaDerivatives(robot.model), joint_limits(robot), cost or Cost(effort=1.0, jerk=1e-6),
        layout.quadrature(), layout.grid(2), pins, kinds=(POSITION, VELOCITY, EFFORT), hull=(VELOCITY,),
    )  # fmt: skip
    C = robot.home + 0.1 * rng.normal(size=(2, basis.size, robot.nv))
    return problem, layout.pack(C, np.array([0.6, 0.9]) if free else None)


@pytest.mark.parametrize("free", [False, True], ids=["fixed durations", "free durations"])
def test_every_jacobian_of_the_problem_matches_finite_differences(ur5, free: bool) -> None:
    """Residuals, equalities and inequalities (torque rows by the RNEA derivatives, chained
    through the basis; the durations' columns too) against central differences."""
    problem, x = _problem(ur5, free)
    ev = problem.evaluate(x, jacobians=True)
    h = 1e-6
    columns = np.random.default_rng(0).choice(x.size, 25, replace=False)
    if free:
        columns = np.concatenate([columns, np.arange(x.size - 2, x.size)])
    for i in columns:
        e = np.zeros(x.size)
        e[i] = h
        up, down = problem.evaluate(x + e), problem.evaluate(x - e)
        for name, J in (
            ("residual", ev.residual_jacobian),
            ("equality", ev.equality_jacobian),
            ("inequality", ev.inequality_jacobian),
        ):
            fd = (getattr(up, name) - getattr(down, name)) / (2 * h)
            assert J is not None
            np.testing.assert_allclose(
                J[:, i], fd, rtol=1e-5, atol=1e-5 * (1 + np.abs(fd).max()), err_msg=f"{name}, column {i}"
            )


def test_tracking_a_spline_recovers_its_coefficients(twolink) -> None:
    """A pure position-tracking cost whose reference is a spline of the same basis: the SQP's
    answer, converged tightly, is that spline's coefficients (the cost is zero there, and only
    there)."""
    basis = BSplineBasis.uniform(0.0, 1.0, 4, 5)
    layout = SplineLayout(basis, 1, 2, np.array([1.5]))
    rng = np.random.default_rng(7)
    C = 0.05 * rng.normal(size=(1, basis.size, 2))  # well inside every limit
    x_ref = layout.pack(C)
    points = layout.quadrature()
    reference = (layout.derivative(x_ref, points, 0), layout.derivative(x_ref, points, 1))
    limits = joint_limits(twolink)
    problem = TrajectoryProblem(
        layout, RneaDerivatives(twolink.model), limits, Cost(position=1.0, velocity=0.1, reference=reference),
        points, layout.grid(2), (),
    )  # fmt: skip
    result = solve_sqp(problem, np.zeros(layout.size), SQPOptions(cost_tolerance=1e-14))
    np.testing.assert_allclose(result.x, x_ref, atol=1e-6)


def test_a_real_time_iteration_pins_the_initial_state(twolink) -> None:
    """One full step (what a receding-horizon law does per replan) from a guess that violates
    them satisfies the linear pins q(0), q̇(0) exactly: the equalities are linear in ``x``."""
    basis = BSplineBasis.uniform(0.0, 1.0, 5, 5)
    layout = SplineLayout(basis, 1, 2, np.array([0.5]))
    start = layout.points(np.array([0]), np.array([0.0]))
    q0, v0 = np.array([[0.3, -0.4]]), np.array([[1.0, 0.5]])
    points = layout.quadrature()
    reference = (np.zeros((points.size, 2)), np.zeros((points.size, 2)))
    problem = TrajectoryProblem(
        layout, RneaDerivatives(twolink.model), joint_limits(twolink),
        Cost(position=100.0, velocity=1.0, effort=1e-4, reference=reference), points, layout.grid(2),
        (Pin("initial", start, 0, q0), Pin("initial", start, 1, v0)),
    )  # fmt: skip
    step = sqp_step(problem, np.zeros(layout.size))
    np.testing.assert_allclose(layout.derivative(step.x, start, 0), q0, atol=1e-7)
    np.testing.assert_allclose(layout.derivative(step.x, start, 1), v0, atol=1e-6)
    moved = problem.with_pin("initial", 0, np.array([[0.1, 0.1]]))
    step = sqp_step(moved, step.x, step.qp)
    np.testing.assert_allclose(layout.derivative(step.x, start, 0), [[0.1, 0.1]], atol=1e-7)
