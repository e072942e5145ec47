"""The batch engine: many independent closed-loop runs advanced together.

:func:`simulate_batch` runs N controllers of one kind (different gains, initial states,
parameter estimates or model errors) on one plant along one reference, in lock step: the
same RK4 scheme as :func:`twolink_pin.simulation.simulate` (per-stage law, or the held
law of ``control_period``), with the N states as the columns of ``(nv, N)`` arrays.

* the plant's accelerations come from ``pin.abaInParallel`` over a ``pin.ModelPool``;
* the controllers' Pinocchio terms from ``pin.rneaInParallel``: the model term
  ``M(q) a + C(q, q̇) w + g(q)`` by the polarisation identity, both terms in one call on
  :func:`twolink_pin.dynamics.polarisation_forest`, and, for the adaptive laws or when the
  controllers' models differ, the regressor ``Y_p`` column by column: RNEA is linear in
  the inertial parameters π, so ``Y_p[:, j] = τ(π₀ + P[:, j]) − τ(π₀)`` on models that
  differ by the map's column ``P[:, j]`` (π₀: the plant's parameters; see
  :class:`_Regressor`), all columns in one call;
* the laws themselves in numpy over the batch, written as explicit per-column sums so a
  run's numbers do not depend on N or on which runs share its batch.

Results equal N separate :func:`~twolink_pin.simulation.simulate` calls to rounding
(tested to 1e-9). Memory is O(N) unless ``record=True``: each run's metrics (the norms of
:mod:`twolink_pin.metrics`, torque peaks, the first time a limit was exceeded) are
accumulated step by step instead of keeping its trajectory. A run that diverges is
stopped and reported in :attr:`BatchResult.diverged_at` instead of failing the batch.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.controllers import (
    Adaptive,
    AdaptiveFriction,
    ComputedTorque,
    Controller,
    PDFeedforward,
    WrongModel,
)
from twolink_pin.dynamics import model_torque, model_with_parameters, polarisation_forest
from twolink_pin.errors import InvalidParameterError, TwolinkPinError
from twolink_pin.metrics import Metrics, Norms
from twolink_pin.model import RobotModel
from twolink_pin.model.parameters import N_BODY_PARAMETERS, ParameterMap, inertial_parameters
from twolink_pin.plant import Plant
from twolink_pin.simulation import DIVERGENCE_LIMIT, SimulationConfig
from twolink_pin.trajectory import JointTrajectory

MIN_RUNS_PER_THREAD = 256
"""Fewer runs than this per thread and the batch uses fewer threads: a parallel region on
a handful of columns costs more in synchronisation (and, on a busy machine, in waiting for
a descheduled thread) than it saves."""

_KINDS: tuple[type[Controller], ...] = (PDFeedforward, ComputedTorque, WrongModel, Adaptive, AdaptiveFriction)


class BatchUnavailableError(TwolinkPinError):
    """Pinocchio lacks the parallel algorithms the batch engine needs.

    Attributes:
        missing: Names of the missing ``pinocchio`` attributes.
    """

    def __init__(self, missing: Sequence[str]) -> None:
        self.missing = tuple(missing)
        super().__init__(
            f"pinocchio {pin.__version__} has no {', '.join(self.missing)}: it was built without its "
            "parallel module (OpenMP). Install a build that has it (pip install 'pin>=3' or conda-forge "
            "pinocchio), or run the cases one by one with twolink_pin.simulation.simulate"
        )


def robot_with_parameters(robot: RobotModel, p: np.ndarray) -> RobotModel:
    """``robot`` as a controller that believes the parameters ``p`` sees it.

    The model's inertias give ``p`` through the parameter map
    (:func:`twolink_pin.dynamics.model_with_parameters`); the kinematics, limits and map
    are unchanged. Build a controller on it to give it a parameter error: PD and
    Slotine–Li use ``p`` in their model terms, the adaptive laws start from
    ``p̂(0) = initial_estimate × p`` (their regressor does not depend on the inertias).
    Runs judge ``p̂`` against the plant's values (:meth:`Controller.parameters_of`).
    """
    model = model_with_parameters(robot.model, robot.parameter_map, p)
    values = np.array(robot.parameter_map.values(model), dtype=float)
    values.setflags(write=False)
    return replace(robot, model=model, p=values)


# -- results --------------------------------------------------------------------------------


class BatchMetrics(NamedTuple):
    """Each run's metrics, accumulated during the batch; arrays of shape (N, nv).

    The norms are those of :func:`twolink_pin.metrics.compute_metrics` (trapezoidal
    rule on the output grid). Rows of diverged runs are NaN.
    """

    rms: Norms
    """Root mean square of ``e`` [rad], ``ė`` [rad/s], applied ``τ`` [N·m]."""
    l2: Norms
    """``sqrt(∫ x² dt)`` of the same signals."""
    max: Norms
    """``max |x|`` of the same signals."""
    final_period_max_abs_e: np.ndarray
    """``max |e|`` over the last reference period [rad]."""
    peak_command: np.ndarray
    """``max |τ_command|`` [N·m] (before saturation)."""
    first_exceeded_at: np.ndarray
    """First time [s] ``|τ_command|`` exceeded the joint's limit; NaN if never."""

    def run(self, i: int) -> Metrics:
        """Run ``i``'s metrics as a :class:`~twolink_pin.metrics.Metrics`."""
        pick = lambda n: Norms(n.e[i], n.edot[i], n.tau[i])  # noqa: E731
        return Metrics(pick(self.rms), pick(self.l2), pick(self.max), self.final_period_max_abs_e[i])


