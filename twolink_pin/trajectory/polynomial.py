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

import numpy as np
from numpy.polynomial import polynomial as P

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError
from twolink_pin.trajectory.base import Trajectory, TrajectorySample


def check_times(times: tuple[float, ...], n: int, what: str) -> None:
    if len(times) != n:
        raise InvalidParameterError("times", times, f"one time per via point ({n} from {what})")
    if n < 2:
        raise InvalidParameterError("times", times, "at least two via points")
    if not all(math.isfinite(t) for t in times) or any(b <= a for a, b in itertools.pairwise(times)):
        raise InvalidParameterError("times", times, "finite, strictly increasing times [s]")


def check_period(period: float | None, times: tuple[float, ...]) -> None:
    if period is None:
        return
    span = times[-1] - times[0]
    if not (math.isfinite(period) and period >= span):
        raise InvalidParameterError("period", period, f"a finite period >= the via-point span {span:g} s")


class JointTrajectory(Trajectory):
    """Periodic polynomial joint trajectory through via points (any number of joints).

    Build it with :meth:`from_via_q` (joint-space via points),
    :func:`~twolink_pin.trajectory.build_trajectory` (a planar 2R arm's end-effector via
    points) or :func:`~twolink_pin.trajectory.cartesian_trajectory` (any arm's).
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
        check_times(times_t, len(via_q), "via_q")
        if via_q.ndim != 2 or not np.all(np.isfinite(via_q)):
            raise InvalidParameterError("via_q", via_q.tolist(), "finite joint positions, shape (n + 1, nv)")
        check_period(period, times_t)
        span = times_t[-1] - times_t[0]
        return cls(np.array(times_t), via_q, span if period is None else period, boundary_order)

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.via_q.shape[1])

    @property
    def via_times(self) -> np.ndarray:
        return self.times

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
