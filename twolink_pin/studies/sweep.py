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
  that did not diverge, and the counts of runs that diverged or exceeded a torque limit,
  computed from the Parquet dataset column by column, as is ``distributions.png``.

What is drawn for run ``i``, from its own generator
``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i,)))`` in this order — so a run's
case depends only on the seed and its index, whatever the chunking or where it runs:

* ``q(0) − q_d(0) = q0_offset + U(−q0_spread, q0_spread)`` per joint [rad];
* ``δ ~ U(−param_error, param_error)`` per parameter of the map: the law believes
  ``p ⊙ (1 + δ)`` (model-based laws use it in their model, the adaptive laws start from
  ``p̂(0) = initial_estimate × p ⊙ (1 + δ)``);
* each ``--gain NAME=LO:HI``: ``U(LO, HI)``, in the order given.

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
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import math
import shutil
import tempfile
import threading
import time
import uuid
from collections import OrderedDict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.files import atomic_write, check_output_directory, output_directory, write_json
from twolink_pin.model import RobotModel
from twolink_pin.scenario import Scenario, law_class, make_scenario
from twolink_pin.simulation import SimulationConfig
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.batch import BatchResult, simulate_batch
from twolink_pin.studies.cluster import CONNECT_TIMEOUT, ClusterError
from twolink_pin.studies.cluster import (
    dask_setup as dask_setup,  # the workers' preload hook (--preload this module)
)
from twolink_pin.studies.parquet import (
    FLAGS,
    RUNS_FOLDER,
    chunk_table,
    read_columns,
    read_part,
    table_schema,
    write_part,
)
from twolink_pin.trajectory import Trajectory

PERCENTILES = (5.0, 50.0, 95.0)
"""Percentiles in the summary (the 50th is the median)."""
MARKER = ".twolink-pin-sweep"
"""File that marks a folder as written by ``sweep`` (safe to replace)."""
MAX_SAMPLES = 10_000_000
"""Largest number of runs of one sweep."""
MAX_KEPT_VALUES = 1_000_000_000
"""Largest number of floats ``--keep-trajectories`` writes over the whole sweep (8 GB):
samples × (steps + 1) × 3 nv (q, q̇, τ_command)."""
MAX_CHUNK = 100_000
"""Largest number of runs advanced together (memory: ~2 kB per run and chunk)."""
AUTO_CHUNK = 1000
"""Largest chunk the automatic rule chooses (the batch engine's rate levels off there)."""
MIN_AUTO_CHUNK = 250
"""Smallest chunk the automatic rule chooses on a cluster, unless N is smaller: the batch
engine's rate at 250 runs is 80–90 % of its rate at 1000 (per-chunk setup amortised)."""
CHUNKS_PER_WORKER = 4
"""Chunks per worker thread the automatic rule aims at on a cluster: load balance, a
progress display that moves, and little lost when a worker dies."""


