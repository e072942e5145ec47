"""One run of the tuner: a :class:`~twolink_pin.run_spec.RunSpec` simulated and measured,
with what ``simulate --json`` prints of it (the gains it ran with, the metrics, the plant).

While it runs, after every block of samples the engine writes
(:func:`~twolink_pin.simulation.deadline.watched`), the runner asks whether the run is still
wanted (else it stops with :class:`~twolink_pin.simulation.deadline.RunCancelled`) and, once
the run has taken ``stream_after`` seconds, publishes the part simulated so far
(:class:`Partial`) at most every ``stream_period`` seconds."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from twolink_pin.simulation.deadline import RunCancelled, watched

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


class _Stream:
    """The blocks of one run gathered (copies), published as :class:`Partial` when due."""

    def __init__(self, runner: Runner, request: Request, limits: np.ndarray) -> None:
        self.runner, self.request, self.limits = runner, request, limits
        self.blocks: list[tuple[np.ndarray, ...]] = []
        self.start, self.last = time.perf_counter(), -math.inf

    def __call__(self, block: Any) -> None:
        runner = self.runner
        runner.alive()
        if runner.cancelled():
            raise RunCancelled(f"run of {self.request.spec.law} superseded")
        if runner.partial is None:
            return
        columns = (np.array(x[:, 0, :]) for x in (block.q, block.q_des, block.tau_command))
        self.blocks.append((np.array(block.t), *columns))
        now = time.perf_counter()
        if now - self.start < runner.stream_after or now - self.last < runner.stream_period:
            return
        self.last = now
        t, q, q_des, tau = (np.concatenate(x) for x in zip(*self.blocks, strict=True))
        runner.partial(
            Partial(self.request, t, q, q_des, tau, self.limits, self.request.spec.simulation.duration)
        )


class Runner:
    """Runs requests, one at a time (the tuner's worker thread calls :meth:`__call__`).

    Args:
        arm: ``payload`` [kg] → the robot and its reference (the CLI's loading: ``--robot``,
            ``--trajectory``); called once per payload value.
        cancelled: Asked after every block: True stops the run (:class:`RunCancelled`).
        partial: Called with the part simulated so far (:class:`Partial`), on the run's thread.
        stream_after: A run publishes partial results once it has taken this long [s].
        stream_period: At most one partial result per this many seconds [s].
        alive: Called after every block: the run makes progress.
    """

    def __init__(
        self,
        arm: Callable[[float], tuple[RobotModel, Trajectory]],
        cancelled: Callable[[], bool] = lambda: False,
        partial: Callable[[Partial], None] | None = None,
        stream_after: float = 1.0,
        stream_period: float = 0.5,
        alive: Callable[[], None] = lambda: None,
    ) -> None:
        self._arm = arm
        self.cancelled, self.partial, self.alive = cancelled, partial, alive
        self.stream_after, self.stream_period = stream_after, stream_period
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
            RunCancelled: ``cancelled()`` said so after a block.
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
        stream = _Stream(self, request, np.asarray(scenario.plant.limits, dtype=float))
        with watched(stream):
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


__all__ = ["Finished", "Partial", "Request", "Runner"]
