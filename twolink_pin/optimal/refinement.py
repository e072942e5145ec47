"""Limits between the check points: solve, look on a finer grid, add what it finds, solve again.

A trajectory problem keeps its limits at its check points (a few per knot interval). Between
them the spline can bulge past a limit. :func:`solve_within_limits` solves the problem
(:func:`~twolink_pin.optimal.sqp.solve_sqp`), evaluates every limit on a grid ``fine`` times
finer, adds each fine point where a row is beyond its (margin-tightened) bound to the check
points, and solves again from the solution, until the fine grid finds nothing: then every
limit holds on the fine grid to the problem's margin (a fraction of the limit kept free).
Between the fine grid's points a quantity can still rise by about ``(Δt)²/8`` times its second
derivative: with 40 fine points per knot interval that is far below the margin for the
trajectories here (the docs' page states the measured figures).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.errors import OptimizationError
from twolink_pin.optimal.layout import Points
from twolink_pin.optimal.sqp import SQPOptions, SQPResult, solve_sqp
from twolink_pin.optimal.transcription import TrajectoryProblem

FINE = 25
"""The fine grid has this many times the check grid's points per knot interval."""
ROUNDS = 6
"""Most solves (the first and those after adding points)."""


class WithinLimits(NamedTuple):
    """What :func:`solve_within_limits` returns."""

    result: SQPResult
    """The last solve."""
    problem: TrajectoryProblem
    """The problem with every check point it ended with."""
    iterations: int
    """SQP iterations over all solves."""
    rounds: int
    """Solves."""
    fine_excess: float
    """The largest excess on the fine grid over the tightened bounds (a fraction of the
    limit), at most the SQP's feasibility tolerance, which is below the margin: <= 0 over
    the limits themselves."""


def _excess_points(
    problem: TrajectoryProblem, x: np.ndarray, fine: Points, tolerance: float
) -> tuple[np.ndarray, float]:
    """The fine points where a limit row is beyond its (tightened) bound by more than
    ``tolerance``, and the largest excess."""
    ev = problem.with_check_points(fine).evaluate(x)
    rows = np.maximum(ev.lower - ev.inequality, ev.inequality - ev.upper)
    limit_rows = rows[: problem.grid_rows(fine.size)]
    if not limit_rows.size:
        return np.zeros(0, dtype=int), -np.inf
    per_point = np.concatenate(
        [b.reshape(fine.size, -1) for b in _blocks(problem, limit_rows, fine.size)], axis=1
    )
    worst = per_point.max(axis=1)
    return np.flatnonzero(worst > tolerance), float(worst.max())


def _blocks(problem: TrajectoryProblem, rows: np.ndarray, k: int) -> list[np.ndarray]:
    """The inequality rows split by limit kind (each (K · joints with the limit),)."""
    out, start = [], 0
    for kind in problem.kinds:
        joints = int(problem.limits.given(kind).sum())
        if joints:
            out.append(rows[start : start + k * joints])
            start += k * joints
    return out


def _merged(problem: TrajectoryProblem, extra: Points) -> Points:
    """The check points and ``extra`` together."""
    points = problem.check_points
    layout = problem.layout
    segment = np.concatenate([points.segment, extra.segment])
    sigma = np.concatenate([points.sigma, extra.sigma])
    return layout.points(segment, sigma)


def solve_within_limits(
    problem: TrajectoryProblem,
    x0: np.ndarray,
    options: SQPOptions | None = None,
    *,
    per_piece: int,
    fine: int = FINE,
    rounds: int = ROUNDS,
    what: str = "the trajectory optimisation",
) -> WithinLimits:
    """Solve ``problem`` (checked at ``per_piece`` points per knot interval) so that its limits
    hold on a grid ``fine`` times finer too (module docstring).

    Raises:
        OptimizationError: a solve failed, or the fine grid still found a limit exceeded
            after ``rounds`` solves (by how much said).
    """
    fine_points = problem.layout.grid(per_piece * fine)
    x, warm, iterations = np.asarray(x0, dtype=float), None, 0
    excess = np.inf
    for round_ in range(1, rounds + 1):
        interrupts.check()
        result = solve_sqp(problem, x, options, warm=warm, what=what)
        iterations += result.iterations
        x = result.x
        bad, excess = _excess_points(problem, x, fine_points, (options or SQPOptions()).feasibility)
        if bad.size == 0:
            return WithinLimits(result, problem, iterations, round_, excess)
        extra = problem.layout.points(fine_points.segment[bad], fine_points.sigma[bad])
        problem = problem.with_check_points(_merged(problem, extra))
    raise OptimizationError(
        what,
        f"a limit is still exceeded by {excess:.3g} of it between the check points after {rounds} solves",
        iterations,
    )


__all__ = ["FINE", "ROUNDS", "WithinLimits", "solve_within_limits"]
