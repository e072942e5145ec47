"""Tests of twolink_pin.optimal.qp: the one QP solve, against closed forms and its own KKT
conditions computed independently of the solver."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.errors import OptimizationError
from twolink_pin.optimal import QP, kkt_residual, solve_qp


def test_equality_constrained_qp_equals_the_kkt_system_solved_by_numpy() -> None:
    rng = np.random.default_rng(1)
    n, m = 8, 3
    M = rng.normal(size=(n, n))
    H, g = M @ M.T + np.eye(n), rng.normal(size=n)
    A, b = rng.normal(size=(m, n)), rng.normal(size=m)
    K = np.block([[H, A.T], [A, np.zeros((m, m))]])
    expected = np.linalg.solve(K, np.concatenate([-g, b]))
    solution = solve_qp(QP(H, g, A, b))
    np.testing.assert_allclose(solution.x, expected[:n], atol=1e-8)
    np.testing.assert_allclose(solution.y, expected[n:], atol=1e-7)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_box_qp_meets_its_kkt_conditions(seed: int) -> None:
    """Random strictly convex QPs with boxes on random rows: the KKT residual computed here
    (not the solver's report) is below 1e-6, and an active bound's multiplier has its sign."""
    rng = np.random.default_rng(seed)
    n, k = 6, 10
    M = rng.normal(size=(n, n))
    H, g = M @ M.T + 0.1 * np.eye(n), 10 * rng.normal(size=n)
    C = rng.normal(size=(k, n))
    qp = QP(H, g, None, None, C, -np.ones(k), np.ones(k))
    solution = solve_qp(qp)
    assert kkt_residual(qp, solution) < 1e-6
    cx = C @ solution.x
    assert np.all(solution.z[cx < 1 - 1e-6] <= 1e-7) and np.all(solution.z[cx > -1 + 1e-6] >= -1e-7)


def test_a_kkt_residual_sees_a_wrong_answer() -> None:
    H, g = np.eye(2), np.array([1.0, -1.0])
    qp = QP(H, g)
    good = solve_qp(qp)
    assert kkt_residual(qp, good) < 1e-9
    assert kkt_residual(qp, good._replace(x=good.x + 1e-3)) > 9e-4


def test_constraints_that_cannot_hold_name_the_row() -> None:
    """x0 >= 1 and x0 <= -1: the error names a labelled row and the gap."""
    C = np.array([[1.0, 0.0], [1.0, 0.0]])
    qp = QP(np.eye(2), np.zeros(2), None, None, C, np.array([1.0, -np.inf]), np.array([np.inf, -1.0]),
            labels=("effort of joint 1 at t = 0.2 s", "velocity of joint 1 at t = 0.2 s"))  # fmt: skip
    with pytest.raises(
        OptimizationError,
        match=r"cannot all hold: the closest point misses (effort|velocity) of joint 1 at t = 0.2 s by",
    ):
        solve_qp(qp, what="the test QP")


def test_warm_start_from_the_answer_needs_few_iterations() -> None:
    rng = np.random.default_rng(3)
    n = 12
    M = rng.normal(size=(n, n))
    qp = QP(
        M @ M.T + np.eye(n),
        rng.normal(size=n),
        None,
        None,
        rng.normal(size=(20, n)),
        -np.ones(20),
        np.ones(20),
    )
    cold = solve_qp(qp)
    warm = solve_qp(qp, cold)
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-7)
    assert warm.iterations <= cold.iterations
