"""Identification by weighted least squares on the stacked observation matrix (Gautier).

From a :class:`~twolink_pin.identification.data.RunLog`:

1. filter and differentiate (:func:`~twolink_pin.identification.filtering.filter_log`);
2. split off the last :attr:`IdentificationOptions.validation` fraction of the run as a
   validation period, never used for fitting;
3. keep every ``stride``-th valid sample of the fitting period (default: a rate of
   ``4 f_c``, which keeps the information of data that hold nothing above ``f_c``) and stack
   ``W θ = τ``;
4. ordinary least squares; the residual of each joint's rows gives its error variance
   ``σ_j² = ‖ρ_j‖² / (K (1 − n_θ / (K n)))`` (K samples, n joints);
5. **weighted** least squares with each joint's rows divided by ``σ_j`` (Gautier 1997,
   "Dynamic identification of robots with power model"; Gautier & Poignet 2001): a joint with
   larger torque noise counts less; ``σ_j`` is re-estimated from the weighted residual and
   the solve repeated (3 solves in all: the ordinary residual of a quiet joint carries some of
   a noisy joint's error through the shared estimate);
6. the covariance of ``θ̂``: the sandwich ``B⁻¹ S B⁻¹`` (``B = W_wᵀ W_w``, ``S`` the
   Parzen-windowed sum of the score products of samples up to :data:`CORRELATION_TIMES`
   periods of ``f_c`` apart): the filter makes neighbouring rows' errors correlated, and
   position noise becomes a *blue* acceleration noise that the low-frequency regressor barely
   sees, so the textbook ``s² (W_wᵀ W_w)⁻¹`` for independent rows overstates it up to 3×;
   then the standard deviation ``σ_θi = sqrt(Σ_θ,ii)`` of each estimate and its relative
   standard deviation ``100 σ_θi / |θ̂_i|`` [%] (above ~10 %: poorly identified).

What the standard deviations do not contain: the bias that position noise causes through
the regressor (errors in variables, relative size ``≈ σ²(q̈ noise) / mean(q̈²)``): negligible
at encoder-level noise, it dominates beyond ~1e-4 rad at the default cut-off
(docs/identification.md measures it).

The condition number of ``W`` (SI units, unweighted, the fitted rows) says how well the
motion excites ``θ``; the residual RMS per joint, on the fitting and the validation period,
how well the identified model predicts the torques.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.blas import one_blas_thread
from twolink_pin.errors import InputFileError, InvalidParameterError, require_type
from twolink_pin.identification.data import MIN_SAMPLES, RunLog, check_sample_count
from twolink_pin.identification.filtering import FilteredLog, ZeroPhaseFilter, filter_log
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.identification.weighted_solve import solve
from twolink_pin.model import RobotModel

DEFAULT_VALIDATION = 0.25
"""Fraction of the run (its end) kept for validation."""
MAX_CONDITION = 1e10
"""An observation matrix worse conditioned than this does not identify every parameter."""
SAMPLES_PER_CUTOFF = 4.0
"""Default fitting rate, in multiples of the cut-off: the filtered data hold nothing above
``f_c``, so a rate of ``4 f_c`` keeps their information with a fraction of the rows."""
CORRELATION_TIMES = 10.0
"""Bandwidth of the covariance's lag window, in ``1 / f_c``: the filtered errors are far from
white (position noise becomes a blue ``q̈`` noise, torque noise a band-limited one), and lags
over ten periods of the cut-off, Parzen-weighted, count them (Monte Carlo: scatter of the
normalised errors within 0.9–1.2 of the stated σ; a Bartlett window over 3 periods overstated
σ by up to 1.6×, independent rows by 3×)."""


@dataclass(frozen=True)
class IdentificationOptions:
    """How a log is turned into parameters.

    Attributes:
        zero_phase: The filter and its cut-off (:class:`ZeroPhaseFilter`).
        friction: Identify viscous and Coulomb friction per joint too.
        validation: Fraction of the run, at its end, kept for validation (0 to 0.9).
        stride: Keep every ``stride``-th valid sample for fitting; None: ``round(1 / (f_c dt))``.
        weighted: Gautier's weighted least squares (else ordinary).
        instruments: Use the log's reference trajectory (when it has one) as instruments:
            instrumental variables instead of least squares, free of the bias position noise
            causes (module docstring).
    """

    zero_phase: ZeroPhaseFilter = field(default_factory=ZeroPhaseFilter)
    friction: bool = True
    validation: float = DEFAULT_VALIDATION
    stride: int | None = None
    weighted: bool = True
    instruments: bool = True

    def __post_init__(self) -> None:
        if not (isinstance(self.validation, (int, float)) and 0 <= self.validation <= 0.9):
            raise InvalidParameterError("validation", self.validation, "a fraction from 0 to 0.9 of the run")
        if self.stride is not None and (
            isinstance(self.stride, bool) or not isinstance(self.stride, int) or self.stride < 1
        ):
            raise InvalidParameterError("stride", self.stride, "a whole number >= 1, or None (automatic)")


class Validation(NamedTuple):
    """Measured against predicted torque on the validation period (M samples)."""

    t: np.ndarray
    """Time [s], shape (M,)."""
    tau_measured: np.ndarray
    """Logged torque [N·m], shape (M, n)."""
    tau_filtered: np.ndarray
    """Logged torque after the zero-phase filter [N·m], shape (M, n)."""
    tau_predicted: np.ndarray
    """``W θ̂`` from the filtered positions [N·m], shape (M, n)."""
    valid: np.ndarray
    """Samples the model holds at, shape (M,)."""
    rms: np.ndarray
    """RMS of (filtered − predicted) over the valid samples, per joint [N·m]."""


@dataclass(frozen=True)
class Identification:
    """The identified parameters of one log, with their uncertainty (n_θ parameters)."""

    robot: str
    """The robot's name."""
    names: tuple[str, ...]
    """Parameter names (base parameters, then V1..Vn, C1..Cn)."""
    units: tuple[str, ...]
    """SI unit of each."""
    kinds: tuple[str, ...]
    """``"inertial"`` or ``"friction"`` each."""
    estimate: np.ndarray
    """``θ̂``, shape (n_θ,)."""
    std: np.ndarray
    """Standard deviation of each estimate, shape (n_θ,)."""
    covariance: np.ndarray = field(repr=False)
    """``Σ_θ``, shape (n_θ, n_θ)."""
    true: np.ndarray | None
    """True values where the data were simulated, else None."""
    condition_number: float
    """``cond(W)`` of the fitted rows (SI units, unweighted)."""
    weighted_condition_number: float
    """``cond(W_w)`` of the weighted rows."""
    joint_sigma: np.ndarray
    """Error standard deviation per joint from the OLS residual [N·m] (the weights)."""
    residual_rms: np.ndarray
    """RMS of the fitted rows' residual per joint [N·m]."""
    validation: Validation | None = field(repr=False)
    """The validation period, or None (``validation = 0``)."""
    samples: int
    """Samples in the log."""
    fit_samples: int
    """Samples stacked into ``W`` (after dropping and striding)."""
    stride: int
    """Every ``stride``-th valid sample was used."""
    dt: float
    """Sampling step [s]."""
    cutoff_hz: float
    """Filter cut-off [Hz]."""
    order: int
    """Filter order."""
    guard: float
    """Samples within this time [s] of an end or a reversal were dropped."""
    resampled: bool
    """Whether the log was resampled onto a uniform grid."""
    fit_interval: tuple[float, float]
    """Time span fitted [s]."""
    velocity_check: np.ndarray | None
    """RMS (logged − estimated) velocity per joint [rad/s] where the log has velocities."""
    source: str = ""
    """Where the data came from."""
    weighted: bool = True
    """Whether the weighted solution is reported."""
    method: str = "least squares"
    """``"least squares"`` or ``"instrumental variables"`` (the reference motion's regressor
    as instruments)."""
    gram: np.ndarray | None = field(default=None, repr=False)
    """``W_wᵀ W_w`` of the fitted rows weighted by ``1 / joint_sigma`` (the metric of the
    weighted least squares: ``‖y_w − W_w θ‖² = (θ − θ̂)ᵀ G (θ − θ̂) + const``), shape (n_θ, n_θ)."""

    @property
    def relative_std(self) -> np.ndarray:
        """``100 σ / |θ̂|`` [%] (inf where the estimate is 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.estimate != 0, 100 * self.std / np.abs(self.estimate), np.inf)

    @property
    def size(self) -> int:
        """Number of parameters n_θ."""
        return len(self.names)

    def parameters(self) -> list[dict[str, Any]]:
        """One dict per parameter: name, unit, kind, estimate, std, relative_std_percent, true."""
        rows = []
        for i, name in enumerate(self.names):
            rel = float(self.relative_std[i])
            rows.append(
                {
                    "name": name,
                    "unit": self.units[i],
                    "kind": self.kinds[i],
                    "estimate": float(self.estimate[i]),
                    "std": float(self.std[i]),
                    "relative_std_percent": rel if math.isfinite(rel) else None,
                    "true": None if self.true is None else float(self.true[i]),
                }
            )
        return rows

    def within(self, k: float = 3.0) -> np.ndarray | None:
        """Whether each true value is within ``±k σ`` of its estimate (None without truth)."""
        return None if self.true is None else np.abs(self.estimate - self.true) <= k * self.std


def _poorly_excited(W: np.ndarray, names: tuple[str, ...]) -> str:
    """The parameters that dominate the least-excited direction of ``W``."""
    _, _, Vt = np.linalg.svd(W.reshape(-1, W.shape[2]), full_matrices=False)
    direction = Vt[-1]
    top = np.argsort(-np.abs(direction))[:3]
    return ", ".join(f"{names[i]} ({direction[i]:+.2f})" for i in top)


def identify(log: RunLog, robot: RobotModel, options: IdentificationOptions | None = None) -> Identification:
    """The base parameters (and friction) of ``robot`` from ``log`` (see the module docstring).

    Raises:
        InputFileError: the log has too few samples for the number of parameters, before or
            after dropping the samples near ends and reversals (the message gives the counts).
        InvalidParameterError: the log is for another number of joints, the cut-off is too
            high for its sampling rate, or the motion does not excite every parameter (the
            message names the worst-excited combination).
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    require_type(log, RunLog, "log", "a RunLog (twolink_pin.read_log, simulate_log)")
    with one_blas_thread():  # small dense algebra: OpenBLAS's threads only slow it (twolink_pin/blas.py)
        return _identify(log, robot, options)


