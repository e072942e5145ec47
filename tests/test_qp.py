"""Tests of twolink_pin.optimal.qp: the one QP solve, against closed forms and its own KKT
conditions computed independently of the solver."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.errors import OptimizationError
from twolink_pin.optimal import QP, kkt_residual, solve_qp, unconstrained_minimiser

FIXTURES = Path(__file__).resolve().parent / "fixtures"


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


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_the_unconstrained_minimiser_first_is_prox_qps_answer(seed: int) -> None:
    """solve_qp(unconstrained_first=True) on random strictly convex QPs with equalities and
    boxes: when the equality-constrained minimiser (numpy's KKT solve) lies inside every box it
    is returned after 0 iterations with zero inequality multipliers, else ProxQP's; either way
    it is ProxQP's answer to 1e-7 and meets the KKT conditions (residual computed here)."""
    rng = np.random.default_rng(seed)
    n, m, k = 6, 2, 8
    M = rng.normal(size=(n, n))
    H, g = M @ M.T + 0.1 * np.eye(n), rng.normal(size=n)
    C = rng.normal(size=(k, n))
    width = rng.uniform(0.5, 20.0)  # narrow boxes bind, wide ones do not
    point = np.linalg.lstsq(C, rng.uniform(-0.5, 0.5, k) * width, rcond=None)[0]
    if not np.all(np.abs(C @ point) <= width):
        point = np.zeros(n)
    A = rng.normal(size=(m, n))
    b = A @ point  # equalities that a point inside every box meets
    qp = QP(H, g, A, b, C, -width * np.ones(k), width * np.ones(k))
    K = np.block([[H, A.T], [A, np.zeros((m, m))]])
    free = np.linalg.solve(K, np.concatenate([-g, b]))[:n]
    inside = bool(np.all(np.abs(C @ free) <= width))
    first = solve_qp(qp, unconstrained_first=True)
    prox = solve_qp(qp)
    assert (first.iterations == 0) == inside
    if inside:
        np.testing.assert_allclose(first.x, free, rtol=0, atol=1e-12)
        assert not first.z.any()
    np.testing.assert_allclose(first.x, prox.x, atol=1e-7)
    assert kkt_residual(qp, first) < 1e-6


def test_the_unconstrained_minimiser_needs_a_positive_definite_hessian() -> None:
    """A semidefinite H (min x0² with x1 free, x1 in [0, 1]) has no unique minimiser: the
    linear solve is not tried, ProxQP answers; an outside minimiser is not returned either."""
    qp = QP(np.diag([1.0, 0.0]), np.array([-1.0, 0.0]), C=np.eye(2), l=np.zeros(2), u=np.ones(2))
    assert unconstrained_minimiser(qp) is None
    assert solve_qp(qp, unconstrained_first=True).iterations > 0
    outside = QP(np.eye(2), np.array([-2.0, 0.0]), C=np.eye(2), l=np.zeros(2), u=np.ones(2))
    assert unconstrained_minimiser(outside) is None
    np.testing.assert_allclose(solve_qp(outside, unconstrained_first=True).x, [1.0, 0.0], atol=1e-8)


def test_bounds_beyond_the_cap_are_none_on_their_loose_side_and_the_cap_on_the_other() -> None:
    """A damper of horizon 1e-12 s asks for bounds of 1e24 (issue 48): on the equilibrated problem a
    bound past BOUND_CAP on its loose side is no bound (−inf / +inf), one past it on the tight side
    is the cap (the problem stays infeasible, with sane numbers), and the minimiser of a problem
    whose bounds are loose is the unconstrained one. ProxQP's inner iterations are capped, so a QP
    that cannot hold is told so within max_iter outer iterations of at most max_inner each."""
    from twolink_pin.optimal.qp import BOUND_CAP, equilibrate

    H, g = np.diag([2.0, 8.0]), np.array([-2.0, 8.0])
    C = np.eye(2)
    loose = QP(H, g, None, None, C, np.array([-1e24, -1e30]), np.array([1e24, 1e30]))
    scaled, _ = equilibrate(loose)
    assert np.all(np.isneginf(scaled.l)) and np.all(np.isposinf(scaled.u))
    np.testing.assert_allclose(solve_qp(loose, scale=True, max_inner=20).x, [1.0, -1.0], atol=1e-9)
    tight = QP(H, g, None, None, C, np.array([1e24, -1.0]), np.array([1.0, 1.0]))  # x₀ ≥ 1e24 and ≤ 1
    scaled, _ = equilibrate(tight)
    assert scaled.l[0] == BOUND_CAP and np.isfinite(scaled.u[0])
    with pytest.raises(OptimizationError, match="cannot all hold"):
        solve_qp(tight, scale=True, max_iter=200, max_inner=20, infeasibility_eps=1e-9)


MPC_SETTINGS = {"infeasibility_eps": 1e-9, "scale": True, "accept": 1e-6, "max_inner": 20}
"""What mpc asks of :func:`solve_qp` for a replan (``twolink_pin/controllers/mpc.py``)."""


def _pr2_replan(side: str) -> QP:
    """A replan of mpc on the PR2's ``side`` arm at its defaults (issue 50: ``examples/arms``;
    the left one at t = 0 s, the right one at t = 0.31 s; 56 variables, 536 box rows), saved
    as mpc built it."""
    saved = np.load(FIXTURES / f"pr2_{side}_replan_qp.npz")
    return QP(saved["H"], saved["g"], None, None, saved["C"], saved["l"], saved["u"])


def _clarabel_optimum(qp: QP) -> float:
    """The QP's optimal cost by Clarabel (an interior-point method, through cvxpy): the second
    method, which never calls ProxQP; raises unless Clarabel finds it feasible and solved."""
    import cvxpy as cp

    assert qp.C is not None and qp.l is not None and qp.u is not None
    x = cp.Variable(qp.g.shape[0])
    rows = [qp.C @ x <= qp.u, qp.C @ x >= qp.l]
    problem = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(qp.H)) + qp.g @ x), rows)
    problem.solve(solver="CLARABEL")
    assert problem.status == cp.OPTIMAL, problem.status
    return float(problem.value)