@dataclass(frozen=True)
class BatchResult:
    """N runs of one controller kind. Arrays are read-only; K = number of output samples."""

    controller: str
    """Controller's registry name."""
    dt: float
    """Output grid spacing (and RK4 step) [s]."""
    t: np.ndarray = field(repr=False)
    """Time [s], shape (K,)."""
    q0_offset: np.ndarray = field(repr=False)
    """``q(0) − q_d(0)`` of each run [rad], shape (N, nv)."""
    v0_offset: np.ndarray = field(repr=False)
    """``q̇(0) − q̇_d(0)`` of each run [rad/s], shape (N, nv)."""
    metrics: BatchMetrics = field(repr=False)
    """Each run's metrics."""
    diverged_at: np.ndarray = field(repr=False)
    """Time [s] at which each run diverged (as :class:`~twolink_pin.errors.SimulationDivergedError`
    would report it); NaN for runs that did not, shape (N,)."""
    torque_limits: np.ndarray = field(repr=False)
    """Motor limits [N·m], shape (nv,)."""
    saturate: bool
    """Whether the plant clipped torques to the limits."""
    threads: int
    """Threads given to Pinocchio's parallel algorithms (after the cap of ``MIN_RUNS_PER_THREAD``)."""
    control_period: float | None = None
    """Sampling period of the held law [s], or None (law at every RK4 stage)."""
    p_hat_final: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates at the end, shape (N, n_p), adaptive laws only (NaN if diverged)."""
    p_true: np.ndarray | None = field(repr=False, default=None)
    """The plant's true values of the estimated parameters, shape (n_p,), or None."""
    parameter_names: tuple[str, ...] = ()
    """Names of the estimated parameters."""
    q: np.ndarray | None = field(repr=False, default=None)
    """Joint positions [rad], shape (N, K, nv), only with ``record=True``."""
    v: np.ndarray | None = field(repr=False, default=None)
    """Joint velocities [rad/s], shape (N, K, nv), only with ``record=True``."""
    tau_command: np.ndarray | None = field(repr=False, default=None)
    """Commanded torque [N·m], shape (N, K, nv), only with ``record=True``."""
    p_hat: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates, shape (N, K, n_p), only with ``record=True`` (adaptive laws)."""

    @property
    def n_runs(self) -> int:
        """Number of runs N."""
        return int(self.diverged_at.shape[0])

    @property
    def diverged(self) -> np.ndarray:
        """Whether each run diverged, shape (N,)."""
        return ~np.isnan(self.diverged_at)

    @property
    def limit_exceeded(self) -> np.ndarray:
        """Whether each run's command ever exceeded each joint's limit, shape (N, nv)."""
        return ~np.isnan(self.metrics.first_exceeded_at)


# -- Pinocchio over the batch -----------------------------------------------------------------


def _check_parallel() -> None:
    missing = [name for name in ("ModelPool", "abaInParallel", "rneaInParallel") if not hasattr(pin, name)]
    if missing:
        raise BatchUnavailableError(missing)


class _PolarisedTerms:
    """``M_i(q) a + C_i(q, v) w + g_i(q)`` [N·m] of several models over the batch, in one call.

    One ``rneaInParallel`` on the :func:`~twolink_pin.dynamics.polarisation_forest` of the
    models (same kinematics): the two terms of the polarisation identity of every model in
    one parallel region instead of two per model.
    """

    def __init__(self, models: Sequence[pin.Model], threads: int, n: int) -> None:
        forest = polarisation_forest(models)
        self.pool = pin.ModelPool(forest, threads)
        self.threads = threads
        self.k, self.nv = len(models), models[0].nv
        size = 2 * self.k * self.nv
        self.q, self.v, self.a = np.empty((n, size)), np.empty((n, size)), np.zeros((n, size))
        self.out = np.empty((n, size))

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> list[np.ndarray]:
        n, k, nv = q.shape[0], self.k, self.nv
        self.q.reshape(n, 2 * k, nv)[:] = q[:, None, :]
        velocities = self.v.reshape(n, k, 2, nv)
        velocities[:, :, 0, :] = (0.5 * (v + w))[:, None, :]
        velocities[:, :, 1, :] = (0.5 * (v - w))[:, None, :]
        self.a.reshape(n, k, 2, nv)[:, :, 0, :] = a[:, None, :]  # copies B keep a = 0
        pin.rneaInParallel(self.threads, self.pool, self.q.T, self.v.T, self.a.T, self.out.T)
        out = self.out.reshape(n, k, 2, nv)
        return [out[:, i, 0, :] - out[:, i, 1, :] for i in range(k)]


class _ModelTerm:
    """``M(q) a + C(q, v) w + g(q)`` [N·m] of one model over the batch (one RNEA call)."""

    def __init__(self, model: pin.Model, threads: int, n: int) -> None:
        self.terms = _PolarisedTerms([model], threads, n)

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        return self.terms(q, v, w, a)[0]


class _Regressor:
    """``Y_p(q, v, w, a)`` with ``Y_p p = M a + C(q, v) w + g`` over the batch, shape (N, nv, n_p).

    RNEA is linear in the inertial parameters π (also for the non-physical π of a column),
    so on the column models ``π₀ + P_j`` it gives ``T_j = τ(π₀) + Y_j``. π₀ is ``model``'s
    parameters, with any zero mass set to 1 kg so that every column model has a finite
    inertia. When the map describes π₀'s dynamics completely, ``τ(π₀) = Y p₀``
    (``p₀ = values(π₀)``), so ``τ(π₀) = Σ_k p₀_k T_k / (1 + Σ p₀)`` and no base model is
    needed: n_p models, not n_p + 1 (checked numerically at construction; otherwise the base
    is computed). All models go through one :class:`_PolarisedTerms` call.
    """

    def __init__(self, model: pin.Model, parameter_map: ParameterMap, threads: int, n: int) -> None:
        pi0 = inertial_parameters(model)
        masses = pi0[::N_BODY_PARAMETERS]
        masses[masses <= 0] = 1.0
        pi0[::N_BODY_PARAMETERS] = masses
        base = _with_inertial_parameters(model, pi0)
        P = parameter_map.matrix
        columns = [_with_inertial_parameters(model, pi0 + P[:, j]) for j in range(P.shape[1])]
        self.size = P.shape[1]
        p0 = parameter_map.values(base)
        denominator = 1.0 + float(np.sum(p0))
        self.weights: np.ndarray | None = None
        if abs(denominator) > 1e-6 and _complete(base, columns, p0 / denominator):
            self.weights = p0 / denominator
            self.terms = _PolarisedTerms(columns, threads, n)
        else:
            self.terms = _PolarisedTerms([base, *columns], threads, n)

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> list[np.ndarray]:
        terms = self.terms(q, v, w, a)
        if self.weights is None:
            return [column - terms[0] for column in terms[1:]]
        base = terms[0] * self.weights[0]
        for weight, term in zip(self.weights[1:], terms[1:], strict=True):
            base = base + term * weight
        return [term - base for term in terms]


def _complete(base: pin.Model, columns: Sequence[pin.Model], weights: np.ndarray) -> bool:
    """Whether ``τ(π₀) = Σ_k weights_k T_k`` at random states, to 1e-10 relative."""
    rng = np.random.default_rng(0)
    q, v, w, a = (rng.uniform(-2.0, 2.0, (8, base.nv)) for _ in range(4))
    direct = _PolarisedTerms([base], 1, 8)(q, v, w, a)[0]
    terms = _PolarisedTerms(columns, 1, 8)(q, v, w, a)
    combined = sum(
        (weight * term for weight, term in zip(weights, terms, strict=True)), np.zeros_like(direct)
    )
    return bool(np.abs(combined - direct).max() <= 1e-10 * max(1.0, float(np.abs(direct).max())))


def _with_inertial_parameters(model: pin.Model, pi: np.ndarray) -> pin.Model:
    copy = pin.Model(model)
    for j in range(1, model.njoints):
        copy.inertias[j] = pin.Inertia.FromDynamicParameters(
            np.array(pi[N_BODY_PARAMETERS * (j - 1) : N_BODY_PARAMETERS * j])
        )
    return copy


def _same_kinematics(a: pin.Model, b: pin.Model) -> bool:
    if (a.nq, a.nv, a.njoints) != (b.nq, b.nv, b.njoints):
        return False
    if not np.array_equal(a.gravity.vector, b.gravity.vector):
        return False
    for j in range(1, a.njoints):
        if a.joints[j].shortname() != b.joints[j].shortname() or a.parents[j] != b.parents[j]:
            return False
        if not np.array_equal(a.jointPlacements[j].homogeneous, b.jointPlacements[j].homogeneous):
            return False
    return True


# -- the laws over the batch -------------------------------------------------------------------


def _stack(controllers: Sequence[Any], attribute: str) -> np.ndarray:
    return np.array(
        [
            np.broadcast_to(getattr(c, attribute), np.shape(getattr(controllers[0], attribute)))
            for c in controllers
        ],
        dtype=float,
    )


class _ModelSource:
    """The controllers' model term ``M̂ a + Ĉ w + ĝ``: one shared model, or per-run p̂ through Y_p."""

    def __init__(self, controllers: Sequence[Controller], plant: Plant, threads: int) -> None:
        n = len(controllers)
        first = controllers[0].model
        pi = [inertial_parameters(c.model) for c in controllers]
        if all(np.array_equal(x, pi[0]) for x in pi[1:]):
            self.shared: _ModelTerm | None = _ModelTerm(first, threads, n)
            return
        self.shared = None
        parameter_map = plant.robot.parameter_map
        self.regressor = _Regressor(plant.model, parameter_map, threads, n)
        self.p = np.array([parameter_map.values(c.model) for c in controllers])
        _check_representable(controllers, self.p, self.regressor)

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        if self.shared is not None:
            return self.shared(q, v, w, a)
        columns = self.regressor(q, v, w, a)
        tau = columns[0] * self.p[:, 0:1]
        for j in range(1, len(columns)):
            tau = tau + columns[j] * self.p[:, j : j + 1]
        return tau