def _identify(log: RunLog, robot: RobotModel, options: IdentificationOptions | None) -> Identification:
    opts = options if options is not None else IdentificationOptions()
    if log.nv != robot.nv:
        raise InvalidParameterError("log", f"{log.nv} joints", f"a log of {robot.name}'s {robot.nv} joints")
    pset = ParameterSet.of(robot, friction=opts.friction)
    where = log.source or "log"
    check_sample_count(where, log.samples, max(MIN_SAMPLES, pset.size), f"identifying {pset.size} parameters")
    filtered = filter_log(log, opts.zero_phase)
    t = filtered.t
    split = t[0] + (1.0 - opts.validation) * (t[-1] - t[0])
    rows, stride = _fit_rows(filtered, robot, pset, opts, split, where)
    W = pset.observation(
        robot.model, filtered.q[rows], filtered.v[rows], filtered.a[rows], filtered.coulomb[rows]
    )
    y = filtered.tau[rows]
    condition = _checked_condition(W, pset, where)
    lags = math.ceil(CORRELATION_TIMES / (opts.zero_phase.cutoff_hz * filtered.dt * stride))
    Z = _instruments(log, filtered, robot, pset, rows, opts) if opts.instruments else None
    theta, covariance, sigma = solve(W, y, opts.weighted, rows, lags, Z)
    weighted = (W / sigma[None, :, None]).reshape(-1, pset.size)
    sw = np.linalg.svd(weighted, compute_uv=False)
    residual = y - np.einsum("knp,p->kn", W, theta)
    validation = (
        _validation(filtered, robot, pset, theta, split, opts.zero_phase.guard)
        if opts.validation > 0
        else None
    )
    true = log.true_parameters
    if true is not None and true.size != pset.size:
        true = true[: pset.size] if true.size == pset.size + 2 * robot.nv else None
    return Identification(
        robot=robot.name,
        names=pset.names,
        units=pset.units,
        kinds=pset.kinds,
        estimate=theta,
        std=np.sqrt(np.maximum(np.diag(covariance), 0.0)),
        covariance=covariance,
        true=true,
        condition_number=condition,
        weighted_condition_number=float(sw[0] / sw[-1]),
        joint_sigma=sigma,
        residual_rms=np.sqrt(np.mean(residual**2, axis=0)),
        validation=validation,
        samples=log.samples,
        fit_samples=int(rows.size),
        stride=int(stride),
        dt=filtered.dt,
        cutoff_hz=opts.zero_phase.cutoff_hz,
        order=opts.zero_phase.order,
        guard=opts.zero_phase.guard,
        resampled=filtered.resampled,
        fit_interval=(float(t[rows[0]]), float(t[rows[-1]])),
        velocity_check=filtered.velocity_check,
        source=log.source,
        weighted=opts.weighted,
        method="least squares" if Z is None else "instrumental variables",
        gram=weighted.T @ weighted,
    )


