"""Velocities and accelerations from logged positions: a zero-phase low-pass, then differences.

Identification practice (Gautier 1990s; Swevers et al. 1997) never differentiates raw
encoder positions: the noise would be amplified by ``(2π f)²`` in ``q̈``. Here:

1. **Uniform sampling.** The filter needs a fixed step: a log whose steps vary by more than
   :data:`JITTER_TOLERANCE` is resampled onto a uniform grid at its median step (cubic
   spline for ``q``, linear for ``τ``), and the result says so.
2. **Zero-phase low-pass.** A Butterworth filter of order :attr:`ZeroPhaseFilter.order`
   (default 4) at the cut-off ``f_c`` (default :data:`DEFAULT_CUTOFF_HZ` = 20 Hz, 40 times
   the 0.5-Hz bandwidth of the default excitation and well above an arm's closed-loop
   bandwidth), run forwards and backwards (``scipy.signal.sosfiltfilt``): no phase lag, an
   amplitude response ``1 / (1 + (f/f_c)^{2n})`` (−6 dB at ``f_c``; 1.5e-13 below 1 at a
   0.5-Hz harmonic).
3. **Differentiation** of the filtered positions by 5-point central differences (fourth
   order: error ``(ωh)⁴/30``, 3e-12 at 0.5 Hz and 1 kHz).
4. **The same filter on τ** (so that the torque and the regressor see the same band), and
   on the Coulomb column ``sgn q̇`` of the observation matrix (Gautier's parallel
   filtering, for the one column that jumps): friction makes ``τ`` jump at a velocity
   reversal, the filter spreads that jump over its impulse response, and the filtered sign
   column spreads it identically, so ``τ_f = W θ`` holds through the reversal.
5. **Samples dropped** within the filter's settling time :attr:`ZeroPhaseFilter.guard` of
   either end (the forward-backward transients: the time in which the filter's slowest pole
   decays :data:`GUARD_DECAY`-fold, ``ln(1e8) / (2π f_c sin(π / 2n))``, 0.38 s at 20 Hz),
   and where a joint moves slower than :attr:`ZeroPhaseFilter.min_speed` (sticking: there
   the friction is not ``C sgn q̇``). With :attr:`ZeroPhaseFilter.reversal_guard`, also
   within the settling time of any joint's velocity reversal: needed for a log whose
   *accelerations* jump there (an arm whose controller does not compensate friction), as
   the filter spreads that jump into ``q̈`` too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.identification.data import RunLog

DEFAULT_CUTOFF_HZ = 20.0
"""Default cut-off frequency of the zero-phase Butterworth filter [Hz]."""
DEFAULT_ORDER = 4
"""Default order of the Butterworth filter (each pass; forward-backward doubles the roll-off)."""
GUARD_DECAY = 1e8
"""Factor by which the filter's response to a jump has decayed at the guard's edge."""
JITTER_TOLERANCE = 1e-6
"""Relative spread of the sampling steps beyond which a log is resampled."""
MAX_CUTOFF_FRACTION = 0.45
"""The cut-off must be below this fraction of the sampling rate (Nyquist is 0.5)."""


@dataclass(frozen=True)
class ZeroPhaseFilter:
    """How positions become velocities and accelerations (see the module docstring).

    Attributes:
        cutoff_hz: Butterworth cut-off ``f_c`` [Hz], > 0.
        order: Butterworth order ``n`` per pass, 1 to 8.
        min_speed: Samples where some joint's filtered ``|q̇|`` is below this [rad/s] are
            dropped (near-sticking); default 0.01 rad/s.
        reversal_guard: Also drop the samples within :attr:`guard` of any joint's velocity
            reversal (for logs whose accelerations jump there).
    """

    cutoff_hz: float = DEFAULT_CUTOFF_HZ
    order: int = DEFAULT_ORDER
    min_speed: float = 0.01
    reversal_guard: bool = False

    def __post_init__(self) -> None:
        if not (
            isinstance(self.cutoff_hz, (int, float)) and math.isfinite(self.cutoff_hz) and self.cutoff_hz > 0
        ):
            raise InvalidParameterError("cutoff", self.cutoff_hz, "a finite cut-off frequency > 0 Hz")
        if isinstance(self.order, bool) or not (isinstance(self.order, int) and 1 <= self.order <= 8):
            raise InvalidParameterError("order", self.order, "a Butterworth order from 1 to 8")
        if not (math.isfinite(self.min_speed) and self.min_speed >= 0):
            raise InvalidParameterError("min_speed", self.min_speed, "a finite speed >= 0 rad/s")

    @property
    def guard(self) -> float:
        """Settling time [s]: ``ln(GUARD_DECAY) / (2π f_c sin(π / 2n))``."""
        return math.log(GUARD_DECAY) / (2 * math.pi * self.cutoff_hz * math.sin(math.pi / (2 * self.order)))

    def check_rate(self, sampling_hz: float) -> None:
        """Raise unless the cut-off is below :data:`MAX_CUTOFF_FRACTION` of the sampling rate."""
        if self.cutoff_hz >= MAX_CUTOFF_FRACTION * sampling_hz:
            raise InvalidParameterError(
                "cutoff",
                self.cutoff_hz,
                f"a cut-off below {MAX_CUTOFF_FRACTION:g} × the sampling rate {sampling_hz:.6g} Hz "
                f"(< {MAX_CUTOFF_FRACTION * sampling_hz:.6g} Hz)",
            )


class FilteredLog(NamedTuple):
    """A log on a uniform grid, filtered and differentiated (K samples, n joints)."""

    t: np.ndarray
    """Time [s], shape (K,), uniform."""
    q: np.ndarray
    """Filtered positions [rad], shape (K, n)."""
    v: np.ndarray
    """Velocities [rad/s] from the filtered positions, shape (K, n)."""
    a: np.ndarray
    """Accelerations [rad/s²] from the filtered positions, shape (K, n)."""
    tau: np.ndarray
    """Filtered torques [N·m], shape (K, n)."""
    coulomb: np.ndarray
    """The Coulomb column ``sgn q̇`` filtered like τ, shape (K, n)."""
    tau_raw: np.ndarray
    """The torques as logged (resampled if the log was), shape (K, n)."""
    valid: np.ndarray
    """Samples the model holds at (not near an end, a reversal or sticking), shape (K,) bool."""
    dt: float
    """Sampling step [s]."""
    resampled: bool
    """Whether the log was resampled onto a uniform grid."""
    velocity_check: np.ndarray | None
    """RMS of (logged − estimated) velocity per joint over the valid samples [rad/s], or None."""


def _five_point(x: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives by 5-point central differences (NaN at 2 samples each end)."""
    d1 = np.full_like(x, np.nan)
    d2 = np.full_like(x, np.nan)
    d1[2:-2] = (-x[4:] + 8 * x[3:-1] - 8 * x[1:-3] + x[:-4]) / (12 * h)
    d2[2:-2] = (-x[4:] + 16 * x[3:-1] - 30 * x[2:-2] + 16 * x[1:-3] - x[:-4]) / (12 * h * h)
    return d1, d2


