"""Monte Carlo studies of one law on the batch engine: ``twolink-pin sweep``.

:func:`run_sweep` draws N cases of one law — initial errors, parameter-estimate errors
and gains, uniformly in the given ranges — cuts them into chunks of runs, runs each chunk
through :func:`~twolink_pin.studies.batch.simulate_batch` (in this process, or as a task on
a Dask cluster: :mod:`twolink_pin.studies.cluster`) and streams one row per run (its inputs
and metrics) as each chunk arrives:

* ``runs/part-<first run>.parquet`` — one Parquet file per chunk, the sweep's configuration
  (:func:`sweep_metadata`) in the schema metadata, each column's unit, missing values as
  nulls (:mod:`twolink_pin.studies.parquet`): pandas, polars and DuckDB read the folder as
  one table;
* ``runs.csv`` and ``runs.json`` — the same rows in run order (NaN as ``nan`` / null);
* ``summary.json`` — the median and the 5th / 95th percentiles of every metric over the runs
  that did not diverge, and the counts of runs that diverged, exceeded a torque limit, crossed
  a joint's position range or a velocity limit (and, per joint, in how many runs it crossed),
  computed from the Parquet dataset column by column, as is ``distributions.png``.

What is drawn for run ``i``, from its own generator
``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i,)))`` in this order — so a run's
case depends only on the seed and its index, whatever the chunking or where it runs:

* ``q(0) − q_d(0) = q0_offset + U(−q0_spread, q0_spread)`` per joint [rad];
* ``δ ~ U(−param_error, param_error)`` per parameter of the map: the law believes
  ``p ⊙ (1 + δ)`` (model-based laws use it in their model, the adaptive laws start from
  ``p̂(0) = initial_estimate × p ⊙ (1 + δ)``);
* each ``--gain NAME=LO:HI``: ``U(LO, HI)``, in the order given;
* with ``--wrench-scale LO:HI``: the run's factor ``U(LO, HI)`` on the plant's ``--wrench``
  (column ``wrench_scale``).

A gain is any field of the law's gains class (``kp``, ``k``, ``lam``, ``gamma``,
``model_scale``, ... — what a law's gains are, its class declares): a per-joint or
per-parameter field gets the drawn value on every entry, ``NAME2`` on its second entry.

Since the batch engine computes a run bit for bit the same whatever its batch and thread
count, the tables are identical in every byte whatever the chunking, in-process or on a
cluster — provided every worker runs the same twolink-pin, numpy and Pinocchio as the
client (checked on every chunk) on the same instruction set (see ``docs/cluster.md``).
The client holds one chunk at a time plus, for the summary, one column of N floats:
memory is O(chunk + N), never O(N · metrics) nor O(N · trajectory) unless trajectories
are asked for.

The study lives in four modules beside this one, along its seams:

=======================  ===================================================================
``sweep_cases.py``       the study (:class:`SweepConfig`), the draws (:class:`Cases`), chunk sizes
``sweep_rows.py``        the columns, one chunk's runs as rows, the summary statistics
``sweep_writers.py``     Parquet parts, ``runs.csv``, ``runs.json``, metadata, the figure
``sweep_transport.py``   what a Dask worker gets and runs (:func:`run_chunk_task`)
=======================  ===================================================================

This module runs the study (:func:`run_sweep`) and re-exports their public names.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from twolink_pin.controllers import Controller
from twolink_pin.errors import ControllerError, InvalidParameterError
from twolink_pin.files import atomic_write, check_output_directory, output_directory, write_json
from twolink_pin.limits import joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.simulation.deadline import run_limit
from twolink_pin.studies.cluster import CONNECT_TIMEOUT, ClusterError, TaskTimeout
from twolink_pin.studies.cluster import (
    dask_setup as dask_setup,  # the workers' preload hook (--preload this module)
)
from twolink_pin.studies.cluster_errors import WorkerKilled
from twolink_pin.studies.parquet import (
    RUNS_FOLDER,
    table_schema,
)
from twolink_pin.studies.sweep_cases import (
    AUTO_CHUNK,
    CHUNKS_PER_WORKER,
    MAX_CHUNK,
    MAX_SAMPLES,
    MIN_AUTO_CHUNK,
    Cases,
    GainRange,
    SweepConfig,
    auto_chunk,
    gain_target,
)
from twolink_pin.studies.sweep_rows import (
    FLAG_COLUMNS,
    MAX_KEPT_VALUES,
    METRIC_UNITS,
    PERCENTILES,
    ChunkRows,
    PreparedSweep,
    environment,
    input_columns,
    metric_columns,
    summarize,
)
from twolink_pin.studies.sweep_transport import RobotSource, SweepJob, run_chunk_task, versions_text
from twolink_pin.studies.sweep_writers import (
    FIGURE_MAX_RUNS,
    FIGURE_METRICS,
    SUMMARY_MEMORY,
    RowSink,
    json_row_writer,
    save_distribution_figure,
    summarize_dataset,
    sweep_metadata,
    write_figure,
)
from twolink_pin.trajectory import Trajectory

MARKER = ".twolink-pin-sweep"
"""File that marks a folder as written by ``sweep`` (safe to replace)."""


# -- the study --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepOutput:
    """What :func:`run_sweep` wrote and found."""

    summary: dict[str, Any]
    """The content of ``summary.json``."""
    files: tuple[Path, ...]
    """Files written (table, dataset folder, summary, figure, trajectories)."""
    seconds: float
    """Wall-clock time of the runs [s] (not written to any file: files are reproducible)."""
    engine: str = "in-process"
    """Where the runs ran: ``in-process``, a LocalCluster or a scheduler."""
    chunk: int = 0
    """Runs per chunk."""


@contextlib.contextmanager
def _named_timeout(cls: type[Controller], ranges: list[tuple[int, int]]) -> Iterator[None]:
    """A chunk past ``--timeout`` on a Dask worker, or one that killed its workers, as the
    failed run it is: an error naming the law and the bound (as in-process,
    :func:`~twolink_pin.simulation.deadline.timed_out`) or the workers' deaths (exit status 1;
    it was a cluster error without the law, exit 2)."""
    try:
        yield
    except WorkerKilled as exc:
        start, stop = ranges[exc.index]
        raise ControllerError(
            cls.name,
            math.nan,
            f"runs {start}–{stop - 1} killed {exc.deaths} Dask worker process{'es' if exc.deaths != 1 else ''} "
            f"in a row: the law {cls.__qualname__} ended them (os._exit, a crash in C code, out of memory?); "
            f"the last was {exc.last}: see its log",
        ) from None
    except TaskTimeout as exc:
        start, stop = ranges[exc.index]
        raise ControllerError(
            cls.name,
            math.nan,
            f"runs {start}–{stop - 1} did not finish within --timeout {exc.seconds:g} s of wall-clock time "
            f"on a Dask worker (the law {cls.__qualname__} may never return; {exc.stopped}); give a larger "
            "--timeout for a longer run",
        ) from None


def run_sweep(
    config: SweepConfig,
    robot: RobotModel,
    trajectory: Trajectory,
    out_dir: str | Path,
    progress: Callable[[int, int], None] | None = None,
    keep_trajectories: bool = False,
    plot: bool = True,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    timeout: float = CONNECT_TIMEOUT,
    client: Any = None,
    notify: Callable[[str], None] | None = None,
) -> SweepOutput:
    """Run the study and write ``runs/``, ``runs.csv``, ``runs.json``, ``summary.json``
    (and the figure).

    The folder ``out_dir`` is written as a whole (:func:`twolink_pin.files.output_directory`):
    it must be new, empty or an earlier sweep's; an interrupted or failed sweep leaves it as
    it was (and cancels the tasks on the cluster).

    Args:
        config: The study.
        robot: The arm (the plant, and the laws' nominal model).
        trajectory: The reference.
        out_dir: Output directory.
        progress: Called as ``progress(runs_done, samples)`` during the runs.
        keep_trajectories: Also write each chunk's q, q̇, τ_command to
            ``trajectories-<first run>.npz`` (N·K·nv floats each: large; on a cluster they
            travel to the client).
        plot: Write ``distributions.png`` (matplotlib).
        scheduler: Run the chunks on the Dask scheduler at this address (``tcp://HOST:PORT``).
        workers: Run them on a new LocalCluster of this many worker processes (127.0.0.1).
        timeout: Seconds for the scheduler to answer and to have a worker.
        client: Run them through this ``distributed.Client`` (yours: left open), e.g. on a
            cluster that serves several sweeps.
        notify: Called with one-line messages for the user (where the sweep runs, the
            dashboard's address).

    Raises:
        InvalidParameterError: an inconsistent study, both ``scheduler`` and ``workers``.
        ClusterError: Dask missing, the cluster unreachable, a worker that differs.
        OutputError: ``out_dir`` is someone else's folder or cannot be written.
    """
    cls = config.run.law_class()
    prepared = PreparedSweep(config, cls, robot, trajectory, keep_trajectories)
    check_output_directory(out_dir, MARKER)  # before a cluster is started or reached
    schema = table_schema(prepared.header, prepared.units, sweep_metadata(config, robot, cls, trajectory))
    with contextlib.ExitStack() as stack:
        engine = _engine(stack, client, scheduler, workers, timeout, notify)
        chunk = config.chunk or auto_chunk(config.samples, None if engine is None else engine.slots)
        ranges = [(s, min(s + chunk, config.samples)) for s in range(0, config.samples, chunk)]
        started = time.perf_counter()
        with output_directory(out_dir, MARKER) as stage:
            with (
                atomic_write(stage / "runs.csv") as csv_file,
                json_row_writer(stage / "runs.json") as json_rows,
            ):
                sink = RowSink(stage, prepared, schema, csv_file, json_rows)
                if engine is None:
                    _run_in_process(prepared, ranges, sink, progress)
                else:
                    job = SweepJob.of(config, cls, robot, trajectory, keep_trajectories)
                    _run_on_cluster(engine, job, cls, ranges, sink, progress)
                assert sink.next == config.samples and not sink.early
            seconds = time.perf_counter() - started
            summary, files = _conclude(stage, prepared, sink, robot, plot)
        description = "in-process" if engine is None else engine.description
    out = Path(out_dir)
    return SweepOutput(summary, tuple(out / f.name for f in files), seconds, description, chunk)


def _engine(
    stack: contextlib.ExitStack,
    client: Any,
    scheduler: str | None,
    workers: int | None,
    timeout: float,
    notify: Callable[[str], None] | None,
) -> Any:
    """Where the chunks run: None (in this process), the given client's cluster, or a cluster
    opened on ``stack`` (a scheduler's, or a new LocalCluster of ``workers``), announced
    through ``notify``."""
    if client is not None:
        if scheduler is not None or workers is not None:
            raise InvalidParameterError("client", client, "no scheduler or workers beside a client")
        from twolink_pin.studies.cluster import engine_for

        return engine_for(client)
    if scheduler is None and workers is None:
        return None
    from twolink_pin.studies.cluster import open_cluster

    engine = stack.enter_context(open_cluster(scheduler, workers, timeout, preload=(__name__,)))
    if notify is not None:
        notify(f"sweep on {engine.description}")
        if engine.dashboard:
            notify(f"dashboard: {engine.dashboard}")
    return engine


def _run_in_process(
    prepared: PreparedSweep,
    ranges: list[tuple[int, int]],
    sink: RowSink,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Run the chunks one after the other in this process, each into ``sink``."""
    samples = prepared.config.samples
    for start, stop in ranges:

        def chunk_progress(done: int, start: int = start) -> None:
            if progress is not None:
                progress(start + done, samples)

        sink.add(prepared.run(start, stop, prepared.config.threads, chunk_progress))


def _run_on_cluster(
    engine: Any,
    job: SweepJob,
    cls: type[Controller],
    ranges: list[tuple[int, int]],
    sink: RowSink,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Run the chunks of ``job`` (a study of the law ``cls``) as tasks on ``engine``'s cluster,
    each into ``sink`` as it arrives in run order; a worker whose versions differ from this
    process's is refused."""
    here = environment()
    samples = job.config.samples
    finished = [0, 0]  # runs in finished chunks, runs last shown

    def partial(running: dict[int, int]) -> None:
        done = finished[0] + sum(running.values())
        if progress is not None and done > finished[1]:
            finished[1] = min(done, samples)
            progress(finished[1], samples)

    tasks = [(job, start, stop) for start, stop in ranges]
    results = engine.run(run_chunk_task, tasks, name="sweep", progress=partial, limit_s=run_limit())
    with _named_timeout(cls, ranges), contextlib.closing(results):
        for _, worker, rows in results:
            if rows.environment != here:
                raise ClusterError(
                    worker,
                    f"runs {versions_text(rows.environment)} but the client {versions_text(here)}: its "
                    "runs would not be bit-identical; install the same versions everywhere",
                )
            sink.add(rows)
            finished[0] += rows.stop - rows.start
            partial({})


def _conclude(
    stage: Path, prepared: PreparedSweep, sink: RowSink, robot: RobotModel, plot: bool
) -> tuple[dict[str, Any], list[Path]]:
    """After the runs: ``summary.json`` from the dataset in ``stage`` and ``distributions.png``
    (if ``plot`` and some run did not diverge); returns the summary and every file written."""
    config, cls = prepared.config, prepared.cls
    found = summarize_dataset(stage / RUNS_FOLDER, prepared.metric_columns, robot.nv)
    summary = _summary(config, robot, cls, found)
    write_json(stage / "summary.json", summary)
    files = [stage / "runs.csv", stage / "runs.json", stage / RUNS_FOLDER, stage / "summary.json"]
    files += sink.kept
    if summary["diverged"] == summary["runs"]:  # nothing to draw: the table and summary say so
        summary["note"] = f"every one of the {summary['runs']} runs diverged: no distributions.png"
        write_json(stage / "summary.json", summary)
    elif plot:
        files.append(write_figure(stage, config.samples, robot.nv, cls.name, prepared.task))
    return summary, files


def _summary(
    config: SweepConfig, robot: RobotModel, cls: type[Controller], found: dict[str, Any]
) -> dict[str, Any]:
    """``summary.json``: the study's settings (law, robot, draws' ranges, simulation, torque
    limits [N·m]), then what :func:`summarize_dataset` ``found``."""
    return {
        "controller": cls.name,
        "robot": robot.name,
        "samples": config.samples,
        "seed": config.seed,
        "q0_spread": config.q0_spread,
        "param_error": config.param_error,
        "gains": {g.name: [g.low, g.high] for g in config.gains},
        "wrench_scale": None if config.wrench_scale is None else list(config.wrench_scale),
        "duration": config.run.simulation.duration,
        "dt": config.run.simulation.dt,
        "control_period": config.run.simulation.control_period,
        "method": config.run.simulation.method,
        "lam": config.run.lam,
        "saturate": config.run.plant.saturate,
        "joint_stops": config.run.plant.position_stops,
        "friction_smoothing": config.run.friction_smoothing,
        "torque_limits": [x if math.isfinite(x) else None for x in robot.torque_limits.tolist()],
        "limits": joint_limits(robot).as_dict(),
        **found,
    }


__all__ = [
    "AUTO_CHUNK",
    "CHUNKS_PER_WORKER",
    "FIGURE_MAX_RUNS",
    "FIGURE_METRICS",
    "FLAG_COLUMNS",
    "MARKER",
    "MAX_CHUNK",
    "MAX_KEPT_VALUES",
    "MAX_SAMPLES",
    "METRIC_UNITS",
    "MIN_AUTO_CHUNK",
    "PERCENTILES",
    "SUMMARY_MEMORY",
    "Cases",
    "ChunkRows",
    "GainRange",
    "RobotSource",
    "SweepConfig",
    "SweepJob",
    "SweepOutput",
    "auto_chunk",
    "environment",
    "gain_target",
    "input_columns",
    "metric_columns",
    "run_chunk_task",
    "run_sweep",
    "save_distribution_figure",
    "summarize",
    "summarize_dataset",
    "sweep_metadata",
]