def _fit_rows(
    filtered: FilteredLog,
    robot: RobotModel,
    pset: ParameterSet,
    opts: IdentificationOptions,
    split: float,
    where: str,
) -> tuple[np.ndarray, int]:
    """The samples that enter the fit and the stride between them: the valid ones before the
    validation part (``t < split`` [s]), every ``stride``-th (default: :data:`SAMPLES_PER_CUTOFF`
    per period of the filter's cutoff); an error if too few are left for ``pset``."""
    t = filtered.t
    fitting = filtered.valid & (t < split)
    stride = (
        opts.stride
        if opts.stride is not None
        else max(1, round(1.0 / (SAMPLES_PER_CUTOFF * opts.zero_phase.cutoff_hz * filtered.dt)))
    )
    rows = np.flatnonzero(fitting)[::stride]
    needed = math.ceil((pset.size + 1) / robot.nv)
    if rows.size < max(needed, 2):
        _refuse_still_joints(filtered, robot, opts.zero_phase.min_speed, t < split, where)
        raise InputFileError(
            where,
            f"leaves {rows.size} samples to fit after dropping {np.count_nonzero(~filtered.valid)} of {t.size} "
            f"(within {opts.zero_phase.guard:.3g} s of an end{' or a velocity reversal' if opts.zero_phase.reversal_guard else ''}, or slower than "
            f"{opts.zero_phase.min_speed:g} rad/s) and keeping every {stride}th; identifying {pset.size} parameters "
            f"from {robot.nv} joints needs at least {max(needed, 2)}: log a longer run",
        )
    return rows, stride


