"""The spline every optimal reference is (:mod:`twolink_pin.trajectory.optimal`): its via
points, its layout, its start and its samples.

**The via points** (:class:`Vias`) of a via-point, end-effector or via-pose reference: times,
joint via points (after the inverse kinematics of via poses) and the poses; :func:`check_vias`
refuses, before any solve, what no trajectory through them can have (a via point outside a
range, two via points further apart than a velocity limit lets a joint go between their times,
gravity alone beyond an effort limit at one).

**The spline** (:func:`spline_problem`): one segment between each two via points, each a
quintic B-spline on the same basis (its knots about ``spacing`` apart in the longest segment),
through each via point exactly (a linear equality at each segment's start and at the end), its
derivatives up to ``continuity`` continuous where two segments meet; ``rest``: the derivatives
that vanish at both ends; the limits at :data:`CHECK` points per knot interval.

**Its start** (:func:`fit`): the spline nearest a trajectory (least squares, per segment).
**Its samples** (:func:`knot_samples`): the spline at its knots, which a quintic Hermite
interpolation reproduces exactly (:class:`~twolink_pin.trajectory.sampled.SampledTrajectory`).
"""

from __future__ import annotations

from itertools import pairwise
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics.derivatives import RneaDerivatives
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import POSITION, JointLimits, LimitKind
from twolink_pin.model import RobotModel
from twolink_pin.optimal.cost import Cost
from twolink_pin.optimal.layout import SplineLayout
from twolink_pin.optimal.spline import BSplineBasis
from twolink_pin.optimal.transcription import Pin, TrajectoryProblem
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.polynomial import JointTrajectory
from twolink_pin.trajectory.sampled import SampledTrajectory
from twolink_pin.trajectory.se3 import PoseTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

CHECK = 4
"""Points per knot interval at which the limits are constrained (the refinement's fine grid:
25 times more, :mod:`twolink_pin.optimal.refinement`)."""
MIN_PIECES = 2
"""Fewest knot intervals of a segment."""
MAX_PIECES = 16
"""Most knot intervals of a segment."""


class Vias(NamedTuple):
    """The via points an optimal reference goes through."""

    times: np.ndarray
    """Their times [s], shape (K,)."""
    q: np.ndarray
    """Joint via points [rad], shape (K, nv)."""
    poses: tuple[np.ndarray, np.ndarray] | None
    """Via poses: positions (K, 3) [m] and rotations (K, 3, 3); None for joint via points."""


def vias_of(trajectory: Trajectory) -> Vias:
    """The via points of a via-point or via-pose reference.

    Raises:
        InvalidParameterError: a reference without via points (a Fourier series, samples).
    """
    if isinstance(trajectory, PoseTrajectory):
        return Vias(
            np.asarray(trajectory.times),
            np.asarray(trajectory.via_q),
            (trajectory.positions, trajectory.rotations),
        )
    if isinstance(trajectory, JointTrajectory):
        return Vias(np.asarray(trajectory.times), np.asarray(trajectory.via_q), None)
    raise InvalidParameterError(
        "trajectory",
        type(trajectory).__name__,
        "a reference through via points: joint via points, end-effector via points or via poses",
    )


def _check_speeds(vias: Vias, limits: JointLimits) -> None:
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


SHORTFALL = 1e6
"""A velocity, acceleration or effort limit below ``1/SHORTFALL`` of what the reference needs at
its own timing is refused before solving (:func:`check_reference_needs`)."""


def check_reference_needs(robot: RobotModel, reference: Trajectory, limits: JointLimits) -> None:
    """Raise (bad input) for a limit a millionth or less of what ``reference`` needs at its own
    timing (:data:`SHORTFALL`), named with its value and the need: no trajectory through the
    same via points at the same times comes within it, and the solver's rows, divided by it,
    would hold numbers of 1e300 (an effort limit of 1e-300 failed with "the equality
    constraints cannot all hold (row 12 …)")."""
    from twolink_pin.limits import check_limits, shortfall

    short = shortfall(check_limits(robot, reference, limits=limits), lambda _: SHORTFALL)
    if short is not None:
        what, value, need = short.describe(limits.joint_names)
        raise InvalidParameterError(what, value, f"a limit a millionth of the need or more: it is {need}")


