"""The minimum-effort reference through via points at their times, within every limit
(``optimize --cost effort``; :func:`~twolink_pin.trajectory.optimal.optimize`).

**The cost**::

    J = ∫ τᵀτ dt + R,     R = w_q ∫ ‖q − q_ref(t)‖² dt   (path, the default)
                          R = w_v ∫ ‖q̇‖² dt             (velocity)

over the motion (the first via time to the last), ``τ`` by RNEA on the robot's model (plus a
plant's friction when given). ``R`` is the **regulariser** (``regulariser``; ``"none"``: the
effort alone). The least ``∫ τᵀτ dt`` through via points alone lets the joints that cost little
torque (a base turning about gravity's axis, a wrist) run as far and as fast as their limits
allow to save a little on the others — on the UR5's 20-cm square
(``examples/ur5_square_pose.toml``) it swung joint 1 to −2.49 rad and the tool behind the base;
on the Panda's fold the joints the task never moves ran at 95–100 % of their velocity limits.

- ``path`` (default) keeps the motion near the reference's own path in time ``q_ref(t)`` — for
  via poses the inverse kinematics of the straight SE(3) path between them, so a Cartesian-path
  term in the joints' coordinates, and for joint via points the reference's polynomial: a
  posture that moves. Its weight ``w_q = κ ∫ τ_refᵀτ_ref dt / (T · (0.1 rad)²)``: one joint
  held :data:`PATH_SCALE` off the path over the whole motion would cost ``κ`` times the
  reference's effort. The reference itself costs its own effort, so (up to what the spline
  can represent of it) the result never needs more effort than the reference.
- ``velocity``: ``w_v = κ ∫ τ_refᵀτ_ref dt / ∫ ‖q̇_ref‖² dt`` (on the reference it would cost
  ``κ`` times its effort; crocoddyl's examples regularise the state this way): the least
  motion, not the task's path, so the end effector bows between via poses, and a large ``κ``
  can cost more effort than the reference.

``κ`` is ``regulariser_weight`` (default :data:`REGULARISER_WEIGHT`). Measured (the end
effector's largest distance from the via points' convex hull, the reference's 0; the effort
against the reference's): path, κ = 0.3: the UR5's square 18 mm, −6 %; the Panda's fold 20 mm,
−2 %; the twolink's course path −28 %; κ = 0.1: 41 mm, −13 %; 67 mm, −5 %; velocity, κ = 1:
31 mm, −8 %; 28 mm, −1 %; no regulariser: the UR5's tool 51 cm out and behind the base, −88 %
(docs/within_limits.md).

**The ends** (``ends``): ``"smooth"`` (default), at rest with zero acceleration and jerk at both
ends, like the course's polynomial, so that the two compare on the same terms and a repeating
reference has no torque step at its period; ``"rest"``, at rest only (the acceleration free,
as crocoddyl's least-effort problems are posed: the torque may step at the start).

**The spline** (:func:`~twolink_pin.trajectory.optimal_spline.spline_problem`): one segment
per via interval, its knots about :data:`KNOT_SPACING` apart, through each via point exactly;
``q``, ``q̇``, ``q̈`` continuous at a via point and the jerk free to jump there (the least-effort
motion's jerk does jump where a via point pulls on it: with the jerk kept continuous it cost
8 % more on the UR5). Every limit (position, velocity, acceleration, effort) at the check
points, and between them on a grid 25 times finer (:func:`~twolink_pin.optimal.solve_within_limits`:
a point added where a limit's excess peaks). It starts from the reference itself (its
least-squares fit).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from twolink_pin.errors import InvalidParameterError, OptimizationError
from twolink_pin.limits import KINDS, JointLimits
from twolink_pin.model import RobotModel
from twolink_pin.optimal.cost import Cost
from twolink_pin.optimal.refinement import solve_within_limits
from twolink_pin.optimal.sqp import SQPOptions
from twolink_pin.optimal.transcription import TrajectoryProblem
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.optimal_measures import effort_integral
from twolink_pin.trajectory.optimal_spline import CHECK, Vias, fit, knot_samples, pieces, spline_problem
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

ENDS = {"smooth": (1, 2, 3), "rest": (1,)}
"""The end conditions: the derivatives of ``q`` that vanish at both ends."""
REGULARISERS = ("path", "velocity", "none")
"""The regularisers of the effort (module docstring)."""
DEFAULT_REGULARISER = "path"
"""The regulariser by default."""
PATH_SCALE = 0.1
"""The deviation from the reference's path [rad] the ``path`` regulariser's weight is stated
by: held by one joint over the whole motion, it costs ``κ`` times the reference's effort."""
REGULARISER_WEIGHT = 0.3
"""Default ``κ``: on the reference, the regulariser would cost this fraction of its effort."""
KNOT_SPACING = 1.0 / 6.0
"""Time between two knots of the longest segment [s] (about)."""
MARGIN = 1e-3
"""The fraction of each limit kept free at the check points (the motion between them may use
it before the refinement adds a point)."""
CONTINUITY = 2
"""``q`` to this derivative is continuous at a via point (the jerk may jump there)."""