def _refuse_still_joints(
    filtered: FilteredLog, robot: RobotModel, min_speed: float, fitted: np.ndarray, where: str
) -> None:
    """Name the joints that never move in the fitted part of the log (``fitted``: its samples),
    when there are: their ``|q̇|`` stays below ``min_speed`` [rad/s] at every sample, so every
    sample is dropped as sticking — a longer log would not help."""
    speed = np.abs(filtered.v[fitted])
    peak = np.nanmax(np.where(np.isfinite(speed), speed, 0.0), axis=0) if speed.size else np.zeros(robot.nv)
    still = [j for j in range(robot.nv) if peak[j] < min_speed]
    if not still:
        return
    names = tuple(robot.model.names)[1:]
    joints = ", ".join(f"joint {j + 1}" + (f" ({names[j]})" if len(names) == robot.nv else "") for j in still)
    fastest = ", ".join(f"{peak[j]:.3g}" for j in still)
    raise InputFileError(
        where,
        f"{joints} never move{'s' if len(still) == 1 else ''}: the largest |q̇| is {fastest} rad/s, below the "
        f"{min_speed:g} rad/s under which a sample is dropped as sticking, so no sample is left to fit; "
        "identification needs every joint to move (a trajectory that moves each joint, e.g. twolink-pin excite)",
    )


