"""Optimal trajectories through via points: the least effort with the via times given, or the
shortest duration with the via times free, within every limit of the arm.

The joint trajectory is a quintic B-spline (:mod:`twolink_pin.optimal`: one core for this
and the model-predictive law); the torque comes from Pinocchio's RNEA and its analytical
derivatives (:class:`~twolink_pin.dynamics.RneaDerivatives`, the robot's model with its
payload, plus a plant's friction when given); the problem is solved by SQP with ProxQP
steps, its limits checked on a grid ten times finer than the one they are constrained on
and points added where they are exceeded (:func:`~twolink_pin.optimal.solve_within_limits`).

``cost="effort"`` minimises ``∫ τᵀτ dt`` with the via times of the reference: one spline over
the reference's motion, knots about :data:`KNOT_SPACING` apart (at least :data:`MIN_PIECES`
between two via points), through each via point exactly (a linear equality: the spline's
value there), from rest to rest with zero acceleration and jerk at both ends like the
course's polynomial, so the two compare on the same terms; it starts from the reference
itself (its least-squares fit).

``cost="time"`` minimises the duration with the via times free (their order kept): one spline
segment between two via points, each with its duration a variable, ``q`` to its fourth
derivative continuous where they meet (equalities in the coefficients and durations), from
rest to rest (zero velocity; the acceleration jumps across the period as a time-optimal
retiming's does), a little ``∫‖q⃛‖² dt`` (a millionth of the duration's scale) to choose among
equally fast paths. It starts from the time-optimal retiming of the reference
(:func:`~twolink_pin.trajectory.retiming.time_optimal`): its via times and its motion; the
SQP's merit never accepts a longer one, so its result is no longer than the retiming (it is
free to leave the reference's path between the via points).

The result is a :class:`~twolink_pin.trajectory.sampled.SampledTrajectory`: the spline's
samples at its knots (exact: a quintic between two knots is what its quintic Hermite
interpolation reproduces) with the torque it was designed with.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin import interrupts
from twolink_pin.dynamics.derivatives import RneaDerivatives
from twolink_pin.dynamics.rigid_body import inverse_dynamics_rows
from twolink_pin.errors import InvalidParameterError, OptimizationError, require_type
from twolink_pin.limits import (
    ACCELERATION,
    EFFORT,
    POSITION,
    VELOCITY,
    JointLimits,
    LimitsCheck,
    check_motion,
    joint_limits,
)
from twolink_pin.model import RobotModel
from twolink_pin.optimal.layout import SplineLayout
from twolink_pin.optimal.refinement import solve_within_limits
from twolink_pin.optimal.spline import BSplineBasis
from twolink_pin.optimal.sqp import SQPOptions
from twolink_pin.optimal.transcription import Cost, Pin, TrajectoryProblem
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.polynomial import JointTrajectory
from twolink_pin.trajectory.retiming import TimeOptimal, time_optimal
from twolink_pin.trajectory.sampled import SampledTrajectory
from twolink_pin.trajectory.se3 import PoseTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

COSTS = ("effort", "time")
"""What :func:`optimize` can minimise."""
KNOT_SPACING = 0.25
"""Time between two knots of the minimum-effort spline [s] (about)."""
MIN_PIECES = 2
"""Fewest spline pieces between two via points (effort)."""
MAX_PIECES = 8
"""Most spline pieces between two via points (effort)."""
STRETCHES = (1.0, 1.01, 1.03, 1.1)
"""The minimum-time search starts from the retiming's via times, stretched by these until a
spline keeps every limit with them."""
SEARCH_STEP = 0.02
"""The search's first step down from its start (doubled after each feasible probe until one
is not; then bisection)."""
SEARCH_TOLERANCE = 4e-3
"""It stops when the shortest feasible and the longest infeasible scaling are this close
(relative)."""
TIME_MARGIN = 1e-3
"""The fraction of each limit a minimum-time spline keeps free: near-bang-bang, its torque
turns fast, and between the check grid's points (100 per piece) it rose up to 3e-5 of a limit
(1e-5 was the margin)."""
PROBE_ITERATIONS = 25
"""SQP iterations of one probe (a probe that needs more counts as infeasible)."""
PROBE_QP_ITERATIONS = 400
"""ProxQP iterations of a probe's step (an infeasible step takes them all)."""
CHECK = 4
"""Points per spline piece at which the limits are constrained (the fine grid: ten times more)."""
EFFORT_GRID = 20
"""Points per spline piece of the grid on which the results' ``∫ τᵀτ dt`` and limits are reported."""
HULL = (POSITION, VELOCITY, ACCELERATION)
"""The limits kept on the spline's coefficients (everywhere, no grid); effort at the check points."""
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
    """The largest excess over any limit on the report grid, a fraction of the limit (of the
    range for a position); <= 0: within every limit; None: the robot has no limit."""
    check: LimitsCheck
    """Every limit on the report grid."""
    limits: JointLimits
    """The limits (scaled)."""
    iterations: int
    """SQP iterations, all solves."""
    seconds: float
    """Wall time [s]."""


