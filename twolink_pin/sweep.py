"""Monte Carlo studies on the batch engine: ``twolink-pin sweep``.

:func:`run_sweep` draws N cases of one controller — initial errors, parameter-estimate
errors and gains, uniformly in the given ranges — runs them through
:func:`twolink_pin.batch.simulate_batch` in chunks, and streams one row per run (its
inputs and metrics) to ``runs.csv`` and ``runs.json``; ``summary.json`` holds the median
and the 5th / 95th percentiles of every metric over the runs that did not diverge, and
the counts of runs that diverged or exceeded a torque limit.

What is drawn for run ``i`` (all from one ``numpy.random.default_rng(seed)``, in this
order, so a seed gives the same cases whatever the chunk size or thread count):

* ``q(0) − q_d(0) = q0_offset + U(−q0_spread, q0_spread)`` per joint [rad];
* ``δ ~ U(−param_error, param_error)`` per parameter of the map: the controller believes
  ``p ⊙ (1 + δ)`` (PD and Slotine–Li use it in their model, the robust law scales it by
  β, the adaptive laws start from ``p̂(0) = initial_estimate × p ⊙ (1 + δ)``);
* each ``--gain NAME=LO:HI``: ``U(LO, HI)``, in the order given.

Memory is O(N · metrics), never O(N · trajectory) unless trajectories are asked for
(then written chunk by chunk). Seeded runs are reproducible bit for bit.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.batch import BatchResult, default_threads, robot_with_parameters, simulate_batch
from twolink_pin.controllers import (
    CONTROLLERS,
    Adaptive,
    AdaptiveFriction,
    AdaptiveFrictionGains,
    AdaptiveGains,
    Controller,
    PDGains,
    SlotineLiGains,
    WrongModel,
)
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.files import atomic_write, write_json
from twolink_pin.model import RobotModel
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig
from twolink_pin.trajectory import JointTrajectory

_GAINS: dict[str, type] = {
    "pd": PDGains,
    "computed-torque": SlotineLiGains,
    "robust": SlotineLiGains,
    "adaptive": AdaptiveGains,
    "adaptive-friction": AdaptiveFrictionGains,
}
MODEL_SCALE = "model_scale"
"""Gain name of the robust law's β (a constructor argument, not a gains field)."""
PERCENTILES = (5.0, 50.0, 95.0)
"""Percentiles in the summary (the 50th is the median)."""