def _checked_condition(W: np.ndarray, pset: ParameterSet, where: str) -> float:
    """The condition number of the stacked observation matrix ``W`` (K, nv, p); an error
    naming the least excited combination when it is :data:`MAX_CONDITION` or more."""
    stacked = W.reshape(-1, pset.size)
    singular = np.linalg.svd(stacked, compute_uv=False)
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else math.inf
    if not condition < MAX_CONDITION:
        raise InvalidParameterError(
            "log",
            f"{where}: observation matrix with condition number {condition:.3g}",
            f"a motion that excites every parameter (condition < {MAX_CONDITION:.0e}); the least excited "
            f"combination is {_poorly_excited(W, pset.names)}: use an excitation trajectory (twolink-pin excite)",
        )
    return condition


def validation_of(
    log: RunLog, robot: RobotModel, theta: np.ndarray, options: IdentificationOptions | None = None
) -> Validation | None:
    """The validation period of ``log`` (as :func:`identify` splits it) predicted by any ``θ``
    (e.g. a constrained estimate), or None without one."""
    opts = options if options is not None else IdentificationOptions()
    if opts.validation <= 0:
        return None
    pset = ParameterSet.of(robot, friction=opts.friction)
    filtered = filter_log(log, opts.zero_phase)
    t = filtered.t
    split = t[0] + (1.0 - opts.validation) * (t[-1] - t[0])
    return _validation(filtered, robot, pset, np.asarray(theta, dtype=float), split, opts.zero_phase.guard)


def _instruments(
    log: RunLog,
    filtered: FilteredLog,
    robot: RobotModel,
    pset: ParameterSet,
    rows: np.ndarray,
    opts: IdentificationOptions,
) -> np.ndarray | None:
    """The regressor of the log's reference motion at the fitted samples (its Coulomb column
    filtered like the data's), or None without a reference."""
    from twolink_pin.identification.filtering import lowpass

    if log.reference is None:
        return None
    ref = log.reference.sample(filtered.t)
    coulomb = lowpass(np.sign(ref.v), filtered.dt, opts.zero_phase)
    return pset.observation(robot.model, ref.q[rows], ref.v[rows], ref.a[rows], coulomb[rows])


def _validation(
    filtered: FilteredLog,
    robot: RobotModel,
    pset: ParameterSet,
    theta: np.ndarray,
    split: float,
    guard: float,
) -> Validation | None:
    """Predicted against measured torque from ``split`` [s] to ``guard`` [s] before the end (the
    filter's transient), or None if nothing is left."""
    t = filtered.t
    period = np.flatnonzero((t >= split) & (t <= t[-1] - guard) & np.isfinite(filtered.a).all(axis=1))
    if period.size == 0:
        return None
    W = pset.observation(
        robot.model, filtered.q[period], filtered.v[period], filtered.a[period], filtered.coulomb[period]
    )
    predicted = np.einsum("knp,p->kn", W, theta)
    valid = filtered.valid[period]
    error = (filtered.tau[period] - predicted)[valid]
    rms = np.sqrt(np.mean(error**2, axis=0)) if error.size else np.full(robot.nv, np.nan)
    return Validation(
        filtered.t[period], filtered.tau_raw[period], filtered.tau[period], predicted, valid, rms
    )