class _Vias(NamedTuple):
    times: np.ndarray
    q: np.ndarray
    poses: tuple[np.ndarray, np.ndarray] | None


def _vias(trajectory: Trajectory) -> _Vias:
    """The via points of a via-point or via-pose reference."""
    if isinstance(trajectory, PoseTrajectory):
        return _Vias(
            np.asarray(trajectory.times),
            np.asarray(trajectory.via_q),
            (trajectory.positions, trajectory.rotations),
        )
    if isinstance(trajectory, JointTrajectory):
        return _Vias(np.asarray(trajectory.times), np.asarray(trajectory.via_q), None)
    raise InvalidParameterError(
        "trajectory",
        type(trajectory).__name__,
        "a reference through via points: joint via points, end-effector via points or via poses",
    )


def _check_speeds(vias: _Vias, limits: JointLimits) -> None:
    """Raise (bad input) where two via points are further apart than a joint's velocity limit
    lets it go in the time between them (the mean velocity, which any motion reaches)."""
    mean = np.abs(np.diff(vias.q, axis=0)) / np.diff(vias.times)[:, None]
    over = mean / limits.velocity
    if np.any(over > 1.0):
        k, j = (int(i) for i in np.unravel_index(np.argmax(over), over.shape))
        raise InvalidParameterError(
            f"velocity limit of joint {j + 1} ({limits.joint_names[j]})",
            f"{limits.velocity[j]:g} rad/s",
            f"at least the mean {mean[k, j]:.4g} rad/s from via point {k} to {k + 1} ({vias.times[k]:g} s to "
            f"{vias.times[k + 1]:g} s): via points too far apart for their times",
        )


def check_vias(robot: RobotModel, vias: _Vias, limits: JointLimits, timed: bool = True) -> None:
    """Raise (bad input) for a via point outside a joint's position range, two via points
    further apart than a velocity limit lets a joint go between their times, or a via point
    where gravity alone needs more than an effort limit (the arm could not even hold still
    there). ``timed``: the via times are kept (the velocity check applies)."""
    lower, upper = limits.bounds(POSITION)
    for k, q in enumerate(vias.q):
        outside = (q < lower) | (q > upper)
        if outside.any():
            j = int(np.argmax(outside))
            raise InvalidParameterError(
                f"via point {k}, joint {j + 1} ({limits.joint_names[j]})",
                f"{q[j]:.6g} rad",
                f"a position within its range [{lower[j]:g}, {upper[j]:g}] rad",
            )
    if timed:
        _check_speeds(vias, limits)
    data = robot.create_data()
    for k, q in enumerate(vias.q):
        g = pin.computeGeneralizedGravity(robot.model, data, q)
        excess = np.abs(g) - limits.effort
        if np.any(excess > 0):
            j = int(np.argmax(excess))
            raise InvalidParameterError(
                f"effort limit of joint {j + 1} ({limits.joint_names[j]})",
                f"{limits.effort[j]:g} N·m",
                f"at least the {abs(g[j]):.4g} N·m gravity needs at via point {k} (q = {np.round(q, 4).tolist()} rad): "
                "the path needs more torque than the limits allow even at rest",
            )


def _pieces(times: np.ndarray) -> np.ndarray:
    """Spline pieces between each two via points (effort): :data:`KNOT_SPACING` apart, within
    :data:`MIN_PIECES` .. :data:`MAX_PIECES`."""
    return np.clip(np.round(np.diff(times) / KNOT_SPACING), MIN_PIECES, MAX_PIECES).astype(int)


