"""Periodic finite-Fourier-series joint trajectory (Swevers, Ganseman, Tükel, De Schutter and
Van Brussel, 1997, "Optimal robot excitation and identification", IEEE T-RA 13(5)).

Each joint ``j`` follows, with base pulsation ``ω_f = 2π / T`` and ``N`` harmonics::

    q_j(t)  = q_j0 + Σ_{l=1..N} [ a_jl / (l ω_f) sin(l ω_f t') − b_jl / (l ω_f) cos(l ω_f t') ]
    q̇_j(t)  =        Σ_l [ a_jl cos(l ω_f t') + b_jl sin(l ω_f t') ]
    q̈_j(t)  =        Σ_l l ω_f [ −a_jl sin(l ω_f t') + b_jl cos(l ω_f t') ]

with ``t' = t − t0``. The coefficients ``a_jl, b_jl`` are velocity amplitudes [rad/s] (Swevers'
convention) and ``q_j0`` [rad] is the mean position (every sine and cosine term averages to zero
over a period). The motion is periodic with period ``T`` by construction and smooth (every
derivative is continuous), so it repeats without the rest phases or boundary conditions a
via-point polynomial needs. Its spectrum holds exactly the frequencies ``l / T`` [Hz],
``l = 1..N``: the bandwidth is ``N / T``.

Closed-form bounds (used as the optimiser's constraints, :mod:`twolink_pin.identification.excitation`)::

    |q_j − q_j0| <= Σ_l ρ_jl / (l ω_f),   |q̇_j| <= Σ_l ρ_jl,   |q̈_j| <= Σ_l l ω_f ρ_jl,
    ρ_jl = sqrt(a_jl² + b_jl²)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError
from twolink_pin.trajectory.base import Trajectory, TrajectorySample

MIN_PERIOD = 1e-3
"""Shortest period [s]: its harmonics' accelerations (∝ 1/T²) and jerks (∝ 1/T³) stay
finite and meaningful (a period of 1e-300 s would overflow them to inf)."""
MAX_PERIOD = 1e6
"""Longest period [s] (the longest simulation)."""
MAX_HARMONICS = 100
"""Most harmonics per joint a Fourier trajectory may have."""


def _array(name: str, value: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, what) from None
    if array.shape != shape:
        raise InvalidParameterError(name, f"shape {array.shape}", f"{what}, shape {shape}")
    if not np.all(np.isfinite(array)):
        raise InvalidParameterError(
            name, array.tolist() if array.size <= 24 else "non-finite values", f"finite {what}"
        )
    return array


class FourierTrajectory(Trajectory):
    """A periodic joint reference as a finite Fourier series (see the module docstring).

    Args:
        period: ``T`` [s], > 0: the base frequency is ``1 / T`` [Hz].
        a: Sine coefficients ``a_jl`` [rad/s] of the velocity, shape (nv, N).
        b: Cosine coefficients ``b_jl`` [rad/s] of the velocity, shape (nv, N).
        offset: ``q_j0`` [rad], the mean position of each joint, shape (nv,).
        t0: Start of the first period [s].

    Raises:
        InvalidParameterError: a non-positive or non-finite period, coefficient arrays of
            different or wrong shapes, more than :data:`MAX_HARMONICS` harmonics.
    """

    def __init__(self, period: float, a: Any, b: Any, offset: Any, t0: float = 0.0) -> None:
        if isinstance(period, bool) or not (
            isinstance(period, (int, float)) and MIN_PERIOD <= period <= MAX_PERIOD
        ):
            raise InvalidParameterError("period", period, f"a period from {MIN_PERIOD:g} to {MAX_PERIOD:g} s")
        if isinstance(t0, bool) or not (isinstance(t0, (int, float)) and math.isfinite(t0)):
            raise InvalidParameterError("t0", t0, "a finite start time [s]")
        a_arr = np.array(a, dtype=float) if np.ndim(a) == 2 else None
        if a_arr is None or not 1 <= a_arr.shape[1] <= MAX_HARMONICS or a_arr.shape[0] < 1:
            raise InvalidParameterError(
                "a", a, f"sine coefficients [rad/s], shape (nv, N) with 1 <= N <= {MAX_HARMONICS}"
            )
        nv, harmonics = a_arr.shape
        self.period = float(period)
        """Repetition period ``T`` [s]."""
        self.t0 = float(t0)
        self.a = readonly(_array("a", a, (nv, harmonics), "sine coefficients [rad/s]"))
        """Sine coefficients ``a_jl`` [rad/s], shape (nv, N)."""
        self.b = readonly(_array("b", b, (nv, harmonics), "cosine coefficients [rad/s] like a"))
        """Cosine coefficients ``b_jl`` [rad/s], shape (nv, N)."""
        self.offset = readonly(_array("offset", offset, (nv,), "mean joint positions [rad], one per joint"))
        """Mean position ``q_j0`` [rad], shape (nv,)."""
        self._pulsations = 2.0 * np.pi * np.arange(1, harmonics + 1) / self.period

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.a.shape[0])

    @property
    def harmonics(self) -> int:
        """Number of harmonics ``N`` per joint."""
        return int(self.a.shape[1])

    @property
    def bandwidth(self) -> float:
        """Highest frequency in the motion, ``N / T`` [Hz]."""
        return self.harmonics / self.period

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closed-form bounds per joint: max ``|q − q0|`` [rad], ``|q̇|`` [rad/s], ``|q̈|`` [rad/s²]."""
        rho = np.hypot(self.a, self.b)
        w = self._pulsations
        return (rho / w).sum(axis=1), rho.sum(axis=1), (rho * w).sum(axis=1)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        """Desired q [rad], q̇ [rad/s], q̈ [rad/s²] and jerk [rad/s³] at time(s) ``t`` [s]:
        shape (nv,) for a scalar, (K, nv) for K times."""
        t_arr = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t_arr)):
            raise InvalidParameterError("t", t, "finite times [s]")
        phase = np.multiply.outer(t_arr - self.t0, self._pulsations)  # (..., N)
        s, c = np.sin(phase), np.cos(phase)
        w = self._pulsations
        q = self.offset + s @ (self.a / w).T - c @ (self.b / w).T
        v = c @ self.a.T + s @ self.b.T
        a = -s @ (self.a * w).T + c @ (self.b * w).T
        jerk = -c @ (self.a * w**2).T - s @ (self.b * w**2).T
        return TrajectorySample(q, v, a, jerk)

    def as_dict(self) -> dict[str, Any]:
        """The trajectory-file form: ``{"period", "harmonics", "a", "b", "offset"}`` (see
        :mod:`twolink_pin.trajectory.file`)."""
        return {
            "period": self.period,
            "harmonics": self.harmonics,
            "a": self.a.tolist(),
            "b": self.b.tolist(),
            "offset": self.offset.tolist(),
        }

    def __repr__(self) -> str:
        return f"<FourierTrajectory nv={self.nv} N={self.harmonics} T={self.period:g} s>"