def uniform(log: RunLog) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, bool]:
    """``(t, q, tau, v, resampled)`` on a uniform grid (the log's own if it is uniform)."""
    steps = np.diff(log.t)
    dt = float(np.median(steps))
    if float(np.abs(steps - dt).max()) <= JITTER_TOLERANCE * dt:
        return log.t, log.q, log.tau, log.v, False
    from scipy.interpolate import CubicSpline

    count = math.floor(log.duration / dt + 1e-9) + 1
    t = log.t[0] + dt * np.arange(count)
    q = CubicSpline(log.t, log.q, axis=0)(t)
    tau = np.column_stack([np.interp(t, log.t, log.tau[:, j]) for j in range(log.nv)])
    v = None if log.v is None else np.column_stack([np.interp(t, log.t, log.v[:, j]) for j in range(log.nv)])
    return t, q, tau, v, True


def lowpass(x: np.ndarray, dt: float, zero_phase: ZeroPhaseFilter) -> np.ndarray:
    """``x`` (K, …) through the zero-phase Butterworth filter, along the first axis."""
    from scipy.signal import butter, sosfiltfilt

    sos = butter(zero_phase.order, zero_phase.cutoff_hz, fs=1.0 / dt, output="sos")
    return np.asarray(sosfiltfilt(sos, x, axis=0))


def filter_log(log: RunLog, zero_phase: ZeroPhaseFilter | None = None) -> FilteredLog:
    """Filter and differentiate ``log`` (see the module docstring).

    Raises:
        InvalidParameterError: the cut-off is too high for the sampling rate, or the log is
            shorter than the filter needs (three times the guard).
    """
    f = zero_phase if zero_phase is not None else ZeroPhaseFilter()
    t, q, tau, v_logged, resampled = uniform(log)
    dt = float(t[1] - t[0])
    f.check_rate(1.0 / dt)
    guard = max(3, math.ceil(f.guard / dt))
    if t.size <= 3 * guard:
        raise InvalidParameterError(
            "log",
            f"{t.size} samples over {log.duration:.6g} s",
            f"more than 3 × the filter's settling time {f.guard:.3g} s ({3 * guard} samples at dt = {dt:.6g} s); "
            "log a longer run or raise the cut-off",
        )
    qf = lowpass(q, dt, f)
    tauf = lowpass(tau, dt, f)
    v, a = _five_point(qf, dt)
    valid = np.isfinite(a).all(axis=1)
    valid[:guard] = False
    valid[-guard:] = False
    slow = np.abs(np.nan_to_num(v)) < f.min_speed
    valid &= ~slow.any(axis=1)
    sign = np.sign(np.nan_to_num(v))
    coulomb = lowpass(sign, dt, f)
    if f.reversal_guard:
        near = np.zeros(t.size, dtype=int)
        for j in range(log.nv):
            flips = np.flatnonzero(sign[1:, j] != sign[:-1, j])
            np.add.at(near, np.maximum(flips - guard, 0), 1)
            np.subtract.at(near, np.minimum(flips + guard + 2, t.size - 1), 1)
        valid &= np.cumsum(near) == 0
    check = None
    if v_logged is not None and valid.any():
        check = np.sqrt(np.mean((v_logged[valid] - v[valid]) ** 2, axis=0))
    return FilteredLog(t, qf, v, a, tauf, coulomb, tau, valid, dt, resampled, check)
