"""N runs of one law advanced together, with each run's metrics streamed: :func:`simulate_batch`.

The runs share the plant and the reference; they differ in their initial state and in
whatever the law object holds per run — gains of shape ``(N, k)``, believed parameters
``model_parameters`` of shape ``(N, n_p)`` (see :mod:`twolink_pin.controllers.gains`).
Every run is what :func:`~twolink_pin.simulate` computes for its row (to rounding;
tested), except that a diverging run is parked and flagged instead of raising. Memory is
O(N) unless ``record=True``: the engine hands each block of samples to
:class:`~twolink_pin.metrics.RunningMetrics`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.contact_metrics import ContactMetrics, contact_observer
from twolink_pin.controllers import Controller
from twolink_pin.errors import InvalidParameterError
from twolink_pin.metrics import Metrics, RunningMetrics
from twolink_pin.plant import Plant
from twolink_pin.simulation import EngineRun, SimulationConfig, estimated_truth, integrate
from twolink_pin.simulation.config import check_recorded_size
from twolink_pin.simulation.run import check_setup, initial_state, state_labels
from twolink_pin.simulation.step_check import require_stable_step
from twolink_pin.simulation.terms import check_parallel, threads_for
from twolink_pin.studies.progress import Progress, progress_callback
from twolink_pin.task_metrics import RunningTaskMetrics, TaskMetrics
from twolink_pin.trajectory import Trajectory


@dataclass(frozen=True)
class BatchResult:
    """N runs of one law. Arrays are read-only; K = number of output samples."""

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
    metrics: Metrics = field(repr=False)
    """Each run's metrics (NaN rows for diverged runs)."""
    diverged_at: np.ndarray = field(repr=False)
    """Time [s] at which each run diverged (as :func:`~twolink_pin.simulate` would report
    it); NaN for runs that did not, shape (N,)."""
    divergence: tuple[str | None, ...]
    """What was detected for each diverged run (None for the others)."""
    torque_limits: np.ndarray = field(repr=False)
    """Motor limits [N·m], shape (nv,)."""
    saturate: bool
    """Whether the plant clipped torques to the limits."""
    threads: int
    """Threads given to Pinocchio's parallel algorithms."""
    control_period: float | None = None
    """Sampling period of the held law [s], or None (law at every RK4 stage)."""
    p_hat_final: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates at the end, shape (N, n_p) (NaN if diverged); None if the law
    estimates nothing."""
    p_true: np.ndarray | None = field(repr=False, default=None)
    """The plant's values of the estimated parameters, shape (n_p,), or None."""
    parameter_names: tuple[str, ...] = ()
    """Names of the estimated parameters."""
    parameter_units: tuple[str, ...] = ()
    """Their SI units."""
    q: np.ndarray | None = field(repr=False, default=None)
    """Joint positions [rad], shape (N, K, nv), only with ``record=True``."""
    v: np.ndarray | None = field(repr=False, default=None)
    """Joint velocities [rad/s], shape (N, K, nv), only with ``record=True``."""
    tau_command: np.ndarray | None = field(repr=False, default=None)
    """Commanded torque [N·m], shape (N, K, nv), only with ``record=True``."""
    p_hat: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates, shape (N, K, n_p), only with ``record=True``."""
    state_final: np.ndarray | None = field(repr=False, default=None)
    """The law's whole state ``z`` at the end, shape (N, nz) (NaN if diverged); None for a
    law without state."""
    state: np.ndarray | None = field(repr=False, default=None)
    """The law's whole state, shape (N, K, nz), only with ``record=True``."""
    state_names: tuple[str, ...] = ()
    """Name of each state entry."""
    state_units: tuple[str, ...] = ()
    """SI unit of each state entry."""
    task_metrics: TaskMetrics | None = field(repr=False, default=None)
    """Each run's task-space metrics (position error [mm], angle [deg] of the end effector; arrays
    (N,), NaN for diverged runs), whatever the law (None only in a result built by hand)."""
    contact_metrics: ContactMetrics | None = field(repr=False, default=None)
    """Each run's contact metrics (force errors, impact, penetration, …; arrays (N,), NaN for
    diverged runs) when the plant has a scene, else None (:mod:`twolink_pin.contact_metrics`)."""
    trajectory: Trajectory | None = field(repr=False, default=None)
    """The reference every run tracked (``trajectory.sample(t)`` gives ``q_d``, ``q̇_d``,
    ``q̈_d`` at the output times ``t``)."""

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