def _spline_problem(
    robot: RobotModel,
    times: np.ndarray,
    vias: _Vias,
    limits: JointLimits,
    friction: Friction | None,
    cost: Cost,
    rest: tuple[int, ...],
    margin: float = 1e-5,
) -> TrajectoryProblem:
    """One spline through the via points at ``times`` [s] (its knots :func:`_pieces` apart),
    at rest at both ends to the derivatives ``rest``, its limits at :data:`CHECK` points per piece."""
    nv = robot.nv
    span = float(times[-1] - times[0])
    sigma = (times - times[0]) / span
    sigma[-1] = 1.0
    breaks = np.concatenate(
        [
            np.linspace(a, b, m + 1)[:-1]
            for a, b, m in zip(sigma[:-1], sigma[1:], _pieces(vias.times), strict=True)
        ]
        + [[1.0]]
    )
    layout = SplineLayout(BSplineBasis(breaks, 5), 1, nv, np.array([span]))
    at_vias = layout.points(np.zeros(times.size, dtype=int), sigma)
    ends = layout.points(np.zeros(2, dtype=int), np.array([0.0, 1.0]))
    pins = (Pin("via", at_vias, 0, vias.q), *tuple(Pin("rest", ends, r, np.zeros((2, nv))) for r in rest))
    return TrajectoryProblem(
        layout, RneaDerivatives(robot.model, friction), limits, cost, layout.quadrature(), layout.grid(CHECK), pins,
        kinds=(EFFORT,), hull=HULL, margin=margin, time_scale=span / (times.size - 1),
    )  # fmt: skip


def _fit(problem: TrajectoryProblem, trajectory: Trajectory, t0: float) -> np.ndarray:
    """The variables of the single spline nearest ``trajectory`` from ``t0`` [s] (least squares)."""
    layout = problem.layout
    basis, span = layout.basis, float(layout.durations_of(np.zeros(layout.size))[0])
    sigma = basis.grid(8)
    return layout.pack(basis.fit(sigma, trajectory.sample(t0 + span * sigma).q)[None])


class _Probe(NamedTuple):
    """A spline that keeps every limit with the via times ``scale`` times the retiming's."""

    scale: float
    problem: TrajectoryProblem
    x: np.ndarray


def _probe(
    robot: RobotModel,
    vias: _Vias,
    limits: JointLimits,
    friction: Friction | None,
    times: np.ndarray,
    scale: float,
    x0: np.ndarray,
    iterations: list[int],
) -> _Probe | None:
    """A spline through the via points at ``scale · times`` [s] within every limit (the least
    ``∫‖q⃛‖² dt``, from the variables ``x0``: the same in normalised time at every scale), or
    None when the solver finds none in :data:`PROBE_ITERATIONS` SQP iterations."""
    problem = _spline_problem(robot, times * scale, vias, limits, friction, Cost(jerk=1.0), (1,), TIME_MARGIN)
    options = SQPOptions(max_iterations=PROBE_ITERATIONS, qp_iterations=PROBE_QP_ITERATIONS, explain=False)
    try:
        solved = solve_within_limits(problem, x0, options, per_piece=CHECK, rounds=3, what="a probe")
    except OptimizationError:
        iterations[0] += PROBE_ITERATIONS  # a failed probe: counted in full
        return None
    iterations[0] += solved.iterations
    return _Probe(scale, solved.problem, solved.result.x)


def _time_search(
    robot: RobotModel, retimed: SampledTrajectory, vias: _Vias, limits: JointLimits, friction: Friction | None
) -> tuple[_Probe, int]:
    """The shortest uniform scaling of the retiming's via times for which a spline keeps every
    limit (module docstring: steps down, then bisection, each probe a feasibility solve); the
    SQP iterations."""
    times = retimed.via_times - retimed.via_times[0]
    start = _spline_problem(robot, times, vias, limits, friction, Cost(jerk=1.0), (1,), TIME_MARGIN)
    x0 = _fit(start, retimed, float(retimed.via_times[0]))
    spent = [0]
    best = None
    for stretch in STRETCHES:
        best = _probe(robot, vias, limits, friction, times, stretch, x0, spent)
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
        found = _probe(robot, vias, limits, friction, times, trial, best.x, spent)
        if found is None:
            low = trial
        else:
            best, step = found, 2.0 * step
    return best, spent[0]


