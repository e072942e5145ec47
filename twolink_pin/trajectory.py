"""Via-point joint trajectory: one polynomial per joint, repeated periodically.

For via points ``q_0 .. q_n`` at times ``t_0 < .. < t_n`` the polynomial of each joint
satisfies ``n + 1`` position conditions and ``order`` zero derivatives (velocity,
acceleration, jerk for the default ``order = 3``) at ``t_0`` and ``t_n``: with the report's
five via points that is 5 + 2·3 = 11 conditions and a 10th-order polynomial (report
eqs. 4–7). Angles [rad], times [s].

The linear system is solved and evaluated in normalised time ``s = (t − t_0)/T``
(``T = t_n − t_0``), which keeps the matrix's scale independent of the time unit and span
(for the report's 4 s the condition number is 2e8 against 5e8 in ``t``); the coefficients
in powers of ``t − t_0`` follow by scaling, ``a_k = c_k / T^k``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.polynomial import polynomial as P

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class ViaPoints:
    """End-effector via points and their timing.

    Attributes:
        xy: Via points ``(x, y)`` [m]; for a periodic trajectory the last equals the first.
        times: Strictly increasing times [s], one per via point.
        branch: IK elbow branch: 0 for ``q2 >= 0`` (the report's choice), 1 for ``q2 <= 0``.
        period: Repetition period [s] (>= ``times[-1] − times[0]``; the arm rests at the
            last point for the difference); ``None`` means ``times[-1] − times[0]``.
        boundary_order: Highest derivative set to zero at both ends (3: up to jerk).
    """

    xy: tuple[tuple[float, float], ...]
    times: tuple[float, ...]
    branch: int = 0
    period: float | None = None
    boundary_order: int = 3

    def __post_init__(self) -> None:
        _check_times(self.times, len(self.xy), "xy")
        for point in self.xy:
            if len(point) != 2 or not all(math.isfinite(c) for c in point):
                raise InvalidParameterError("xy", self.xy, "via points of two finite coordinates (x, y) [m]")
        if self.branch not in (0, 1):
            raise InvalidParameterError("branch", self.branch, "0 (q2 >= 0) or 1 (q2 <= 0)")
        _check_period(self.period, self.times)
        if not (isinstance(self.boundary_order, int) and 0 <= self.boundary_order <= 6):
            raise InvalidParameterError("boundary_order", self.boundary_order, "an integer from 0 to 6")


def _check_times(times: tuple[float, ...], n: int, what: str) -> None:
    if len(times) != n:
        raise InvalidParameterError("times", times, f"one time per via point ({n} from {what})")
    if n < 2:
        raise InvalidParameterError("times", times, "at least two via points")
    if not all(math.isfinite(t) for t in times) or any(b <= a for a, b in itertools.pairwise(times)):
        raise InvalidParameterError("times", times, "finite, strictly increasing times [s]")


def _check_period(period: float | None, times: tuple[float, ...]) -> None:
    if period is None:
        return
    span = times[-1] - times[0]
    if not (math.isfinite(period) and period >= span):
        raise InvalidParameterError("period", period, f"a finite period >= the via-point span {span:g} s")


class TrajectorySample(NamedTuple):
    """Desired motion at one or more times; each array has shape (nv,) or (N, nv)."""

    q: np.ndarray
    """Position [rad]."""
    v: np.ndarray
    """Velocity [rad/s]."""
    a: np.ndarray
    """Acceleration [rad/s²]."""
    jerk: np.ndarray
    """Jerk [rad/s³]."""


class JointTrajectory:
    """Periodic polynomial joint trajectory through via points (any number of joints).

    Build it with :meth:`from_via_q` (joint-space via points) or
    :func:`build_trajectory` (end-effector via points through IK).
    """

    def __init__(self, times: np.ndarray, via_q: np.ndarray, period: float, boundary_order: int) -> None:
        self.times = readonly(times)
        """Via-point times [s], shape (n + 1,)."""
        self.via_q = readonly(via_q)
        """Via points [rad], shape (n + 1, nv)."""
        self.period = float(period)
        """Repetition period [s]."""
        self.t0 = float(times[0])
        self.span = float(times[-1] - times[0])
        self.boundary_order = boundary_order
        s = (self.times - self.t0) / self.span
        rows, rhs = [], []
        degree = len(s) + 2 * boundary_order - 1
        powers = np.arange(degree + 1)
        for k, sk in enumerate(s):
            rows.append(sk**powers)
            rhs.append(self.via_q[k])
        for endpoint in (0.0, 1.0):
            for order in range(1, boundary_order + 1):
                row = np.zeros(degree + 1)
                for p in range(order, degree + 1):
                    row[p] = math.perm(p, order) * endpoint ** (p - order)
                rows.append(row)
                rhs.append(np.zeros(self.via_q.shape[1]))
        A, b = np.array(rows), np.array(rhs)
        self._c = [np.linalg.solve(A, b)]  # (degree + 1, nv), powers of s
        for _ in range(3):
            self._c.append(P.polyder(self._c[-1]))
        scale = self.span ** -powers.astype(float)
        self.coefficients = readonly((self._c[0] * scale[:, None]).T)
        """Coefficients [rad/s^k], shape (nv, degree + 1), ascending powers of ``t − t0``."""

    @classmethod
    def from_via_q(
        cls,
        times: tuple[float, ...] | np.ndarray,
        via_q: np.ndarray,
        period: float | None = None,
        boundary_order: int = 3,
    ) -> JointTrajectory:
        """Trajectory through joint-space via points ``via_q`` [rad], shape (n + 1, nv)."""
        via_q = np.asarray(via_q, dtype=float)
        times_t = tuple(float(t) for t in times)
        _check_times(times_t, len(via_q), "via_q")
        if via_q.ndim != 2 or not np.all(np.isfinite(via_q)):
            raise InvalidParameterError("via_q", via_q.tolist(), "finite joint positions, shape (n + 1, nv)")
        _check_period(period, times_t)
        span = times_t[-1] - times_t[0]
        return cls(np.array(times_t), via_q, span if period is None else period, boundary_order)

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.via_q.shape[1])

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        """Desired q, q̇, q̈ and jerk at time(s) ``t`` [s], repeated with :attr:`period`.

        Between the last via point and the end of a period longer than the via-point
        span the arm rests at the last via point.
        """
        t_arr = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t_arr)):
            raise InvalidParameterError("t", t, "finite times [s]")
        tau = np.mod(t_arr - self.t0, self.period)
        resting = tau > self.span
        s = np.minimum(tau, self.span) / self.span
        out = []
        for order, c in enumerate(self._c):
            value = P.polyval(s, c) / self.span**order  # (nv,) or (nv, N)
            if order > 0:
                value = np.where(resting, 0.0, value)
            out.append(np.moveaxis(np.asarray(value), 0, -1))
        return TrajectorySample(*out)

    def __call__(self, t: float | np.ndarray) -> TrajectorySample:
        return self.sample(t)


def build_trajectory(robot: RobotModel, via: ViaPoints | None = None) -> JointTrajectory:
    """Trajectory through end-effector via points of a planar 2R arm (IK branch
    ``via.branch``); default: the robot's own trajectory (:func:`default_via_points`).

    Raises:
        UnreachableTargetError: a via point is outside the reachable annulus.
        InvalidParameterError: no via points given and the robot's profile has none.
    """
    if via is None:
        return default_trajectory(robot)
    via_q = np.array([inverse_kinematics(robot, xy)[via.branch] for xy in via.xy])
    return JointTrajectory.from_via_q(via.times, via_q, via.period, via.boundary_order)


def default_via_points(robot: RobotModel) -> ViaPoints | None:
    """The robot profile's end-effector via points as :class:`ViaPoints` (planar), or None."""
    spec = robot.profile.trajectory
    if spec is None or spec.cartesian_points is None:
        return None
    xy = tuple((float(p[0]), float(p[1])) for p in spec.cartesian_points)
    return ViaPoints(xy=xy, times=tuple(spec.times), branch=spec.branch, period=spec.period)


def default_trajectory(robot: RobotModel) -> JointTrajectory:
    """The robot's default reference: its profile's via points (joint or end-effector), else
    a periodic motion through the middle of each joint's range (see :func:`neutral_motion`)."""
    spec = robot.profile.trajectory
    if spec is None:
        return neutral_motion(robot)
    if spec.joint_points is not None:
        return JointTrajectory.from_via_q(spec.times, np.array(spec.joint_points, dtype=float), spec.period)
    via = default_via_points(robot)
    assert via is not None
    return build_trajectory(robot, via)


NEUTRAL_AMPLITUDE = 0.4
"""Largest excursion [rad] of :func:`neutral_motion` from the middle of a joint's range."""


def neutral_motion(robot: RobotModel, period: float = 4.0) -> JointTrajectory:
    """A periodic reference for any arm: each joint leaves the middle of its range
    (0 rad for an unlimited joint), swings ``±a_j`` and comes back, with
    ``a_j = min(NEUTRAL_AMPLITUDE, 25 % of the range)``, the joints out of phase.
    """
    model = robot.model
    lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
    finite = np.isfinite(lower) & np.isfinite(upper) & (upper > lower) & (upper - lower < 1e3)
    middle = np.where(finite, 0.5 * (lower + upper), 0.0)
    amplitude = np.where(finite, np.minimum(NEUTRAL_AMPLITUDE, 0.25 * (upper - lower)), NEUTRAL_AMPLITUDE)
    signs = np.where(np.arange(robot.nv) % 2 == 0, 1.0, -1.0)
    times = tuple(period * k / 4 for k in range(5))
    shape = np.array([0.0, 1.0, 0.0, -1.0, 0.0])
    via_q = middle + np.outer(shape, signs * amplitude)
    return JointTrajectory.from_via_q(times, via_q)
