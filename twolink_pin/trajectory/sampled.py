"""A periodic joint reference given by samples of ``q``, ``q̇``, ``q̈`` (and the torque it
was designed with), interpolated by quintic Hermite polynomials.

Between two samples ``(t_i, q_i, q̇_i, q̈_i)`` and ``(t_{i+1}, …)`` the reference is the one
polynomial of degree 5 with those positions, velocities and accelerations at both ends
(``τ = (t − t_i)/h``, ``h = t_{i+1} − t_i``)::

    q(τ) = c_0 + c_1 τ + .. + c_5 τ⁵,  c_0 = q_i, c_1 = h q̇_i, c_2 = h² q̈_i / 2,
    c_3 = 10 Δ − 6 h q̇_i − 4 h q̇_{i+1} − h² (3 q̈_i − q̈_{i+1}) / 2,
    c_4 = −15 Δ + 8 h q̇_i + 7 h q̇_{i+1} + h² (3 q̈_i − 2 q̈_{i+1}) / 2,
    c_5 = 6 Δ − 3 h (q̇_i + q̇_{i+1}) − h² (q̈_i − q̈_{i+1}) / 2,      Δ = q_{i+1} − q_i

so it reproduces exactly any trajectory that is a polynomial of degree ≤ 5 between its samples:
a quintic spline sampled at its knots (what ``twolink-pin optimize`` saves), a cubic one.
A time given twice marks a jump of the acceleration (the same ``q`` and ``q̇``, the
acceleration before and after): a time-optimal retiming's acceleration jumps wherever its
path acceleration switches (TOPP-RA's grid points), and its samples are taken there.

The reference repeats with period ``times[-1] − times[0]``; it must end where it starts
(``q`` and ``q̇``; the acceleration may jump across the period, as a rest-to-rest
retiming's does).
"""

from __future__ import annotations

import numpy as np

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.errors import InvalidParameterError
from twolink_pin.trajectory.base import Trajectory, TrajectorySample

JUMP_TOLERANCE = 1e-9
"""How far [rad, rad/s] ``q`` and ``q̇`` may differ between the two samples of a repeated time."""
CLOSURE_TOLERANCE = 1e-6
"""How far [rad, rad/s] the last sample's ``q`` and ``q̇`` may be from the first's."""


def hermite_coefficients(
    h: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray, q1: np.ndarray, v1: np.ndarray, a1: np.ndarray
) -> np.ndarray:
    """The quintic's coefficients in powers of ``τ`` (module docstring) for each interval:
    ``h`` shape (n,), the rest (n, nv); returns (n, 6, nv)."""
    h1, h2 = h[:, None], h[:, None] ** 2
    d = q1 - q
    c = np.empty((h.size, 6, q.shape[1]))
    c[:, 0] = q
    c[:, 1] = h1 * v
    c[:, 2] = 0.5 * h2 * a
    c[:, 3] = 10.0 * d - h1 * (6.0 * v + 4.0 * v1) - 0.5 * h2 * (3.0 * a - a1)
    c[:, 4] = -15.0 * d + h1 * (8.0 * v + 7.0 * v1) + 0.5 * h2 * (3.0 * a - 2.0 * a1)
    c[:, 5] = 6.0 * d - 3.0 * h1 * (v + v1) - 0.5 * h2 * (a - a1)
    return c