def _check_representable(controllers: Sequence[Controller], p: np.ndarray, regressor: _Regressor) -> None:
    """Fail fast if a controller's model is not ``Y_p p̂`` (differs beyond the parameter map)."""
    n, nv = p.shape[0], controllers[0].robot.nv
    rng = np.random.default_rng(0)
    q, v, w, a = (np.tile(rng.uniform(-1, 1, nv), (n, 1)) for _ in range(4))
    columns = regressor(q, v, w, a)
    predicted = sum(columns[j] * p[:, j : j + 1] for j in range(len(columns)))
    for i, c in enumerate(controllers):
        exact = model_torque(c.model, c.model.createData(), q[i], v[i], w[i], a[i])
        if not np.allclose(predicted[i], exact, rtol=1e-9, atol=1e-9 * max(1.0, float(np.abs(exact).max()))):
            raise InvalidParameterError(
                f"controllers[{i}].model",
                c.model.name,
                "a model that differs from the plant's only through the parameter map's parameters "
                f"{c.robot.parameter_map.names} (build it with robot_with_parameters)",
            )


class _Law:
    """A controller kind's law over the batch: ``(τ, ż)`` from ``(N, ·)`` arrays."""

    nz = 0

    def __call__(
        self, q: np.ndarray, v: np.ndarray, qd: np.ndarray, vd: np.ndarray, ad: np.ndarray, z: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class _PDLaw(_Law):
    """:class:`~twolink_pin.controllers.PDFeedforward`: ``τ = M q̈_d + C q̇_d + g − Kp e − Kd ė``."""

    def __init__(self, controllers: Sequence[Any], plant: Plant, threads: int) -> None:
        self.kp, self.kd = _stack(controllers, "kp"), _stack(controllers, "kd")
        self.model = _ModelSource(controllers, plant, threads)

    def __call__(
        self, q: np.ndarray, v: np.ndarray, qd: np.ndarray, vd: np.ndarray, ad: np.ndarray, z: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        tau = self.model(q, v, vd, ad)
        return tau - (self.kp * (q - qd) + self.kd * (v - vd)), z


class _SlotineLiLaw(_Law):
    """:class:`~twolink_pin.controllers.ComputedTorque` and ``WrongModel``:
    ``τ = β (M q̈_r + C q̇_r + g) − K s``."""

    def __init__(self, controllers: Sequence[Any], plant: Plant, threads: int) -> None:
        self.k = _stack(controllers, "k")
        self.lam = np.array([[c.lam] for c in controllers], dtype=float)
        self.scale = np.array([[c.model_scale] for c in controllers], dtype=float)
        self.scaled = bool(np.any(self.scale != 1.0))
        self.model = _ModelSource(controllers, plant, threads)

    def __call__(
        self, q: np.ndarray, v: np.ndarray, qd: np.ndarray, vd: np.ndarray, ad: np.ndarray, z: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        e, edot = q - qd, v - vd
        tau = self.model(q, v, vd - self.lam * e, ad - self.lam * edot)
        if self.scaled:  # 1.0 * x == x exactly, so unscaled runs are untouched
            tau = self.scale * tau
        return tau - self.k * (edot + self.lam * e), z


class _AdaptiveLaw(_Law):
    """:class:`~twolink_pin.controllers.Adaptive` (and ``AdaptiveFriction`` with ``friction``):
    ``τ = Y p̂ − K s``, ``ż = −Γ Yᵀ s``."""

    def __init__(self, controllers: Sequence[Any], plant: Plant, threads: int, friction: bool) -> None:
        first = controllers[0]
        self.k = _stack(controllers, "k")
        self.lam = np.array([[c.lam] for c in controllers], dtype=float)
        self.gamma = _stack(controllers, "Gamma")
        self.nz = self.gamma.shape[1]
        for i, c in enumerate(controllers):
            if not np.array_equal(c.P, first.P):
                raise InvalidParameterError(
                    f"controllers[{i}].P",
                    c.robot.parameter_map.names,
                    f"the first's map {first.robot.parameter_map.names}",
                )
        self.regressor = _Regressor(plant.model, first.robot.parameter_map, threads, len(controllers))
        self.smoothing: float | None = None
        if friction:
            smoothing = {c.friction.smoothing for c in controllers}
            if len(smoothing) != 1:
                raise InvalidParameterError(
                    "friction.smoothing", sorted(smoothing), "one value for the whole batch"
                )
            self.smoothing = smoothing.pop()

    def __call__(
        self, q: np.ndarray, v: np.ndarray, qd: np.ndarray, vd: np.ndarray, ad: np.ndarray, z: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        e, edot = q - qd, v - vd
        s = edot + self.lam * e
        nv = q.shape[1]
        columns = self.regressor(q, v, vd - self.lam * e, ad - self.lam * edot)
        if self.smoothing is not None:  # [diag(q̇), diag(sgn q̇)] as sparse columns
            sign = np.sign(v) if self.smoothing == 0 else np.tanh(v / self.smoothing)
            n = q.shape[0]
            for source in (v, sign):
                for j in range(nv):
                    column = np.zeros((n, nv))
                    column[:, j] = source[:, j]
                    columns.append(column)
        tau = columns[0] * z[:, 0:1]
        for i in range(1, len(columns)):
            tau = tau + columns[i] * z[:, i : i + 1]
        dz = np.empty_like(z)
        for i, column in enumerate(columns):
            acc = column[:, 0] * s[:, 0]
            for j in range(1, nv):
                acc = acc + column[:, j] * s[:, j]
            dz[:, i] = -self.gamma[:, i] * acc
        return tau - self.k * s, dz


def _make_law(controllers: Sequence[Controller], plant: Plant, threads: int) -> _Law:
    kind = type(controllers[0])
    if kind not in _KINDS:
        raise InvalidParameterError(
            "controllers",
            kind.__name__,
            f"one of the five laws {', '.join(k.__name__ for k in _KINDS)} (no vectorised law for others)",
        )
    for i, c in enumerate(controllers):
        if type(c) is not kind:
            raise InvalidParameterError(
                f"controllers[{i}]", type(c).__name__, f"controllers of one kind ({kind.__name__})"
            )
        if not _same_kinematics(c.model, plant.model):
            raise InvalidParameterError(
                f"controllers[{i}].model",
                c.model.name,
                "the plant's kinematics and gravity (only inertias may differ)",
            )
    if kind is PDFeedforward:
        return _PDLaw(controllers, plant, threads)
    if kind in (ComputedTorque, WrongModel):
        return _SlotineLiLaw(controllers, plant, threads)
    return _AdaptiveLaw(controllers, plant, threads, friction=kind is AdaptiveFriction)


class _PlantBatch:
    """``plant.acceleration`` over the batch (``abaInParallel``)."""

    def __init__(self, plant: Plant, threads: int, n: int) -> None:
        self.pool = pin.ModelPool(plant.model, threads)
        self.threads = threads
        self.plant = plant
        self.out = np.empty((n, plant.robot.nv))

    def applied(self, tau: np.ndarray) -> np.ndarray:
        limits = self.plant.limits
        return np.clip(tau, -limits, limits) if self.plant.saturate else tau

    def __call__(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        tau = self.applied(tau)
        friction = self.plant.friction
        if friction is not None:
            tau = tau - friction.torque(v)
        pin.abaInParallel(self.threads, self.pool, q.T, v.T, np.ascontiguousarray(tau).T, self.out.T)
        return self.out.copy()


# -- metrics accumulated step by step -------------------------------------------------------------


class _Accumulator:
    """Running sums and maxima of each run's signals on the output grid (see BatchMetrics)."""

    def __init__(
        self, n: int, nv: int, steps: int, dt: float, t: np.ndarray, period: float, limits: np.ndarray
    ) -> None:
        self.square = {name: np.zeros((n, nv)) for name in Norms._fields}
        self.ends = {name: np.zeros((n, nv)) for name in Norms._fields}
        self.peak = {name: np.zeros((n, nv)) for name in Norms._fields}
        self.final_e = np.zeros((n, nv))
        self.peak_command = np.zeros((n, nv))
        self.first_exceeded = np.full((n, nv), np.nan)
        self.last_start = int(np.argmax(t >= t[-1] - period - 1e-12))
        self.steps, self.dt, self.t, self.limits = steps, dt, t, limits

    def add(self, k: int, e: np.ndarray, edot: np.ndarray, tau: np.ndarray, command: np.ndarray) -> None:
        for name, x in (("e", e), ("edot", edot), ("tau", tau)):
            x2 = x * x
            self.square[name] += x2
            if k == 0 or k == self.steps:
                self.ends[name] += x2
            np.maximum(self.peak[name], np.abs(x), out=self.peak[name])
        if k >= self.last_start:
            np.maximum(self.final_e, np.abs(e), out=self.final_e)
        magnitude = np.abs(command)
        np.maximum(self.peak_command, magnitude, out=self.peak_command)
        newly = (magnitude > self.limits) & np.isnan(self.first_exceeded)
        if newly.any():
            self.first_exceeded[newly] = self.t[k]

    def metrics(self, dead: np.ndarray) -> BatchMetrics:
        duration = self.t[-1] - self.t[0]
        l2 = Norms(**{k: np.sqrt(self.dt * (self.square[k] - 0.5 * self.ends[k])) for k in Norms._fields})
        rms = Norms(**{k: x / np.sqrt(duration) for k, x in l2._asdict().items()})
        mx = Norms(**self.peak)

        def clean(x: np.ndarray) -> np.ndarray:
            x = np.array(x, dtype=float)
            x[dead] = np.nan
            x.setflags(write=False)
            return x

        return BatchMetrics(
            Norms(*(clean(x) for x in rms)),
            Norms(*(clean(x) for x in l2)),
            Norms(*(clean(x) for x in mx)),
            clean(self.final_e),
            clean(self.peak_command),
            clean(self.first_exceeded),
        )


# -- the engine -----------------------------------------------------------------------------------


def _offsets(name: str, value: Any, default: Sequence[float] | None, n: int, nv: int) -> np.ndarray:
    if value is None:
        base = np.zeros(nv) if default is None else np.asarray(default, dtype=float)
        return np.tile(base, (n, 1))
    array = np.array(value, dtype=float)
    if array.shape != (n, nv):
        raise InvalidParameterError(
            name, f"shape {array.shape}", f"shape ({n}, {nv}): one row per controller"
        )
    if not np.all(np.isfinite(array)):
        raise InvalidParameterError(name, "non-finite entries", "finite offsets")
    return array


def default_threads() -> int:
    """Cores available to this process (the default thread count)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def simulate_batch(
    controllers: Sequence[Controller],
    plant: Plant,
    trajectory: JointTrajectory,
    config: SimulationConfig | None = None,
    *,
    q0_offsets: np.ndarray | Sequence[Sequence[float]] | None = None,
    v0_offsets: np.ndarray | Sequence[Sequence[float]] | None = None,
    threads: int | None = None,
    record: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> BatchResult:
    """Run each controller on ``plant`` along ``trajectory``, all N runs together.

    Run ``i`` is what ``simulate(controllers[i], plant, trajectory, config)`` computes with
    ``q0_offset = q0_offsets[i]`` and ``v0_offset = v0_offsets[i]`` (to rounding), except
    that a diverging run is stopped and flagged instead of raising.

    Args:
        controllers: N controllers of one of the five kinds (same class), each with its own
            gains; their models may differ from the plant's only in inertial parameters
            expressible by the parameter map (see :func:`robot_with_parameters`).
        plant: The arm all runs drive (one model: friction and saturation are shared).
        trajectory: The reference.
        config: Duration, step, ``control_period``; ``method`` must be ``"rk4"``. Its
            ``q0_offset`` / ``v0_offset`` are the defaults for every run.
        q0_offsets: ``q(0) − q_d(0)`` per run [rad], shape (N, nv).
        v0_offsets: ``q̇(0) − q̇_d(0)`` per run [rad/s], shape (N, nv).
        threads: Threads for Pinocchio's parallel algorithms; default all cores. At most
            one thread per :data:`MIN_RUNS_PER_THREAD` runs is used (at least one).
        record: Keep every run's trajectory (memory N × K × nv × 8 bytes per signal).
        progress: Called as ``progress(steps_done, steps_total)`` about 100 times.

    Raises:
        InvalidParameterError: mixed or unsupported controller kinds, bad offsets, a
            controller model that differs from the plant beyond the parameter map,
            ``method != "rk4"``, ``threads < 1``.
        BatchUnavailableError: this Pinocchio has no parallel algorithms.
    """
    _check_parallel()
    config = config if config is not None else SimulationConfig()
    if config.method != "rk4":
        raise InvalidParameterError("method", config.method, "'rk4' (the batch engine is fixed-step)")
    if len(controllers) == 0:
        raise InvalidParameterError("controllers", "[]", "at least one controller")
    threads = default_threads() if threads is None else threads
    if not (isinstance(threads, int) and threads >= 1):
        raise InvalidParameterError("threads", threads, "a whole number >= 1")
    nv, n_runs = plant.robot.nv, len(controllers)
    threads = max(1, min(threads, n_runs // MIN_RUNS_PER_THREAD))
    if trajectory.nv != nv:
        raise InvalidParameterError(
            "trajectory", f"nv = {trajectory.nv}", f"a trajectory for nv = {nv} joints"
        )
    law = _make_law(controllers, plant, threads)
    accel = _PlantBatch(plant, threads, n_runs)
    q0_off = _offsets("q0_offsets", q0_offsets, config.q0_offset, n_runs, nv)
    v0_off = _offsets("v0_offsets", v0_offsets, config.v0_offset, n_runs, nv)

    n = config.steps
    dt = config.duration / n
    hold = config.hold_steps
    t = np.arange(n + 1) * dt
    half = trajectory.sample(np.arange(2 * n + 1) * (dt / 2))
    rq, rv = half.q, half.v
    ra = half.a
    ad_buffer = np.empty((n_runs, nv))  # RNEA wants the acceleration as an (N, nv) array

    def reference(i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ad_buffer[:] = ra[i]
        return rq[i], rv[i], ad_buffer

    q = rq[0] + q0_off
    v = rv[0] + v0_off
    z = np.array([c.initial_state() for c in controllers], dtype=float).reshape(n_runs, law.nz)
    z0 = z.copy()
    limits = np.array(plant.limits, dtype=float)
    acc = _Accumulator(n_runs, nv, n, dt, t, trajectory.period, limits)
    diverged_at = np.full(n_runs, np.nan)
    alive = np.ones(n_runs, dtype=bool)
    if record:
        Q, V, T = (np.empty((n_runs, n + 1, nv)) for _ in range(3))
        Z = np.empty((n_runs, n + 1, law.nz))
    h, h2, h6 = dt, dt / 2, dt / 6
    report_every = max(1, n // 100)
    tau1 = dz1 = np.zeros((n_runs, nv))

    def observe(k: int, tau: np.ndarray) -> None:
        acc.add(k, q - rq[2 * k], v - rv[2 * k], accel.applied(tau), tau)
        if record:
            Q[:, k], V[:, k], T[:, k], Z[:, k] = q, v, tau, z

    # A diverging run overflows before the end-of-step check parks it: no warnings for that.
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(n):
            i = 2 * k
            if hold is None or k % hold == 0:
                tau1, dz1 = law(q, v, *reference(i), z)
            a1 = accel(q, v, tau1)
            observe(k, tau1)
            if hold is None:
                q2, v2, z2 = q + h2 * v, v + h2 * a1, z + h2 * dz1
                tau2, dz2 = law(q2, v2, *reference(i + 1), z2)
                a2 = accel(q2, v2, tau2)
                q3, v3, z3 = q + h2 * v2, v + h2 * a2, z + h2 * dz2
                tau3, dz3 = law(q3, v3, *reference(i + 1), z3)
                a3 = accel(q3, v3, tau3)
                q4, v4, z4 = q + h * v3, v + h * a3, z + h * dz3
                tau4, dz4 = law(q4, v4, *reference(i + 2), z4)
                a4 = accel(q4, v4, tau4)
                z = z + h6 * (dz1 + 2 * (dz2 + dz3) + dz4)
            else:
                q2, v2 = q + h2 * v, v + h2 * a1
                a2 = accel(q2, v2, tau1)
                q3, v3 = q + h2 * v2, v + h2 * a2
                a3 = accel(q3, v3, tau1)
                q4, v4 = q + h * v3, v + h * a3
                a4 = accel(q4, v4, tau1)
                z = z + h * dz1
            q = q + h6 * (v + 2 * (v2 + v3) + v4)
            v = v + h6 * (a1 + 2 * (a2 + a3) + a4)
            ok = (np.abs(q) < DIVERGENCE_LIMIT).all(axis=1) & (np.abs(v) < DIVERGENCE_LIMIT).all(axis=1)
            if law.nz:
                ok &= (np.abs(z) < DIVERGENCE_LIMIT).all(axis=1)
            newly = alive & ~ok
            if newly.any():  # stop those runs: park them on the reference, keep the batch going
                diverged_at[newly] = (k + 1) * dt
                alive &= ~newly
                q[newly], v[newly], z[newly] = rq[i + 2], rv[i + 2], z0[newly]
            if progress is not None and ((k + 1) % report_every == 0 or k + 1 == n):
                progress(k + 1, n)
        if hold is None or n % hold == 0:
            tau1, _ = law(q, v, *reference(2 * n), z)
        observe(n, tau1)

    dead = ~alive
    p_hat_final = None
    p_true = None
    names: tuple[str, ...] = ()
    if isinstance(controllers[0], Adaptive):
        p_hat_final = z.copy()
        p_hat_final[dead] = np.nan
        p_true = controllers[0].parameters_of(plant.robot, plant.friction)
        names = controllers[0].parameter_names
    return BatchResult(
        controller=controllers[0].name,
        dt=dt,
        t=readonly(t),
        q0_offset=readonly(q0_off),
        v0_offset=readonly(v0_off),
        metrics=acc.metrics(dead),
        diverged_at=readonly(diverged_at),
        torque_limits=readonly(limits),
        saturate=plant.saturate,
        threads=threads,
        control_period=None if hold is None else hold * dt,
        p_hat_final=readonly_or_none(p_hat_final),
        p_true=readonly_or_none(p_true),
        parameter_names=tuple(names),
        q=readonly_or_none(Q) if record else None,
        v=readonly_or_none(V) if record else None,
        tau_command=readonly_or_none(T) if record else None,
        p_hat=readonly_or_none(Z) if record and law.nz and p_hat_final is not None else None,
    )


__all__ = [
    "MIN_RUNS_PER_THREAD",
    "BatchMetrics",
    "BatchResult",
    "BatchUnavailableError",
    "default_threads",
    "robot_with_parameters",
    "simulate_batch",
]
