"""Sequential quadratic programming on a :class:`~twolink_pin.optimal.transcription.TrajectoryProblem`.

Each iteration linearises the problem at ``x`` (Gauss–Newton model of the cost, linearised
constraints) and solves the step ``d`` with
:func:`~twolink_pin.optimal.active_set.solve_qp_active_set` (DAQP's dual active-set method,
its active set started from the previous step's: a handful of iterations once the active
limits settle; ProxQP when DAQP stops without an answer)::

    min_d  s (∇fᵀd + dᵀJᵀJ d) + ½ μ dᵀ D d
    s.t.   c_E(x) + A_E d = 0,   l <= c_I(x) + A_I d <= u

``s`` normalises the cost by its value at the start; ``μ D`` (Levenberg–Marquardt damping,
``D = diag(2 s JᵀJ) + mean of it``) is the trust region: a step is accepted when the ℓ1
merit ``φ = s f + ρ (‖c_E‖₁ + Σ excess of c_I)`` falls by at least a small fraction of what the
model predicts, and ``μ`` shrinks after a good step and grows after a poor or rejected one.
``ρ`` stays above twice the largest multiplier (an exact penalty). The loop stops when a
step is below ``step_tolerance`` (relative to ``x``) or the model predicts no decrease, with
every constraint within ``feasibility``; otherwise after ``max_iterations`` QP solves it
raises :class:`~twolink_pin.errors.OptimizationError` with the remaining violation.

:func:`sqp_step` is one full step without the merit test (real-time iteration, Diehl et al.
2005): what a receding-horizon law does once per replanning period from its shifted previous
plan.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.errors import InvalidParameterError, OptimizationError
from twolink_pin.optimal.active_set import solve_qp_active_set
from twolink_pin.optimal.qp import QP, QPSolution, solve_qp
from twolink_pin.optimal.transcription import Evaluation, TrajectoryProblem

PROXIMAL_RHO = 1e-8
"""ProxQP's proximal step on the primal variables for the steps' QPs (its default 1e-6 was
large beside the smallest curvature of these steps: 1635 iterations instead of 200 on the UR5)."""
INFEASIBILITY_EPS = 1e-9
"""ProxQP's infeasibility tolerances for the steps' QPs (its default, 1e-4, declared feasible
steps infeasible: badly scaled rows)."""
QP_ITERATIONS = 3000
"""Most ProxQP iterations of one step (a step closer than 1000 times its tolerance is taken
as it is then)."""
TRUST_RADIUS = 0.05
"""The first trust region on free durations: each step within this fraction of each."""
MAX_RADIUS = 0.5
"""The largest it grows to."""


@dataclass(frozen=True)
class SQPOptions:
    """The stopping rules and trust region of :func:`solve_sqp`.

    Attributes:
        max_iterations: Most QP solves (accepted and rejected steps).
        step_tolerance: A step ``‖d‖∞ <= step_tolerance (1 + ‖x‖∞)`` ends the loop.
        feasibility: Largest violation accepted at the end (equalities [rad], inequalities
            [fraction of their limit]).
        cost_tolerance: A step whose model predicts a merit decrease below this fraction of
            the starting cost ends the loop.
        damping: Initial Levenberg–Marquardt ``μ``.
        qp_tolerance: ProxQP's absolute tolerance.
        qp_iterations: Most ProxQP iterations of one step.
        screen: A limit row enters the QP once it is within this fraction of its limit
            (or a step brings it within half of that); the others cannot be active.
        explain: Whether a step's QP without solution names the constraint that cannot hold.
    """

    max_iterations: int = 60
    step_tolerance: float = 1e-9
    cost_tolerance: float = 1e-5
    feasibility: float = 1e-6
    damping: float = 1e-3
    qp_tolerance: float = 1e-9
    qp_iterations: int = QP_ITERATIONS
    screen: float = 0.5
    explain: bool = True

    def __post_init__(self) -> None:
        for name in ("max_iterations", "qp_iterations"):
            value = getattr(self, name)
            if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
                raise InvalidParameterError(name, value, "an integer >= 1")
        for name in ("step_tolerance", "cost_tolerance", "feasibility", "damping", "qp_tolerance", "screen"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise InvalidParameterError(name, value, "a finite number > 0")


class SQPResult(NamedTuple):
    """What :func:`solve_sqp` returns."""

    x: np.ndarray
    """The solution's variables."""
    evaluation: Evaluation
    """The problem at ``x`` (cost, constraint values, torques at the check points)."""
    iterations: int
    """QP solves."""
    qp: QPSolution | None
    """The last QP's solution (a warm start for a problem of the same sizes)."""
    seconds: float
    """Wall time [s]."""
    multipliers: np.ndarray | None = None
    """The last step's multiplier of every inequality row of ``problem`` in its own scale (0:
    a row left out of the QP; positive: the upper bound active): where another solve of a
    problem with these rows first may start its active set."""
    damping: float | None = None
    """The last Levenberg–Marquardt ``μ``."""