@pytest.mark.parametrize("side", ["left", "right"])
def test_a_feasible_replan_prox_qp_flags_infeasible_is_solved(side: str) -> None:
    """ProxQP flags these feasible replans PRIMAL_INFEASIBLE at mpc's tolerance 1e-9 (its
    iterate within 1e-7 of every row); :func:`solve_qp` solves them: the cost is Clarabel's to
    1e-7 relative, the KKT conditions (computed here) hold to 1e-6 and every row to 1e-6."""
    import proxsuite

    from twolink_pin.optimal.qp import _solve_set, equilibrate

    qp = _pr2_replan(side)
    flagged = _solve_set(equilibrate(qp)[0], None, 1e-9, 200, None, 1e-9, 0.0, 20)
    assert flagged.info.status == proxsuite.proxqp.PROXQP_PRIMAL_INFEASIBLE  # the case still arises
    solution = solve_qp(qp, max_iter=200, **MPC_SETTINGS)  # raised OptimizationError before
    cost = 0.5 * solution.x @ qp.H @ solution.x + qp.g @ solution.x
    best = _clarabel_optimum(qp)
    assert abs(cost - best) <= 1e-7 * max(1.0, abs(best)), (cost, best)
    assert kkt_residual(qp, solution) < 1e-6


def test_constraints_that_cannot_hold_still_fail_at_mpc_settings() -> None:
    """The re-solves do not turn a QP that cannot hold (x0 >= 1 and x0 <= -1, among boxes
    that can) into an answer: it still raises, naming the row."""
    C = np.vstack([np.eye(3), [[1.0, 0.0, 0.0]]])
    qp = QP(np.eye(3), np.ones(3), None, None, C, np.array([1.0, -2, -2, -np.inf]), np.array([np.inf, 2, 2, -1.0]),
            labels=("lower", "b1", "b2", "upper"))  # fmt: skip
    with pytest.raises(
        OptimizationError, match=r"cannot all hold: the closest point misses (lower|upper) by"
    ):
        solve_qp(qp, max_iter=200, **MPC_SETTINGS)
