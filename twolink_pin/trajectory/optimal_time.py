"""The minimum-time reference through via points, the via times free (``optimize --cost
time``; :func:`~twolink_pin.trajectory.optimal.optimize`).

It starts from the time-optimal retiming of the reference
(:func:`~twolink_pin.trajectory.retiming.time_optimal`, TOPP-RA): its via times and its motion.
A spline through the via points (:func:`~twolink_pin.trajectory.optimal_spline.spline_problem`:
one segment per via interval, ``C⁴`` where they meet, at rest at both ends; the acceleration
jumps across the period as a retiming's does) is free to leave the retiming's path between the
via points, so it may be faster. The search scales the retiming's via times uniformly: each
**probe** is a feasibility solve (the least ``∫‖q⃛‖² dt`` within every limit at that scale,
from the last feasible spline); from scale 1 it steps down (:data:`SEARCH_STEP`, doubled after
each feasible probe) until a probe fails, then bisects, and it **stops when the gain left to
find is below** :data:`SEARCH_TOLERANCE` of the duration (the shortest feasible and the longest
infeasible scale that close). A probe whose linearised limits cannot all hold fails at once
(the active-set solver says so in a few iterations: :mod:`twolink_pin.optimal.active_set`),
so the failed probes that end the search cost little. The result is never longer than the
retiming: when no spline is as fast (a near-bang-bang timing a ``C⁴`` spline cannot follow
within the limits), the retiming itself is the answer.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.errors import OptimizationError
from twolink_pin.limits import ACCELERATION, EFFORT, POSITION, VELOCITY, JointLimits
from twolink_pin.model import RobotModel
from twolink_pin.optimal.cost import Cost
from twolink_pin.optimal.refinement import solve_within_limits
from twolink_pin.optimal.sqp import SQPOptions
from twolink_pin.optimal.transcription import TrajectoryProblem
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.optimal_spline import CHECK, Vias, fit, knot_samples, pieces, spline_problem
from twolink_pin.trajectory.retiming import TimeOptimal, time_optimal
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

KNOT_SPACING = 0.25
"""Time between two knots of the longest segment of the *reference's* via times [s] (about)."""
STRETCHES = (1.0, 1.01, 1.03, 1.1)
"""The search starts from the retiming's via times, stretched by these until a spline keeps
every limit with them."""
SEARCH_STEP = 0.02
"""The search's first step down from its start (doubled after each feasible probe until one
is not; then bisection)."""
SEARCH_TOLERANCE = 4e-3
"""It stops when the shortest feasible and the longest infeasible scaling are this close
(relative): the gain it leaves unfound is below this fraction of the duration."""
TIME_MARGIN = 1e-3
"""The fraction of each limit a minimum-time spline keeps free: near-bang-bang, its torque
turns fast, and between the check grid's points (100 per piece) it rose up to 3e-5 of a limit
(1e-5 was the margin)."""
PROBE_ITERATIONS = 25
"""SQP iterations of one probe (a probe that needs more counts as infeasible)."""
PROBE_ROUNDS = 8
"""Most solves of one probe (each after adding the points where a limit peaked beyond it
between the check points)."""
PROBE_QP_ITERATIONS = 400
"""ProxQP iterations of a probe's step when the active-set solver hands it over."""
HULL = (POSITION, VELOCITY, ACCELERATION)
"""The limits kept on the spline's coefficients (everywhere, no grid); effort at the check points."""


class _Probe(NamedTuple):
    """A spline that keeps every limit with the via times ``scale`` times the retiming's."""

    scale: float
    problem: TrajectoryProblem
    x: np.ndarray


class _Search(NamedTuple):
    """What the probes share: the problem at the retiming's via times (``base``); a probe's
    is the same with its durations scaled (the points, in normalised time, are the same)."""

    base: TrajectoryProblem

    def problem(self, scale: float) -> TrajectoryProblem:
        """The probe's problem at ``scale`` times the retiming's via times."""
        layout = self.base.layout
        assert layout.durations is not None
        return replace(
            self.base,
            layout=replace(layout, durations=layout.durations * scale),
            time_scale=self.base.time_scale * scale,
        )


