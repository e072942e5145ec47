"""A run's first k reference periods as a run of their own, so the page can show each
finished period of a run in flight (issue 38, items 1 and 5) with the metrics of the final
table: :func:`~twolink_pin.metrics.compute_metrics` (and
:func:`~twolink_pin.task_metrics.task_metrics`) of a :class:`~twolink_pin.simulation.SimulationResult`
holding samples ``0 … K_k`` only, ``K_k = round(k T / dt)`` (``t = k T``: the end of period k).

* :func:`period_ends` — where periods 1 … P − 1 of a run end (sample indices);
* :func:`result_of` — the samples written so far by the engine (blocks of one run) as a
  result, laid out as ``simulate`` lays out its own;
* :func:`cut_run` — a finished run (previous, defaults, kept) cut to its first k periods, so
  that every column of the table covers the same periods.

Cut to k periods, a run's metrics are those of a run of k periods: the engine's steps do not
depend on the duration asked (RK4 at a fixed ``dt``), so the samples ``0 … K_k`` of a longer
run are those of the shorter run (tests/test_tune_periods.py checks it against ``simulate``)."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.arrays import readonly

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller
    from twolink_pin.plant import Plant
    from twolink_pin.simulation import SimulationConfig, SimulationResult
    from twolink_pin.trajectory import Trajectory
    from twolink_pin.tuning.outcomes import Finished

PER_SAMPLE = (
    *("t", "q", "v", "tau_command", "tau", "q_des", "v_des", "a_des"),
    *("p_hat", "state", "q_measured", "v_measured"),
)
"""The fields of a :class:`~twolink_pin.simulation.SimulationResult` with one row per sample."""


def periods_of(duration: float, period: float) -> int:
    """How many periods (the last one possibly partial) a run of ``duration`` [s] holds of a
    reference of ``period`` [s]; 0 for a reference without a finite period."""
    if not (math.isfinite(period) and period > 0.0):
        return 0
    return max(1, math.ceil(duration / period - 1e-9))


def period_ends(duration: float, dt: float, period: float) -> list[int]:
    """Sample index ``K_k = round(k T / dt)`` of the end of each period k = 1, 2, … that ends
    before the run does (at least one step earlier), for a run of ``duration`` [s] sampled
    every ``dt`` [s] of a reference of ``period`` ``T`` [s]."""
    ends = []
    for k in range(1, periods_of(duration, period)):
        end = round(k * period / dt)
        if end * dt < duration - 0.5 * dt:
            ends.append(end)
    return ends


def result_of(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    blocks: dict[str, np.ndarray],
) -> SimulationResult:
    """The samples ``blocks`` (the engine's :class:`~twolink_pin.simulation.engine.Samples`
    fields of one run, each (K, ·), from sample 0) of the run ``simulate(controller, plant,
    trajectory, config)`` as the result ``simulate`` makes of them
    (:func:`~twolink_pin.simulation.run.run_result`)."""
    from twolink_pin.simulation.run import run_result

    return run_result(controller, plant, trajectory, config, blocks)


def first_samples(result: SimulationResult, count: int) -> SimulationResult:
    """``result`` with its first ``count`` samples only (the same run, stopped there)."""
    cut: dict[str, Any] = {}
    for name in PER_SAMPLE:
        value = getattr(result, name)
        if value is not None:
            cut[name] = readonly(np.array(value[:count]))
    return dataclasses.replace(result, **cut)


def measured(done: Finished, result: SimulationResult) -> Finished:
    """``done`` with ``result`` in place of its own and the metrics (and task metrics) of it."""
    from twolink_pin.metrics import compute_metrics

    task = None
    if done.task is not None:
        from twolink_pin.task_metrics import task_metrics

        task = task_metrics(result, done.robot)
    return done._replace(result=result, metrics=compute_metrics(result), task=task)


def cut_run(done: Finished | None, k: int) -> Finished | None:
    """``done`` cut to its first ``k`` reference periods (``t ≤ k T``), measured again; the run
    itself when it holds no more; None when it holds fewer (or ``done`` is None)."""
    if done is None:
        return None
    result = done.result
    end = round(k * result.reference_period / result.dt) if result.reference_period > 0 else -1
    if end < 0 or end + 1 > len(result.t):
        return None
    if end + 1 == len(result.t):
        return done
    return measured(done, first_samples(result, end + 1))


class Cuts:
    """:func:`cut_run` of the runs shown beside the one in flight, kept: the same runs are cut
    again at each period of each new run."""

    def __init__(self, size: int = 12) -> None:
        self.size = size
        self.kept: list[tuple[Finished, int, Finished | None]] = []

    def __call__(self, done: Finished | None, k: int) -> Finished | None:
        """``cut_run(done, k)``, computed once per run (by identity) and ``k``."""
        if done is None:
            return None
        for run, periods, cut in self.kept:
            if run is done and periods == k:
                return cut
        cut = cut_run(done, k)
        self.kept = [*self.kept[-(self.size - 1) :], (done, k, cut)]
        return cut


def heading(k: int, periods: int, seconds: float) -> str:
    """The line above the metrics of a run shown up to the end of its period ``k`` of
    ``periods``, at ``seconds`` [s] simulated (plain text)."""
    span = "period 1" if k == 1 else f"periods 1–{k}"
    return f"over {span} of {periods} (t ≤ {seconds:g} s: every column, and the plots)"


__all__ = [
    "Cuts",
    "cut_run",
    "first_samples",
    "heading",
    "measured",
    "period_ends",
    "periods_of",
    "result_of",
]