def check_vias(robot: RobotModel, vias: Vias, limits: JointLimits, timed: bool = True) -> None:
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


def pieces(times: np.ndarray, spacing: float) -> int:
    """Knot intervals of each segment between the via points at ``times`` [s]: the longest
    segment's length over ``spacing`` [s], within :data:`MIN_PIECES` .. :data:`MAX_PIECES`
    (the basis is shared: a shorter segment has its knots closer)."""
    return int(np.clip(round(float(np.diff(times).max()) / spacing), MIN_PIECES, MAX_PIECES))


def spline_problem(
    robot: RobotModel,
    times: np.ndarray,
    vias: Vias,
    limits: JointLimits,
    friction: Friction | None,
    cost: Cost,
    *,
    rest: tuple[int, ...],
    pieces_per_segment: int,
    continuity: int,
    kinds: tuple[LimitKind, ...],
    hull: tuple[LimitKind, ...] = (),
    margin: float = 1e-5,
) -> TrajectoryProblem:
    """The spline through ``vias`` at ``times`` [s] (module docstring): ``rest``, the
    derivatives that vanish at both ends; ``continuity``, the highest derivative continuous at
    a via point; the limit ``kinds`` at :data:`CHECK` points per knot interval, tightened by
    ``margin`` (a fraction of each limit); the ``hull`` kinds on the spline's coefficients
    instead (:class:`~twolink_pin.optimal.transcription.TrajectoryProblem`)."""
    nv = robot.nv
    durations = np.diff(np.asarray(times, dtype=float))
    S = durations.size
    layout = SplineLayout(BSplineBasis.uniform(0.0, 1.0, pieces_per_segment, 5), S, nv, durations)
    at_vias = layout.points(np.append(np.arange(S), S - 1), np.append(np.zeros(S), 1.0))
    ends = layout.points(np.array([0, S - 1]), np.array([0.0, 1.0]))
    pins = (Pin("via", at_vias, 0, vias.q), *(Pin("rest", ends, r, np.zeros((2, nv))) for r in rest))
    return TrajectoryProblem(
        layout, RneaDerivatives(robot.model, friction), limits, cost, layout.quadrature(), layout.grid(CHECK), pins,
        kinds=kinds, hull=hull, margin=margin, time_scale=float(durations.mean()), continuity_order=continuity,
    )  # fmt: skip


def fit(layout: SplineLayout, trajectory: Trajectory, times: np.ndarray) -> np.ndarray:
    """The variables of the spline nearest ``trajectory`` (least squares, each segment on its
    own), its segments from ``times`` [s] (the problem's via times in ``trajectory``'s clock)."""
    basis = layout.basis
    sigma = basis.grid(8)
    coefficients = [basis.fit(sigma, trajectory.sample(a + (b - a) * sigma).q) for a, b in pairwise(times)]
    return layout.pack(np.stack(coefficients))


def knot_samples(
    problem: TrajectoryProblem, x: np.ndarray, t0: float, period: float, via_times: np.ndarray
) -> SampledTrajectory:
    """The solution's samples at its knots (each join once) with its torque, starting at
    ``t0`` [s]; a rest to ``period`` when it is longer than the motion; ``via_times`` [s]
    marked. Exact between the samples however smooth the joins: each knot interval is one
    quintic, which the quintic Hermite through its ends' ``q, q̇, q̈`` is (a jerk that jumps at
    a via point needs no second sample there)."""
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


__all__ = [
    "CHECK",
    "MAX_PIECES",
    "MIN_PIECES",
    "Vias",
    "check_reference_needs",
    "check_vias",
    "fit",
    "knot_samples",
    "pieces",
    "spline_problem",
    "vias_of",
]