def auto_chunk(samples: int, workers: int | None = None) -> int:
    """The chunk size (runs per task) when none is given: chunks of (nearly) equal size, so
    that no worker or thread is left with a short last chunk.

    In-process (``workers`` None): ``ceil(N / ceil(N / 1000))`` — batches as large as the
    engine profits from (at most :data:`AUTO_CHUNK`), the runs split evenly (1200 runs: two
    of 600, both large enough for every thread, instead of 1000 and 200); progress comes
    from inside the chunk. On a cluster of ``workers`` worker threads: about
    :data:`CHUNKS_PER_WORKER` chunks each, of at least :data:`MIN_AUTO_CHUNK` runs — but
    never fewer chunks than workers (while N allows it), so that every worker has runs from
    the start (200 runs on 2 workers: two chunks of 100, not one of 200) — at most
    :data:`AUTO_CHUNK`, and a number of chunks that is a multiple of ``workers`` when the
    chunks are few (no last round with one worker busy and the others idle).
    """
    if workers is None:
        return math.ceil(samples / math.ceil(samples / AUTO_CHUNK))
    workers = max(1, workers)
    target = math.ceil(samples / (CHUNKS_PER_WORKER * workers))
    floor = min(MIN_AUTO_CHUNK, max(1, samples // workers))
    size = max(floor, min(target, AUTO_CHUNK))
    count = math.ceil(samples / size)
    if count < CHUNKS_PER_WORKER * workers:  # few chunks: whole rounds of every worker
        count = min(samples, math.ceil(count / workers) * workers)
    return math.ceil(samples / count)


@dataclass(frozen=True)
class GainRange:
    """A gain drawn uniformly in ``[low, high]`` for every run.

    Attributes:
        name: A field of the law's gains, optionally with a 1-based entry index (``kp2``).
        low: Lower bound, finite. high: Upper bound, finite, >= low.
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise InvalidParameterError(f"gain {self.name}", (self.low, self.high), "finite LO <= HI")

    @classmethod
    def parse(cls, text: str) -> GainRange:
        """``"NAME=LO:HI"`` (e.g. ``"kp=100:400"``)."""
        name, sep, rest = text.partition("=")
        low, sep2, high = rest.partition(":")
        try:
            if not (sep and sep2 and name.strip()):
                raise ValueError
            return cls(name.strip(), float(low), float(high))
        except ValueError:
            raise InvalidParameterError(
                "--gain", text, "NAME=LO:HI with numbers LO <= HI, e.g. kp=100:400"
            ) from None


def gain_target(cls: type[Controller], name: str) -> tuple[str, int | None]:
    """``(field, entry index or None)`` of gain ``name`` for law ``cls`` (``kp2`` → ("kp", 1)).

    Raises:
        InvalidParameterError: no such gain (the message lists the law's gains).
    """
    fields_ = cls.Gains.field_names()
    if name in fields_:
        return name, None
    stem = name.rstrip("0123456789")
    if stem in fields_ and stem != name and spec_of(cls.Gains, stem).per != "scalar":
        index = int(name[len(stem) :])
        if index >= 1:
            return stem, index - 1
    raise InvalidParameterError(
        "gain",
        name,
        f"one of the gains of '{cls.name}': {', '.join(fields_)} (vector gains also NAME1, NAME2, ...)",
    )


@dataclass(frozen=True)
class SweepConfig:
    """A Monte Carlo study of one law (see the module docstring for the draws).

    Where it runs (in-process, a LocalCluster, a scheduler) is not part of the study: the
    results are the same. Nor is the chunking.

    Attributes:
        controller: The law: a registered name, ``file.py:Class`` or ``module:Class``.
        samples: Number of runs N, 1 to :data:`MAX_SAMPLES`.
        seed: Seed of the draws, >= 0.
        q0_spread: Half-width of the uniform initial position error around the nominal
            ``simulation.q0_offset`` [rad], >= 0.
        param_error: Half-width of the relative parameter error δ, in [0, 1).
        gains: Gain ranges.
        simulation: Duration, step, control period, nominal ``q0_offset``; ``rk4`` only.
        lam: ``λ`` [1/s] for a law with one (None: its default).
        saturate: Clip torques at the URDF limits in the plant.
        friction_smoothing: ε [rad/s] of the friction sign.
        chunk: Runs advanced together (one task on a cluster; bounds memory), 1 to
            :data:`MAX_CHUNK`; None: :func:`auto_chunk`.
        threads: Threads of the batch engine per chunk (None: all cores in-process, one
            per task on a cluster — a worker process per core is the way to use cores there).
    """

    controller: str
    samples: int
    seed: int = 0
    q0_spread: float = 0.0
    param_error: float = 0.0
    gains: tuple[GainRange, ...] = ()
    simulation: SimulationConfig = field(default_factory=SimulationConfig)
    lam: float | None = None
    saturate: bool = False
    friction_smoothing: float = 0.0
    chunk: int | None = None
    threads: int | None = None

    def __post_init__(self) -> None:
        cls = law_class(self.controller)
        for name, bound in (("samples", MAX_SAMPLES), ("chunk", MAX_CHUNK)):
            value = getattr(self, name)
            if name == "chunk" and value is None:
                continue
            if not (isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= bound):
                raise InvalidParameterError(name, value, f"a whole number from 1 to {bound}")
        if not (isinstance(self.seed, int) and not isinstance(self.seed, bool) and self.seed >= 0):
            raise InvalidParameterError("seed", self.seed, "a whole number >= 0")
        if not (math.isfinite(self.q0_spread) and self.q0_spread >= 0):
            raise InvalidParameterError("q0_spread", self.q0_spread, "a finite angle >= 0 rad")
        if not (math.isfinite(self.param_error) and 0 <= self.param_error < 1):
            raise InvalidParameterError("param_error", self.param_error, "a fraction in [0, 1)")
        if self.simulation.method != "rk4":
            raise InvalidParameterError("method", self.simulation.method, "'rk4' (the batch engine)")
        names = [g.name for g in self.gains]
        if len(set(names)) != len(names):
            raise InvalidParameterError("gains", names, "each gain at most once")
        for g in self.gains:
            gain_target(cls, g.name)
        if self.lam is not None and not cls.takes("lam"):
            raise InvalidParameterError("lambda", self.lam, f"no λ for controller '{cls.name}'")


# -- the cases ---------------------------------------------------------------------------------


class Cases:
    """The drawn cases of runs ``start .. stop − 1``: arrays with one row per run."""

    def __init__(self, config: SweepConfig, robot: RobotModel, start: int, stop: int) -> None:
        nv, n_p = robot.nv, robot.parameter_map.size
        nominal = joint_offsets("q0_offset", config.simulation.q0_offset, robot.profile.q0_offset, nv)
        n = stop - start
        self.q0_offset = np.empty((n, nv))
        """``q(0) − q_d(0)`` [rad], shape (n, nv)."""
        self.param_factor = np.empty((n, n_p))
        """``1 + δ`` per parameter, shape (n, n_p)."""
        self.gains = {g.name: np.empty(n) for g in config.gains}
        """Drawn value of each gain range, shape (n,) each."""
        for r, i in enumerate(range(start, stop)):
            rng = np.random.default_rng(np.random.SeedSequence(config.seed, spawn_key=(i,)))
            self.q0_offset[r] = nominal + rng.uniform(-config.q0_spread, config.q0_spread, nv)
            self.param_factor[r] = 1.0 + rng.uniform(-config.param_error, config.param_error, n_p)
            for g in config.gains:
                self.gains[g.name][r] = rng.uniform(g.low, g.high)


def _chunk_law(config: SweepConfig, robot: RobotModel, cases: Cases, base: Controller) -> Controller:
    """One law object for the chunk: drawn gains and believed parameters per run."""
    cls = type(base)
    n = len(cases.q0_offset)
    gains: dict[str, Any] = {}
    for g in config.gains:
        key, index = gain_target(cls, g.name)
        drawn = cases.gains[g.name][:, None]
        if index is None:
            gains[key] = drawn if spec_of(cls.Gains, key).per != "scalar" else drawn[:, 0]
            continue
        current = gains.get(key)
        if current is None:
            width = robot.nv if spec_of(cls.Gains, key).per == "joint" else base.state_size
            current = np.array(np.broadcast_to(np.asarray(getattr(base.gains, key), dtype=float), (n, width)))
        if index >= current.shape[1]:
            raise InvalidParameterError("gain", g.name, f"an entry index from 1 to {current.shape[1]}")
        current[:, index] = drawn[:, 0]
        gains[key] = current
    believed = None
    if config.param_error > 0:
        believed = np.asarray(robot.p) * cases.param_factor
    resolved = {k: v for k, v in base.gains.values().items() if k not in gains}
    return make_scenario(
        cls,
        robot,
        gains={**resolved, **gains},
        saturate=config.saturate,
        friction_smoothing=config.friction_smoothing,
        model_parameters=believed,
    ).controller


# -- rows -----------------------------------------------------------------------------------------


def _joint_columns(prefix: str, nv: int) -> list[str]:
    return [f"{prefix}{j + 1}" for j in range(nv)]


METRIC_UNITS = {
    "rms_e": "rad",
    "rms_edot": "rad/s",
    "rms_tau": "N·m",
    "max_e": "rad",
    "max_edot": "rad/s",
    "max_tau": "N·m",
    "final_period_max_abs_e": "rad",
    "peak_command": "N·m",
}
"""SI unit of each per-joint metric (the column names add the joint's 1-based index)."""


def metric_columns(nv: int, parameter_names: Sequence[str] = ()) -> list[str]:
    """Names of the metric columns of a row, in order."""
    columns: list[str] = []
    for kind in ("rms", "max"):
        for signal in ("e", "edot", "tau"):
            columns += _joint_columns(f"{kind}_{signal}", nv)
    columns += _joint_columns("final_period_max_abs_e", nv)
    columns += _joint_columns("peak_command", nv)
    columns += [f"p_hat_final_{name}" for name in parameter_names]
    return columns


def input_columns(config: SweepConfig, nv: int, parameter_names: Sequence[str]) -> list[str]:
    """Names of the input columns of a row, in order."""
    columns = ["run", *_joint_columns("q0_offset", nv)]
    columns += [f"param_factor_{name}" for name in parameter_names]
    columns += [f"gain_{g.name}" for g in config.gains]
    return columns


FLAG_COLUMNS = ("limit_exceeded", "diverged", "diverged_at")
"""Per-run outcome columns after the inputs."""


def _chunk_rows(
    result: BatchResult, cases: Cases, config: SweepConfig, start: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(inputs, flags, metrics) of one chunk as float arrays, plus the limit-exceeded mask."""
    m = result.metrics
    stop = start + result.n_runs
    inputs = [np.arange(start, stop, dtype=float)[:, None], cases.q0_offset, cases.param_factor]
    inputs += [cases.gains[g.name][:, None] for g in config.gains]
    exceeded = np.asarray(result.limit_exceeded.any(axis=1)) & ~result.diverged
    flags = np.column_stack([exceeded, result.diverged, result.diverged_at]).astype(float)
    parts = [
        m.rms.e,
        m.rms.edot,
        m.rms.tau,
        m.max.e,
        m.max.edot,
        m.max.tau,
        m.final_period_max_abs_e,
        m.peak_command,
    ]
    if result.p_hat_final is not None:
        parts.append(result.p_hat_final)
    return np.hstack(inputs), flags, np.hstack(parts), exceeded


def _stats(column: np.ndarray) -> dict[str, float | None]:
    if column.size == 0:
        return {"median": None, "p5": None, "p95": None}
    p5, p50, p95 = np.percentile(column, PERCENTILES)
    return {"median": float(p50), "p5": float(p5), "p95": float(p95)}


def summarize(
    metrics: np.ndarray, names: Sequence[str], diverged: np.ndarray, exceeded: np.ndarray
) -> dict[str, Any]:
    """Summary statistics of the metric table ``metrics`` (N, len(names)).

    Percentiles are ``numpy.percentile`` (linear interpolation) over the runs that did not
    diverge; a metric with no such run gets None.
    """
    keep = ~diverged
    return {
        "runs": int(diverged.size),
        "diverged": int(diverged.sum()),
        "limit_exceeded": int((exceeded & keep).sum()),
        "metrics": {name: _stats(metrics[keep, j]) for j, name in enumerate(names)},
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
    """``limit_exceeded``, ``diverged`` (0/1) and ``diverged_at`` [s], shape (n, 3)."""
    metrics: np.ndarray
    """Metric columns, shape (n, metrics)."""
    environment: tuple[tuple[str, str], ...]
    """:func:`environment` where the chunk ran."""
    trajectories: dict[str, np.ndarray] | None = None
    """``t``, ``q``, ``v``, ``tau_command`` when trajectories are kept."""

    @property
    def stop(self) -> int:
        """One past the last run."""
        return self.start + int(self.inputs.shape[0])


class _Prepared:
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
        self.base: Scenario = make_scenario(
            cls, robot, lam=config.lam, saturate=config.saturate, friction_smoothing=config.friction_smoothing
        )
        nv = robot.nv
        if record:
            kept = config.samples * (config.simulation.steps + 1) * 3 * nv
            if kept > MAX_KEPT_VALUES:
                raise InvalidParameterError(
                    "keep_trajectories",
                    True,
                    f"at most {MAX_KEPT_VALUES:.3g} recorded values over the whole sweep (8 GB: samples × "
                    f"(steps + 1) × 3 nv); {config.samples} runs of {config.simulation.steps} steps need "
                    f"{kept:.3g} ({8 * kept / 1e9:.3g} GB): fewer samples, a larger dt or a shorter duration",
                )
        self.parameter_names = tuple(robot.parameter_map.names)
        law = self.base.controller
        estimated = law.parameter_names if law.estimates else ()
        self.input_columns = input_columns(config, nv, self.parameter_names)
        self.metric_columns = metric_columns(nv, estimated)
        self.header = [*self.input_columns, *FLAG_COLUMNS, *self.metric_columns]
        units = {"run": "", **{c: "rad" for c in _joint_columns("q0_offset", nv)}}
        units.update({f"param_factor_{n}": "" for n in self.parameter_names})
        for g in config.gains:
            key, _ = gain_target(cls, g.name)
            units[f"gain_{g.name}"] = spec_of(cls.Gains, key).unit
        units.update(limit_exceeded="", diverged="", diverged_at="s")
        for stem, unit in METRIC_UNITS.items():
            units.update({c: unit for c in _joint_columns(stem, nv)})
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
        law = _chunk_law(config, self.robot, cases, self.base.controller)
        size = stop - start

        def steps(done: int, total: int) -> None:
            if progress is not None:
                progress(int(size * done / total))

        result = simulate_batch(
            law,
            self.base.plant,
            self.trajectory,
            config.simulation,
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
        return ChunkRows(start, inputs, flags, metrics, environment(), kept)


# -- on a worker -------------------------------------------------------------------------------------


def _robot_digest(robot: RobotModel) -> str:
    """A digest of everything of the robot a run's numbers depend on."""
    model = robot.model
    digest = hashlib.sha256()
    arrays = [robot.p, robot.torque_limits, robot.link_lengths, np.asarray(model.gravity.linear)]
    arrays += [np.asarray(inertia.toDynamicParameters()) for inertia in model.inertias]
    arrays += [np.asarray(placement.homogeneous) for placement in model.jointPlacements]
    for name in (
        "lowerPositionLimit",
        "upperPositionLimit",
        "effortLimit",
        "velocityLimit",
        "damping",
        "friction",
    ):
        arrays.append(np.asarray(getattr(model, name)))
    for array in arrays:
        digest.update(np.ascontiguousarray(array, dtype=float).tobytes())
    digest.update("\0".join([robot.name, *robot.parameter_map.names, str(robot.ee_frame_id)]).encode())
    return digest.hexdigest()


@dataclass(frozen=True)
class RobotSource:
    """How a worker rebuilds the client's robot (a :class:`RobotModel` does not pickle):
    its catalog name, or its URDF text when it is not a catalog robot, the payload, the
    end-effector frame — and a digest the rebuilt robot must match."""

    name: str
    """Catalog name or URDF file stem."""
    urdf: str | None
    """The URDF text (None for a catalog robot, which every worker has)."""
    payload: float
    """Point mass at the end effector [kg]."""
    ee_frame: str
    """End-effector frame name."""
    digest: str
    """:func:`_robot_digest` of the client's robot."""

    @classmethod
    def of(cls, robot: RobotModel) -> RobotSource:
        """The source of ``robot``."""
        from twolink_pin.model import catalog

        in_catalog = False
        if robot.name in catalog.CATALOG:
            with contextlib.suppress(Exception):
                own = catalog.resolve(robot.name)[0]
                in_catalog = own.exists() and Path(robot.urdf_path).samefile(own)
        text = None if in_catalog else Path(robot.urdf_path).read_text(encoding="utf-8")
        return cls(robot.name, text, float(robot.payload), robot.ee_frame, _robot_digest(robot))

    def load(self) -> RobotModel:
        """The robot, rebuilt here (a URDF into this process's :func:`_stored` files).

        Raises:
            ClusterError: the rebuilt robot differs from the client's.
        """
        from twolink_pin.model import load_robot

        source: str | Path = self.name
        if self.urdf is not None:
            source = _stored(f"{self.name}.urdf", self.urdf)
        robot = load_robot(source, payload=self.payload)
        if robot.ee_frame != self.ee_frame or _robot_digest(robot) != self.digest:
            robot = load_robot(source, payload=self.payload, ee_frame=self.ee_frame)
        if _robot_digest(robot) != self.digest:
            import socket

            raise ClusterError(
                f"worker on {socket.gethostname()}",
                f"its robot '{self.name}' differs from the client's (another URDF, example-robot-data or "
                "parameter map): the runs would not be the client's",
            )
        return robot


@dataclass(frozen=True)
class SweepJob:
    """Everything a worker needs to run chunks of one study (pickled into each task)."""

    token: str
    """Unique per sweep: the workers' cache key."""
    config: SweepConfig
    """The study."""
    law_class_name: str
    """The law's class name."""
    law_file: tuple[str, str] | None
    """``(file name, source)`` of a law loaded from a file (shipped: workers need not have it)."""
    robot: RobotSource
    """The arm."""
    trajectory: Trajectory
    """The reference."""
    record: bool
    """Keep trajectories."""
    threads: int
    """Threads of the batch engine per task."""

    def prepare(self) -> _Prepared:
        """The shared part of the chunks, built on this worker."""
        from twolink_pin.controllers.loading import load_controller

        robot = self.robot.load()
        if self.law_file is not None:
            path = _stored(*self.law_file)
            cls = load_controller(f"{path}:{self.law_class_name}")
        else:
            cls = law_class(self.config.controller)
        return _Prepared(self.config, cls, robot, self.trajectory, self.record)


_STORE: list[Path] = []


def _stored(name: str, text: str) -> Path:
    """``text`` as file ``name`` in this process's private folder (created on first use with
    mode 0700, removed at exit), one subfolder per content: the same law or URDF in a later
    sweep is the same path, so the module loaded then is reused (a law registers its name
    once per process: after editing a law's file, restart the workers or rename the law)."""
    if not _STORE:
        import atexit

        folder = Path(tempfile.mkdtemp(prefix="twolink-pin-worker-"))
        atexit.register(shutil.rmtree, folder, True)
        _STORE.append(folder)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    path = _STORE[0] / digest / Path(name).name
    if not path.is_file():
        path.parent.mkdir(exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return path


_PREPARED: OrderedDict[str, _Prepared] = OrderedDict()
_PREPARED_LOCK = threading.Lock()
_PREPARED_KEEP = 4


def run_chunk_task(
    job: SweepJob, start: int, stop: int, progress: Callable[[int], None] | None = None
) -> ChunkRows:
    """The task of one chunk on a worker: :meth:`SweepJob.prepare` once per worker and
    sweep (cached), then the runs."""
    with _PREPARED_LOCK:
        prepared = _PREPARED.get(job.token)
        if prepared is None:
            prepared = job.prepare()
            _PREPARED[job.token] = prepared
            while len(_PREPARED) > _PREPARED_KEEP:
                _PREPARED.popitem(last=False)
    return prepared.run(start, stop, job.threads, progress)


def _law_file(cls: type[Controller]) -> tuple[str, str] | None:
    """``(file name, source)`` of a law loaded from a file, else None (an importable law)."""
    if not cls.__module__.startswith("twolink_pin_user_"):
        return None
    import inspect

    path = Path(inspect.getfile(cls))
    return path.name, path.read_text(encoding="utf-8")


# -- the table -----------------------------------------------------------------------------------------


class _Sink:
    """Writes each chunk to its Parquet file as it arrives, and the rows to runs.csv and
    runs.json in run order (a chunk that arrives early is read back from its file)."""

    def __init__(
        self,
        stage: Path,
        prepared: _Prepared,
        schema: Any,
        csv_file: Any,
        json_rows: Callable[[list[str]], None],
    ) -> None:
        self.folder = stage / RUNS_FOLDER
        self.folder.mkdir()
        self.stage, self.prepared, self.schema = stage, prepared, schema
        self.writer = csv.writer(csv_file, lineterminator="\n")
        self.writer.writerow(prepared.header)
        self.json_rows = json_rows
        keys = [json.dumps(name).replace("{", "{{").replace("}", "}}") for name in prepared.header]
        self.template = "{{" + ", ".join(f"{key}: {{}}" for key in keys) + "}}"
        """A row as JSON (what ``json.dumps(row)`` writes), from the values' texts."""
        self.next = 0
        self.early: dict[int, int] = {}
        self.kept: list[Path] = []

    def add(self, rows: ChunkRows) -> None:
        table = chunk_table(np.hstack([rows.inputs, rows.flags, rows.metrics]), self.schema)
        write_part(table, self.folder, rows.start)
        if rows.trajectories is not None:
            path = self.stage / f"trajectories-{rows.start:07d}.npz"
            with atomic_write(path, "wb") as f:
                kept = rows.trajectories
                np.savez_compressed(f, t=kept["t"], q=kept["q"], v=kept["v"], tau_command=kept["tau_command"])
            self.kept.append(path)
        if rows.start != self.next:
            self.early[rows.start] = rows.stop
            return
        self._emit(table)
        self.next = rows.stop
        while self.next in self.early:
            stop = self.early.pop(self.next)
            self._emit(read_part(self.folder, self.next, self.schema))
            self.next = stop

    def _emit(self, table: Any) -> None:
        """The rows of ``table`` to runs.csv and runs.json, formatted column by column: floats
        as their shortest round-trip text (``repr``), NaN as ``nan`` (CSV) or null (JSON)."""
        csv_columns, json_columns = [], []
        for name in self.prepared.header:
            values = table.column(name).to_numpy(zero_copy_only=False)
            if name in FLAGS:
                csv_columns.append(["1" if v else "0" for v in values.tolist()])
                json_columns.append(["true" if v else "false" for v in values.tolist()])
                continue
            if name == "run":
                text = list(map(str, values.tolist()))
            else:
                if np.isinf(values).any():
                    raise ValueError(f"column {name} holds an infinite value, which JSON cannot")
                text = list(map(repr, values.tolist()))
            csv_columns.append(text)
            has_nan = name != "run" and bool(np.isnan(values).any())
            json_columns.append(["null" if t == "nan" else t for t in text] if has_nan else text)
        self.writer.writerows(zip(*csv_columns))
        self.json_rows([self.template.format(*row) for row in zip(*json_columns)])


SUMMARY_MEMORY = 64 * 2**20
"""Bytes of metric columns the summary holds at once (more passes over the files beyond)."""
FIGURE_MAX_RUNS = 1_000_000
"""Most runs the histograms show (every k-th run beyond: the runs are independent draws)."""


def summarize_dataset(folder: str | Path, names: Sequence[str]) -> dict[str, Any]:
    """:func:`summarize` of the Parquet dataset in ``folder``: the metric columns are read a
    few at a time (:data:`SUMMARY_MEMORY`), so memory is O(N) for N runs (8 bytes per run and
    column held), whatever the number of metrics."""
    flags = read_columns(folder, FLAGS)
    diverged, exceeded = flags["diverged"], flags["limit_exceeded"]
    keep = ~diverged
    per_pass = max(1, SUMMARY_MEMORY // (8 * max(1, diverged.size)))
    stats = {}
    for first in range(0, len(names), per_pass):
        columns = read_columns(folder, names[first : first + per_pass])
        for name, column in columns.items():
            stats[name] = _stats(column[keep])
        del columns
    return {
        "runs": int(diverged.size),
        "diverged": int(diverged.sum()),
        "limit_exceeded": int((exceeded & keep).sum()),
        "metrics": {name: stats[name] for name in names},
    }


def _trajectory_metadata(trajectory: Trajectory | None) -> dict[str, Any] | None:
    """The reference as metadata: its kind, via times [s] and, for via points, the points [rad]."""
    if trajectory is None:
        return None
    described: dict[str, Any] = {
        "kind": type(trajectory).__name__,
        "via_times": trajectory.via_times.tolist(),
    }
    via_q = getattr(trajectory, "via_q", None)
    if via_q is not None:
        described["via_q"] = np.asarray(via_q).tolist()
        described["period"] = getattr(trajectory, "period", None)
    return described


def sweep_metadata(
    config: SweepConfig, robot: RobotModel, cls: type[Controller], trajectory: Trajectory | None = None
) -> dict[str, Any]:
    """The sweep's configuration as written into every Parquet file (JSON): everything the
    rows depend on (the reference ``trajectory`` too, when given), nothing about where or in
    which chunks they ran."""
    from twolink_pin.version import __version__

    nominal = joint_offsets("q0_offset", config.simulation.q0_offset, robot.profile.q0_offset, robot.nv)
    return {
        "twolink_pin": __version__,
        "controller": cls.name,
        "controller_spec": config.controller,
        "robot": robot.name,
        "payload": float(robot.payload),
        "samples": config.samples,
        "seed": config.seed,
        "draws": "numpy.random.default_rng(SeedSequence(seed, spawn_key=(run,)))",
        "q0_offset": nominal.tolist(),
        "q0_spread": config.q0_spread,
        "param_error": config.param_error,
        "parameters": list(robot.parameter_map.names),
        "gains": {g.name: [g.low, g.high] for g in config.gains},
        "lam": config.lam,
        "saturate": config.saturate,
        "friction_smoothing": config.friction_smoothing,
        "method": config.simulation.method,
        "duration": config.simulation.duration,
        "dt": config.simulation.dt,
        "control_period": config.simulation.control_period,
        "torque_limits": [x if math.isfinite(x) else None for x in robot.torque_limits.tolist()],
        "trajectory": _trajectory_metadata(trajectory),
    }


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
def _json_rows(path: Path) -> Iterator[Callable[[list[str]], None]]:
    """``runs.json``: an array of row objects, one per line; ``write`` takes rows as JSON texts."""
    with atomic_write(path) as f:
        f.write("[")
        first = [True]

        def write(rows: list[str]) -> None:
            if not rows:
                return
            f.write("\n  " if first[0] else ",\n  ")
            first[0] = False
            f.write(",\n  ".join(rows))

        yield write
        f.write("\n]\n")


def _versions(env: Sequence[tuple[str, str]]) -> str:
    return ", ".join(f"{name} {version}" for name, version in env)


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
    cls = law_class(config.controller)
    prepared = _Prepared(config, cls, robot, trajectory, keep_trajectories)
    check_output_directory(out_dir, MARKER)  # before a cluster is started or reached
    schema = table_schema(prepared.header, prepared.units, sweep_metadata(config, robot, cls, trajectory))
    here = environment()
    with contextlib.ExitStack() as stack:
        engine = None
        if client is not None:
            if scheduler is not None or workers is not None:
                raise InvalidParameterError("client", client, "no scheduler or workers beside a client")
            from twolink_pin.studies.cluster import engine_for

            engine = engine_for(client)
        elif scheduler is not None or workers is not None:
            from twolink_pin.studies.cluster import open_cluster

            engine = stack.enter_context(open_cluster(scheduler, workers, timeout, preload=(__name__,)))
            if notify is not None:
                notify(f"sweep on {engine.description}")
                if engine.dashboard:
                    notify(f"dashboard: {engine.dashboard}")
        chunk = config.chunk or auto_chunk(config.samples, None if engine is None else engine.slots)
        ranges = [(s, min(s + chunk, config.samples)) for s in range(0, config.samples, chunk)]
        started = time.perf_counter()
        with output_directory(out_dir, MARKER) as stage:
            with atomic_write(stage / "runs.csv") as csv_file, _json_rows(stage / "runs.json") as json_rows:
                sink = _Sink(stage, prepared, schema, csv_file, json_rows)
                if engine is None:
                    for start, stop in ranges:

                        def chunk_progress(done: int, start: int = start) -> None:
                            if progress is not None:
                                progress(start + done, config.samples)

                        sink.add(prepared.run(start, stop, config.threads, chunk_progress))
                else:
                    job = SweepJob(
                        uuid.uuid4().hex,
                        config,
                        cls.__name__,
                        _law_file(cls),
                        RobotSource.of(robot),
                        trajectory,
                        keep_trajectories,
                        config.threads or 1,
                    )
                    finished = [0, 0]  # runs in finished chunks, runs last shown

                    def partial(running: dict[int, int]) -> None:
                        done = finished[0] + sum(running.values())
                        if progress is not None and done > finished[1]:
                            finished[1] = min(done, config.samples)
                            progress(finished[1], config.samples)

                    tasks = [(job, start, stop) for start, stop in ranges]
                    with contextlib.closing(
                        engine.run(run_chunk_task, tasks, name="sweep", progress=partial)
                    ) as results:
                        for _, worker, rows in results:
                            if rows.environment != here:
                                raise ClusterError(
                                    worker,
                                    f"runs {_versions(rows.environment)} but the client {_versions(here)}: its "
                                    "runs would not be bit-identical; install the same versions everywhere",
                                )
                            sink.add(rows)
                            finished[0] += rows.stop - rows.start
                            partial({})
                assert sink.next == config.samples and not sink.early
            seconds = time.perf_counter() - started
            summary = summarize_dataset(stage / RUNS_FOLDER, prepared.metric_columns)
            summary = {
                "controller": cls.name,
                "robot": robot.name,
                "samples": config.samples,
                "seed": config.seed,
                "q0_spread": config.q0_spread,
                "param_error": config.param_error,
                "gains": {g.name: [g.low, g.high] for g in config.gains},
                "duration": config.simulation.duration,
                "dt": config.simulation.dt,
                "control_period": config.simulation.control_period,
                "method": config.simulation.method,
                "lam": config.lam,
                "saturate": config.saturate,
                "friction_smoothing": config.friction_smoothing,
                "torque_limits": [x if math.isfinite(x) else None for x in robot.torque_limits.tolist()],
                **summary,
            }
            write_json(stage / "summary.json", summary)
            files = [stage / "runs.csv", stage / "runs.json", stage / RUNS_FOLDER, stage / "summary.json"]
            files += sink.kept
            if plot:
                files.append(_figure(stage, config.samples, robot.nv, cls.name))
        description = "in-process" if engine is None else engine.description
    out = Path(out_dir)
    return SweepOutput(summary, tuple(out / f.name for f in files), seconds, description, chunk)


def _figure(stage: Path, samples: int, nv: int, controller: str) -> Path:
    """``distributions.png`` from the dataset: only the plotted columns, of at most
    :data:`FIGURE_MAX_RUNS` runs (every k-th beyond)."""
    names = [name for stem in FIGURE_METRICS for name in _joint_columns(stem, nv)]
    every = math.ceil(samples / FIGURE_MAX_RUNS)
    columns = read_columns(stage / RUNS_FOLDER, [*names, "diverged"], every)
    metrics = np.column_stack([columns.pop(n) for n in names])
    return save_distribution_figure(
        stage / "distributions.png", metrics, names, columns["diverged"], nv, controller, every=every
    )


FIGURE_METRICS = ("rms_e", "final_period_max_abs_e", "peak_command")
"""The per-joint metrics whose histograms ``distributions.png`` shows."""


def save_distribution_figure(
    path: Path,
    metrics: np.ndarray,
    names: Sequence[str],
    diverged: np.ndarray,
    nv: int,
    controller: str,
    every: int = 1,
) -> Path:
    """Histograms of the main metrics over the non-diverged runs (PNG, atomically); ``every``
    > 1 says that the rows are every k-th run of the sweep."""
    from twolink_pin.plotting import save_distribution_figure as plot_distributions

    keep = ~diverged
    rows = {
        f"{name} [{METRIC_UNITS[stem]}]": metrics[keep, list(names).index(name)]
        for stem in FIGURE_METRICS
        for name in _joint_columns(stem, nv)
    }
    title = f"{controller}: {int(keep.sum())} of {keep.size} runs ({int(diverged.sum())} diverged)"
    if every > 1:
        title += f", every {every}th run of the sweep"
    if not keep.any():
        rows = {"diverged_at [s]": np.zeros(0)}
    return plot_distributions(rows, path, title=title)


__all__ = [
    "FLAG_COLUMNS",
    "MARKER",
    "PERCENTILES",
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
