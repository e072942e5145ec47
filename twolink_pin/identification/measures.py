"""How well a trajectory excites the parameters: for identification, and for adaptive laws.

Two questions, one regressor. Over one period ``T`` of the desired motion, sampled at K
evenly spaced instants:

* **Identification** (:func:`excitation_measures`): the observation matrix ``W`` of the
  identified parameters ``θ = (β, V, C)`` (:class:`~twolink_pin.identification.observation.ParameterSet`)
  has the condition number ``cond(W)`` (SI units, unscaled: what the least squares sees),
  and the Gram matrix ``G = (1/T) ∫ Y_θᵀ Y_θ dt`` [per second] whose smallest eigenvalue
  ``λ_min`` says how strongly the weakest combination is excited (the estimates' standard
  deviations scale with ``1 / sqrt(λ_min · duration)``). ``cond(W)² = cond(G)``.
* **Adaptation** (:func:`averaged_adaptation`): a Slotine–Li law ``dp̂/dt = −Γ Yᵀ s`` that
  tracks well has ``s ≈ K⁻¹ Y p̃``, so averaged over a period ``dp̃/dt ≈ −Γ G_K p̃`` with
  ``G_K = (1/T) ∫ Yᵀ K⁻¹ Y dt`` (Y at the desired motion, the law's own parameters and
  friction columns). The eigenvalues of ``Γ G_K`` [1/s] are the rates of the averaged
  modes; the slowest one's time constant is how long the estimates take to converge
  (Anderson et al. 1986, "Stability of adaptive systems: passivity and averaging analysis").

Both are computed here once; the report's errata and the identification docs use them.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from twolink_pin.blas import one_blas_thread
from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import one_row
from twolink_pin.controllers.matrix_gains import gain_solve
from twolink_pin.dynamics import friction_regressor, regressor
from twolink_pin.errors import InvalidParameterError
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.model import RobotModel
from twolink_pin.trajectory import Trajectory, TrajectorySample

DEFAULT_SAMPLES = 1000
"""Instants per period at which the measures are evaluated."""


def period_samples(
    trajectory: Trajectory, samples: int = DEFAULT_SAMPLES
) -> tuple[np.ndarray, TrajectorySample]:
    """``samples`` evenly spaced instants of one period (the end excluded: it is the start)
    and the desired motion there."""
    if isinstance(samples, bool) or not (isinstance(samples, int) and samples >= 2):
        raise InvalidParameterError("samples", samples, "a whole number >= 2 of instants per period")
    t = trajectory.t0 + trajectory.period * np.arange(samples) / samples
    return t, trajectory.sample(t)


class ExcitationMeasures(NamedTuple):
    """How a trajectory excites the identified parameters (see the module docstring)."""

    condition_number: float
    """``cond(W)`` over one period (SI units, unscaled)."""
    gram_eigenvalues: np.ndarray
    """Eigenvalues of ``G = (1/T) ∫ Y_θᵀ Y_θ dt``, ascending (SI units squared per second)."""
    gram_min_eigenvalue: float
    """``λ_min`` of ``∫_0^T Y_θᵀ Y_θ dt`` (over one period, not per second)."""
    period: float
    """The trajectory's period ``T`` [s]."""
    names: tuple[str, ...]
    """The parameters ``θ``."""

    @property
    def gram_min_eigenvalue_per_s(self) -> float:
        """``λ_min(G)``: the smallest eigenvalue per second of motion."""
        return float(self.gram_eigenvalues[0])

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: condition number, Gram eigenvalues (per second and over a period)."""
        return {
            "condition_number": self.condition_number,
            "gram_min_eigenvalue": self.gram_min_eigenvalue,
            "gram_min_eigenvalue_per_s": self.gram_min_eigenvalue_per_s,
            "gram_eigenvalues_per_s": self.gram_eigenvalues.tolist(),
            "period_s": self.period,
            "parameters": list(self.names),
        }


def excitation_measures(
    robot: RobotModel, trajectory: Trajectory, friction: bool = True, samples: int = DEFAULT_SAMPLES
) -> ExcitationMeasures:
    """``cond(W)`` and the Gram eigenvalues of ``trajectory`` for ``robot``'s base parameters
    (plus viscous and Coulomb friction if ``friction``), over one period."""
    pset = ParameterSet.of(robot, friction=friction)
    _, ref = period_samples(trajectory, samples)
    W = pset.observation(robot.model, ref.q, ref.v, ref.a).reshape(-1, pset.size)
    return measures_of(W, samples, trajectory.period, pset.names)


def measures_of(W: np.ndarray, samples: int, period: float, names: tuple[str, ...]) -> ExcitationMeasures:
    """:class:`ExcitationMeasures` of a stacked observation matrix of ``samples`` instants
    evenly spread over ``period`` [s]."""
    with one_blas_thread():  # a tall matrix: OpenBLAS's threads only slow it (twolink_pin/blas.py)
        singular = np.linalg.svd(W, compute_uv=False)
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else float("inf")
    eigen = np.sort(singular**2)[: W.shape[1]] / samples  # mean over the period = (1/T) ∫ dt
    return ExcitationMeasures(condition, np.sort(eigen), float(eigen.min() * period), period, names)


class AveragedAdaptation(NamedTuple):
    """The averaged adaptation ``dp̃/dt ≈ −Γ G_K p̃`` of one law along one trajectory."""

    gram: np.ndarray
    """``G_K = (1/T) ∫ Yᵀ K⁻¹ Y dt``, shape (n_p, n_p)."""
    rate_matrix: np.ndarray
    """``Γ G_K`` [1/s], shape (n_p, n_p)."""
    rates: np.ndarray
    """Its eigenvalues [1/s], ascending (real: ``Γ G_K`` is similar to ``Γ^½ G_K Γ^½``)."""
    slowest_mode: np.ndarray
    """Eigenvector of the slowest rate, unit norm, in the parameters' coordinates."""
    names: tuple[str, ...]
    """The estimated parameters."""

    @property
    def slowest_time_constant(self) -> float:
        """``1 / min(rates)`` [s]: how long the slowest combination takes to shrink e-fold."""
        return float(1.0 / self.rates[0]) if self.rates[0] > 0 else float("inf")

    def predicted_error(self, initial: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``p̃(t) = exp(−Γ G_K t) p̃(0)`` at times ``t`` [s], shape (len(t), n_p).

        Evenly spaced times (a figure's curve) take one ``expm`` for the first time and one
        for the spacing, then one product per time (``exp(A (t + h)) = exp(A h) exp(A t)``,
        equal to an ``expm`` per time to rounding: ~1e-14 relative over 300 points, 1 ms
        instead of 0.6 s); other times one ``expm`` each.
        """
        import scipy.linalg  # 0.5 s to import: not at every process's start-up

        with one_blas_thread():  # small matrices: OpenBLAS's threads made an expm 15 ms, not 0.1
            return self._predicted_error(scipy.linalg.expm, np.asarray(initial), t)

    def _predicted_error(self, expm: Any, initial: np.ndarray, t: np.ndarray) -> np.ndarray:
        times = np.atleast_1d(np.asarray(t, dtype=float))
        step = np.diff(times)
        if len(times) > 2 and np.allclose(step, step[0], rtol=1e-12, atol=0.0):
            out = np.empty((len(times), np.size(initial)))
            out[0] = expm(-self.rate_matrix * times[0]) @ initial
            advance = expm(-self.rate_matrix * step[0])
            for k in range(1, len(times)):
                out[k] = advance @ out[k - 1]
            return out
        return np.array([expm(-self.rate_matrix * tk) @ initial for tk in times])

    def time_to_within(self, initial: np.ndarray, true: np.ndarray, fraction: float = 0.05) -> float:
        """First time [s] at which the averaged model has every ``|p̃_i| <= fraction |p_i|``
        from ``p̃(0) = initial`` (parameters with ``p_i = 0`` are held to ``fraction`` of the
        largest ``|p_i|``), to 1 %; inf if not within 1e6 s."""
        scale = np.where(np.abs(true) > 0, np.abs(true), np.abs(true).max()) * fraction

        def inside(tk: float) -> bool:
            return bool(np.all(np.abs(self.predicted_error(initial, np.array([tk]))[0]) <= scale))

        if inside(0.0):
            return 0.0
        hi = self.slowest_time_constant if np.isfinite(self.slowest_time_constant) else 1.0
        while not inside(hi):
            hi *= 2.0
            if hi > 1e6:
                return float("inf")
        lo = 0.0
        while hi - lo > 0.01 * hi:  # bisection on the bracket found by doubling
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if inside(mid) else (mid, hi)
        return hi

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: the rates, the slowest time constant and its mode."""
        return {
            "rates_per_s": self.rates.tolist(),
            "slowest_time_constant_s": self.slowest_time_constant,
            "slowest_mode": dict(zip(self.names, self.slowest_mode.tolist())),
            "gram_eigenvalues": np.linalg.eigvalsh(self.gram).tolist(),
        }


def averaged_adaptation(
    controller: Controller[Any], trajectory: Trajectory, samples: int = 2000
) -> AveragedAdaptation:
    """The averaged adaptation of an adaptive ``controller`` (gains ``k`` and ``gamma``, what
    it estimates) along ``trajectory``, from ``samples`` instants of one period.

    Raises:
        InvalidParameterError: the law estimates nothing or has no ``k`` / ``gamma`` gains.
    """
    gains = controller.gains
    if not controller.estimates or not hasattr(gains, "k") or not hasattr(gains, "gamma"):
        raise InvalidParameterError(
            "controller", controller.name, "an adaptive law (estimates, gains k and gamma)"
        )
    robot = controller.robot
    rate = 1.0 / one_row(gains.gamma, controller.state_size)
    P = robot.parameter_map.matrix
    data = robot.create_data()
    smoothing = float(getattr(getattr(controller, "friction", None), "smoothing", 0.0) or 0.0)
    _, ref = period_samples(trajectory, samples)
    gram = np.zeros((controller.state_size, controller.state_size))
    for i in range(samples):
        columns = []
        if "inertial" in controller.estimates:
            columns.append(regressor(robot.model, data, ref.q[i], ref.v[i], ref.v[i], ref.a[i]) @ P)
        if "friction" in controller.estimates:
            columns.append(friction_regressor(ref.v[i], smoothing))
        Y = np.hstack(columns)
        gram += Y.T @ gain_solve(gains.k, Y)  # Yᵀ K⁻¹ Y
    gram /= samples
    root = np.sqrt(rate)
    values, vectors = np.linalg.eigh(root[:, None] * gram * root[None, :])
    mode = root * vectors[:, 0]  # Γ G v = λ v for v = Γ^½ u, u an eigenvector of Γ^½ G Γ^½
    return AveragedAdaptation(
        gram, rate[:, None] * gram, values, mode / np.linalg.norm(mode), controller.parameter_names
    )
