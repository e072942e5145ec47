"""The one quadratic-program solve every optimisation of the package goes through.

``min ½ xᵀ H x + gᵀ x  s.t.  A x = b,  l <= C x <= u`` solved by ProxQP (``proxsuite``,
dense backend: an augmented-Lagrangian interior of primal-dual proximal iterations that
warm-starts well, Bambade et al. 2022), the solver of the trajectory optimiser's SQP
steps, the model-predictive law's replans and the constrained task-space law's steps.

A QP solved again and again whose inequalities rarely bind (a constrained law's step) may ask
for its **unconstrained minimiser first** (``unconstrained_first``): one linear solve of the
cost's stationarity under the equalities; when that point satisfies every inequality it is the
QP's solution (the KKT conditions hold with zero inequality multipliers: the start of Goldfarb
and Idnani's dual active-set method, 1983) and ProxQP is not called.

Each row of ``C`` may carry a label (``"effort of joint 2 at t = 0.31 s"``), so that a
problem whose constraints cannot all hold names the one most violated by ProxQP's
closest feasible point. :func:`kkt_residual` measures a solution's optimality
independently of the solver's own report.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.errors import OptimizationError

DEFAULT_EPS = 1e-9
"""Absolute tolerance on the primal and dual residuals (ProxQP's ``eps_abs``)."""
STRICT_INFEASIBILITY_EPS = 1e-9
"""ProxQP's primal and dual infeasibility tolerances for a second solve of a QP its default
(1e-4) flagged infeasible: a problem that truly cannot hold is flagged again (or named below by
its closest point), a feasible one is solved."""
NEAR_FEASIBLE = 1e3
"""A QP flagged infeasible whose iterate meets every row to within this times ``eps`` (or
``accept``, the larger) is solved again with infeasibility never declared (:func:`_solve_checked`)."""
DEFAULT_MAX_ITER = 10_000
"""Most ProxQP iterations of one solve."""
BOUND_CAP = 1e12
"""An equilibrated problem's bound beyond ±this (rows of unit largest coefficient, variables of
unit curvature) is read as none on its side (±inf) or as this on the other (a bound no point
of the problem's scale reaches: the problem stays infeasible, with sane numbers)."""


class QP(NamedTuple):
    """A dense convex QP; ``None`` for a block that is absent."""

    H: np.ndarray
    """Hessian, symmetric positive semidefinite, shape (n, n)."""
    g: np.ndarray
    """Linear cost, shape (n,)."""
    A: np.ndarray | None = None
    """Equality rows, shape (n_eq, n)."""
    b: np.ndarray | None = None
    """Equality right-hand side, shape (n_eq,)."""
    C: np.ndarray | None = None
    """Inequality rows, shape (n_in, n)."""
    l: np.ndarray | None = None  # noqa: E741  (the solver's and the literature's name)
    """Lower bounds of ``C x`` (``-inf``: none), shape (n_in,)."""
    u: np.ndarray | None = None
    """Upper bounds of ``C x`` (``inf``: none), shape (n_in,)."""
    labels: Sequence[str] | None = None
    """What each inequality row is, for messages (one per row of ``C``; any sequence: a long
    one may make its labels when one is read)."""


class QPSolution(NamedTuple):
    """What :func:`solve_qp` returns."""

    x: np.ndarray
    """The minimiser, shape (n,)."""
    y: np.ndarray
    """Multipliers of the equalities, shape (n_eq,)."""
    z: np.ndarray
    """Multipliers of the inequalities (positive: the upper bound active), shape (n_in,)."""
    iterations: int
    """ProxQP iterations."""
    primal_residual: float
    """ProxQP's primal residual (largest constraint violation)."""
    dual_residual: float
    """ProxQP's dual residual."""


def kkt_residual(qp: QP, solution: QPSolution) -> float:
    """The largest violation of the KKT conditions at ``solution``, computed here, not by the
    solver: stationarity ``‖H x + g + Aᵀ y + Cᵀ z‖∞``, primal feasibility, the sign of each
    multiplier against the side of its bound (a multiplier against a side without a bound,
    ±inf, is its own violation), and complementarity ``|z_i| · dist(C_i x, its bound)`` (all in
    the problem's own units)."""
    x, y, z = solution.x, solution.y, solution.z
    stationarity = qp.H @ x + qp.g
    residuals = []
    if qp.A is not None and qp.A.size:
        stationarity = stationarity + qp.A.T @ y
        residuals.append(np.abs(qp.A @ x - qp.b).max())
    if qp.C is not None and qp.C.size:
        assert qp.l is not None and qp.u is not None
        stationarity = stationarity + qp.C.T @ z
        cx = qp.C @ x
        residuals.append(np.maximum(np.maximum(qp.l - cx, cx - qp.u), 0.0).max())
        # z > 0 pushes against the upper bound, z < 0 against the lower one; against a side
        # that has no bound (±inf) a multiplier is itself the violation (its sign is wrong)
        finite_u, finite_l = np.isfinite(qp.u), np.isfinite(qp.l)
        upper = np.where(finite_u, np.abs(np.where(finite_u, qp.u, 0.0) - cx), 1.0)
        lower = np.where(finite_l, np.abs(cx - np.where(finite_l, qp.l, 0.0)), 1.0)
        residuals.append((np.maximum(z, 0.0) * upper).max())
        residuals.append((np.maximum(-z, 0.0) * lower).max())
    residuals.append(np.abs(stationarity).max())
    return float(max(residuals))


def solve_qp(
    qp: QP,
    warm: QPSolution | None = None,
    *,
    eps: float = DEFAULT_EPS,
    max_iter: int = DEFAULT_MAX_ITER,
    what: str = "QP",
    unconstrained_first: bool = False,
    accept: float | None = None,
    explain: bool = True,
    rho: float | None = None,
    infeasibility_eps: float | None = None,
    scale: bool = False,
    gap_rel: float = 0.0,
    max_inner: int | None = None,
) -> QPSolution:
    """Solve ``qp`` with ProxQP (dense), warm-started from ``warm`` when given.

    Args:
        qp: The problem.
        warm: A previous solution of a problem of the same sizes (primal and dual start).
        eps: Absolute tolerance of the primal and dual residuals.
        max_iter: Most iterations.
        what: The problem in words, for messages (``"the MPC replan at t = 1.2 s"``).
        unconstrained_first: First try the minimiser of the cost under the equalities alone
            (:func:`unconstrained_minimiser`): when it satisfies every inequality it is
            returned (0 iterations, zero inequality multipliers), else ProxQP solves the QP.
        accept: When ProxQP stops at ``max_iter`` with both residuals below this, its point
            is the answer (an SQP step needs no more than a descent direction; None: never).
        explain: Whether a failure names the constraint that cannot hold (a second solve;
            False where the failure is an answer in itself, a feasibility probe's).
        rho: ProxQP's proximal step on the primal variables (None: its default, 1e-6; the
            trajectory optimiser's steps take 1e-8: 200 iterations where 1e-6 took 1635).
        infeasibility_eps: ProxQP's primal and dual infeasibility tolerances (None: its
            default, 1e-4, which declared the trajectory optimiser's feasible steps
            infeasible; it takes 1e-9, a problem that cannot hold still told apart below).
        scale: Solve the problem equilibrated (:func:`equilibrate`: every variable of unit
            curvature, every row of unit largest coefficient) and map the solution back, so
            that ``eps`` and ``accept`` mean the same on an arm whose joint inertias span
            four decades as on one whose do not; the residuals returned are the scaled ones.
        gap_rel: ProxQP's relative duality-gap tolerance (the absolute one is ``eps``): a
            problem whose costs are large (a relaxed QP's penalties, 10⁶) cannot close its gap to
            1e-9 absolutely; it takes ``eps`` relative.
        max_inner: Most of ProxQP's inner (Newton) iterations per outer one (None: its 1500):
            ``max_iter`` bounds the outer ones only, and a problem that cannot hold took 1300
            inner iterations per outer one, a second a solve, where a law asks for thousands.

    Raises:
        OptimizationError: ProxQP did not solve it: the constraints cannot all hold (the
            closest feasible point misses one: the row, by its label, and by how much) or
            it stopped without converging (its status and iterations).
    """
    if unconstrained_first:
        inside = unconstrained_minimiser(qp)
        if inside is not None:
            return inside
    n = qp.g.shape[0]
    problem, back = equilibrate(qp) if scale else (qp, None)
    start = warm if back is None or warm is None else back.scaled(warm)
    settings = _Settings(eps, max_iter, rho, infeasibility_eps, gap_rel, max_inner)
    result = _solve_checked(problem, start, settings, accept)
    _check_status(qp, result.info, accept, explain, eps, max_iter, what)
    m = 0 if qp.A is None else qp.A.shape[0]
    k = 0 if qp.C is None else qp.C.shape[0]
    info = result.info
    x = np.array(result.x[:n], dtype=float)
    solution = QPSolution(
        x,
        np.array(result.y[:m], dtype=float),
        np.array(result.z[:k], dtype=float),
        int(info.iter),
        float(info.pri_res),
        float(info.dua_res),
    )
    return solution if back is None else back.unscaled(solution)


def _check_status(
    qp: QP, info: Any, accept: float | None, explain: bool, eps: float, max_iter: int, what: str
) -> None:
    """Raise :class:`OptimizationError` unless ProxQP solved ``qp`` (or stopped at its
    iteration cap within ``accept``), naming the row that cannot hold (``explain``) or the status."""
    import proxsuite

    proxqp = proxsuite.proxqp
    status = info.status
    near = (
        accept is not None
        and status == proxqp.PROXQP_MAX_ITER_REACHED
        and info.iter > 0  # with no iteration run ProxQP reports residuals of 0
        and max(info.pri_res, info.dua_res) <= accept
    )
    if status == proxqp.PROXQP_SOLVED or near:
        return
    # ProxQP flags infeasibility only sometimes (an unbounded side keeps it iterating):
    # the closest feasible point tells a problem that cannot hold from a slow one
    flagged = status == proxqp.PROXQP_PRIMAL_INFEASIBLE
    infeasible = _infeasible_reason(qp, eps, max_iter, flagged) if explain else None
    reason = infeasible or (
        f"ProxQP stopped with status {str(status).rsplit('.', 1)[-1]} after {info.iter} iterations "
        f"(primal residual {info.pri_res:.3g}, dual residual {info.dua_res:.3g})"
    )
    raise OptimizationError(what, reason, int(info.iter))


class Equilibration(NamedTuple):
    """How :func:`equilibrate` scaled a QP: ``x = D x'``, ``C' = R C D``, ``A' = S A D``
    (multipliers ``z = R z'``, ``y = S y'``)."""

    D: np.ndarray
    """Variable scales, (n,)."""
    R: np.ndarray
    """Inequality row scales, (n_in,)."""
    S: np.ndarray
    """Equality row scales, (n_eq,)."""

    def scaled(self, solution: QPSolution) -> QPSolution:
        """A solution of the original problem in the scaled variables (a warm start)."""
        return solution._replace(x=solution.x / self.D, y=solution.y / self.S, z=solution.z / self.R)

    def unscaled(self, solution: QPSolution) -> QPSolution:
        """A solution of the scaled problem in the original variables."""
        return solution._replace(x=solution.x * self.D, y=solution.y * self.S, z=solution.z * self.R)


def equilibrate(qp: QP) -> tuple[QP, Equilibration]:
    """``qp`` scaled so that every variable has unit curvature and every constraint row a
    largest coefficient of 1 (Jacobi on the Hessian's diagonal, then each row by its
    ∞-norm): ``x = D x'`` with ``D = diag(H)^(−1/2)`` (1 where the curvature is 0), ``H' = D H D``,
    ``g' = D g``, ``C' = R C D`` with ``l, u`` times ``R`` (beyond :data:`BOUND_CAP`: none, or the
    cap). The minimiser and the active set are the same; the solver's absolute tolerances then
    weigh every joint alike (an arm whose
    wrist inertia is 10⁻⁴ of its shoulder's has a Hessian whose diagonal spans eight decades,
    on which an absolute dual tolerance of 1e-9 is met for the shoulder long before the wrist)."""
    diagonal = np.diag(qp.H)
    D = np.where(diagonal > 0, 1.0 / np.sqrt(np.where(diagonal > 0, diagonal, 1.0)), 1.0)
    H = qp.H * D[:, None] * D[None, :]
    g = qp.g * D

    def rows(M: np.ndarray | None) -> tuple[np.ndarray | None, np.ndarray]:
        if M is None or not M.size:
            return M, np.ones(0 if M is None else M.shape[0])
        scaled = M * D[None, :]
        largest = np.abs(scaled).max(axis=1)
        r = np.where(largest > 0, 1.0 / np.where(largest > 0, largest, 1.0), 1.0)
        return scaled * r[:, None], r

    A, S = rows(qp.A)
    C, R = rows(qp.C)
    b = None if qp.b is None else qp.b * S
    # a bound beyond BOUND_CAP (a damper of horizon 1e-12 s asks for 1e24 rad/s²) is as good as
    # none on one side and as impossible on the other: ProxQP took a second a solve on such numbers
    lower = None if qp.l is None else np.clip(qp.l * R, -np.inf, BOUND_CAP)
    lower = None if lower is None else np.where(lower < -BOUND_CAP, -np.inf, lower)
    upper = None if qp.u is None else np.clip(qp.u * R, -BOUND_CAP, np.inf)
    upper = None if upper is None else np.where(upper > BOUND_CAP, np.inf, upper)
    return QP(H, g, A, b, C, lower, upper, qp.labels), Equilibration(D, R, S)


class _Settings(NamedTuple):
    """What :func:`solve_qp` asks of ProxQP (None: its default)."""

    eps: float
    max_iter: int
    rho: float | None
    infeasibility_eps: float | None
    gap_rel: float
    max_inner: int | None


def _solve_checked(qp: QP, warm: QPSolution | None, settings: _Settings, accept: float | None) -> Any:
    """ProxQP's solve of ``qp`` (its functional solve when every setting is its default); when
    it says the QP cannot hold, solved again before that is believed:

    - at ProxQP's default tolerances, again at :data:`STRICT_INFEASIBILITY_EPS` (ProxQP flagged
      a box QP that x = 0 satisfies at its 1e-4 after 13 iterations, tests/test_qp.py seed 8425);
    - flagged while its iterate met every row to within ``accept`` (or 1e3 ``eps``: a QP that
      cannot hold misses a row by far more): again with infeasibility never declared
      (tolerances 0), ProxQP going on to its iteration cap, whose point :func:`_check_status`
      accepts within ``accept``. ProxQP flagged two feasible replans of mpc on the PR2's arms at
      1e-9 (and at 1e-12) with primal residuals of 8.5e-8 and 3.2e-9 (tests/test_qp.py): so
      solved, the first in 41 iterations, the second at its cap within 3.2e-9.

    A QP that truly cannot hold is flagged again or stops, and is named by its closest point."""
    import proxsuite

    flagged = proxsuite.proxqp.PROXQP_PRIMAL_INFEASIBLE
    eps, max_iter, rho, infeasibility, gap_rel, max_inner = settings
    if rho is None and infeasibility is None and max_inner is None:
        result = _solve_default(qp, warm, eps, max_iter, gap_rel)
    else:
        result = _solve_set(qp, warm, eps, max_iter, rho, infeasibility, gap_rel, max_inner)
    if result.info.status == flagged and infeasibility is None:
        result = _solve_set(qp, warm, eps, max_iter, rho, STRICT_INFEASIBILITY_EPS, gap_rel, max_inner)
    near = max(accept or 0.0, NEAR_FEASIBLE * eps)
    if result.info.status == flagged and result.info.pri_res <= near:
        result = _solve_set(qp, warm, eps, max_iter, rho, 0.0, gap_rel, max_inner)
    return result


def _solve_default(qp: QP, warm: QPSolution | None, eps: float, max_iter: int, gap_rel: float = 0.0) -> Any:
    """ProxQP's functional dense solve with its default settings, the duality gap checked
    (without it ProxQP may stop with an active bound 1e-5 away); its results."""
    import proxsuite

    proxqp = proxsuite.proxqp
    kwargs = {}
    if warm is not None:
        kwargs = {"x": warm.x, "y": warm.y, "z": warm.z, "initial_guess": proxqp.InitialGuess.WARM_START}
    return proxqp.dense.solve(
        qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u, eps_abs=eps, eps_rel=0.0, max_iter=max_iter,
        check_duality_gap=True, eps_duality_gap_abs=eps, eps_duality_gap_rel=gap_rel, **kwargs,
    )  # fmt: skip


def _solve_set(
    qp: QP,
    warm: QPSolution | None,
    eps: float,
    max_iter: int,
    rho: float | None,
    infeasibility: float | None,
    gap_rel: float = 0.0,
    max_inner: int | None = None,
) -> Any:
    """ProxQP's dense solver object with ``rho`` and the infeasibility tolerances set (the
    functional ``dense.solve`` takes neither), the duality gap checked; its results."""
    import proxsuite

    proxqp = proxsuite.proxqp
    m = 0 if qp.A is None else qp.A.shape[0]
    k = 0 if qp.C is None else qp.C.shape[0]
    solver = proxqp.dense.QP(qp.g.shape[0], m, k)
    settings = solver.settings
    settings.eps_abs, settings.eps_rel, settings.max_iter = eps, 0.0, max_iter
    settings.check_duality_gap = True
    settings.eps_duality_gap_abs, settings.eps_duality_gap_rel = eps, gap_rel
    if infeasibility is not None:
        settings.eps_primal_inf = settings.eps_dual_inf = infeasibility
    if rho is not None:
        settings.default_rho = rho
    if max_inner is not None:
        settings.max_iter_in = max_inner
    solver.init(qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u)
    if warm is not None:
        settings.initial_guess = proxqp.InitialGuess.WARM_START
        solver.solve(warm.x, warm.y, warm.z)
    else:
        solver.solve()
    return solver.results


def unconstrained_minimiser(qp: QP) -> QPSolution | None:
    """The minimiser of ``qp``'s cost under its equalities alone — one linear solve of the KKT
    system ``[H Aᵀ; A 0] (x, y) = (−g, b)`` — when ``H`` is positive definite (a Cholesky
    factorisation says so) and that point satisfies every inequality, exactly (no tolerance):
    then it is the QP's solution, with zero inequality multipliers. None otherwise (an
    inequality would be violated, ``H`` is only semidefinite, or the system is singular)."""
    from scipy.linalg import lapack  # imported where used: scipy.linalg is 0.1 s at start-up

    H, g = qp.H, qp.g
    n = g.shape[0]
    m = 0 if qp.A is None else qp.A.shape[0]
    _, x, info = lapack.dposv(H, -g)  # Cholesky of H and the solve: info > 0 when H is not definite
    if info != 0:
        return None
    y = np.zeros(0)
    if m:
        assert qp.A is not None and qp.b is not None
        K = np.zeros((n + m, n + m))
        K[:n, :n], K[:n, n:], K[n:, :n] = H, qp.A.T, qp.A
        try:
            xy = np.linalg.solve(K, np.concatenate((-g, qp.b)))
        except np.linalg.LinAlgError:
            return None
        x, y = xy[:n], xy[n:]
    k = 0 if qp.C is None else qp.C.shape[0]
    if k:
        assert qp.C is not None and qp.l is not None and qp.u is not None
        cx = qp.C @ x
        if not ((cx >= qp.l) & (cx <= qp.u)).all():  # NaN fails both: ProxQP then
            return None
    stationarity = H @ x + g
    primal = 0.0
    if m:
        assert qp.A is not None and qp.b is not None
        stationarity += qp.A.T @ y
        primal = float(np.abs(qp.A @ x - qp.b).max())
    return QPSolution(x, y, np.zeros(k), 0, primal, float(np.abs(stationarity).max()))


def _infeasible_reason(qp: QP, eps: float, max_iter: int, flagged: bool = False) -> str | None:
    """Which constraint the closest feasible point (ProxQP's infeasibility solve) violates
    most, or None when it violates none by more than the tolerance: ``max(1e3 eps, 1e-6)``,
    or ``10 eps`` when ProxQP itself ``flagged`` the problem infeasible (a state at the edge of
    what its limits allow: the closest point then misses a row by a hair, 1e-7, which is
    still the row to name)."""
    import proxsuite

    closest = proxsuite.proxqp.dense.solve(
        qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u,
        eps_abs=eps, eps_rel=0.0, max_iter=max_iter, primal_infeasibility_solving=True,
    )  # fmt: skip
    x = np.asarray(closest.x)
    tolerance = 10 * eps if flagged else max(1e3 * eps, 1e-6)
    if qp.A is not None and qp.A.size:
        assert qp.b is not None
        gap = np.abs(qp.A @ x - qp.b)
        if gap.max() > tolerance:
            return f"the equality constraints cannot all hold (row {int(np.argmax(gap))} missed by {gap.max():.3g})"
    if qp.C is None or not qp.C.size:
        return None
    assert qp.l is not None and qp.u is not None
    cx = qp.C @ x
    excess = np.maximum(qp.l - cx, cx - qp.u)
    i = int(np.argmax(excess))
    if excess[i] <= tolerance:
        return None
    row = qp.labels[i] if qp.labels is not None and i < len(qp.labels) else f"inequality row {i}"
    return (
        f"the constraints cannot all hold: the closest point misses {row} by {excess[i]:.3g} "
        f"(bounds [{qp.l[i]:.6g}, {qp.u[i]:.6g}], value {cx[i]:.6g})"
    )


infeasible_reason = _infeasible_reason
"""Which constraint a QP's closest feasible point violates most, in words (or None): what a
failed solve says; public for the trajectory optimiser's active-set steps
(:mod:`twolink_pin.optimal.active_set`)."""
