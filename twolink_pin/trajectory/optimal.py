"""Optimal trajectories through via points: the least effort with the via times given, or the
shortest duration with the via times free, within every limit of the arm.

The joint trajectory is a quintic B-spline, one segment between each two via points
(:mod:`twolink_pin.trajectory.optimal_spline`, on :mod:`twolink_pin.optimal`: one core for this
and the model-predictive law); the torque comes from Pinocchio's RNEA and its analytical
derivatives (:class:`~twolink_pin.dynamics.RneaDerivatives`, the robot's model with its
payload, plus a plant's friction when given); the problem is solved by SQP whose steps are QPs
solved by a dual active-set method (DAQP), its limits checked on a grid 25 times finer than
the one they are constrained on and a point added where a limit's excess peaks
(:func:`~twolink_pin.optimal.solve_within_limits`).

- ``cost="effort"``: the least ``∫ τᵀτ dt`` with the via times of the reference, regularised by
  default (:mod:`twolink_pin.trajectory.optimal_effort`: the cost, the regulariser, the ends).
- ``cost="time"``: the shortest duration with the via times free, from the reference's
  time-optimal retiming (:mod:`twolink_pin.trajectory.optimal_time`).

The result is a :class:`~twolink_pin.trajectory.sampled.SampledTrajectory`: the spline's
samples at its knots (exact: a quintic between two knots is what its quintic Hermite
interpolation reproduces) with the torque it was designed with; it is measured here
(:mod:`twolink_pin.trajectory.optimal_measures`), not by the solver: every limit on the check
grid (:func:`~twolink_pin.limits.check_limits`), ``∫ τᵀτ dt``, the via errors and how far the end
effector leaves the convex hull of the via points.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from twolink_pin.errors import InvalidParameterError, require_type
from twolink_pin.limits import VELOCITY, JointLimits, LimitsCheck, check_limits, joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.optimal.sqp import SQPOptions
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.optimal_effort import (
    DEFAULT_REGULARISER,
    ENDS,
    REGULARISER_WEIGHT,
    REGULARISERS,
    Regulariser,
    minimum_effort,
)
from twolink_pin.trajectory.optimal_measures import (
    HullExcursion,
    effort_integral,
    hull_excursion,
    pose_error,
    violation,
)
from twolink_pin.trajectory.optimal_spline import Vias, check_reference_needs, check_vias, vias_of
from twolink_pin.trajectory.optimal_time import minimum_time
from twolink_pin.trajectory.retiming import TimeOptimal
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

COSTS = ("effort", "time")
"""What :func:`optimize` can minimise."""
MAX_ITERATIONS = 60
"""Default most SQP iterations per solve."""


class OptimalTrajectory(NamedTuple):
    """What :func:`optimize` returns."""

    trajectory: SampledTrajectory
    """The optimal reference (samples at the spline's knots, with its torque)."""
    cost: str
    """``effort`` or ``time``."""
    duration: float
    """Its motion's duration [s] (the period: the reference's for ``effort``)."""
    effort: float
    """Its ``∫ τᵀτ dt`` over a period [N²·m²·s] (RNEA on a fine grid, trapezoid)."""
    reference_duration: float
    """The reference's motion [s] (via-point span)."""
    reference_effort: float
    """The reference's ``∫ τᵀτ dt`` over its period [N²·m²·s] (the same way)."""
    retimed_duration: float | None
    """``time``: the time-optimal retiming of the reference's path [s] (the start)."""
    via_error: float
    """Largest ``|q(t_k) − q_k|`` at the via points [rad], from the samples."""
    pose_error: tuple[float, float] | None
    """For via poses: the largest position [m] and rotation [rad] error of the end effector
    at the via times (forward kinematics of the samples)."""
    max_violation: float | None
    """The largest excess over any limit on the check grid, a fraction of the limit (of the
    range for a position); <= 0: within every limit; None: the robot has no limit."""
    check: LimitsCheck
    """Every limit on the check grid (:func:`~twolink_pin.limits.check_limits`)."""
    limits: JointLimits
    """The limits (scaled)."""
    iterations: int
    """SQP iterations, all solves."""
    seconds: float
    """Wall time [s]."""
    hull: HullExcursion
    """How far the end effector leaves the convex hull of its positions at the via points."""
    reference_hull: HullExcursion
    """The same for the reference."""
    ends: str | None = None
    """``effort``: the end conditions (:data:`~twolink_pin.trajectory.optimal_effort.ENDS`)."""
    regulariser: Regulariser | None = None
    """``effort``: the regulariser it was designed with."""


def optimize(
    robot: RobotModel,
    via: Trajectory,
    cost: str = "effort",
    *,
    limit_scale: float = 1.0,
    limits: JointLimits | None = None,
    friction: Friction | None = None,
    max_iterations: int = MAX_ITERATIONS,
    ends: str = "smooth",
    regulariser: str = DEFAULT_REGULARISER,
    regulariser_weight: float = REGULARISER_WEIGHT,
) -> OptimalTrajectory:
    """The trajectory through ``via``'s via points that minimises ``cost`` within every limit
    of ``robot`` (module docstring).

    Args:
        robot: The arm (its model, payload included, gives the torque).
        via: A reference through via points (joint, end-effector or via poses: after their
            inverse kinematics, the joint via points are kept exactly).
        cost: ``effort`` (``∫ τᵀτ dt`` [N²·m²·s] plus the regulariser, the via times of
            ``via``) or ``time`` (the duration [s], the via times free).
        limit_scale: Fraction ``0 < F <= 1`` of each velocity, acceleration and effort limit.
        limits: The limits (default :func:`~twolink_pin.limits.joint_limits` of ``robot``).
        friction: A plant's joint friction added to the torque, or None.
        max_iterations: Most SQP iterations per solve.
        ends: ``effort``: ``smooth`` (at rest, zero acceleration and jerk at both ends) or
            ``rest`` (at rest only) (:mod:`~twolink_pin.trajectory.optimal_effort`).
        regulariser: ``effort``: ``path`` (``w_q ∫ ‖q − q_ref(t)‖² dt`` added: near the
            reference's path), ``velocity`` (``w_v ∫ ‖q̇‖² dt``) or ``none`` (the effort alone).
        regulariser_weight: ``κ``, the regulariser's weight as a fraction of the reference's
            effort (:mod:`~twolink_pin.trajectory.optimal_effort`).

    Raises:
        InvalidParameterError: an unknown cost, end condition or regulariser, a reference
            without via points, a via point outside a position range or where gravity alone
            exceeds an effort limit, no velocity limit for ``time``, ``limit_scale`` outside
            (0, 1].
        OptimizationError: the solver did not converge (what did not, by how much, what to
            try), or its constraints cannot hold.
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    require_type(via, Trajectory, "via", "a Trajectory through via points (twolink_pin.read_trajectory_file)")
    if cost not in COSTS:
        raise InvalidParameterError("cost", cost, f"one of {', '.join(COSTS)}")
    if ends not in ENDS:
        raise InvalidParameterError("ends", ends, f"one of {', '.join(ENDS)}")
    if regulariser not in REGULARISERS:
        raise InvalidParameterError("regulariser", regulariser, f"one of {', '.join(REGULARISERS)}")
    start = time.perf_counter()
    wanted = (joint_limits(robot) if limits is None else limits).scaled(limit_scale)
    vias = vias_of(via)
    check_vias(robot, vias, wanted, timed=cost == "effort")
    if cost == "effort":  # the retiming checks its own (the timing free)
        check_reference_needs(robot, via, wanted)
    from twolink_pin.blas import one_blas_thread

    with one_blas_thread():  # small dense algebra: BLAS threads only spin (twolink_pin.blas)
        if cost == "effort":
            options = SQPOptions(max_iterations=max_iterations, screen=0.03)
            result, iterations, chosen = minimum_effort(
                robot, via, vias, wanted, friction, options, ends=ends, regulariser=regulariser, kappa=regulariser_weight
            )  # fmt: skip
            design: tuple[TimeOptimal | None, str | None, Regulariser | None] = (None, ends, chosen)
        else:
            wanted.require(VELOCITY, "find the shortest duration")
            result, iterations, retimed = minimum_time(robot, via, vias, wanted, friction)
            design = (retimed, None, None)
    return _report(robot, via, vias, result, cost, wanted, friction, design, iterations, start)


def _report(
    robot: RobotModel,
    via: Trajectory,
    vias: Vias,
    result: SampledTrajectory,
    cost: str,
    limits: JointLimits,
    friction: Friction | None,
    design: tuple[TimeOptimal | None, str | None, Regulariser | None],
    iterations: int,
    start: float,
) -> OptimalTrajectory:
    """The result measured: its effort and the reference's, via errors, every limit on the
    check grid, the end effector's excursion from the via points' hull."""
    retimed, ends, regulariser = design
    check = check_limits(robot, result, limits=limits, friction=friction)
    via_error = float(np.abs(result.sample(result.via_times).q - vias.q).max())
    return OptimalTrajectory(
        result, cost, result.period, effort_integral(robot, result, friction),
        float(vias.times[-1] - vias.times[0]), effort_integral(robot, via, friction),
        None if retimed is None else float(retimed.duration),
        via_error, pose_error(robot, result, vias), violation(check), check, limits, iterations,
        time.perf_counter() - start, hull_excursion(robot, result, vias.q), hull_excursion(robot, via, vias.q),
        ends, regulariser,
    )  # fmt: skip


__all__ = [
    "COSTS",
    "DEFAULT_REGULARISER",
    "ENDS",
    "MAX_ITERATIONS",
    "REGULARISERS",
    "REGULARISER_WEIGHT",
    "OptimalTrajectory",
    "check_vias",
    "effort_integral",
    "optimize",
]