class StepResult(NamedTuple):
    """What :func:`sqp_step` returns."""

    x: np.ndarray
    """``x + d``."""
    qp: QPSolution
    """The step's QP solution (warm start of the next)."""
    evaluation: Evaluation
    """The problem at the old ``x`` (linearised)."""


class _ScaledQP(NamedTuple):
    """A step's QP with its rows and objective normalised (ProxQP's absolute tolerances then
    mean the same on every problem), and the factors to undo it."""

    qp: QP
    objective: float
    """The objective was multiplied by this."""
    equality_rows: np.ndarray
    """Each equality row was divided by this."""
    inequality_rows: np.ndarray
    """Each inequality row of the problem was divided by this."""
    trust: int
    """Rows after the problem's: the trust region on free durations."""

    def multipliers(self, solution: QPSolution) -> np.ndarray:
        """The step's multipliers of the problem's rows in its own scale (equalities, then
        inequalities; not the trust region's)."""
        z = solution.z[: solution.z.size - self.trust]
        return np.concatenate(
            [solution.y / self.equality_rows / self.objective, z / self.inequality_rows / self.objective]
        )


def _rows(J: np.ndarray | None) -> np.ndarray:
    """The largest entry of each row of ``J`` (1 for an empty row)."""
    if J is None or not J.size:
        return np.ones(0 if J is None else J.shape[0])
    norm = np.abs(J).max(axis=1)
    return np.where(norm > 0, norm, 1.0)


def _qp(
    problem: TrajectoryProblem,
    x: np.ndarray,
    ev: Evaluation,
    scale: float,
    mu: float,
    rows: np.ndarray | None = None,
    radius: float | None = None,
) -> _ScaledQP:
    """The step's QP at ``x`` (module docstring), normalised, with the inequality rows
    ``rows`` (default all) and, with free durations and a ``radius``, a trust region on them:
    each duration's step within ``radius`` times the duration."""
    assert ev.gradient is not None and ev.residual_jacobian is not None and ev.inequality_jacobian is not None
    J = ev.residual_jacobian
    H = 2.0 * scale * (J.T @ J)
    diag = np.diag(H).copy()
    D = diag + 1e-9 * max(float(diag.max()), 1e-300)
    H[np.diag_indices_from(H)] += mu * D
    g = scale * ev.gradient
    objective = 1.0 / max(float(np.abs(np.diag(H)).max()), 1e-300)
    keep = np.arange(ev.inequality.size) if rows is None else rows
    A = ev.equality_jacobian if ev.equality.size else None
    C = ev.inequality_jacobian[keep]
    ea, ec = _rows(A), _rows(C)
    C, lower, upper = (
        C / ec[:, None],
        (ev.lower - ev.inequality)[keep] / ec,
        (ev.upper - ev.inequality)[keep] / ec,
    )
    layout, trust = problem.layout, 0
    labels: Sequence[str] = _Subset(problem.labels(x), keep)
    if layout.free_durations and radius is not None:
        S = layout.segments
        h = layout.durations_of(x)
        T = np.zeros((S, layout.size))
        T[np.arange(S), S * layout.block + np.arange(S)] = 1.0 / h
        C, lower, upper = (
            np.vstack([C, T]),
            np.append(lower, np.full(S, -radius)),
            np.append(upper, np.full(S, radius)),
        )
        labels, trust = (
            _Subset(
                [*labels, *(f"the trust region of segment {k}'s duration" for k in range(S))],
                np.arange(C.shape[0]),
            ),
            S,
        )
    qp = QP(
        H * objective,
        g * objective,
        None if A is None else A / ea[:, None],
        None if A is None else -ev.equality / ea,
        C if C.size else None,
        lower if C.size else None,
        upper if C.size else None,
        labels=labels if C.size else None,
    )
    return _ScaledQP(qp, objective, ea, ec, trust)


