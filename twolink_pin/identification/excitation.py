"""Optimal excitation: a Fourier-series trajectory whose coefficients make the data informative.

Swevers et al. (1997) parameterise each joint's motion as a finite Fourier series
(:class:`~twolink_pin.trajectory.fourier.FourierTrajectory`: ``N`` harmonics of the base
frequency ``1/T``, coefficients ``a_jl, b_jl`` [rad/s] and a mean position ``q_j0``) and
choose the coefficients by constrained optimisation. Here (:func:`optimise_excitation`):

* **Criterion** ``"condition"`` (default, for identification): minimise ``log cond(W)``, ``W``
  the observation matrix of the base parameters and friction over one period sampled at
  :attr:`ExcitationDesign.samples` instants (SI units, unscaled — the matrix the least
  squares inverts). Criterion ``"adaptation"`` (for adaptive control): maximise the slowest
  rate of the averaged adaptation ``λ_min(Γ G_K)`` of a given adaptive law
  (:func:`~twolink_pin.identification.measures.averaged_adaptation`): the excitation that makes
  that law's estimates converge fastest.
* **Constraints** (:class:`ExcitationLimits`), by the series' closed-form bounds (smooth, so
  the optimiser sees their gradients): positions within the joint limits less a margin,
  ``|q̇_j| <=`` a fraction of the URDF velocity limit, ``|q̈_j| <=`` an acceleration limit
  (URDFs give none), and — sampled — the torque the motion needs (rigid body and the
  friction identification runs use) within a fraction of the URDF effort limits.
* **Optimiser**: ``scipy.optimize.minimize(method="SLSQP")`` with finite-difference
  gradients, from :attr:`ExcitationDesign.starts` random starts drawn from
  ``numpy.random.default_rng(seed)`` and scaled to half the limits; the best feasible result
  is kept. Its time, iterations and evaluations are reported.

Robots may ship a stored excitation, which :func:`excitation_trajectory` returns without
optimising (:func:`stored_excitation`): registered with :func:`register_excitation` (the
twolink's default-design results, :mod:`twolink_pin.twolink.excitation`), or a trajectory
file ``excitations/<robot>.json`` beside this module (the UR5's, written by
``twolink-pin excite --robot ur5 --starts 1 --max-iterations 100``).

The optimisation runs BLAS on one thread (:func:`~twolink_pin.blas.one_blas_thread`: its
matrices are small, and OpenBLAS's threads made it six times slower on a busy machine).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.blas import one_blas_thread
from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import one_row
from twolink_pin.errors import InvalidParameterError, require_type
from twolink_pin.identification.measures import ExcitationMeasures, excitation_measures
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.identification.simulated import plant_friction
from twolink_pin.limits import VELOCITY, joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.fourier import FourierTrajectory

CRITERIA = ("condition", "adaptation")
"""What an excitation is optimised for (see the module docstring)."""
DEFAULT_VELOCITY = 2.0
"""Velocity limit [rad/s] of a joint whose URDF gives none (velocity 0)."""
FEASIBILITY_TOLERANCE = 1e-6
"""A start whose constraints are violated by more than this (relative) is not feasible."""
STORED_FOLDER = Path(__file__).with_name("excitations")
"""Stored excitations as trajectory files, ``<robot name>.json``."""


def _finite_positive(name: str, value: Any, what: str) -> float:
    if isinstance(value, bool) or not (
        isinstance(value, (int, float)) and math.isfinite(value) and value > 0
    ):
        raise InvalidParameterError(name, value, what)
    return float(value)


@dataclass(frozen=True)
class ExcitationLimits:
    """The bounds an excitation must respect.

    Attributes:
        position_margin: Fraction of each joint's range kept free at each end (0 to < 0.5).
        velocity_fraction: ``|q̇_j| <=`` this × the URDF velocity limit (or
            :data:`DEFAULT_VELOCITY` where it gives none), in (0, 1].
        acceleration: ``|q̈_j| <=`` this [rad/s²], > 0 (URDFs give no acceleration limit).
        torque_fraction: ``|τ_j| <=`` this × the URDF effort limit along the motion, in
            (0, 1] (joints without an effort limit are not bounded).
        unbounded_range: Half range [rad] about home for a joint without position limits.
    """

    position_margin: float = 0.05
    velocity_fraction: float = 0.5
    acceleration: float = 10.0
    torque_fraction: float = 0.8
    unbounded_range: float = math.pi

    def __post_init__(self) -> None:
        if not (isinstance(self.position_margin, (int, float)) and 0 <= self.position_margin < 0.5):
            raise InvalidParameterError("position_margin", self.position_margin, "a fraction from 0 to < 0.5")
        for name in ("velocity_fraction", "torque_fraction"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and 0 < value <= 1):
                raise InvalidParameterError(name, value, "a fraction in (0, 1]")
        _finite_positive("acceleration", self.acceleration, "a finite acceleration limit > 0 rad/s²")
        _finite_positive("unbounded_range", self.unbounded_range, "a finite half range > 0 rad")

    def resolve(self, robot: RobotModel) -> dict[str, np.ndarray]:
        """Per joint: ``lower``, ``upper`` [rad], ``velocity`` [rad/s], ``acceleration``
        [rad/s²], ``torque`` [N·m] (inf: unbounded)."""
        limits = joint_limits(robot)
        lo, hi = np.array(limits.position_lower), np.array(limits.position_upper)
        bounded = np.isfinite(lo) & np.isfinite(hi)
        home = robot.home
        lo = np.where(bounded, lo, home - self.unbounded_range)
        hi = np.where(bounded, hi, home + self.unbounded_range)
        margin = self.position_margin * (hi - lo)
        velocity = (
            np.where(limits.given(VELOCITY), limits.velocity, DEFAULT_VELOCITY) * self.velocity_fraction
        )
        return {
            "lower": lo + margin,
            "upper": hi - margin,
            "velocity": np.asarray(velocity, dtype=float),
            "acceleration": np.full(robot.nv, float(self.acceleration)),
            "torque": np.array(limits.effort) * self.torque_fraction,
        }


@dataclass(frozen=True)
class ExcitationDesign:
    """What :func:`optimise_excitation` optimises and how.

    Attributes:
        harmonics: ``N`` per joint, 1 to 20 (default 5, Swevers et al.).
        period: ``T`` [s] (default 10 s: base frequency 0.1 Hz, bandwidth 0.5 Hz).
        criterion: ``"condition"`` or ``"adaptation"``.
        samples: Instants per period at which the criterion and the torques are evaluated.
        starts: Random starts, 1 to 50.
        max_iterations: SLSQP iterations per start.
        seed: Seed of the starts.
        friction: Condition criterion: include the friction columns (as identification does).
        limits: The bounds.
    """

    harmonics: int = 5
    period: float = 10.0
    criterion: str = "condition"
    samples: int = 100
    starts: int = 3
    max_iterations: int = 200
    seed: int = 0
    friction: bool = True
    limits: ExcitationLimits = field(default_factory=ExcitationLimits)

    def __post_init__(self) -> None:
        for name, low, high in (
            ("harmonics", 1, 20),
            ("samples", 10, 100_000),
            ("starts", 1, 50),
            ("max_iterations", 1, 100_000),
            ("seed", 0, 2**63 - 1),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, int) and low <= value <= high):
                raise InvalidParameterError(name, value, f"a whole number from {low} to {high}")
        _finite_positive("period", self.period, "a finite period > 0 s")
        if self.criterion not in CRITERIA:
            raise InvalidParameterError("criterion", self.criterion, f"one of {', '.join(CRITERIA)}")


class Excitation(NamedTuple):
    """An optimised excitation and how it was found."""

    trajectory: FourierTrajectory
    """The excitation."""
    criterion: str
    """What it was optimised for."""
    objective: float
    """The criterion's value: ``cond(W)`` on the design's samples, or the slowest averaged
    adaptation time constant [s]."""
    measures: ExcitationMeasures
    """Its identification measures on :data:`~twolink_pin.identification.measures.DEFAULT_SAMPLES`
    instants per period."""
    seconds: float
    """Wall time of the optimisation [s]."""
    iterations: int
    """SLSQP iterations over all starts."""
    evaluations: int
    """Criterion evaluations over all starts."""
    starts: int
    """Random starts tried."""
    success: bool
    """Whether the best start converged (SLSQP's own test) to a feasible point."""
    converged: bool
    """Whether SLSQP's own convergence test passed for the best start (it may stop at its
    iteration limit at a feasible point: then ``success`` is False but the excitation usable)."""
    message: str
    """SLSQP's message for the best start."""
    limits: dict[str, list[float]]
    """The bounds per joint (lower, upper [rad], velocity [rad/s], acceleration [rad/s²],
    torque [N·m])."""
    peaks: dict[str, list[float]]
    """Sampled along one period: q min and max [rad], max |q̇| [rad/s], |q̈| [rad/s²], |τ| [N·m]."""


def _unpack(x: np.ndarray, nv: int, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return x[: nv * n].reshape(nv, n), x[nv * n : 2 * nv * n].reshape(nv, n), x[2 * nv * n :]


class _Problem:
    """The criterion and constraints of one design on one robot, with the last evaluation cached."""

    def __init__(
        self, robot: RobotModel, design: ExcitationDesign, controller: Controller[Any] | None
    ) -> None:
        self.robot, self.design = robot, design
        self.nv, self.n = robot.nv, design.harmonics
        self.limits = design.limits.resolve(robot)
        self.pset = ParameterSet.of(robot, friction=True)
        self.theta = self.pset.true_values(robot.model, plant_friction(robot))
        self.t = design.period * np.arange(design.samples) / design.samples
        self.w = 2 * np.pi * np.arange(1, self.n + 1) / design.period
        phase = np.outer(self.t, self.w)
        self.sin, self.cos = np.sin(phase), np.cos(phase)
        self.data = robot.create_data()
        self.P_base = np.ascontiguousarray(self.pset.base.matrix)
        self.controller = controller
        if controller is not None:
            self.P_law = np.ascontiguousarray(robot.parameter_map.matrix)
            k = np.asarray(controller.gains.k, dtype=float)  # K: a matrix (1, nv, nv) or per joint
            full = k.ndim == 3 and bool(np.any(k[0] - np.diag(np.diag(k[0]))))
            self.k_matrix = k[0] if full else None
            self.k = np.diag(k[0]) if k.ndim == 3 and not full else one_row(k, robot.nv)
            self.root_rate = np.sqrt(1.0 / one_row(controller.gains.gamma, controller.state_size))
        self._key: bytes | None = None
        self._value: tuple[float, np.ndarray] = (0.0, np.zeros(0))
        self.evaluations = 0

    def motion(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        a, b, q0 = _unpack(x, self.nv, self.n)
        q = q0 + self.sin @ (a / self.w).T - self.cos @ (b / self.w).T
        v = self.cos @ a.T + self.sin @ b.T
        acc = -self.sin @ (a * self.w).T + self.cos @ (b * self.w).T
        return q, v, acc

    def evaluate(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """(criterion, torque margins) at ``x``, cached for the last ``x``."""
        key = x.tobytes()
        if key == self._key:
            return self._value
        self.evaluations += 1
        q, v, acc = self.motion(x)
        K, nv, nb = q.shape[0], self.nv, self.pset.base.size
        Y_pi = np.empty((K, nv, self.P_base.shape[0]))
        for k in range(K):
            Y_pi[k] = pin.computeJointTorqueRegressor(self.robot.model, self.data, q[k], v[k], acc[k])
        W = np.zeros((K, nv, self.pset.size))
        W[:, :, :nb] = Y_pi @ self.P_base
        j = np.arange(nv)
        W[:, j, nb + j] = v
        W[:, j, nb + nv + j] = np.sign(v)
        tau = W @ self.theta
        limit = self.limits["torque"]
        finite = np.isfinite(limit)
        margins = 1.0 - np.abs(tau[:, finite]).max(axis=0) / limit[finite]
        if self.design.criterion == "condition":
            columns = self.pset.size if self.design.friction else nb
            s = np.linalg.svd(W[:, :, :columns].reshape(K * nv, columns), compute_uv=False)
            value = float(np.log(s[0] / max(s[-1], 1e-300)))
        else:
            assert self.controller is not None
            parts = []
            if "inertial" in self.controller.estimates:
                parts.append(Y_pi @ self.P_law)
            if "friction" in self.controller.estimates:
                parts.append(W[:, :, nb:])
            Y = np.concatenate(parts, axis=2)
            KinvY = Y / self.k[None, :, None] if self.k_matrix is None else np.linalg.solve(self.k_matrix, Y)
            gram = np.einsum("kip,kiq->pq", KinvY, Y) / K
            smallest = float(np.linalg.eigvalsh(self.root_rate[:, None] * gram * self.root_rate[None, :])[0])
            value = -float(np.log(max(smallest, 1e-300)))
        self._key, self._value = key, (value, margins)
        return self._value

    def bounds(self, x: np.ndarray) -> np.ndarray:
        """The closed-form constraints, each >= 0 when met (scaled to order one)."""
        a, b, q0 = _unpack(x, self.nv, self.n)
        rho = np.sqrt(a * a + b * b + 1e-12)
        lim = self.limits
        span = lim["upper"] - lim["lower"]
        q_amp = (rho / self.w).sum(axis=1)
        return np.concatenate(
            [
                (q0 - q_amp - lim["lower"]) / span,
                (lim["upper"] - q0 - q_amp) / span,
                1.0 - rho.sum(axis=1) / lim["velocity"],
                1.0 - (rho * self.w).sum(axis=1) / lim["acceleration"],
            ]
        )

    def constraints(self, x: np.ndarray) -> np.ndarray:
        return np.concatenate([self.bounds(x), self.evaluate(x)[1]])

    def start(self, rng: np.random.Generator) -> np.ndarray:
        """Random coefficients scaled so that the closed-form bounds are half used."""
        lim = self.limits
        a, b = rng.standard_normal((2, self.nv, self.n))
        rho = np.hypot(a, b)
        ratio = np.max(
            [
                (rho / self.w).sum(axis=1) / (0.5 * (lim["upper"] - lim["lower"])),
                rho.sum(axis=1) / lim["velocity"],
                (rho * self.w).sum(axis=1) / lim["acceleration"],
            ]
        )
        scale = 0.5 / ratio
        centre = 0.5 * (lim["lower"] + lim["upper"])
        return np.concatenate([(a * scale).ravel(), (b * scale).ravel(), centre])


def optimise_excitation(
    robot: RobotModel,
    design: ExcitationDesign | None = None,
    controller: Controller[Any] | None = None,
    progress: Any = None,
) -> Excitation:
    """The Fourier excitation of ``robot`` that best meets ``design`` (module docstring).

    Args:
        robot: The arm.
        design: Harmonics, period, criterion, limits, starts, seed.
        controller: For the ``"adaptation"`` criterion, the adaptive law whose averaged
            adaptation is made fastest (default: ``adaptive`` with the robot's gains).
        progress: Called as ``progress(iterations_done, iterations_at_most)`` after each
            optimiser iteration.

    Raises:
        InvalidParameterError: the controller estimates nothing or lacks ``k``/``gamma``.
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    design = design if design is not None else ExcitationDesign()
    if design.criterion == "adaptation":
        if controller is None:
            from twolink_pin.scenario import make_controller  # the law alone: no plant, no run

            controller = make_controller("adaptive", robot)
        if not controller.estimates or not hasattr(controller.gains, "gamma"):
            raise InvalidParameterError("controller", controller.name, "an adaptive law (gains k and gamma)")
    problem = _Problem(robot, design, controller if design.criterion == "adaptation" else None)
    rng = np.random.default_rng(design.seed)
    started = time.perf_counter()
    with one_blas_thread():
        best, iterations = _run_starts(problem, design, rng, progress)
    seconds = time.perf_counter() - started
    (_, objective), result, feasible = best
    a, b, q0 = _unpack(result.x, robot.nv, design.harmonics)
    trajectory = FourierTrajectory(design.period, a, b, q0)
    with one_blas_thread():
        measures = excitation_measures(robot, trajectory, friction=design.friction)
        peaks = motion_peaks(robot, trajectory)
    value = math.exp(objective)  # cond(W), or 1 / λ_min(Γ G_K): the slowest time constant
    return Excitation(
        trajectory=trajectory,
        criterion=design.criterion,
        objective=value,
        measures=measures,
        seconds=seconds,
        iterations=iterations,
        evaluations=problem.evaluations,
        starts=design.starts,
        success=bool(result.success) and feasible,
        converged=bool(result.success),
        message=str(result.message),
        limits={k: v.tolist() for k, v in problem.limits.items()},
        peaks=peaks,
    )


def _run_starts(
    problem: _Problem, design: ExcitationDesign, rng: np.random.Generator, progress: Any
) -> tuple[Any, int]:
    """SLSQP from each random start; the best (feasible first, then lowest criterion) and the
    iterations over all starts."""
    from scipy.optimize import minimize

    best: Any = None
    iterations = 0
    at_most = design.starts * design.max_iterations
    for start in range(design.starts):
        x0 = problem.start(rng)
        done = [start * design.max_iterations]

        def step(_: Any, done: list[int] = done) -> None:
            done[0] += 1
            if progress is not None:
                progress(done[0], at_most)

        result = minimize(
            lambda x: problem.evaluate(x)[0],
            x0,
            method="SLSQP",
            constraints=[{"type": "ineq", "fun": problem.constraints}],
            options={"maxiter": design.max_iterations, "ftol": 1e-9},
            callback=step,
        )
        if progress is not None:
            progress((start + 1) * design.max_iterations, at_most)
        iterations += int(result.nit)
        feasible = float(problem.constraints(result.x).min()) >= -FEASIBILITY_TOLERANCE
        key = (not feasible, float(result.fun))
        if best is None or key < best[0]:
            best = (key, result, feasible)
    return best, iterations


def motion_peaks(robot: RobotModel, trajectory: Any, samples: int = 2000) -> dict[str, list[float]]:
    """Sampled over one period: q min and max [rad], max |q̇| [rad/s], |q̈| [rad/s²], and max
    |τ| [N·m] of the rigid body plus the identification runs' friction."""
    t = trajectory.t0 + trajectory.period * np.arange(samples) / samples
    ref = trajectory.sample(t)
    pset = ParameterSet.of(robot, friction=True)
    theta = pset.true_values(robot.model, plant_friction(robot))
    tau = pset.observation(robot.model, ref.q, ref.v, ref.a) @ theta
    return {
        "q_min": ref.q.min(axis=0).tolist(),
        "q_max": ref.q.max(axis=0).tolist(),
        "v_max": np.abs(ref.v).max(axis=0).tolist(),
        "a_max": np.abs(ref.a).max(axis=0).tolist(),
        "tau_max": np.abs(tau).max(axis=0).tolist(),
    }


_STORED: dict[str, Callable[[], FourierTrajectory]] = {}


def register_excitation(robot_name: str, factory: Callable[[], FourierTrajectory]) -> None:
    """Store the default-design excitation of the robot ``robot_name`` (a result of
    :func:`optimise_excitation` with :class:`ExcitationDesign` defaults, kept as numbers so
    that it is not recomputed)."""
    _STORED[robot_name] = factory


def _is_catalog_robot(robot: RobotModel) -> bool:
    """Whether ``robot`` is the catalog's robot of its name (not a URDF file of that stem)."""
    from twolink_pin.model import catalog

    if robot.name not in catalog.CATALOG:
        return False
    return catalog.resolve(robot.name)[0].resolve() == robot.urdf_path.resolve()


def stored_excitation(robot: RobotModel) -> FourierTrajectory | None:
    """The stored excitation of an unloaded robot of the catalog (registered with
    :func:`register_excitation`, else the file ``STORED_FOLDER/<name>.json``), or None."""
    if robot.payload != 0 or not _is_catalog_robot(robot):
        return None
    factory = _STORED.get(robot.name)
    if factory is not None:
        return factory()
    path = STORED_FOLDER / f"{robot.name}.json"
    if not path.is_file():
        return None
    from twolink_pin.trajectory.file import read_trajectory_file

    trajectory = read_trajectory_file(path, robot)
    assert isinstance(trajectory, FourierTrajectory)  # the folder holds Fourier excitations only
    return trajectory


def excitation_trajectory(robot: RobotModel) -> FourierTrajectory:
    """The robot's excitation: its stored one (:func:`stored_excitation`), else
    :func:`optimise_excitation` with the defaults."""
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    stored = stored_excitation(robot)
    return stored if stored is not None else optimise_excitation(robot).trajectory