class SampledTrajectory(Trajectory):
    """Periodic joint reference through samples (module docstring).

    Args:
        times: Sample times [s], shape (K,), non-decreasing; a time at most twice in a row
            (an acceleration jump), never at the ends.
        q: Positions [rad], shape (K, nv).
        v: Velocities [rad/s], shape (K, nv).
        a: Accelerations [rad/s²], shape (K, nv).
        tau: The torque the trajectory was designed with [N·m] (feedforward), shape (K, nv),
            or None.
        via_times: Times [s] the figures mark as via points (e.g. where a retimed path
            passes its via points), or None.

    Raises:
        InvalidParameterError: shapes, non-finite values, times, jumps or the closure wrong.
    """

    def __init__(
        self,
        times: np.ndarray,
        q: np.ndarray,
        v: np.ndarray,
        a: np.ndarray,
        tau: np.ndarray | None = None,
        via_times: np.ndarray | None = None,
    ) -> None:
        t = np.asarray(times, dtype=float)
        arrays = {"q": q, "v": v, "a": a} | ({} if tau is None else {"tau": tau})
        _check_times(t)
        for name, value in arrays.items():
            x = np.asarray(value, dtype=float)
            if x.ndim != 2 or x.shape[0] != t.size or x.shape[1] < 1:
                raise InvalidParameterError(
                    name, f"shape {x.shape}", f"shape ({t.size}, nv): one row per sample"
                )
            if not np.all(np.isfinite(x)):
                row = int(np.argwhere(~np.isfinite(x))[0][0])
                raise InvalidParameterError(f"{name}[{row}]", x[row].tolist(), "finite numbers")
        shapes = {np.shape(value) for value in arrays.values()}
        if len(shapes) != 1:
            raise InvalidParameterError("q, v, a, tau", sorted(shapes), "arrays of one shape (K, nv)")
        self.times = readonly(t)
        """Sample times [s], shape (K,)."""
        self.q, self.v, self.a = readonly(q), readonly(v), readonly(a)
        self.tau = readonly_or_none(tau)
        """Feedforward torque at the samples [N·m], shape (K, nv), or None."""
        self.t0 = float(t[0])
        self.period = float(t[-1] - t[0])
        self._via = readonly(np.zeros(0) if via_times is None else np.asarray(via_times, dtype=float))
        _check_jumps(self)
        step = np.diff(t) > 0
        self._starts = t[:-1][step] - self.t0
        self._h = np.diff(t)[step]
        i, j = np.flatnonzero(step), np.flatnonzero(step) + 1
        self._c = hermite_coefficients(
            self._h, self.q[i], self.v[i], self.a[i], self.q[j], self.v[j], self.a[j]
        )
        self._rows = (i, j)

    @property
    def nv(self) -> int:
        return int(self.q.shape[1])

    @property
    def via_times(self) -> np.ndarray:
        return self._via

    @property
    def span(self) -> float:
        """Time from the first sample to the last [s] (the period)."""
        return self.period

    def _locate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Interval index and ``τ`` of each time (reduced to one period)."""
        tau = np.mod(t - self.t0, self.period)
        k = np.clip(np.searchsorted(self._starts, tau, side="right") - 1, 0, self._h.size - 1)
        return k, np.clip((tau - self._starts[k]) / self._h[k], 0.0, 1.0)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        """Desired q, q̇, q̈ and jerk at time(s) ``t`` [s], repeated every :attr:`period`."""
        t_arr = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t_arr)):
            raise InvalidParameterError("t", t, "finite times [s]")
        k, s = self._locate(np.atleast_1d(t_arr))
        out = self._evaluate(k, s)
        if t_arr.ndim == 0:
            return TrajectorySample(*(x[0] for x in out))
        return TrajectorySample(*out)

    def dense(self, per_interval: int) -> tuple[np.ndarray, TrajectorySample]:
        """Every interval between two sample times at ``per_interval + 1`` evenly spaced
        points, both its ends included (a sample time inside the period twice: the end of
        one interval, the start of the next, each with its own acceleration): the times [s]
        and the motion there, one period."""
        if not (isinstance(per_interval, int) and per_interval >= 1):
            raise InvalidParameterError("per_interval", per_interval, "an integer >= 1")
        s = np.linspace(0.0, 1.0, per_interval + 1)
        k = np.repeat(np.arange(self._h.size), s.size)
        tau = np.tile(s, self._h.size)
        t = self.t0 + self._starts[k] + tau * self._h[k]
        return t, TrajectorySample(*self._evaluate(k, tau))

    def _evaluate(self, k: np.ndarray, s: np.ndarray) -> list[np.ndarray]:
        """q, q̇, q̈, jerk of interval ``k`` at ``τ = s``, each (K, nv)."""
        c, h = self._c[k], self._h[k][:, None]
        powers = s[:, None] ** np.arange(6)[None, :]  # (K, 6)
        out = []
        for order in range(4):
            factors = np.array([_falling(p, order) for p in range(6)], dtype=float)
            shifted = np.zeros_like(powers)
            shifted[:, order:] = powers[:, : 6 - order]
            out.append(np.einsum("kp,kpj->kj", shifted * factors, c) / h**order)
        return out

    def feedforward(self, t: float | np.ndarray) -> np.ndarray:
        """The design torque [N·m] at time(s) ``t`` [s], linear between samples (shape (nv,)
        or (N, nv)).

        Raises:
            InvalidParameterError: the trajectory carries no torque.
        """
        if self.tau is None:
            raise InvalidParameterError("tau", None, "a sampled trajectory saved with its torque")
        t_arr = np.asarray(t, dtype=float)
        k, s = self._locate(np.atleast_1d(t_arr))
        i, j = self._rows[0][k], self._rows[1][k]
        out = (1.0 - s)[:, None] * self.tau[i] + s[:, None] * self.tau[j]
        return out[0] if t_arr.ndim == 0 else out


def _falling(p: int, r: int) -> int:
    """``p (p − 1) .. (p − r + 1)``, 0 when ``r > p``."""
    out = 1
    for i in range(r):
        out *= p - i
    return out


def _check_times(t: np.ndarray) -> None:
    """Raise unless ``t`` [s] is finite, non-decreasing, at least two distinct, and a time
    appears at most twice in a row and not at either end."""
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise InvalidParameterError(
            "times", t.tolist() if t.size < 10 else f"{t.size} values", "at least two finite times [s]"
        )
    steps = np.diff(t)
    if np.any(steps < 0):
        k = int(np.flatnonzero(steps < 0)[0])
        raise InvalidParameterError(
            f"times[{k + 1}]", float(t[k + 1]), f"non-decreasing times: >= times[{k}] = {t[k]:.17g} s"
        )
    repeated = steps == 0
    if repeated[0] or repeated[-1] or np.any(repeated[1:] & repeated[:-1]):
        k = int(np.flatnonzero(repeated)[0])
        raise InvalidParameterError(
            f"times[{k + 1}]",
            float(t[k + 1]),
            "a time at most twice in a row (an acceleration jump), never at the first or last sample",
        )


def _check_jumps(trajectory: SampledTrajectory) -> None:
    """Raise unless ``q`` and ``q̇`` agree at a repeated time and the reference closes."""
    t = trajectory.times
    same = np.flatnonzero(np.diff(t) == 0)
    for name, x, unit in (("q", trajectory.q, "rad"), ("v", trajectory.v, "rad/s")):
        gaps = np.abs(x[same + 1] - x[same]).max(axis=1) if same.size else np.zeros(0)
        if gaps.size and gaps.max() > JUMP_TOLERANCE:
            k = int(same[np.argmax(gaps)])
            raise InvalidParameterError(
                f"{name}[{k + 1}]",
                x[k + 1].tolist(),
                f"{name}[{k}] again at the repeated time {t[k]:.17g} s (to {JUMP_TOLERANCE:g} {unit}: only the "
                "acceleration may jump)",
            )
        gap = float(np.abs(x[-1] - x[0]).max())
        if gap > CLOSURE_TOLERANCE:
            raise InvalidParameterError(
                f"{name}[{t.size - 1}]",
                x[-1].tolist(),
                f"the first sample's {name} {x[0].tolist()} again (to {CLOSURE_TOLERANCE:g} {unit}): the reference "
                "repeats every period",
            )


__all__ = ["CLOSURE_TOLERANCE", "JUMP_TOLERANCE", "SampledTrajectory", "hermite_coefficients"]
