"""What the tuner asks of one run and what it gets back: :class:`Request`, :class:`Finished`,
:class:`Partial` (the part simulated so far) and :class:`PeriodDone` (a finished period of a run
in flight). :mod:`~twolink_pin.tuning.runner` makes them, :mod:`~twolink_pin.tuning.periods`
measures them, the page shows them."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller
    from twolink_pin.metrics import Metrics
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.task_metrics import TaskMetrics


class Request(NamedTuple):
    """What one run is asked for."""

    spec: RunSpec
    """The run (law, gains, plant, simulation settings)."""
    payload: float
    """Point mass at the end effector [kg] (a robot option: the arm is loaded with it)."""
    law_version: int = 0
    """Bumped when the law's file changed (``--watch``): the law is read again first."""


class Finished(NamedTuple):
    """A run that ended (the tuner shows it and prints its JSON line)."""

    request: Request
    robot: RobotModel
    controller: Controller
    result: SimulationResult
    metrics: Metrics
    task: TaskMetrics | None
    """Task-space metrics (mm, deg) of a task-space law, else None."""
    gains: dict[str, Any]
    """The gains the law ran with (:func:`~twolink_pin.run_spec.gains_used`)."""
    plant: str
    """Which plant (:func:`~twolink_pin.run_spec.plant_description`)."""
    seconds: float
    """Wall-clock time of the run [s]."""


class Partial(NamedTuple):
    """The part of a run in flight simulated so far (samples 0 … k − 1 of its result)."""

    request: Request
    t: np.ndarray
    """Times [s], (k,)."""
    q: np.ndarray
    """Joint positions [rad], (k, nv)."""
    q_des: np.ndarray
    """Reference [rad], (k, nv)."""
    tau_command: np.ndarray
    """The law's torques [N·m], (k, nv)."""
    torque_limits: np.ndarray
    """The plant's effort limits [N·m], (nv,)."""
    duration: float
    """The whole run's duration [s]."""


class PeriodDone(NamedTuple):
    """A run in flight shown up to the end of its reference period ``k`` of ``periods``."""

    done: Finished
    """The run's first k periods as a run of their own (samples ``0 … round(k T / dt)``), its
    metrics those of the final table; ``seconds``: the wall-clock time so far [s]."""
    k: int
    """The periods simulated (1 … periods − 1)."""
    periods: int
    """The periods of the whole run."""


__all__ = ["Finished", "Partial", "PeriodDone", "Request"]
