"""All five controllers side by side: our Table 2, with the report's beside it.

:func:`run_comparison` runs each controller (through a caller-supplied runner, so the
simulation settings stay the caller's), computes its metrics, optionally writes its
figures, and writes Table 2 as Markdown, CSV and JSON into the output directory.
"""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from twolink_pin.controllers import CONTROLLERS
from twolink_pin.files import atomic_write, write_json
from twolink_pin.metrics import Metrics, compute_metrics
from twolink_pin.simulation import SimulationResult

REPORT_TABLE2: dict[str, tuple[float, float, float, float, float, float]] = {
    "pd": (0.2543, 0.0164, 1.3443, 0.1258, 85.6407, 13.6080),
    "computed-torque": (0.3832, 0.0188, 0.6507, 0.0871, 116.0244, 13.6746),
    "robust": (0.4071, 0.0391, 0.7749, 0.1266, 139.1337, 23.2539),
    "adaptive": (0.0347, 0.0159, 0.0799, 0.0915, 42.1057, 16.9666),
    "adaptive-friction": (0.0212, 0.0025, 0.0533, 0.0804, 39.5083, 14.0296),
}
"""The report's Table 2 "norms" (unspecified) of e1, e2, ė1, ė2, τ1, τ2 over 30 s."""

COLUMNS = ("e1", "e2", "edot1", "edot2", "tau1", "tau2")
UNITS = {
    "rms": ("rad", "rad/s", "N·m"),
    "l2": ("rad·√s", "rad/s·√s", "N·m·√s"),
    "max": ("rad", "rad/s", "N·m"),
}


def _row(metrics: Metrics, kind: str) -> list[float]:
    norms = getattr(metrics, kind)
    return [float(x) for name in ("e", "edot", "tau") for x in getattr(norms, name)]


@dataclass(frozen=True)
class Table2:
    """Metrics of every controller, in the report's order."""

    metrics: dict[str, Metrics]
    """Metrics by controller name."""
    seconds: dict[str, float]
    """Wall-clock time of each run [s]."""

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: our metrics and the report's Table 2."""
        return {
            "controllers": {name: m.as_dict() for name, m in self.metrics.items()},
            "report_table2": {name: list(v) for name, v in REPORT_TABLE2.items()},
            "report_table2_columns": list(COLUMNS),
            "seconds": self.seconds,
        }

    def csv(self) -> str:
        """One row per (controller, norm): the six columns of Table 2."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(["controller", "norm", *COLUMNS])
        for name, m in self.metrics.items():
            for kind in ("rms", "l2", "max"):
                writer.writerow([name, kind, *(f"{x:.6g}" for x in _row(m, kind))])
            writer.writerow(
                [
                    name,
                    "last_period_max_abs_e",
                    *(f"{x:.6g}" for x in m.final_period_max_abs_e),
                    "",
                    "",
                    "",
                    "",
                ]
            )
        for name, values in REPORT_TABLE2.items():
            writer.writerow([name, "report", *values])
        return buffer.getvalue()

    def markdown(self) -> str:
        """Our three norms and the report's Table 2 as Markdown tables."""
        out = []
        for kind, title in (("rms", "RMS over 30 s"), ("l2", "L2 = sqrt(∫x² dt)"), ("max", "max |x|")):
            u = UNITS[kind]
            out.append(f"### {title}\n")
            heads = [f"{s}{j} [{unit}]" for s, unit in zip(("e", "ė", "τ"), u) for j in (1, 2)]
            out.append("| controller | " + " | ".join(heads) + " |")
            out.append("|---|" + "---:|" * 6)
            for name, m in self.metrics.items():
                out.append(f"| {name} | " + " | ".join(f"{x:.4g}" for x in _row(m, kind)) + " |")
            out.append("")
        out.append("### max |e| over the last period [rad]\n")
        out.append("| controller | e1 | e2 |")
        out.append("|---|---:|---:|")
        for name, m in self.metrics.items():
            out.append(f"| {name} | " + " | ".join(f"{x:.3g}" for x in m.final_period_max_abs_e) + " |")
        out.append("")
        out.append("### The report's Table 2 (norm not stated)\n")
        out.append("| controller | θ1 | θ2 | θ̇1 | θ̇2 | τ1 | τ2 |")
        out.append("|---|" + "---:|" * 6)
        for name, values in REPORT_TABLE2.items():
            out.append(f"| {name} | " + " | ".join(f"{x:g}" for x in values) + " |")
        return "\n".join(out) + "\n"


def run_comparison(
    runner: Callable[[str], SimulationResult],
    out_dir: Path | None = None,
    progress: Callable[[int, int, str, float | None], None] | None = None,
    plots: bool = False,
    names: tuple[str, ...] = tuple(CONTROLLERS),
) -> Table2:
    """Run every controller in ``names``; write Table 2 (and figures) into ``out_dir``.

    Args:
        runner: Runs one controller by name and returns its result.
        out_dir: Where ``table2.md``, ``table2.csv``, ``table2.json`` (and figures) go;
            None writes nothing.
        progress: Called as ``progress(i, n, name, seconds)`` before (seconds None) and
            after each run.
        plots: Also write each controller's figures into ``out_dir``.
    """
    metrics: dict[str, Metrics] = {}
    seconds: dict[str, float] = {}
    for i, name in enumerate(names, start=1):
        if progress:
            progress(i, len(names), name, None)
        start = time.perf_counter()
        result = runner(name)
        metrics[name] = compute_metrics(result)
        if plots and out_dir is not None:
            from twolink_pin.plotting import save_simulation_figures

            save_simulation_figures(result, out_dir)
        seconds[name] = time.perf_counter() - start
        if progress:
            progress(i, len(names), name, seconds[name])
    table = Table2(metrics, seconds)
    if out_dir is not None:
        with atomic_write(Path(out_dir) / "table2.md") as f:
            f.write(table.markdown())
        with atomic_write(Path(out_dir) / "table2.csv") as f:
            f.write(table.csv())
        write_json(Path(out_dir) / "table2.json", table.as_dict())
    return table
