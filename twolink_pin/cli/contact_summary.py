"""What the commands say and draw of a run against a scene: its contact metrics (one definition,
:mod:`twolink_pin.contact_metrics`) and the contact figure (:mod:`twolink_pin.plotting.contact`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from twolink_pin.contact_metrics import ContactMetrics
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationResult

CONTACT_FIGURE = "contact.png"
"""The contact figure's file name (``compare``: every law's run drawn together)."""


def contact_lines(metrics: ContactMetrics | None) -> list[str]:
    """The summary's lines for ``metrics`` (none for None: a run without a scene)."""
    if metrics is None:
        return []
    from twolink_pin.contact_metrics import SETTLE

    rms, worst, peak, touching, depth, along, first = metrics.text()
    return [
        f"  contact first at {first} s, {touching} s in contact, peak impact force {peak} N, "
        f"max penetration {depth} mm",
        f"  contact force error RMS {rms} N   max {worst} N (from {SETTLE:g} s after the first contact); "
        f"position error along the surface RMS {along} mm",
    ]


def contact_summary(result: SimulationResult, robot: RobotModel) -> tuple[dict[str, Any] | None, list[str]]:
    """``simulate``'s contact metrics of ``result`` as JSON-ready data and as lines (None and no
    lines for a run without a scene)."""
    from twolink_pin.contact_metrics import contact_metrics

    metrics = contact_metrics(result, robot)
    return (None if metrics is None else metrics.as_dict()), contact_lines(metrics)


def save_run_contact_figure(
    result: SimulationResult, robot: RobotModel, folder: Path, prefix: str
) -> list[str]:
    """``<prefix>_contact.png`` in ``folder`` for a run against a scene (none otherwise)."""
    if result.wrench is None:
        return []
    from twolink_pin.plotting.contact import save_contact_figure

    name = f"{prefix}_{CONTACT_FIGURE}" if prefix else CONTACT_FIGURE
    return [str(save_contact_figure({result.controller: result}, robot, Path(folder) / name))]


class ContactRuns:
    """``compare``'s runs against a scene: their metrics by row, and the figure of them all."""

    def __init__(self, robot: RobotModel) -> None:
        self.robot = robot
        self.metrics: dict[str, ContactMetrics] = {}
        self.results: dict[str, SimulationResult] = {}

    def add(self, key: str, result: SimulationResult) -> None:
        """Row ``key``'s run: its contact metrics kept (nothing without a scene)."""
        from twolink_pin.contact_metrics import contact_metrics

        metrics = contact_metrics(result, self.robot)
        if metrics is not None:
            self.metrics[key] = metrics
            self.results[key] = result

    def figure(self, folder: Path, on: bool) -> None:
        """``contact.png`` in ``folder``: every run against the scene drawn together (``on``)."""
        if on and self.results:
            from twolink_pin.plotting.contact import save_contact_figure

            save_contact_figure(self.results, self.robot, Path(folder) / CONTACT_FIGURE)
