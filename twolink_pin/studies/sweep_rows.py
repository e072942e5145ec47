"""A sweep's rows: the columns, one chunk's runs as rows (:class:`ChunkRows`, wherever it runs)
and the summary statistics over them."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.metrics import metric_array, metric_units
from twolink_pin.model import RobotModel
from twolink_pin.scenario import Scenario
from twolink_pin.studies.batch import BatchResult, simulate_batch
from twolink_pin.studies.parquet import REASON
from twolink_pin.studies.sweep_cases import Cases, SweepConfig, check_draws, chunk_law, gain_target
from twolink_pin.task_metrics import TASK_UNITS
from twolink_pin.trajectory import Trajectory

PERCENTILES = (5.0, 50.0, 95.0)
"""Percentiles in the summary (the 50th is the median)."""
MAX_KEPT_VALUES = 1_000_000_000
"""Largest number of floats ``--keep-trajectories`` writes over the whole sweep (8 GB):
samples × (steps + 1) × 3 nv (q, q̇, τ_command)."""


# -- rows -----------------------------------------------------------------------------------------


def joint_columns(prefix: str, nv: int) -> list[str]:
    return [f"{prefix}{j + 1}" for j in range(nv)]


METRIC_UNITS = metric_units()
"""SI unit of each per-joint metric (the column names add the joint's 1-based index):
:func:`twolink_pin.metrics.metric_units`, the one definition."""


TASK_COLUMNS = {f"task_{name}": unit for name, unit in TASK_UNITS.items()}
"""The task-space metric columns of every row (:data:`twolink_pin.task_metrics.TASK_UNITS`, the
one definition: the end effector's errors, whatever the law), with their units."""


def metric_columns(nv: int, parameter_names: Sequence[str] = ()) -> list[str]:
    """Names of the metric columns of a row, in order: the per-joint metrics, the task metrics
    (every law moves the end effector), the final estimates."""
    columns: list[str] = []
    for stem in METRIC_UNITS:
        columns += joint_columns(stem, nv)
    columns += list(TASK_COLUMNS)
    columns += [f"p_hat_final_{name}" for name in parameter_names]
    return columns


def input_columns(config: SweepConfig, nv: int, parameter_names: Sequence[str]) -> list[str]:
    """Names of the input columns of a row, in order."""
    columns = ["run", *joint_columns("q0_offset", nv)]
    columns += [f"param_factor_{name}" for name in parameter_names]
    columns += [f"gain_{g.name}" for g in config.gains]
    if config.wrench_scale is not None:
        columns.append("wrench_scale")
    return columns


FLAG_COLUMNS = ("limit_exceeded", "diverged", "diverged_at")
"""Per-run outcome columns after the inputs."""
CROSSED_FLAGS = ("position_crossed", "velocity_crossed")
"""Whether a run (that did not diverge) crossed a joint's position range, a velocity limit
(:mod:`twolink_pin.limits.crossings`), after :data:`FLAG_COLUMNS`."""
CROSSING_UNITS = {
    "position_crossed_at": "s",
    "position_excess": "rad",
    "velocity_crossed_at": "s",
    "velocity_excess": "rad/s",
}
"""Per-joint crossing columns (the joint's 1-based index added) after :data:`CROSSED_FLAGS`: the
first time [s] each joint crossed (null: never) and its largest excess (0: never)."""


def outcome_columns(nv: int) -> list[str]:
    """The per-run outcome columns, in order: :data:`FLAG_COLUMNS`, :data:`CROSSED_FLAGS`, the
    per-joint crossing columns (:data:`CROSSING_UNITS`)."""
    columns = [*FLAG_COLUMNS, *CROSSED_FLAGS]
    for stem in CROSSING_UNITS:
        columns += joint_columns(stem, nv)
    return columns


def _outcomes(result: BatchResult) -> tuple[np.ndarray, np.ndarray]:
    """The outcome columns of a chunk's runs (:func:`outcome_columns`) as floats, and its
    limit-exceeded mask."""
    alive = ~result.diverged
    crossings = result.metrics.crossings
    exceeded = np.asarray(result.limit_exceeded.any(axis=1)) & alive
    flags = [exceeded, result.diverged, result.diverged_at]
    flags += [crossings.position.crossed.any(axis=1) & alive, crossings.velocity.crossed.any(axis=1) & alive]
    columns = [np.column_stack(flags).astype(float)]
    for kind in (crossings.position, crossings.velocity):
        columns += [kind.first_time, kind.excess]
    return np.hstack(columns), exceeded


def _chunk_rows(
    result: BatchResult, cases: Cases, config: SweepConfig, start: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(inputs, flags, metrics) of one chunk as float arrays, plus the limit-exceeded mask."""
    m = result.metrics
    stop = start + result.n_runs
    inputs = [np.arange(start, stop, dtype=float)[:, None], cases.q0_offset, cases.param_factor]
    inputs += [cases.gains[g.name][:, None] for g in config.gains]
    if config.wrench_scale is not None:
        inputs.append(cases.wrench_scale[:, None])
    flags, exceeded = _outcomes(result)
    parts = [metric_array(m, stem) for stem in METRIC_UNITS]
    assert result.task_metrics is not None  # simulate_batch gives every law its task errors
    parts.append(np.column_stack(list(result.task_metrics)))
    if result.p_hat_final is not None:
        parts.append(result.p_hat_final)
    return np.hstack(inputs), flags, np.hstack(parts), exceeded


def percentile_stats(column: np.ndarray) -> dict[str, float | None]:
    if column.size == 0:
        return {"median": None, "p5": None, "p95": None}
    p5, p50, p95 = np.percentile(column, PERCENTILES)
    return {"median": float(p50), "p5": float(p5), "p95": float(p95)}


def crossing_counts(crossed: dict[str, np.ndarray], first_times: dict[str, np.ndarray]) -> dict[str, Any]:
    """The summary's crossing counts: ``position_crossed`` and ``velocity_crossed`` (runs, of the
    flags ``crossed[kind]`` (N,) that are set) and ``crossed_joints`` (per kind, how many runs
    each joint crossed in, from the first-time columns ``first_times[kind]`` (N, nv), null
    where never)."""
    return {
        **{f"{kind}_crossed": int(flags.sum()) for kind, flags in crossed.items()},
        "crossed_joints": {
            kind: (~np.isnan(times)).sum(axis=0).astype(int).tolist() for kind, times in first_times.items()
        },
    }


def summarize(
    metrics: np.ndarray,
    names: Sequence[str],
    diverged: np.ndarray,
    exceeded: np.ndarray,
    crossings: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Summary statistics of the metric table ``metrics`` (N, len(names)), with the
    :func:`crossing_counts` ``crossings`` when given.

    Percentiles are ``numpy.percentile`` (linear interpolation) over the runs that did not
    diverge; a metric with no such run gets None.
    """
    keep = ~diverged
    return {
        "runs": int(diverged.size),
        "diverged": int(diverged.sum()),
        "limit_exceeded": int((exceeded & keep).sum()),
        **(crossings or {}),
        "metrics": {name: percentile_stats(metrics[keep, j]) for j, name in enumerate(names)},
    }


# -- one chunk, wherever it runs ------------------------------------------------------------------


def environment() -> tuple[tuple[str, str], ...]:
    """The versions a run's numbers depend on: twolink-pin, numpy, Pinocchio."""
    import pinocchio

    from twolink_pin.version import __version__

    return (
        ("twolink-pin", __version__),
        ("numpy", str(np.__version__)),
        ("pinocchio", str(pinocchio.__version__)),
    )


@dataclass(frozen=True)
class ChunkRows:
    """The rows of runs ``start .. start + n − 1`` as computed by a worker (or in-process)."""

    start: int
    """Index of the first run."""
    inputs: np.ndarray
    """Input columns (the run index as a float first), shape (n, inputs)."""
    flags: np.ndarray
    """The outcome columns (:func:`outcome_columns`): ``limit_exceeded``, ``diverged`` (0/1),
    ``diverged_at`` [s], ``position_crossed``, ``velocity_crossed`` (0/1), then each joint's
    crossing times [s] and largest excesses, shape (n, 5 + 4 nv)."""
    metrics: np.ndarray
    """Metric columns, shape (n, metrics)."""
    environment: tuple[tuple[str, str], ...]
    """:func:`environment` where the chunk ran."""
    trajectories: dict[str, np.ndarray] | None = None
    """``t``, ``q``, ``v``, ``tau_command`` when trajectories are kept."""
    reasons: tuple[str | None, ...] = ()
    """Why each run ended early (:attr:`~twolink_pin.studies.batch.BatchResult.divergence`: its
    law's reason or the state's), None for a run that went to its end; the column
    :data:`~twolink_pin.studies.parquet.REASON`."""

    @property
    def stop(self) -> int:
        """One past the last run."""
        return self.start + int(self.inputs.shape[0])


class PreparedSweep:
    """What every chunk of a study shares: the law's class and base scenario, the columns."""

    def __init__(
        self,
        config: SweepConfig,
        cls: type[Controller],
        robot: RobotModel,
        trajectory: Trajectory,
        record: bool,
    ) -> None:
        self.config, self.cls, self.robot, self.trajectory, self.record = (
            config,
            cls,
            robot,
            trajectory,
            record,
        )
        self.base: Scenario = dataclasses.replace(config.run, law=cls).build(robot)
        check_draws(config, robot, self.base.controller)  # every draw a value simulate takes, first
        nv = robot.nv
        if record:
            kept = config.samples * (config.run.simulation.steps + 1) * 3 * nv
            if kept > MAX_KEPT_VALUES:
                raise InvalidParameterError(
                    "keep_trajectories",
                    True,
                    f"at most {MAX_KEPT_VALUES:.3g} recorded values over the whole sweep (8 GB: samples × "
                    f"(steps + 1) × 3 nv); {config.samples} runs of {config.run.simulation.steps} steps need "
                    f"{kept:.3g} ({8 * kept / 1e9:.3g} GB): fewer samples, a larger dt or a shorter duration",
                )
        self.parameter_names = tuple(robot.parameter_map.names)
        law = self.base.controller
        estimated = law.parameter_names if law.estimates else ()
        self.input_columns = input_columns(config, nv, self.parameter_names)
        self.task = bool(cls.task_space)  # the law's class declares it: its figure shows them first
        self.metric_columns = metric_columns(nv, estimated)
        self.outcome_columns = outcome_columns(nv)
        # the reason a run ended early (text) right after when it did
        after = self.outcome_columns.index("diverged_at") + 1
        outcomes = [*self.outcome_columns[:after], REASON, *self.outcome_columns[after:]]
        self.header = [*self.input_columns, *outcomes, *self.metric_columns]
        units = {"run": "", **{c: "rad" for c in joint_columns("q0_offset", nv)}}
        units.update({f"param_factor_{n}": "" for n in self.parameter_names})
        for g in config.gains:
            key, _ = gain_target(cls, g.name)
            units[f"gain_{g.name}"] = spec_of(cls.Gains, key).unit
        if config.wrench_scale is not None:
            units["wrench_scale"] = ""
        units.update(
            limit_exceeded="", diverged="", diverged_at="s", position_crossed="", velocity_crossed=""
        )
        units[REASON] = ""
        for stem, unit in CROSSING_UNITS.items():
            units.update({c: unit for c in joint_columns(stem, nv)})
        for stem, unit in METRIC_UNITS.items():
            units.update({c: unit for c in joint_columns(stem, nv)})
        units.update(TASK_COLUMNS)
        if law.estimates:
            units.update(
                {f"p_hat_final_{n}": u for n, u in zip(law.parameter_names, law.parameter_units, strict=True)}
            )
        self.units = units

    def run(
        self, start: int, stop: int, threads: int | None, progress: Callable[[int], None] | None = None
    ) -> ChunkRows:
        """Draw and simulate runs ``start .. stop − 1``; ``progress(runs done)`` meanwhile."""
        config = self.config
        cases = Cases(config, self.robot, start, stop)
        law = chunk_law(config, self.robot, cases, self.base.controller)
        size = stop - start

        def steps(done: int, total: int) -> None:
            if progress is not None:
                progress(int(size * done / total))

        plant, noise = self.base.plant, self.base.plant.sensor_noise
        if noise is not None:  # run i of the sweep draws stream i, whatever the chunking
            plant = dataclasses.replace(
                plant, sensor_noise=dataclasses.replace(noise, stream=noise.stream + start)
            )
        wrench = plant.wrench
        if config.wrench_scale is not None and wrench is not None:  # each run its drawn wrench
            plant = dataclasses.replace(
                plant, wrench=dataclasses.replace(wrench, scale=tuple(cases.wrench_scale))
            )
        result = simulate_batch(
            law,
            plant,
            self.trajectory,
            config.run.simulation,
            runs=size,
            q0_offsets=cases.q0_offset,
            threads=threads,
            record=self.record,
            progress=steps,
        )
        inputs, flags, metrics, _ = _chunk_rows(result, cases, config, start)
        kept = None
        if self.record:
            assert result.q is not None and result.v is not None and result.tau_command is not None
            kept = {"t": result.t, "q": result.q, "v": result.v, "tau_command": result.tau_command}
        reasons = tuple(
            (why or "diverged") if dead else None
            for why, dead in zip(result.divergence, result.diverged.tolist(), strict=True)
        )
        return ChunkRows(start, inputs, flags, metrics, environment(), kept, reasons)