@dataclass(frozen=True)
class GainRange:
    """A gain drawn uniformly in ``[low, high]`` for every run.

    Attributes:
        name: A numeric field of the controller's gains (``kp``, ``kd``, ``k``, ``lam``,
            ``gamma``, ``initial_estimate``, ...) — every entry of a vector gain gets the
            drawn value — or such a field with a 1-based entry index (``kp2``), or
            ``model_scale`` (β of ``robust``).
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


@dataclass(frozen=True)
class SweepConfig:
    """A Monte Carlo study of one controller (see the module docstring for the draws).

    Attributes:
        controller: Registry name (``pd``, ``computed-torque``, ...).
        samples: Number of runs N, >= 1.
        seed: Seed of ``numpy.random.default_rng``.
        q0_spread: Half-width of the uniform initial position error around
            ``simulation.q0_offset`` [rad], >= 0.
        param_error: Half-width of the relative parameter error δ, in [0, 1).
        gains: Gain ranges.
        simulation: Duration, step, control period, nominal ``q0_offset``; ``rk4`` only.
        lam: ``λ`` [1/s] of the Slotine–Li laws (None: the gains' default).
        saturate: Clip torques at the URDF limits in the plant.
        friction_smoothing: ε [rad/s] of the friction sign (``adaptive-friction``).
        chunk: Runs per batch (bounds memory), >= 1.
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
        if self.controller not in CONTROLLERS:
            raise InvalidParameterError("controller", self.controller, f"one of {', '.join(CONTROLLERS)}")
        for name in ("samples", "chunk"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 1):
                raise InvalidParameterError(name, value, "a whole number >= 1")
        if not (math.isfinite(self.q0_spread) and self.q0_spread >= 0):
            raise InvalidParameterError("q0_spread", self.q0_spread, "a finite angle >= 0 rad")
        if not (math.isfinite(self.param_error) and 0 <= self.param_error < 1):
            raise InvalidParameterError("param_error", self.param_error, "a fraction in [0, 1)")
        if self.simulation.method != "rk4":
            raise InvalidParameterError("method", self.simulation.method, "'rk4' (the batch engine)")
        names = [g.name for g in self.gains]
        if len(set(names)) != len(names):
            raise InvalidParameterError("gains", names, "each gain at most once")
        valid = gain_names(self.controller)
        for g in self.gains:
            if _gain_target(g.name, valid) is None:
                raise InvalidParameterError(
                    "gain", g.name, f"one of {', '.join(valid)} (vector gains also NAME1, NAME2, ...)"
                )


def gain_names(controller: str) -> tuple[str, ...]:
    """The gain names ``controller`` accepts in :class:`GainRange`."""
    cls = _GAINS[controller]
    names = [f.name for f in fields(cls)]
    if controller == "robust":
        names.append(MODEL_SCALE)
    return tuple(names)


def _gain_target(name: str, valid: Sequence[str]) -> tuple[str, int | None] | None:
    """``(field, index or None)`` for ``name`` (``kp`` -> ("kp", None), ``kp2`` -> ("kp", 1))."""
    if name in valid:
        return name, None
    stem = name.rstrip("0123456789")
    if stem in valid and stem != name and stem != MODEL_SCALE:
        index = int(name[len(stem) :])
        return (stem, index - 1) if index >= 1 else None
    return None


# -- the cases ---------------------------------------------------------------------------------


class Cases:
    """The N drawn cases: arrays with one row per run."""

    def __init__(self, config: SweepConfig, robot: RobotModel) -> None:
        rng = np.random.default_rng(config.seed)
        n, nv, n_p = config.samples, robot.nv, robot.parameter_map.size
        nominal = np.asarray(config.simulation.q0_offset, dtype=float)
        if nominal.shape != (nv,):
            raise InvalidParameterError("q0_offset", tuple(nominal), f"{nv} values, one per joint")
        self.q0_offset = nominal + rng.uniform(-config.q0_spread, config.q0_spread, (n, nv))
        """``q(0) − q_d(0)`` [rad], shape (N, nv)."""
        self.param_factor = 1.0 + rng.uniform(-config.param_error, config.param_error, (n, n_p))
        """``1 + δ`` per parameter, shape (N, n_p)."""
        self.gains = {g.name: rng.uniform(g.low, g.high, n) for g in config.gains}
        """Drawn value of each gain range, shape (N,) each."""


def _controller(
    config: SweepConfig, robot: RobotModel, cases: Cases, i: int, friction: Friction | None
) -> Controller:
    gains_cls = _GAINS[config.controller]
    gains = gains_cls()
    if config.lam is not None and any(f.name == "lam" for f in fields(gains_cls)):
        gains = replace(gains, lam=config.lam)
    model_scale = 0.5
    changes: dict[str, Any] = {}
    for name, values in cases.gains.items():
        target = _gain_target(name, gain_names(config.controller))
        assert target is not None  # checked in SweepConfig
        key, index = target
        value = float(values[i])
        if key == MODEL_SCALE:
            model_scale = value
            continue
        current = changes.get(key, getattr(gains, key))
        if isinstance(current, tuple):
            value_t = (
                tuple(value for _ in current) if index is None else _replace_at(current, index, value, name)
            )
            changes[key] = value_t
        else:
            changes[key] = value
    gains = replace(gains, **changes)
    if config.param_error > 0:
        robot = robot_with_parameters(robot, robot.p * cases.param_factor[i])
    if config.controller == "robust":
        return WrongModel(robot, gains, model_scale)
    if config.controller == "adaptive-friction":
        return AdaptiveFriction(robot, gains, friction)
    return CONTROLLERS[config.controller](robot, gains)  # type: ignore[call-arg]


def _replace_at(values: tuple[float, ...], index: int, value: float, name: str) -> tuple[float, ...]:
    if index >= len(values):
        raise InvalidParameterError("gain", name, f"an entry index from 1 to {len(values)}")
    return tuple(value if j == index else x for j, x in enumerate(values))


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
    inputs = [
        np.arange(start, stop, dtype=float)[:, None],
        cases.q0_offset[start:stop],
        cases.param_factor[start:stop],
    ]
    inputs += [cases.gains[g.name][start:stop, None] for g in config.gains]
    exceeded = np.asarray(result.limit_exceeded.any(axis=1))
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

    Args:
        config: The study.
        robot: The arm (the plant, and the controllers' nominal model).
        trajectory: The reference.
        out_dir: Output directory.
        progress: Called as ``progress(runs_done_equivalent, samples)`` during the runs.
        keep_trajectories: Also write each chunk's q, q̇, τ_command to
            ``trajectories-<first run>.npz`` (N·K·nv floats each: large).
        plot: Write ``distributions.png`` (matplotlib).

    Raises:
        InvalidParameterError: an inconsistent study.
        BatchUnavailableError: Pinocchio has no parallel algorithms.
    """
    out = Path(out_dir)
    cases = Cases(config, robot)
    friction = (
        Friction.report(smoothing=config.friction_smoothing)
        if config.controller == "adaptive-friction"
        else None
    )
    plant = Plant(robot, friction=friction, saturate=config.saturate)
    nv = robot.nv
    parameter_names = tuple(robot.parameter_map.names)
    probe = _controller(config, robot, cases, 0, friction)
    estimated = probe.parameter_names if isinstance(probe, Adaptive) else ()
    in_cols = input_columns(config, nv, parameter_names)
    metric_cols = metric_columns(nv, estimated)
    header = [*in_cols, *FLAG_COLUMNS, *metric_cols]
    all_metrics = np.empty((config.samples, len(metric_cols)))
    diverged = np.zeros(config.samples, dtype=bool)
    exceeded = np.zeros(config.samples, dtype=bool)
    files = [out / "runs.csv", out / "runs.json", out / "summary.json"]
    threads = config.threads if config.threads is not None else default_threads()
    started = time.perf_counter()
    with atomic_write(out / "runs.csv") as csv_file, _json_rows(out / "runs.json") as json_row:
        writer = csv.writer(csv_file, lineterminator="\n")
        writer.writerow(header)
        for start in range(0, config.samples, config.chunk):
            stop = min(start + config.chunk, config.samples)
            controllers = [_controller(config, robot, cases, i, friction) for i in range(start, stop)]

            def chunk_progress(done: int, total: int, start: int = start, size: int = stop - start) -> None:
                if progress is not None:
                    progress(start + int(size * done / total), config.samples)

            result = simulate_batch(
                controllers,
                plant,
                trajectory,
                config.simulation,
                q0_offsets=cases.q0_offset[start:stop],
                threads=threads,
                record=keep_trajectories,
                progress=chunk_progress,
            )
            del controllers
            inputs, flags, metrics, over = _chunk_rows(result, cases, config, start)
            all_metrics[start:stop] = metrics
            diverged[start:stop] = result.diverged
            exceeded[start:stop] = over
            for r in range(stop - start):
                values = [*inputs[r], *flags[r], *metrics[r]]
                writer.writerow(
                    [str(int(inputs[r, 0])), *(_text(x) for x in values[1 : len(in_cols)])]
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
                path = out / f"trajectories-{start:07d}.npz"
                assert result.q is not None and result.v is not None and result.tau_command is not None
                with atomic_write(path, "wb") as f:
                    np.savez_compressed(f, t=result.t, q=result.q, v=result.v, tau_command=result.tau_command)
                files.append(path)
    seconds = time.perf_counter() - started
    summary = summarize(all_metrics, metric_cols, diverged, exceeded)
    summary = {
        "controller": config.controller,
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
    write_json(out / "summary.json", summary)
    if plot:
        files.append(
            save_distribution_figure(
                out / "distributions.png", all_metrics, metric_cols, diverged, robot, config
            )
        )
    return SweepOutput(summary, tuple(files), seconds)


def save_distribution_figure(
    path: Path,
    metrics: np.ndarray,
    names: Sequence[str],
    diverged: np.ndarray,
    robot: RobotModel,
    config: SweepConfig,
) -> Path:
    """Histograms of the main metrics over the non-diverged runs (PNG, atomically),
    drawn by :func:`twolink_pin.plotting.save_distribution_figure`."""
    from twolink_pin.plotting import save_distribution_figure as plot_distributions

    nv = robot.nv
    units = {"rms_e": "rad", "final_period_max_abs_e": "rad", "peak_command": "N·m"}
    keep = ~diverged
    rows = {
        f"{name} [{units[stem]}]": metrics[keep, list(names).index(name)]
        for stem in units
        for name in _joint_columns(stem, nv)
    }
    title = f"{config.controller}: {int(keep.sum())} of {keep.size} runs ({int(diverged.sum())} diverged)"
    return plot_distributions(rows, path, title=title)


__all__ = [
    "FLAG_COLUMNS",
    "PERCENTILES",
    "Cases",
    "GainRange",
    "SweepConfig",
    "SweepOutput",
    "gain_names",
    "input_columns",
    "metric_columns",
    "run_sweep",
    "save_distribution_figure",
    "summarize",
]