class _Subset(Sequence[str]):
    """The labels of some rows of a longer list of labels."""

    def __init__(self, labels: Sequence[str], rows: np.ndarray) -> None:
        self.labels, self.rows = labels, rows

    def __len__(self) -> int:
        return int(self.rows.size)

    def __getitem__(self, i: int) -> str:  # type: ignore[override]
        return self.labels[int(self.rows[i])]


def _warm(warm: QPSolution | None, qp: QP) -> QPSolution | None:
    """``warm`` if it fits ``qp``'s sizes."""
    if warm is None:
        return None
    m = 0 if qp.A is None else qp.A.shape[0]
    k = 0 if qp.C is None else qp.C.shape[0]
    if warm.x.shape != qp.g.shape or warm.y.shape != (m,) or warm.z.shape != (k,):
        return None
    return warm


def sqp_step(
    problem: TrajectoryProblem,
    x: np.ndarray,
    warm: QPSolution | None = None,
    *,
    damping: float = 1e-8,
    what: str = "the trajectory step",
) -> StepResult:
    """One full SQP step from ``x`` (real-time iteration): linearise, solve the QP
    (warm-started from ``warm``), return ``x + d``. The cost is not normalised (a receding
    horizon's weights set its scale); every inequality row is in the QP.

    Raises:
        OptimizationError: the QP has no solution (a constraint that cannot hold, named).
    """
    ev = problem.evaluate(x, jacobians=True)
    scaled = _qp(problem, x, ev, 1.0, damping)
    solution = solve_qp(
        scaled.qp, _warm(warm, scaled.qp), what=what, rho=PROXIMAL_RHO, infeasibility_eps=INFEASIBILITY_EPS
    )
    return StepResult(x + solution.x, solution, ev)


def _excess(ev: Evaluation) -> np.ndarray:
    """How far each inequality row lies beyond its bounds (negative: inside) [fraction of its
    limit]."""
    return np.maximum(ev.lower - ev.inequality, ev.inequality - ev.upper)


class _Loop:
    """The state of :func:`solve_sqp`'s iterations."""

    def __init__(
        self,
        problem: TrajectoryProblem,
        x0: np.ndarray,
        options: SQPOptions,
        warm: QPSolution | None,
        multipliers: np.ndarray | None = None,
    ):
        self.problem, self.options = problem, options
        self.x = np.array(x0, dtype=float)
        self.ev = problem.evaluate(self.x, jacobians=True)
        self.scale = 1.0 / max(abs(self.ev.cost), 1e-12)
        self.mu, self.rho = options.damping, 1.0
        self.solves, self.last_step = 0, np.inf
        self.gained, self.left = np.inf, np.inf  # the last accepted step's cost decrease, the model's next
        self.z = np.zeros(self.ev.inequality.size)  # the multipliers of every row (0: not in the QP)
        if multipliers is not None and multipliers.shape == self.z.shape:
            self.z = np.array(multipliers, dtype=float)
        self.warm = warm
        self.watched = (_excess(self.ev) > -options.screen) | (self.z != 0)
        self.radius = TRUST_RADIUS if problem.layout.free_durations else None

    def step(self, what: str) -> bool:
        """One QP solve and its test; True once converged."""
        ev, options = self.ev, self.options
        rows = np.flatnonzero(self.watched)
        scaled = _qp(self.problem, self.x, ev, self.scale, self.mu, rows, self.radius)
        z = np.append(self.z[rows] * scaled.objective * scaled.inequality_rows, np.zeros(scaled.trust))
        warm = None if self.warm is None else self.warm._replace(z=z)
        if warm is None and z.any():  # the active set a previous solve of these rows ended with
            equalities = 0 if scaled.qp.A is None else scaled.qp.A.shape[0]
            warm = QPSolution(np.zeros(scaled.qp.g.size), np.zeros(equalities), z, 0, 0.0, 0.0)
        fallback = {
            "eps": options.qp_tolerance, "max_iter": options.qp_iterations, "accept": 1e3 * options.qp_tolerance,
            "rho": PROXIMAL_RHO, "infeasibility_eps": INFEASIBILITY_EPS,
        }  # fmt: skip
        try:
            solution = solve_qp_active_set(
                scaled.qp, _warm(warm, scaled.qp), what=what, explain=options.explain, fallback=fallback
            )
        except OptimizationError as exc:  # counted in SQP iterations, not the QP solver's
            raise OptimizationError(exc.problem, exc.reason, self.solves + 1) from None
        self.solves += 1
        d = solution.x
        multipliers = scaled.multipliers(solution)
        assert ev.gradient is not None and ev.residual_jacobian is not None
        Jd = ev.residual_jacobian @ d
        model = self.scale * (float(ev.gradient @ d) + float(Jd @ Jd))  # the cost's predicted change
        self.rho = max(self.rho, 2.0 * float(np.abs(multipliers).max(initial=0.0)))
        if (
            ev.violation > options.feasibility and model > 0
        ):  # feasibility bought with cost: worth it (N&W 18.36)
            self.rho = max(self.rho, 2.0 * model / ev.l1_violation)
        predicted = self.rho * ev.l1_violation - model
        self.left = -model
        if ev.violation <= options.feasibility and -model <= options.cost_tolerance:
            return True  # feasible, and the model sees no cost left to gain
        merit = self.scale * ev.cost + self.rho * ev.l1_violation
        trial = self.problem.evaluate(self.x + d, jacobians=True)
        missed = (_excess(trial) > -0.5 * options.screen) & ~self.watched
        if missed.any():  # rows left out of the QP came near their bounds: solve again with them
            self.watched |= missed
            return False
        actual = merit - (self.scale * trial.cost + self.rho * trial.l1_violation)
        small = float(np.abs(d).max()) <= options.step_tolerance * (1.0 + float(np.abs(self.x).max()))
        if not (small or actual >= 1e-4 * predicted):
            self.mu *= 10.0
            self.radius = None if self.radius is None else self.radius / 4.0
            return False
        self.x, self.ev, self.last_step = self.x + d, trial, float(np.abs(d).max())
        self.gained = self.scale * (ev.cost - trial.cost)
        self.warm = solution
        self.z = np.zeros(trial.inequality.size)
        self.z[rows] = solution.z[: rows.size] / scaled.objective / scaled.inequality_rows
        self.watched |= _excess(trial) > -options.screen
        ratio = actual / predicted if predicted > 0 else 1.0
        self.mu = max(self.mu / 4.0, 1e-12) if ratio > 0.75 else self.mu * 4.0 if ratio < 0.25 else self.mu
        if self.radius is not None:
            self.radius = (
                min(2.0 * self.radius, MAX_RADIUS)
                if ratio > 0.75
                else self.radius / 4.0
                if ratio < 0.25
                else self.radius
            )
        return (small or abs(actual) <= options.cost_tolerance) and trial.violation <= options.feasibility