def _per_run(name: str, value: Any, runs: int, nv: int) -> np.ndarray | None:
    if value is None:
        return None
    array = np.array(value, dtype=float)
    if array.shape != (runs, nv):
        raise InvalidParameterError(name, f"shape {array.shape}", f"shape ({runs}, {nv}): one row per run")
    bad = np.argwhere(~np.isfinite(array))
    if len(bad):
        i, j = (int(x) for x in bad[0])
        raise InvalidParameterError(f"{name}[{i}, {j}]", float(array[i, j]), "finite offsets [rad or rad/s]")
    return array


def batch_size(controller: Controller, *arrays: Any, runs: int | None = None) -> int:
    """N from ``runs``, the per-run arrays (leading axis) and the law's per-run values, all
    of which must agree."""
    counts: dict[str, int] = {}
    if runs is not None:
        if not (isinstance(runs, int) and not isinstance(runs, bool) and runs >= 1):
            raise InvalidParameterError("runs", runs, "a whole number >= 1")
        counts["runs"] = runs
    for i, array in enumerate(arrays):
        if array is not None:
            counts[f"offsets[{i}]"] = int(np.shape(array)[0]) if np.ndim(array) else 1
    law_runs = controller.runs
    if law_runs is not None:
        counts["the controller's per-run gains"] = law_runs
    sizes = set(counts.values())
    if len(sizes) > 1:
        raise InvalidParameterError("runs", counts, "one number of runs N for every per-run input")
    return sizes.pop() if sizes else 1


def simulate_batch(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig | None = None,
    *,
    runs: int | None = None,
    q0_offsets: np.ndarray | Sequence[Sequence[float]] | None = None,
    v0_offsets: np.ndarray | Sequence[Sequence[float]] | None = None,
    threads: int | None = None,
    record: bool = False,
    progress: Progress = None,
) -> BatchResult:
    """Run N copies of ``controller`` on ``plant`` along ``trajectory``, all together.

    Args:
        controller: One law object; gains or ``model_parameters`` with a leading run axis
            give each run its own (N inferred from them).
        plant: The arm all runs drive (friction and saturation shared).
        trajectory: The reference.
        config: Duration, step, ``control_period``; ``method`` must be ``"rk4"``. Its
            ``q0_offset`` / ``v0_offset`` are the defaults for every run.
        runs: N, when nothing else says it.
        q0_offsets: ``q(0) − q_d(0)`` per run [rad], shape (N, nv).
        v0_offsets: ``q̇(0) − q̇_d(0)`` per run [rad/s], shape (N, nv).
        threads: Threads for Pinocchio's parallel algorithms; default (None) the cores this
            process may use that other work leaves free, or ``TWOLINK_PIN_THREADS`` if set
            (:mod:`twolink_pin.openmp`); at most one per 256 runs either way.
        record: Keep every run's trajectory (memory N × K × nv × 8 bytes per signal).
        progress: Called as ``progress(steps_done, steps_total)`` after each block; None
            (default): a tqdm bar on stderr if it is a terminal, once the batch has run 2 s;
            True: that bar always; False: nothing (:mod:`twolink_pin.studies.progress`).

    Raises:
        InvalidParameterError: inconsistent N, bad offsets, ``method != "rk4"``.
        StepTooLargeError: one gain set for every run, and ``dt`` beyond RK4's stability bound on
            the fastest mode of the start (:mod:`~twolink_pin.simulation.step_check`).
        BatchUnavailableError: this Pinocchio has no parallel algorithms.
    """
    check_parallel()
    config = config if config is not None else SimulationConfig()
    if config.method != "rk4":
        raise InvalidParameterError("method", config.method, "'rk4' (the batch engine is fixed-step)")
    check_setup(controller, plant, trajectory)
    nv = plant.robot.nv
    n = batch_size(controller, q0_offsets, v0_offsets, runs=runs)
    q0_off, v0_off = _offsets(plant, trajectory, config, n, q0_offsets, v0_offsets)
    ref0, z0 = trajectory.sample(0.0), _initial_law_states(controller, n)
    if record:
        check_recorded_size(config.steps, nv, controller.state_size, n)
    # one gain set: its step checked as a single run's (per-run gains: a run beyond its bound diverges, flagged)
    if controller.runs is None:
        require_stable_step(controller, plant, trajectory, config)
    used = threads_for(n, threads) if n > 1 else 1
    samples, dt = config.steps + 1, config.duration / config.steps
    observer = RunningMetrics(n, nv, dt, samples, trajectory.period, plant.joint_limits, plant.applied_torque)
    # Every law moves the end effector: its rows carry the task errors too (and the contact's, with a scene).
    task = RunningTaskMetrics(plant.robot, n, dt, samples, trajectory.period)
    contact = contact_observer(plant, trajectory, n, dt)
    with progress_callback(progress, n) as shown:
        run = integrate(
            controller,
            plant,
            trajectory,
            config,
            ref0.q + q0_off,
            ref0.v + v0_off,
            z0,
            record=record,
            observer=_Both(observer, task, contact),
            threads=used,
            progress=shown,
        )
    dead = ~np.isnan(run.diverged_at)
    metrics, task_metrics = observer.result(dead), task.result(dead)
    result = _batch_result(
        controller, plant, trajectory, config, run, q0_off, v0_off, metrics, task_metrics, used
    )
    return result if contact is None else dataclasses.replace(result, contact_metrics=contact.result(dead))