def _knot_samples(
    problem: TrajectoryProblem, x: np.ndarray, t0: float, period: float, via_times: np.ndarray
) -> SampledTrajectory:
    """The solution's samples at its knots (each join once) with its torque, starting at
    ``t0`` [s]; a rest to ``period`` when it is longer than the motion; ``via_times`` [s]
    marked."""
    layout = problem.layout
    S = layout.segments
    local = layout.basis.breakpoints
    segment = np.append(np.repeat(np.arange(S), local.size - 1), S - 1)
    sigma = np.append(np.tile(local[:-1], S), 1.0)
    points = layout.points(segment, sigma)
    t = t0 + layout.times(x, points)
    q, v, a = (layout.derivative(x, points, r) for r in range(3))
    q[-1], v[-1] = q[0], v[0]
    tau = problem.dynamics(q, v, a).tau
    end = float(t[-1])
    if period > end - t0 + 1e-9:
        rest = problem.dynamics(q[-1:], np.zeros((1, layout.nv)), np.zeros((1, layout.nv))).tau
        t, q = np.append(t, t0 + period), np.vstack([q, q[-1:]])
        v, a, tau = np.vstack([v, v[-1:] * 0]), np.vstack([a, a[-1:] * 0]), np.vstack([tau, rest])
    return SampledTrajectory(t, q, v, a, tau, via_times)


def effort_integral(
    robot: RobotModel, trajectory: Trajectory, friction: Friction | None = None, samples: int = 4001
) -> float:
    """``∫ τᵀτ dt`` over one period [N²·m²·s]: RNEA (plus ``friction``) on ``samples`` evenly
    spaced instants, trapezoid."""
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, samples)
    ref = trajectory.sample(t)
    tau = inverse_dynamics_rows(robot.model, ref.q, ref.v, ref.a)
    if friction is not None:
        tau = tau + friction.torque(ref.v)
    return float(np.trapezoid((tau**2).sum(axis=1), t))


def _pose_error(robot: RobotModel, trajectory: SampledTrajectory, vias: _Vias) -> tuple[float, float] | None:
    """The end effector's largest position [m] and rotation [rad] error at the via times."""
    if vias.poses is None:
        return None
    q = trajectory.sample(trajectory.via_times).q
    data = robot.create_data()
    worst_p = worst_r = 0.0
    for qk, p, R in zip(q, *vias.poses, strict=True):
        pin.framesForwardKinematics(robot.model, data, qk)
        frame = data.oMf[robot.ee_frame_id]
        worst_p = max(worst_p, float(np.linalg.norm(frame.translation - p)))
        worst_r = max(worst_r, float(np.linalg.norm(pin.log3(R.T @ frame.rotation))))
    return worst_p, worst_r


def _violation(check: LimitsCheck) -> float | None:
    """The largest excess over a limit, a fraction of it (of the range for a position); None
    for a robot without limits."""
    worst = -np.inf
    for kind in check.kinds:
        given = check.limits.given(kind.kind)
        if not given.any():
            continue
        lower, upper = check.limits.bounds(kind.kind)
        scale = (upper - lower) if kind.kind is POSITION else upper
        worst = max(worst, float(np.max(-kind.margin[given] / scale[given])))
    return worst if np.isfinite(worst) else None


