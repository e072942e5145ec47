"""Several laws side by side on one robot: the metrics table (our Table 2).

:func:`run_comparison` runs each law through a caller-supplied runner (so the simulation
settings stay the caller's), computes its metrics and, optionally, writes its figures;
:class:`ComparisonTable` renders the table with one column per joint of the robot, as
Markdown, CSV and JSON. The course report's own Table 2 is the twolink's business
(:mod:`twolink_pin.twolink.reference`); the report shows it beside ours.
"""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from twolink_pin.contact_metrics import CONTACT_TITLES, CONTACT_UNITS, SETTLE, ContactMetrics
from twolink_pin.controllers.gains import format_gain
from twolink_pin.controllers.relaxation import RunRelaxation
from twolink_pin.errors import ControllerError, SimulationDivergedError
from twolink_pin.files import atomic_write, write_json
from twolink_pin.metrics import NORMS, SIGNALS, Metrics, compute_metrics
from twolink_pin.simulation import SimulationResult
from twolink_pin.task_metrics import TASK_TITLES, TASK_UNITS, TaskMetrics

TASK_COLUMNS = TaskMetrics._fields
"""Columns of the task-space rows (CSV), in :class:`~twolink_pin.task_metrics.TaskMetrics` order."""
TASK_HEADERS = tuple(f"{TASK_TITLES[name]} [{TASK_UNITS[name]}]" for name in TASK_COLUMNS)
"""Markdown headers of the task-space table (no "|" inside a cell: ‖·‖ for the norm)."""
CONTACT_COLUMNS = ContactMetrics._fields
"""Columns of the contact rows (CSV), in :class:`~twolink_pin.contact_metrics.ContactMetrics` order."""
CONTACT_HEADERS = tuple(f"{CONTACT_TITLES[name]} [{CONTACT_UNITS[name]}]" for name in CONTACT_COLUMNS)
"""Markdown headers of the contact table."""


def gains_text(gains: dict[str, Any]) -> str:
    """The gains a law ran with (:func:`~twolink_pin.run_spec.gains_used`) as one line:
    ``kp = (350, 300), kd = (40, 50)``, a matrix as its rows."""
    import numpy as np

    def shown(value: Any) -> str:
        if value is None:
            return "from the robot"
        if isinstance(value, str):  # a gain of choices
            return value
        array = np.asarray(value, dtype=float)
        return format_gain(array[None] if array.ndim == 2 and array.shape[0] == array.shape[1] else array)

    return ", ".join(f"{name} = {shown(value)}" for name, value in gains.items())


def columns(nv: int) -> list[str]:
    """Column names of a row: ``e1..e_nv, edot1.., tau1..``."""
    return [f"{name}{j + 1}" for name, _, _ in SIGNALS for j in range(nv)]


def headers(nv: int, kind: str) -> list[str]:
    """Column headers with units for norm ``kind``: ``e1 [rad]``, ..."""
    suffix = NORMS[kind][1]
    return [f"{symbol}{j + 1} [{unit}{suffix}]" for _, symbol, unit in SIGNALS for j in range(nv)]


def row(metrics: Metrics, kind: str) -> list[float]:
    """One norm of every signal and joint, in :func:`columns` order."""
    norms = getattr(metrics, kind)
    return [float(x) for name, _, _ in SIGNALS for x in getattr(norms, name)]


