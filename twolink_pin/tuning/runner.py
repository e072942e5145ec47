"""One run of the tuner: a :class:`~twolink_pin.run_spec.RunSpec` simulated and measured,
with what ``simulate --json`` prints of it (the gains it ran with, the metrics, the plant)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller
    from twolink_pin.metrics import Metrics
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.task_metrics import TaskMetrics
    from twolink_pin.trajectory import Trajectory


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


class Runner:
    """Runs requests, one at a time (the tuner's worker thread calls :meth:`__call__`).

    Args:
        arm: ``payload`` [kg] → the robot and its reference (the CLI's loading: ``--robot``,
            ``--trajectory``); called once per payload value.
    """

    def __init__(self, arm: Callable[[float], tuple[RobotModel, Trajectory]]) -> None:
        self._arm = arm
        self._arms: dict[float, tuple[RobotModel, Trajectory]] = {}
        self._law_version = 0

    def arm(self, payload: float) -> tuple[RobotModel, Trajectory]:
        """The robot and reference for ``payload`` [kg] (loaded once per value)."""
        if payload not in self._arms:
            if len(self._arms) > 8:  # a few payloads kept: each is a Pinocchio model
                self._arms.pop(next(iter(self._arms)))
            self._arms[payload] = self._arm(payload)
        return self._arms[payload]

    def __call__(self, request: Request) -> Finished:
        """Simulate ``request``.

        Raises:
            TwolinkPinError: a refused value (the law's message), a diverged run, a law
                that raised, a law file that does not load.
        """
        from twolink_pin.metrics import compute_metrics
        from twolink_pin.run_spec import gains_used, plant_description
        from twolink_pin.simulation import simulate

        if request.law_version != self._law_version and isinstance(request.spec.law, str):
            from twolink_pin.controllers.loading import reload_controller

            self._law_version = request.law_version
            reload_controller(request.spec.law)
        start = time.perf_counter()
        robot, reference = self.arm(request.payload)
        spec = request.spec
        scenario = spec.build(robot, spec.read_parameters(robot))
        result = simulate(*scenario, reference, spec.simulation)
        metrics = compute_metrics(result)
        task = None
        if getattr(scenario.controller, "task_space", False):
            from twolink_pin.task_metrics import task_metrics

            task = task_metrics(result, robot)
        return Finished(
            request,
            robot,
            scenario.controller,
            result,
            metrics,
            task,
            gains_used(scenario.controller),
            plant_description(scenario),
            time.perf_counter() - start,
        )


__all__ = ["Finished", "Request", "Runner"]