def optimize(
    robot: RobotModel,
    via: Trajectory,
    cost: str = "effort",
    *,
    limit_scale: float = 1.0,
    limits: JointLimits | None = None,
    friction: Friction | None = None,
    max_iterations: int = MAX_ITERATIONS,
) -> OptimalTrajectory:
    """The trajectory through ``via``'s via points that minimises ``cost`` within every limit
    of ``robot`` (module docstring).

    Args:
        robot: The arm (its model, payload included, gives the torque).
        via: A reference through via points (joint, end-effector or via poses: after their
            inverse kinematics, the joint via points are kept exactly).
        cost: ``effort`` (``∫ τᵀτ dt`` [N²·m²·s], the via times of ``via``) or ``time`` (the
            duration [s], the via times free).
        limit_scale: Fraction ``0 < F <= 1`` of each velocity, acceleration and effort limit.
        limits: The limits (default :func:`~twolink_pin.limits.joint_limits` of ``robot``).
        friction: A plant's joint friction added to the torque, or None.
        max_iterations: Most SQP iterations per solve.

    Raises:
        InvalidParameterError: an unknown cost, a reference without via points, a via point
            outside a position range or where gravity alone exceeds an effort limit, no
            velocity limit for ``time``, ``limit_scale`` outside (0, 1].
        OptimizationError: the solver did not converge, or its constraints cannot hold (the
            iterations and the remaining violation said).
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    require_type(via, Trajectory, "via", "a Trajectory through via points (twolink_pin.read_trajectory_file)")
    if cost not in COSTS:
        raise InvalidParameterError("cost", cost, f"one of {', '.join(COSTS)}")
    start = time.perf_counter()
    wanted = (joint_limits(robot) if limits is None else limits).scaled(limit_scale)
    vias = _vias(via)
    check_vias(robot, vias, wanted, timed=cost == "effort")
    from twolink_pin.blas import one_blas_thread

    options = SQPOptions(max_iterations=max_iterations)
    with one_blas_thread():  # small dense algebra: BLAS threads only spin (twolink_pin.blas)
        if cost == "effort":
            result, iterations, retimed = *_minimum_effort(robot, via, vias, wanted, friction, options), None
        else:
            wanted.require(VELOCITY, "find the shortest duration")
            result, iterations, retimed = _minimum_time(robot, via, vias, wanted, friction)
    return _report(robot, via, vias, result, cost, wanted, friction, retimed, iterations, start)


def _minimum_effort(
    robot: RobotModel,
    via: Trajectory,
    vias: _Vias,
    limits: JointLimits,
    friction: Friction | None,
    options: SQPOptions,
) -> tuple[SampledTrajectory, int]:
    """The minimum-effort trajectory (module docstring) and its SQP iterations."""
    problem = _spline_problem(robot, vias.times, vias, limits, friction, Cost(effort=1.0), (1, 2, 3))
    t0 = float(vias.times[0])
    solved = solve_within_limits(
        problem, _fit(problem, via, t0), options, per_piece=CHECK, what="the minimum-effort trajectory"
    )
    return _knot_samples(
        solved.problem, solved.result.x, t0, float(via.period), vias.times
    ), solved.iterations


def _minimum_time(
    robot: RobotModel, via: Trajectory, vias: _Vias, limits: JointLimits, friction: Friction | None
) -> tuple[SampledTrajectory, int, TimeOptimal]:
    """The minimum-time trajectory (module docstring), its SQP iterations, the retiming it
    started from: the spline search's result, or the retiming itself when no spline keeps
    the limits as fast."""
    retimed = time_optimal(robot, via, limits=limits, friction=friction)
    try:
        best, spent = _time_search(robot, retimed.trajectory, vias, limits, friction)
    except OptimizationError as err:
        return retimed.trajectory, err.iterations, retimed
    via_times = retimed.trajectory.via_times
    result = _knot_samples(best.problem, best.x, 0.0, 0.0, best.scale * (via_times - via_times[0]))
    if result.period > retimed.duration:
        return retimed.trajectory, spent, retimed
    return result, spent, retimed


def _report(
    robot: RobotModel,
    via: Trajectory,
    vias: _Vias,
    result: SampledTrajectory,
    cost: str,
    limits: JointLimits,
    friction: Friction | None,
    retimed: TimeOptimal | None,
    iterations: int,
    start: float,
) -> OptimalTrajectory:
    """The result measured: its effort and the reference's, via errors, the limits on a fine grid."""
    from twolink_pin.trajectory.retiming import verify_motion

    motion = verify_motion(robot, result, EFFORT_GRID, friction)
    check = check_motion(motion, limits)
    via_times = result.via_times
    via_error = float(np.abs(result.sample(via_times).q - vias.q).max())
    return OptimalTrajectory(
        result, cost, result.period, effort_integral(robot, result, friction),
        float(vias.times[-1] - vias.times[0]), effort_integral(robot, via, friction),
        None if retimed is None else float(retimed.duration),
        via_error, _pose_error(robot, result, vias), _violation(check), check, limits, iterations,
        time.perf_counter() - start,
    )  # fmt: skip


__all__ = ["COSTS", "OptimalTrajectory", "check_vias", "effort_integral", "optimize"]