class Regulariser(NamedTuple):
    """The regulariser a minimum-effort reference was designed with."""

    kind: str
    """``velocity`` or ``none``."""
    kappa: float
    """``κ``: its worth on the reference, a fraction of the reference's effort."""
    weight: float
    """``w_v`` [N²·m²·s²/rad²] (0 without)."""
    value: float
    """``∫ ‖q̇‖² dt`` of the result [rad²/s] (over the motion)."""


def speed_integral(trajectory: Trajectory, t0: float, duration: float, samples: int = 4001) -> float:
    """``∫ ‖q̇‖² dt`` [rad²/s] from ``t0`` over ``duration`` [s] (``samples`` instants, trapezoid)."""
    t = t0 + np.linspace(0.0, duration, samples)
    return float(np.trapezoid((trajectory.sample(t).v ** 2).sum(axis=1), t))


def _regularised(
    problem: TrajectoryProblem, robot: RobotModel, via: Trajectory, vias: Vias, kind: str, kappa: float,
    friction: Friction | None,
) -> tuple[TrajectoryProblem, float]:  # fmt: skip
    """``problem`` with the regulariser ``kind`` added to its effort (module docstring), and its
    weight (0 without)."""
    t0, span = float(vias.times[0]), float(vias.times[-1] - vias.times[0])
    if kind == "none" or kappa == 0:
        return problem, 0.0
    effort = effort_integral(robot, via, friction, start=t0, duration=span)
    points = problem.cost_points
    if kind == "velocity":
        speed = speed_integral(via, t0, span)
        weight = kappa * effort / speed if speed > 0 else 0.0
        zeros = np.zeros((points.size, robot.nv))
        return problem.with_cost(Cost(effort=1.0, velocity=weight, reference=(zeros, zeros))), weight
    weight = kappa * effort / (span * PATH_SCALE**2)
    reference = via.sample(t0 + problem.layout.times(np.zeros(problem.layout.size), points))
    return problem.with_cost(Cost(effort=1.0, position=weight, reference=(reference.q, reference.v))), weight


def _value(result: SampledTrajectory, via: Trajectory, vias: Vias, kind: str) -> float:
    """The regulariser's integral along ``result`` over the motion: ``∫‖q̇‖² dt`` [rad²/s]
    (``velocity``, ``none``) or ``∫‖q − q_ref‖² dt`` [rad²·s] (``path``)."""
    t0, span = float(vias.times[0]), float(vias.times[-1] - vias.times[0])
    if kind != "path":
        return speed_integral(result, t0, span)
    t = t0 + np.linspace(0.0, span, 4001)
    return float(np.trapezoid(((result.sample(t).q - via.sample(t).q) ** 2).sum(axis=1), t))


def minimum_effort(
    robot: RobotModel,
    via: Trajectory,
    vias: Vias,
    limits: JointLimits,
    friction: Friction | None,
    options: SQPOptions,
    *,
    ends: str = "smooth",
    regulariser: str = DEFAULT_REGULARISER,
    kappa: float = REGULARISER_WEIGHT,
) -> tuple[SampledTrajectory, int, Regulariser]:
    """The minimum-effort reference (module docstring), its SQP iterations and its regulariser.

    Raises:
        InvalidParameterError: ``ends``, ``regulariser`` or ``kappa`` not one of those known.
        OptimizationError: the solver did not converge (what, by how much, what to try).
    """
    if ends not in ENDS:
        raise InvalidParameterError("ends", ends, f"one of {', '.join(ENDS)}")
    if regulariser not in REGULARISERS:
        raise InvalidParameterError("regulariser", regulariser, f"one of {', '.join(REGULARISERS)}")
    if not (isinstance(kappa, (int, float)) and np.isfinite(kappa) and kappa >= 0):
        raise InvalidParameterError("regulariser weight", kappa, "a finite number >= 0")
    count = pieces(vias.times, KNOT_SPACING)
    problem = spline_problem(
        robot, vias.times, vias, limits, friction, Cost(effort=1.0), rest=ENDS[ends], pieces_per_segment=count,
        continuity=CONTINUITY, kinds=KINDS, margin=MARGIN,
    )  # fmt: skip
    problem, weight = _regularised(problem, robot, via, vias, regulariser, float(kappa), friction)
    what = "the minimum-effort trajectory"
    try:
        solved = solve_within_limits(
            problem, fit(problem.layout, via, vias.times), options, per_piece=CHECK, what=what
        )
    except OptimizationError as exc:
        hint = f"; try more iterations (--max-iterations, now {options.max_iterations})" + (
            "" if regulariser != "none" else f" or a regulariser (--regulariser {DEFAULT_REGULARISER})"
        )
        raise OptimizationError(exc.problem, exc.reason + hint, exc.iterations) from None
    result = knot_samples(
        solved.problem, solved.result.x, float(vias.times[0]), float(via.period), vias.times
    )
    chosen = Regulariser(regulariser, float(kappa), weight, _value(result, via, vias, regulariser))
    return result, solved.iterations, chosen


__all__ = [
    "CONTINUITY",
    "DEFAULT_REGULARISER",
    "ENDS",
    "KNOT_SPACING",
    "REGULARISERS",
    "REGULARISER_WEIGHT",
    "Regulariser",
    "minimum_effort",
    "speed_integral",
]
