"""The minimum-effort reference through via points at their times, within every limit
(``optimize --cost effort``; :func:`~twolink_pin.trajectory.optimal.optimize`).

**The cost**::

    J = ∫ τᵀτ dt + w_v ∫ ‖q̇‖² dt,     w_v = κ · ∫ τ_refᵀτ_ref dt / ∫ ‖q̇_ref‖² dt

over the motion (the first via time to the last), ``τ`` by RNEA on the robot's model (plus a
plant's friction when given). The second term is the **regulariser** (``regulariser =
"velocity"``, the default; ``"none"``: the effort alone): the least ``∫ τᵀτ dt`` through via
points lets the joints that cost little torque (a base turning about gravity's axis, a wrist)
run as fast as their limits allow to save a little on the others — on the UR5's 20-cm square
(``examples/ur5_square_pose.toml``) it swung joint 1 to −2.49 rad and the tool behind the base;
on the Panda's fold the joints the task never moves ran at 95–100 % of their velocity limits. A
velocity term is the smallest change that stops it (crocoddyl's examples regularise the state
the same way). Its weight is stated by ``κ`` (``regulariser_weight``, default
:data:`REGULARISER_WEIGHT`): on the reference itself the regulariser would cost ``κ`` times its
effort. With 0.3 the UR5's square keeps its tool within 7 cm of the square's plane and saves 17 %
of the reference's effort, the Panda's fold keeps its untouched joints still and saves 18 % (the
docs' page gives the figures).

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
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.optimal_measures import effort_integral
from twolink_pin.trajectory.optimal_spline import CHECK, Vias, fit, knot_samples, pieces, spline_problem
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

ENDS = {"smooth": (1, 2, 3), "rest": (1,)}
"""The end conditions: the derivatives of ``q`` that vanish at both ends."""
REGULARISERS = ("velocity", "none")
"""The regularisers of the effort (module docstring)."""
REGULARISER_WEIGHT = 0.3
"""Default ``κ``: on the reference, the regulariser would cost this fraction of its effort."""
KNOT_SPACING = 1.0 / 6.0
"""Time between two knots of the longest segment [s] (about)."""
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


def _velocity_weight(
    robot: RobotModel, via: Trajectory, vias: Vias, kappa: float, friction: Friction | None
) -> float:
    """``w_v = κ ∫ τ_refᵀτ_ref dt / ∫ ‖q̇_ref‖² dt`` over the reference's motion (0 when it does
    not move)."""
    t0, span = float(vias.times[0]), float(vias.times[-1] - vias.times[0])
    effort = effort_integral(robot, via, friction, start=t0, duration=span)
    return kappa * effort / speed_integral(via, t0, span) if speed_integral(via, t0, span) > 0 else 0.0


def speed_integral(trajectory: Trajectory, t0: float, duration: float, samples: int = 4001) -> float:
    """``∫ ‖q̇‖² dt`` [rad²/s] from ``t0`` over ``duration`` [s] (``samples`` instants, trapezoid)."""
    t = t0 + np.linspace(0.0, duration, samples)
    return float(np.trapezoid((trajectory.sample(t).v ** 2).sum(axis=1), t))


def minimum_effort(
    robot: RobotModel,
    via: Trajectory,
    vias: Vias,
    limits: JointLimits,
    friction: Friction | None,
    options: SQPOptions,
    *,
    ends: str = "smooth",
    regulariser: str = "velocity",
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
    weight = _velocity_weight(robot, via, vias, float(kappa), friction) if regulariser == "velocity" else 0.0
    count = pieces(vias.times, KNOT_SPACING)
    problem = spline_problem(
        robot, vias.times, vias, limits, friction, Cost(effort=1.0), rest=ENDS[ends], pieces_per_segment=count,
        continuity=CONTINUITY, kinds=KINDS,
    )  # fmt: skip
    if weight > 0:
        zeros = np.zeros((problem.cost_points.size, robot.nv))
        problem = problem.with_cost(Cost(effort=1.0, velocity=weight, reference=(zeros, zeros)))
    what = "the minimum-effort trajectory"
    try:
        solved = solve_within_limits(
            problem, fit(problem.layout, via, vias.times), options, per_piece=CHECK, what=what
        )
    except OptimizationError as exc:
        hint = f"; try more iterations (--max-iterations, now {options.max_iterations})" + (
            "" if regulariser != "none" else " or a regulariser (--regulariser velocity)"
        )
        raise OptimizationError(exc.problem, exc.reason + hint, exc.iterations) from None
    result = knot_samples(
        solved.problem, solved.result.x, float(vias.times[0]), float(via.period), vias.times
    )
    value = speed_integral(result, float(vias.times[0]), float(vias.times[-1] - vias.times[0]))
    return result, solved.iterations, Regulariser(regulariser, float(kappa), weight, value)


__all__ = [
    "CONTINUITY",
    "ENDS",
    "KNOT_SPACING",
    "REGULARISERS",
    "REGULARISER_WEIGHT",
    "Regulariser",
    "minimum_effort",
    "speed_integral",
]