def _initial_law_states(controller: Controller, n: int) -> np.ndarray:
    """The law's ``z(0)`` for ``n`` runs, shape (n, nz): its own rows, or one row for every run."""
    z0 = np.asarray(controller.initial_state(), dtype=float)
    return np.broadcast_to(z0 if z0.ndim == 2 else z0[None], (n, controller.state_size)).copy()


def _offsets(
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    n: int,
    q0_offsets: Any,
    v0_offsets: Any,
) -> tuple[np.ndarray, np.ndarray]:
    """Each run's ``q(0) − q_d(0)`` [rad] and ``q̇(0) − q̇_d(0)`` [rad/s], shape (N, nv) each:
    the ones given, else the configuration's (the robot's default offset) for every run."""
    nv = plant.robot.nv
    q0_nominal, v0_nominal = initial_state(plant, trajectory, config)
    ref0 = trajectory.sample(0.0)
    q0_off = _per_run("q0_offsets", q0_offsets, n, nv)
    v0_off = _per_run("v0_offsets", v0_offsets, n, nv)
    q0_off = np.tile(q0_nominal - ref0.q, (n, 1)) if q0_off is None else q0_off
    v0_off = np.tile(v0_nominal - ref0.v, (n, 1)) if v0_off is None else v0_off
    return q0_off, v0_off


def _batch_result(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    run: EngineRun,
    q0_off: np.ndarray,
    v0_off: np.ndarray,
    metrics: Metrics,
    task_metrics: TaskMetrics | None,
    threads: int,
) -> BatchResult:
    """The engine's ``run`` as a :class:`BatchResult`: final states and estimates NaN for the
    diverged runs, the law's estimates picked out of its state, records run-first (N, K, ·)."""
    dead = ~np.isnan(run.diverged_at)
    dt = config.duration / config.steps
    estimates = controller.state_size > 0 and bool(controller.estimates)
    nz = run.z_final.shape[1]
    state_final = run.z_final.copy()
    state_final[dead] = np.nan
    columns = controller.estimate_columns if estimates else None
    whole = columns is not None and len(columns) == nz
    p_hat_final = None
    if columns is not None:
        p_hat_final = state_final if whole else state_final[:, columns]
    names, units = state_labels(controller, nz)
    rec = run.record
    p_hat = None
    if rec is not None and columns is not None:
        p_hat = rec.z.transpose(1, 0, 2) if whole else rec.z[:, :, columns].transpose(1, 0, 2)
    return BatchResult(
        controller=controller.name,
        dt=dt,
        t=readonly(run.t),
        q0_offset=readonly(q0_off),
        v0_offset=readonly(v0_off),
        metrics=metrics,
        diverged_at=readonly(run.diverged_at),
        divergence=run.detail,
        torque_limits=readonly(plant.limits),
        saturate=plant.saturate,
        threads=threads,
        control_period=None if config.hold_steps is None else config.hold_steps * dt,
        p_hat_final=readonly_or_none(p_hat_final),
        p_true=readonly_or_none(estimated_truth(controller, plant)) if estimates else None,
        parameter_names=controller.parameter_names if estimates else (),
        parameter_units=controller.parameter_units if estimates else (),
        q=readonly(rec.q.transpose(1, 0, 2)) if rec is not None else None,
        v=readonly(rec.v.transpose(1, 0, 2)) if rec is not None else None,
        tau_command=readonly(rec.tau_command.transpose(1, 0, 2)) if rec is not None else None,
        p_hat=readonly_or_none(p_hat),
        state_final=readonly(state_final) if nz else None,
        state=readonly(rec.z.transpose(1, 0, 2)) if rec is not None and nz else None,
        state_names=names,
        state_units=units,
        task_metrics=task_metrics,
        trajectory=trajectory,
    )


class _Both:
    """Engine observers fed the same blocks (the joint, the task and, with a scene, the contact
    metrics)."""

    def __init__(self, *observers: Any) -> None:
        self.observers = [o for o in observers if o is not None]

    def add(self, samples: Any) -> None:
        for observer in self.observers:
            observer.add(samples)
