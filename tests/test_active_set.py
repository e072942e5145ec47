"""The SQP steps' QP solver (twolink_pin.optimal.active_set, DAQP): its answers checked by the
KKT conditions computed here and against Clarabel on the same QPs; its warm start; a QP whose
rows cannot all hold named by its row."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.errors import OptimizationError
from twolink_pin.optimal import QP, kkt_residual, solve_qp_active_set


def _random_qp(seed: int, n: int, m: int, k: int) -> QP:
    """A strictly convex QP with ``m`` equalities and ``k`` two-sided rows, feasible (the rows
    bound a point that satisfies them), some of them active at the optimum."""
    rng = np.random.default_rng(seed)
    G = rng.normal(size=(n, n))
    H = G @ G.T + 0.1 * np.eye(n)
    g = rng.normal(size=n) * 10.0
    x0 = rng.normal(size=n)
    A = rng.normal(size=(m, n))
    C = rng.normal(size=(k, n))
    cx = C @ x0
    width = rng.uniform(0.05, 1.0, size=k)
    lower = np.where(rng.random(k) < 0.2, -np.inf, cx - width)
    return QP(H, g, A, A @ x0, C, lower, cx + width)


def _clarabel(qp: QP) -> np.ndarray:
    """The same QP by cvxpy and Clarabel (an interior-point conic solver; the identification's
    dependency): a second method that shares nothing with DAQP."""
    import cvxpy as cp

    x = cp.Variable(qp.g.size)
    constraints = []
    if qp.A is not None and qp.A.size:
        constraints.append(qp.A @ x == qp.b)
    finite_u, finite_l = np.isfinite(qp.u), np.isfinite(qp.l)
    constraints += [qp.C[finite_u] @ x <= qp.u[finite_u], qp.C[finite_l] @ x >= qp.l[finite_l]]
    problem = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(qp.H)) + qp.g @ x), constraints)
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    return np.asarray(x.value)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(2, 30), m=st.integers(0, 3), k=st.integers(1, 60))
def test_daqp_answers_the_qp_to_its_kkt_conditions(seed: int, n: int, m: int, k: int) -> None:
    """Random strictly convex QPs: the KKT residual (stationarity, feasibility, signs,
    complementarity: computed by kkt_residual, not by the solver) is below 1e-7 of the cost's
    scale, and the objective equals Clarabel's to 1e-7 of its size (ProxQP, the first second
    method tried, called some of these feasible QPs infeasible)."""
    qp = _random_qp(seed, n, min(m, n - 1), k)
    ours = solve_qp_active_set(qp)
    assert kkt_residual(qp, ours) <= 1e-7 * max(1.0, float(np.abs(qp.g).max()))

    def f(x: np.ndarray) -> float:
        return float(0.5 * x @ qp.H @ x + qp.g @ x)

    assert f(ours.x) == pytest.approx(f(_clarabel(qp)), rel=1e-7, abs=1e-7)
    assert f(ours.x) <= f(_clarabel(qp)) + 1e-9 * max(1.0, abs(f(ours.x)))


def test_a_warm_start_from_the_answer_takes_one_iteration() -> None:
    """Started from its own multipliers (the active set), the solver adds no row: at most one
    iteration, the same point."""
    qp = _random_qp(7, 25, 2, 80)
    cold = solve_qp_active_set(qp)
    assert cold.iterations > 1 and np.count_nonzero(cold.z) > 0
    warm = solve_qp_active_set(qp, cold)
    assert warm.iterations <= 1
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-10)


def test_rows_that_cannot_all_hold_are_named_with_the_equalities_kept() -> None:
    """x₀ + x₁ = 4 with x₀ <= 1 and x₁ <= 1: the rows cannot hold with the equality; the
    message names the labelled row missed most (by 1, the elastic solution splits the excess
    evenly: either row), its bounds and value."""
    qp = QP(
        np.eye(2), np.zeros(2), np.array([[1.0, 1.0]]), np.array([4.0]), np.eye(2), np.full(2, -np.inf),
        np.ones(2), labels=["the velocity limit of joint 1", "the velocity limit of joint 2"],
    )  # fmt: skip
    with pytest.raises(OptimizationError) as caught:
        solve_qp_active_set(qp, what="a test QP")
    message = str(caught.value)
    assert "with the equalities kept, the velocity limit of joint" in message
    missed = float(message.split(" is missed by ")[1].split(" ")[0])
    assert missed == pytest.approx(1.0, rel=1e-4)