def solve_sqp(
    problem: TrajectoryProblem,
    x0: np.ndarray,
    options: SQPOptions | None = None,
    *,
    warm: QPSolution | None = None,
    what: str = "the trajectory optimisation",
    multipliers: np.ndarray | None = None,
) -> SQPResult:
    """Minimise ``problem`` from ``x0`` (module docstring); ``warm``: a previous step's QP
    solution (same rows), ``multipliers``: each inequality row's multiplier from a previous
    solve of the same rows (:attr:`SQPResult.multipliers`), where the active set starts.

    Raises:
        OptimizationError: a QP without solution, or no convergence within the iterations
            (the remaining violation and step size said).
    """
    options = options or SQPOptions()
    start = time.perf_counter()
    loop = _Loop(problem, x0, options, warm, multipliers)
    while loop.solves < options.max_iterations:
        interrupts.check()
        if loop.step(what):
            return SQPResult(
                loop.x, loop.ev, loop.solves, loop.warm, time.perf_counter() - start, loop.z, loop.mu
            )
    raise OptimizationError(what, _unconverged(loop), loop.solves)


def _unconverged(loop: _Loop) -> str:
    """What did not converge in ``loop``'s iterations, by how much: the constraints (their
    largest violation), or, with them holding, the cost (what the last step gained and the
    model sees left, fractions of the starting cost)."""
    options, violation = loop.options, loop.ev.violation
    cost = (
        f"the last accepted step lowered the cost by {loop.gained:.3g} of its starting value and the model sees "
        f"{loop.left:.3g} more (tolerance {options.cost_tolerance:g})"
    )
    if violation <= options.feasibility:
        return (
            f"the cost did not settle in {loop.solves} SQP iterations: {cost}; the constraints hold (largest "
            f"violation {violation:.3g}, tolerance {options.feasibility:g})"
        )
    return (
        f"the constraints do not hold after {loop.solves} SQP iterations: the largest violation is still "
        f"{violation:.3g} (tolerance {options.feasibility:g}), the last step {loop.last_step:.3g}; {cost}"
    )


__all__ = ["SQPOptions", "SQPResult", "StepResult", "solve_sqp", "sqp_step"]
