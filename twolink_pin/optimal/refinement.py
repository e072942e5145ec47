"""Limits between the check points: solve, look on a finer grid, add what it finds, solve again.

A trajectory problem keeps its limits at its check points (a few per knot interval). Between
them the spline can bulge past a limit. :func:`solve_within_limits` solves the problem
(:func:`~twolink_pin.optimal.sqp.solve_sqp`), evaluates every limit on a grid ``fine`` times
finer, and adds to the check points the fine points where a limit's excess over its bound
(tightened by the problem's margin) peaks — a local maximum in time of one joint's row of one
kind that lies beyond the bound — then solves again from the solution, its active set started
from the last one (:attr:`~twolink_pin.optimal.sqp.SQPResult.multipliers`), until the fine
grid finds no row beyond its limit: every limit then holds on the fine grid. A bulge adds one
point (its peak), not every fine point it covers: an arc that rides a velocity limit for a
second added hundreds of points, each row of the QP, where its peaks are a few (the exchange
method of semi-infinite programming: Hettich & Kortanek, SIAM Review 1993).

"Beyond its limit" is the limit itself: the margin (a fraction of each limit kept free, 1e-5
by default, at the check points) is what a row may use between them before a point is added,
so that the last rounds do not chase excesses of 1e-6 over the margin-tightened bound while the
limit holds (they took half the rounds on the UR5). Between the fine grid's points a quantity can still rise by about ``(Δt)²/8`` times its
second derivative: with 100 fine points per knot interval that is far below the margin for
the trajectories here (the docs' page states the measured figures).
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.errors import OptimizationError
from twolink_pin.optimal.layout import Points
from twolink_pin.optimal.sqp import SQPOptions, SQPResult, solve_sqp
from twolink_pin.optimal.transcription import TrajectoryProblem

FINE = 25
"""The fine grid has this many times the check grid's points per knot interval."""
LOCAL = 17
"""Points at which a peak's neighbourhood on the fine grid (its two neighbours and between) is
evaluated again: 8 times finer."""
ROUNDS = 12
"""Most solves (the first and those after adding points)."""
DAMPING_FLOOR = 1e-6
"""A later round starts its Levenberg–Marquardt ``μ`` where the last one ended, not below this
(a solution that moves a little when points are added needs no trust region to speak of)."""


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
    """The largest excess on the fine grid over the limits themselves (a fraction of the
    limit; of the range's scale for a position): at most the SQP's feasibility tolerance,
    negative when the margin is kept."""


def _row_excess(problem: TrajectoryProblem, x: np.ndarray, points: Points) -> np.ndarray:
    """Each limit row's excess over the limit itself (margin 0) at ``points``, shape (K, rows
    per point): a fraction of the limit, negative inside."""
    ev = replace(problem, margin=0.0).with_check_points(points).evaluate(x)
    rows = np.maximum(ev.lower - ev.inequality, ev.inequality - ev.upper)[: problem.grid_rows(points.size)]
    if not rows.size:
        return np.zeros((points.size, 0))
    return np.concatenate([b.reshape(points.size, -1) for b in _blocks(problem, rows, points.size)], axis=1)


def _excess_points(
    problem: TrajectoryProblem, x: np.ndarray, fine: Points, tolerance: float
) -> tuple[Points, float]:
    """Where a limit row peaks beyond the limit itself (not the margin-tightened bound) by more
    than ``tolerance``, and the largest excess [fraction of the limit]. A peak is a local
    maximum in time of one joint's row of one kind on the fine grid whose neighbourhood may
    rise beyond the limit (the parabola through it and its two neighbours does); the row is
    evaluated there on :data:`LOCAL` points between its neighbours and its largest value kept
    when it is beyond (a velocity that rode its limit with a jerk of 140 rad/s³ rose 1.5e-5 of
    it above the fine grid's values; at a kink — a torque whose derivative jumps with the jerk
    at a via point — the parabola overshoots, the points do not)."""
    layout = problem.layout
    empty = layout.points(np.zeros(0, dtype=int), np.zeros(0))
    E = _row_excess(problem, x, fine)
    if not E.size:
        return empty, -np.inf
    inner, left, right = E[1:-1], E[:-2], E[2:]
    curvature = left - 2.0 * inner + right  # < 0 at a strict peak
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.clip(np.where(curvature < 0, 0.5 * (left - right) / curvature, 0.0), -0.5, 0.5)
    vertex = inner - 0.25 * (left - right) * shift  # the parabola's value at its vertex
    k, column = np.nonzero((inner >= left) & (inner > right) & (np.maximum(vertex, inner) > tolerance))
    worst = float(E.max())
    if not k.size:
        return empty, worst
    t = layout.times(x, fine)
    offsets = np.linspace(-1.0, 1.0, LOCAL)  # from the left neighbour to the right one
    before, after = (t[k + 1] - t[k])[:, None], (t[k + 2] - t[k + 1])[:, None]
    local = t[k + 1][:, None] + np.where(offsets[None, :] < 0, before, after) * offsets[None, :]
    at = layout.points(*layout.locate(x, local.ravel()))
    value = _row_excess(problem, x, at)[np.arange(at.size), np.repeat(column, LOCAL)].reshape(k.size, LOCAL)
    best = np.argmax(value, axis=1)
    peak = value[np.arange(k.size), best]
    worst = max(worst, float(peak.max()))
    keep = np.flatnonzero(peak > tolerance)
    chosen = keep * LOCAL + best[keep]
    return layout.points(at.segment[chosen], at.sigma[chosen]), worst


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
    """The check points and ``extra`` together (``extra`` after them)."""
    points = problem.check_points
    layout = problem.layout
    segment = np.concatenate([points.segment, extra.segment])
    sigma = np.concatenate([points.sigma, extra.sigma])
    return layout.points(segment, sigma)


def _grown(
    problem: TrajectoryProblem, multipliers: np.ndarray | None, old: int, new: int
) -> np.ndarray | None:
    """The inequality multipliers of ``problem`` with ``old`` check points laid out for
    ``new`` of them (the added points after the old ones in each kind's block, with none)."""
    if multipliers is None:
        return None
    out, start = [], 0
    for kind in problem.kinds:
        joints = int(problem.limits.given(kind).sum())
        if joints:
            block = np.zeros(new * joints)
            block[: old * joints] = multipliers[start : start + old * joints]
            out.append(block)
            start += old * joints
    out.append(multipliers[start:])  # the rows after the grid's (hull, durations): the same
    return np.concatenate(out)


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
    options = options or SQPOptions()
    x, iterations, multipliers = np.asarray(x0, dtype=float), 0, None
    excess = np.inf
    for round_ in range(1, rounds + 1):
        interrupts.check()
        result = solve_sqp(problem, x, options, what=what, multipliers=multipliers)
        iterations += result.iterations
        x = result.x
        extra, excess = _excess_points(problem, x, fine_points, 0.0)
        if extra.size == 0:
            return WithinLimits(result, problem, iterations, round_, excess)
        old = problem.check_points.size
        problem = problem.with_check_points(_merged(problem, extra))
        multipliers = _grown(problem, result.multipliers, old, problem.check_points.size)
        if result.damping is not None:
            options = replace(options, damping=max(result.damping, DAMPING_FLOOR))
    raise OptimizationError(
        what,
        f"a limit is still exceeded by {excess:.3g} of it between the check points after {rounds} solves",
        iterations,
    )


__all__ = ["FINE", "ROUNDS", "WithinLimits", "solve_within_limits"]