def _search(
    robot: RobotModel,
    vias: Vias,
    limits: JointLimits,
    friction: Friction | None,
    times: np.ndarray,
    count: int,
) -> _Search:
    """The search on the via times ``times`` [s] (the retiming's, from 0), ``count`` knot
    intervals per segment."""
    base = spline_problem(
        robot, times, vias, limits, friction, Cost(jerk=1.0), rest=(1,), pieces_per_segment=count, continuity=4,
        kinds=(EFFORT,), hull=HULL, margin=TIME_MARGIN,
    )  # fmt: skip
    return _Search(base)


def _probe(search: _Search, scale: float, x0: np.ndarray, iterations: list[int]) -> _Probe | None:
    """A spline through the via points at ``scale`` times the retiming's via times within
    every limit (the least ``∫‖q⃛‖² dt``, from the variables ``x0``: the same in normalised time
    at every scale), or None when the solver finds none in :data:`PROBE_ITERATIONS` SQP
    iterations."""
    problem = search.problem(scale)
    options = SQPOptions(max_iterations=PROBE_ITERATIONS, qp_iterations=PROBE_QP_ITERATIONS, explain=False)
    try:
        solved = solve_within_limits(
            problem, x0, options, per_piece=CHECK, rounds=PROBE_ROUNDS, what="a probe"
        )
    except OptimizationError as exc:
        iterations[0] += exc.iterations
        return None
    iterations[0] += solved.iterations
    return _Probe(scale, solved.problem, solved.result.x)


def _time_search(search: _Search, retimed: SampledTrajectory) -> tuple[_Probe, int]:
    """The shortest uniform scaling of the retiming's via times for which a spline keeps every
    limit (module docstring); the SQP iterations."""
    x0 = fit(search.base.layout, retimed, retimed.via_times)
    spent = [0]
    best = None
    for stretch in STRETCHES:
        best = _probe(search, stretch, x0, spent)
        if best is not None:
            break
    if best is None:
        raise OptimizationError(
            "the minimum-time trajectory",
            "no spline keeps the limits near the retiming's via times",
            spent[0],
        )
    low, step = None, SEARCH_STEP
    while low is None or best.scale - low > SEARCH_TOLERANCE * best.scale:
        interrupts.check()
        trial = best.scale * (1.0 - step) if low is None else 0.5 * (low + best.scale)
        found = _probe(search, trial, best.x, spent)
        if found is None:
            low = trial
        else:
            best, step = found, 2.0 * step
    return best, spent[0]


def minimum_time(
    robot: RobotModel, via: Trajectory, vias: Vias, limits: JointLimits, friction: Friction | None
) -> tuple[SampledTrajectory, int, TimeOptimal]:
    """The minimum-time trajectory (module docstring), its SQP iterations, the retiming it
    started from: the spline search's result, or the retiming itself when no spline keeps
    the limits as fast."""
    retimed = time_optimal(robot, via, limits=limits, friction=friction)
    via_times = retimed.trajectory.via_times
    search = _search(
        robot, vias, limits, friction, via_times - via_times[0], pieces(vias.times, KNOT_SPACING)
    )
    try:
        best, spent = _time_search(search, retimed.trajectory)
    except OptimizationError as err:
        return retimed.trajectory, err.iterations, retimed
    result = knot_samples(best.problem, best.x, 0.0, 0.0, best.scale * (via_times - via_times[0]))
    if result.period > retimed.duration:
        return retimed.trajectory, spent, retimed
    return result, spent, retimed


__all__ = ["SEARCH_STEP", "SEARCH_TOLERANCE", "STRETCHES", "TIME_MARGIN", "minimum_time"]
