"""A sweep's files: the Parquet parts, ``runs.csv`` and ``runs.json`` in run order, the
metadata every file carries, and ``distributions.png``."""

from __future__ import annotations

import contextlib
import csv
import json
import math
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.files import atomic_write
from twolink_pin.model import RobotModel
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.parquet import (
    FLAGS,
    REASON,
    RUNS_FOLDER,
    TEXTS,
    chunk_table,
    read_columns,
    read_part,
    write_part,
)
from twolink_pin.studies.sweep_cases import SweepConfig, law_reference
from twolink_pin.studies.sweep_rows import (
    CROSSED_FLAGS,
    METRIC_UNITS,
    TASK_COLUMNS,
    ChunkRows,
    PreparedSweep,
    crossing_counts,
    joint_columns,
    percentile_stats,
)
from twolink_pin.trajectory import Trajectory

# -- the table -----------------------------------------------------------------------------------------


class RowSink:
    """Writes each chunk to its Parquet file as it arrives, and the rows to runs.csv and
    runs.json in run order (a chunk that arrives early is read back from its file)."""

    def __init__(
        self,
        stage: Path,
        prepared: PreparedSweep,
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
        reasons = {REASON: rows.reasons} if rows.reasons else None
        table = chunk_table(np.hstack([rows.inputs, rows.flags, rows.metrics]), self.schema, reasons)
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
            if name in TEXTS:  # a reason: the text (empty in CSV, null in JSON where there is none)
                texts = table.column(name).to_pylist()
                csv_columns.append(["" if v is None else v for v in texts])
                json_columns.append(["null" if v is None else json.dumps(v) for v in texts])
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


def summarize_dataset(folder: str | Path, names: Sequence[str], nv: int | None = None) -> dict[str, Any]:
    """:func:`summarize` of the Parquet dataset in ``folder``: the metric columns are read a
    few at a time (:data:`SUMMARY_MEMORY`), so memory is O(N) for N runs (8 bytes per run and
    column held), whatever the number of metrics; with ``nv``, the crossing counts
    (:func:`~twolink_pin.studies.sweep_rows.crossing_counts`) from the flag and first-time
    columns (8 nv bytes per run held)."""
    flags = read_columns(folder, FLAGS)
    diverged, exceeded = flags["diverged"], flags["limit_exceeded"]
    crossings: dict[str, Any] = {}
    if nv is not None:
        kinds = [flag.removesuffix("_crossed") for flag in CROSSED_FLAGS]
        times = {}
        for kind in kinds:
            stems = joint_columns(f"{kind}_crossed_at", nv)
            read = read_columns(folder, stems)
            times[kind] = np.column_stack([read[c] for c in stems])
        crossings = crossing_counts({kind: flags[f"{kind}_crossed"] for kind in kinds}, times)
    keep = ~diverged
    per_pass = max(1, SUMMARY_MEMORY // (8 * max(1, diverged.size)))
    stats = {}
    for first in range(0, len(names), per_pass):
        columns = read_columns(folder, names[first : first + per_pass])
        for name, column in columns.items():
            stats[name] = percentile_stats(column[keep])
        del columns
    return {
        "runs": int(diverged.size),
        "diverged": int(diverged.sum()),
        "limit_exceeded": int((exceeded & keep).sum()),
        **crossings,
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

    nominal = joint_offsets("q0_offset", config.run.simulation.q0_offset, robot.profile.q0_offset, robot.nv)
    return {
        "twolink_pin": __version__,
        "controller": cls.name,
        "controller_spec": law_reference(config.run),
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
        "wrench_scale": None if config.wrench_scale is None else list(config.wrench_scale),
        "lam": config.run.lam,
        "saturate": config.run.plant.saturate,
        "friction_smoothing": config.run.friction_smoothing,
        "method": config.run.simulation.method,
        "duration": config.run.simulation.duration,
        "dt": config.run.simulation.dt,
        "control_period": config.run.simulation.control_period,
        "torque_limits": [x if math.isfinite(x) else None for x in robot.torque_limits.tolist()],
        "trajectory": _trajectory_metadata(trajectory),
        "run": config.run.as_dict(),
    }


@contextlib.contextmanager
def json_row_writer(path: Path) -> Iterator[Callable[[list[str]], None]]:
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


def write_figure(stage: Path, samples: int, nv: int, controller: str, task: bool = False) -> Path:
    """``distributions.png`` from the dataset: only the plotted columns (the task metrics
    first for a task-space law, ``task``), of at most :data:`FIGURE_MAX_RUNS` runs (every
    k-th beyond)."""
    names = _figure_columns(nv, task)
    every = math.ceil(samples / FIGURE_MAX_RUNS)
    columns = read_columns(stage / RUNS_FOLDER, [*names, "diverged"], every)
    metrics = np.column_stack([columns.pop(n) for n in names])
    return save_distribution_figure(
        stage / "distributions.png", metrics, names, columns["diverged"], nv, controller, every=every
    )


FIGURE_METRICS = ("rms_e", "final_period_max_abs_e", "peak_command")
"""The per-joint metrics whose histograms ``distributions.png`` shows (after every task metric
of a task-space law: :data:`~twolink_pin.studies.sweep_rows.TASK_COLUMNS`)."""


def _figure_columns(nv: int, task: bool) -> list[str]:
    """The columns ``distributions.png`` shows, in order."""
    joints = [name for stem in FIGURE_METRICS for name in joint_columns(stem, nv)]
    return [*TASK_COLUMNS, *joints] if task else joints


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
    task = TASK_COLUMNS.keys() <= set(names)
    units = {name: METRIC_UNITS[stem] for stem in FIGURE_METRICS for name in joint_columns(stem, nv)}
    units |= TASK_COLUMNS
    rows = {
        f"{name} [{units[name]}]": metrics[keep, list(names).index(name)]
        for name in _figure_columns(nv, task)
    }
    title = f"{controller}: {int(keep.sum())} of {keep.size} runs ({int(diverged.sum())} diverged)"
    if every > 1:
        title += f", every {every}th run of the sweep"
    if not keep.any():
        rows = {"diverged_at [s]": np.zeros(0)}
    return plot_distributions(rows, path, title=title)