@dataclass(frozen=True)
class ComparisonTable:
    """Metrics of every law run, in the order run."""

    metrics: dict[str, Metrics]
    """Metrics by law name."""
    seconds: dict[str, float]
    """Wall-clock time of each run [s]."""
    duration: float
    """Simulated time of each run [s]."""
    failed: dict[str, str] = field(default_factory=dict)
    """What happened to each law that did not finish (diverged, raised), by law name."""
    plants: dict[str, str] = field(default_factory=dict)
    """The plant each law ran on, in a few words, by law name."""
    gains: dict[str, dict[str, Any]] = field(default_factory=dict)
    """The gains each law ran with, by law name."""
    task: dict[str, TaskMetrics] = field(default_factory=dict)
    """Task-space metrics (mm, deg) of the task-space laws, by law name."""
    contact: dict[str, ContactMetrics] = field(default_factory=dict)
    """Contact metrics (force errors, impact, penetration, …) of runs against a scene, by law name."""
    relaxed: dict[str, RunRelaxation] = field(default_factory=dict)
    """Where and by how much each law that relaxed limits it could not all keep did so, by law
    name (:class:`~twolink_pin.controllers.relaxation.RunRelaxation`)."""

    @property
    def nv(self) -> int:
        """Joints of the robot."""
        first = next(iter(self.metrics.values()), None)
        return 0 if first is None else int(first.rms.e.shape[0])

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "controllers": {name: m.as_dict() for name, m in self.metrics.items()},
            "columns": columns(self.nv),
            "duration_s": self.duration,
            "seconds": self.seconds,
            "failed": dict(self.failed),
            "plants": dict(self.plants),
            "gains": dict(self.gains),
            "task_metrics": {name: m.as_dict() for name, m in self.task.items()},
            "contact_metrics": {name: m.as_dict() for name, m in self.contact.items()},
            "crossings": {name: m.crossings.summary() for name, m in self.metrics.items()},
            "relaxed": {name: r.summary() for name, r in self.relaxed.items()},
            "within_limits": {name: m.crossings.within_limits for name, m in self.metrics.items()},
        }

    def crossing_rows(self) -> list[tuple[str, str, int, float, float, str]]:
        """Every law's position and velocity crossings: ``(law, kind, joint from 1, first time
        [s], largest excess, unit)`` (:mod:`twolink_pin.limits.crossings`)."""
        rows = []
        for name, m in self.metrics.items():
            for kind, j, first, excess in m.crossings.events():
                rows.append((name, kind, j + 1, first, excess, getattr(m.crossings, kind).kind.unit))
        return rows

    def csv(self) -> str:
        """One row per (law, norm), then the last-period max |e| row per law."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        cols = columns(self.nv)
        writer.writerow(["controller", "norm", *cols])
        for name, m in self.metrics.items():
            for kind in NORMS:
                writer.writerow([name, kind, *(f"{x:.6g}" for x in row(m, kind))])
            e_last = [f"{x:.6g}" for x in m.final_period_max_abs_e]
            writer.writerow([name, "last_period_max_abs_e", *e_last, *([""] * (len(cols) - len(e_last)))])
        for name, what in self.failed.items():
            writer.writerow([name, "failed", what, *([""] * (len(cols) - 1))])
        if self.gains:
            writer.writerow(["controller", "gains"])
            for name, used in self.gains.items():
                writer.writerow([name, gains_text(used)])
        if self.task:
            writer.writerow(["controller", "task_metric", *TASK_COLUMNS])
            for name, t in self.task.items():
                writer.writerow([name, "task", *(f"{x:.6g}" for x in t)])
        if self.contact:
            writer.writerow(["controller", "contact_metric", *CONTACT_COLUMNS])
            for name, c in self.contact.items():
                writer.writerow([name, "contact", *(f"{x:.6g}" for x in c)])
        crossings = self.crossing_rows()
        if crossings:
            writer.writerow(["controller", "crossed", "joint", "first_time_s", "largest_excess", "unit"])
            for name, kind, j, first, excess, unit in crossings:
                writer.writerow([name, kind, j, f"{first:.6g}", f"{excess:.6g}", unit])
        return buffer.getvalue()

    def markdown(self) -> str:
        """Our three norms and the last-period error as Markdown tables."""
        out = []
        for kind, (title, _) in NORMS.items():
            out.append(f"### {title} over {self.duration:g} s\n")
            heads = headers(self.nv, kind)
            out.append("| controller | " + " | ".join(heads) + " |")
            out.append("|---|" + "---:|" * len(heads))
            for name, m in self.metrics.items():
                out.append(f"| {name} | " + " | ".join(f"{x:.4g}" for x in row(m, kind)) + " |")
            out.append("")
        out.append("### max |e| over the last reference period [rad]\n")
        out.append("| controller | " + " | ".join(f"e{j + 1}" for j in range(self.nv)) + " |")
        out.append("|---|" + "---:|" * self.nv)
        for name, m in self.metrics.items():
            out.append(f"| {name} | " + " | ".join(f"{x:.3g}" for x in m.final_period_max_abs_e) + " |")
        if self.task:
            out.append("\n### task space: end-effector position [mm] and orientation [deg] errors\n")
            out.append("| controller | " + " | ".join(TASK_HEADERS) + " |")
            out.append("|---|" + "---:|" * len(TASK_HEADERS))
            for name, t in self.task.items():
                out.append(f"| {name} | " + " | ".join(t.text()) + " |")
        if self.contact:
            out.append(
                f"\n### contact: the force held (from {SETTLE:g} s after the first contact), the impact\n"
            )
            out.append("| controller | " + " | ".join(CONTACT_HEADERS) + " |")
            out.append("|---|" + "---:|" * len(CONTACT_HEADERS))
            for name, c in self.contact.items():
                out.append(f"| {name} | " + " | ".join(c.text()) + " |")
        crossings = self.crossing_rows()
        if crossings:
            out.append("\n### position and velocity limits crossed by the motion\n")
            out.append("| controller | limit | joint | first at [s] | largest excess |")
            out.append("|---|---|---:|---:|---:|")
            for name, kind, j, first, excess, unit in crossings:
                out.append(f"| {name} | {kind} | {j} | {first:.4g} | {excess:.3g} {unit} |")
        relaxed = [(name, r) for name, r in self.relaxed.items() if r.relaxed]
        if relaxed:
            out.append(
                "\n### limits the law relaxed when they could not all hold (its rows, not the motion)\n"
            )
            out.append("| controller | limit | joint | first at [s] | largest relaxation | instants |")
            out.append("|---|---|---:|---:|---:|---:|")
            for name, r in relaxed:
                for kind, j, first, largest, unit in r.events():
                    out.append(
                        f"| {name} | {kind} | {j + 1} | {first:.4g} | {largest:.3g} {unit} | {r.instants} |"
                    )
        if self.plants or self.failed or self.gains:
            out.append("\n### the runs\n")
            out.append("| controller | gains | plant | outcome |")
            out.append("|---|---|---|---|")
            for name in [*self.metrics, *(n for n in self.failed if n not in self.metrics)]:
                outcome = f"FAILED: {self.failed[name]}" if name in self.failed else "finished"
                if name in self.relaxed and self.relaxed[name].relaxed:
                    outcome += f", limits relaxed at {self.relaxed[name].instants} instants"
                gains = gains_text(self.gains[name]) if name in self.gains else ""
                out.append(f"| {name} | {gains} | {self.plants.get(name, '')} | {outcome} |")
        return "\n".join(out) + "\n"

    def write(self, out_dir: Path) -> list[Path]:
        """``comparison.md``, ``comparison.csv``, ``comparison.json`` into ``out_dir``."""
        paths = [out_dir / "comparison.md", out_dir / "comparison.csv"]
        with atomic_write(paths[0]) as f:
            f.write(self.markdown())
        with atomic_write(paths[1]) as f:
            f.write(self.csv())
        paths.append(write_json(out_dir / "comparison.json", self.as_dict()))
        return paths


def run_comparison(
    runner: Callable[[str], SimulationResult],
    names: Sequence[str],
    progress: Callable[[str, SimulationResult | None], None] | None = None,
    on_result: Callable[[str, SimulationResult], None] | None = None,
) -> ComparisonTable:
    """Run every law in ``names`` with ``runner`` and tabulate their metrics.

    Args:
        runner: Runs one law by name and returns its result.
        names: The laws, in table order.
        progress: Called as ``progress(name, None)`` before and ``progress(name, result)``
            after each run.
        on_result: Called with each result (e.g. to write its figures).

    A law that diverges or raises (:class:`~twolink_pin.errors.SimulationDivergedError`,
    :class:`~twolink_pin.errors.ControllerError`) is a row of ``failed`` saying what
    happened and when; the other laws run on. Bad input still raises.
    """
    metrics: dict[str, Metrics] = {}
    seconds: dict[str, float] = {}
    failed: dict[str, str] = {}
    duration = 0.0
    for name in names:
        if progress:
            progress(name, None)
        start = time.perf_counter()
        try:
            result = runner(name)
        except (SimulationDivergedError, ControllerError) as exc:  # the others' results are kept
            failed[name] = str(exc)
            seconds[name] = time.perf_counter() - start
            if progress:
                progress(name, None)
            continue
        metrics[name] = compute_metrics(result)
        duration = result.duration
        if on_result is not None:
            on_result(name, result)
        seconds[name] = time.perf_counter() - start
        if progress:
            progress(name, result)
    return ComparisonTable(metrics, seconds, duration, failed)
