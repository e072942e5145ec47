"""Monte Carlo studies of one law on the batch engine: ``twolink-pin sweep``.

:func:`run_sweep` draws N cases of one law — initial errors, parameter-estimate errors
and gains, uniformly in the given ranges — runs them through
:func:`~twolink_pin.studies.batch.simulate_batch` in chunks, and streams one row per run
(its inputs and metrics) to ``runs.csv`` and ``runs.json``; ``summary.json`` holds the median
and the 5th / 95th percentiles of every metric over the runs that did not diverge, and
the counts of runs that diverged or exceeded a torque limit.

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
Memory is O(N · metrics), never O(N · trajectory) unless trajectories are asked for.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.files import atomic_write, output_directory, write_json
from twolink_pin.model import RobotModel
from twolink_pin.scenario import law_class, make_scenario
from twolink_pin.simulation import SimulationConfig
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.batch import BatchResult, simulate_batch
from twolink_pin.trajectory import JointTrajectory

PERCENTILES = (5.0, 50.0, 95.0)
"""Percentiles in the summary (the 50th is the median)."""
MARKER = ".twolink-pin-sweep"
"""File that marks a folder as written by ``sweep`` (safe to replace)."""
MAX_SAMPLES = 10_000_000
"""Largest number of runs of one sweep."""
MAX_CHUNK = 100_000
"""Largest number of runs advanced together (memory: ~2 kB per run and chunk)."""


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
        chunk: Runs advanced together (bounds memory), 1 to :data:`MAX_CHUNK`.
        threads: Threads for the batch engine (None: all cores).
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
    chunk: int = 1000
    threads: int | None = None

    def __post_init__(self) -> None:
        cls = law_class(self.controller)
        for name, bound in (("samples", MAX_SAMPLES), ("chunk", MAX_CHUNK)):
            value = getattr(self, name)
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


def _text(x: float) -> str:
    """Shortest round-trip text of a float (deterministic); NaN as ``nan``."""
    return "nan" if math.isnan(x) else repr(float(x))


def summarize(
    metrics: np.ndarray, names: Sequence[str], diverged: np.ndarray, exceeded: np.ndarray
) -> dict[str, Any]:
    """Summary statistics of the metric table ``metrics`` (N, len(names)).

    Percentiles are ``numpy.percentile`` (linear interpolation) over the runs that did not
    diverge; a metric with no such run gets None.
    """
    keep = ~diverged
    stats: dict[str, Any] = {}
    for j, name in enumerate(names):
        column = metrics[keep, j]
        if column.size == 0:
            stats[name] = {"median": None, "p5": None, "p95": None}
            continue
        p5, p50, p95 = np.percentile(column, PERCENTILES)
        stats[name] = {"median": float(p50), "p5": float(p5), "p95": float(p95)}
    return {
        "runs": int(diverged.size),
        "diverged": int(diverged.sum()),
        "limit_exceeded": int((exceeded & keep).sum()),
        "metrics": stats,
    }


# -- the study --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepOutput:
    """What :func:`run_sweep` wrote and found."""

    summary: dict[str, Any]
    """The content of ``summary.json``."""
    files: tuple[Path, ...]
    """Files written (table, summary, figure, trajectories)."""
    seconds: float
    """Wall-clock time of the runs [s] (not written to any file: files are reproducible)."""


@contextlib.contextmanager
def _json_rows(path: Path) -> Iterator[Callable[[dict[str, Any]], None]]:
    with atomic_write(path) as f:
        f.write("[")
        first = [True]

        def write(row: dict[str, Any]) -> None:
            f.write("\n  " if first[0] else ",\n  ")
            first[0] = False
            f.write(json.dumps(row, allow_nan=False))

        yield write
        f.write("\n]\n")


def _json_value(x: float) -> float | None:
    return None if math.isnan(x) else float(x)


def run_sweep(
    config: SweepConfig,
    robot: RobotModel,
    trajectory: JointTrajectory,
    out_dir: str | Path,
    progress: Callable[[int, int], None] | None = None,
    keep_trajectories: bool = False,
    plot: bool = True,
) -> SweepOutput:
    """Run the study and write ``runs.csv``, ``runs.json``, ``summary.json`` (and the figure).

    The folder ``out_dir`` is written as a whole (:func:`twolink_pin.files.output_directory`):
    it must be new, empty or an earlier sweep's; an interrupted sweep leaves it as it was.

    Args:
        config: The study.
        robot: The arm (the plant, and the laws' nominal model).
        trajectory: The reference.
        out_dir: Output directory.
        progress: Called as ``progress(runs_done, samples)`` during the runs.
        keep_trajectories: Also write each chunk's q, q̇, τ_command to
            ``trajectories-<first run>.npz`` (N·K·nv floats each: large).
        plot: Write ``distributions.png`` (matplotlib).

    Raises:
        InvalidParameterError: an inconsistent study.
        OutputError: ``out_dir`` is someone else's folder or cannot be written.
    """
    cls = law_class(config.controller)
    base = make_scenario(
        cls, robot, lam=config.lam, saturate=config.saturate, friction_smoothing=config.friction_smoothing
    )
    nv = robot.nv
    parameter_names = tuple(robot.parameter_map.names)
    estimated = base.controller.parameter_names if base.controller.estimates else ()
    in_cols = input_columns(config, nv, parameter_names)
    metric_cols = metric_columns(nv, estimated)
    header = [*in_cols, *FLAG_COLUMNS, *metric_cols]
    all_metrics = np.empty((config.samples, len(metric_cols)))
    diverged = np.zeros(config.samples, dtype=bool)
    exceeded = np.zeros(config.samples, dtype=bool)
    started = time.perf_counter()
    with output_directory(out_dir, MARKER) as stage:
        files = [stage / "runs.csv", stage / "runs.json", stage / "summary.json"]
        with atomic_write(stage / "runs.csv") as csv_file, _json_rows(stage / "runs.json") as json_row:
            writer = csv.writer(csv_file, lineterminator="\n")
            writer.writerow(header)
            for start in range(0, config.samples, config.chunk):
                stop = min(start + config.chunk, config.samples)
                cases = Cases(config, robot, start, stop)
                law = _chunk_law(config, robot, cases, base.controller)

                def chunk_progress(
                    done: int, total: int, start: int = start, size: int = stop - start
                ) -> None:
                    if progress is not None:
                        progress(start + int(size * done / total), config.samples)

                result = simulate_batch(
                    law,
                    base.plant,
                    trajectory,
                    config.simulation,
                    runs=stop - start,
                    q0_offsets=cases.q0_offset,
                    threads=config.threads,
                    record=keep_trajectories,
                    progress=chunk_progress,
                )
                inputs, flags, metrics, over = _chunk_rows(result, cases, config, start)
                all_metrics[start:stop] = metrics
                diverged[start:stop] = result.diverged
                exceeded[start:stop] = over
                for r in range(stop - start):
                    writer.writerow(
                        [str(int(inputs[r, 0])), *(_text(x) for x in inputs[r, 1:])]
                        + ["1" if flags[r, 0] else "0", "1" if flags[r, 1] else "0", _text(flags[r, 2])]
                        + [_text(x) for x in metrics[r]]
                    )
                    row: dict[str, Any] = {"run": int(inputs[r, 0])}
                    row.update({name: _json_value(x) for name, x in zip(in_cols[1:], inputs[r, 1:])})
                    row.update(
                        limit_exceeded=bool(flags[r, 0]),
                        diverged=bool(flags[r, 1]),
                        diverged_at=_json_value(flags[r, 2]),
                    )
                    row.update({name: _json_value(x) for name, x in zip(metric_cols, metrics[r])})
                    json_row(row)
                if keep_trajectories:
                    path = stage / f"trajectories-{start:07d}.npz"
                    assert result.q is not None and result.v is not None and result.tau_command is not None
                    with atomic_write(path, "wb") as f:
                        np.savez_compressed(
                            f, t=result.t, q=result.q, v=result.v, tau_command=result.tau_command
                        )
                    files.append(path)
        seconds = time.perf_counter() - started
        summary = summarize(all_metrics, metric_cols, diverged, exceeded)
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
            "torque_limits": [x if math.isfinite(x) else None for x in robot.torque_limits.tolist()],
            **summary,
        }
        write_json(stage / "summary.json", summary)
        if plot:
            files.append(
                save_distribution_figure(
                    stage / "distributions.png", all_metrics, metric_cols, diverged, nv, cls.name
                )
            )
    out = Path(out_dir)
    return SweepOutput(summary, tuple(out / f.name for f in files), seconds)


def save_distribution_figure(
    path: Path, metrics: np.ndarray, names: Sequence[str], diverged: np.ndarray, nv: int, controller: str
) -> Path:
    """Histograms of the main metrics over the non-diverged runs (PNG, atomically)."""
    from twolink_pin.plotting import save_distribution_figure as plot_distributions

    units = {"rms_e": "rad", "final_period_max_abs_e": "rad", "peak_command": "N·m"}
    keep = ~diverged
    rows = {
        f"{name} [{units[stem]}]": metrics[keep, list(names).index(name)]
        for stem in units
        for name in _joint_columns(stem, nv)
    }
    title = f"{controller}: {int(keep.sum())} of {keep.size} runs ({int(diverged.sum())} diverged)"
    if not keep.any():
        rows = {"diverged_at [s]": np.zeros(0)}
    return plot_distributions(rows, path, title=title)


__all__ = [
    "FLAG_COLUMNS",
    "MARKER",
    "PERCENTILES",
    "Cases",
    "GainRange",
    "SweepConfig",
    "SweepOutput",
    "gain_target",
    "input_columns",
    "metric_columns",
    "run_sweep",
    "save_distribution_figure",
    "summarize",
]
