"""One run of the tuner: a :class:`~twolink_pin.run_spec.RunSpec` simulated and measured,
with what ``simulate --json`` prints of it (the gains it ran with, the metrics, the plant).

While it runs, after every block of samples the engine writes
(:func:`~twolink_pin.simulation.deadline.watched`), the runner asks whether the run is still
wanted (else it stops with :class:`~twolink_pin.simulation.deadline.RunCancelled`) and, once
the run has taken ``stream_after`` seconds, publishes the part simulated so far
(:class:`Partial`) at most every ``stream_period`` seconds. As soon as the simulated time
passes the end of a reference period k (k = 1 … P − 1 of a P-period run), it publishes the
run cut there (:class:`PeriodDone`: a :class:`Finished` of the first k periods, measured by
the final table's definitions, :mod:`twolink_pin.tuning.periods`) without waiting."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.errors import TwolinkPinError
from twolink_pin.simulation.deadline import RunCancelled, watched
from twolink_pin.tuning.outcomes import Finished, Partial, PeriodDone, Request

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.trajectory import Trajectory


_FIELDS = ("t", "q", "v", "z", "tau_command", "q_des", "v_des", "a_des")
"""The fields of the engine's blocks a period's result is made of."""


class _Stream:
    """The blocks of one run gathered (copies), published as :class:`Partial` when due and as
    :class:`PeriodDone` at the end of each period."""

    def __init__(
        self, runner: Runner, request: Request, scenario: Any, reference: Trajectory, start: float
    ) -> None:
        from twolink_pin.tuning.periods import period_ends, periods_of

        self.runner, self.request, self.scenario, self.reference = runner, request, scenario, reference
        self.limits = np.asarray(scenario.plant.limits, dtype=float)
        config = request.spec.simulation
        ends = period_ends(config.duration, config.duration / config.steps, float(reference.period))
        self.ends = list(enumerate(ends, 1))  # (k, index of the sample ending period k) still to come
        self.periods = periods_of(config.duration, float(reference.period))
        self.blocks: dict[str, list[np.ndarray]] = {name: [] for name in _FIELDS}
        self.start, self.last = start, -math.inf

    def __call__(self, block: Any) -> None:
        runner = self.runner
        runner.alive()
        if runner.cancelled():
            raise RunCancelled(f"run of {self.request.spec.law} superseded")
        periods = runner.period_done is not None and bool(self.ends)
        if runner.partial is None and not periods:
            return
        for name, column in self.blocks.items():
            x = getattr(block, name)
            column.append(np.array(x if name == "t" else x[:, 0, :]))
        written = block.start + len(block.t)
        passed = [(k, end) for k, end in self.ends if end < written]
        if periods and passed:  # the latest period ended in this block: shown at once
            self.ends = self.ends[len(passed) :]
            self._period(*passed[-1])
            return
        now = time.perf_counter()
        if (
            runner.partial is None
            or now - self.start < runner.stream_after
            or now - self.last < runner.stream_period
        ):
            return
        self.last = now
        t, q, q_des, tau = (np.concatenate(self.blocks[x]) for x in ("t", "q", "q_des", "tau_command"))
        runner.partial(
            Partial(self.request, t, q, q_des, tau, self.limits, self.request.spec.simulation.duration)
        )

    def _period(self, k: int, end: int) -> None:
        """Publish the run's first ``k`` periods (samples ``0 … end``), measured as the final run."""
        from twolink_pin.tuning.periods import result_of

        for name, column in self.blocks.items():  # one array per field from now on
            self.blocks[name] = [np.concatenate(column)]
        samples = {name: column[0][: end + 1] for name, column in self.blocks.items()}
        controller, plant = self.scenario.controller, self.scenario.plant
        try:
            result = result_of(controller, plant, self.reference, self.request.spec.simulation, samples)
            done = self.runner.measure(self.request, self.scenario, result, self.start)
        except TwolinkPinError:  # a non-finite sample (diverging): the final run says what happened
            return
        assert self.runner.period_done is not None
        self.runner.period_done(PeriodDone(done, k, self.periods))


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
        period_done: Called with the run cut at the end of each reference period but the last
            (:class:`PeriodDone`), on the run's thread, as soon as the period is simulated.
    """

    def __init__(
        self,
        arm: Callable[[float], tuple[RobotModel, Trajectory]],
        cancelled: Callable[[], bool] = lambda: False,
        partial: Callable[[Partial], None] | None = None,
        stream_after: float = 2.0,
        stream_period: float = 0.5,
        alive: Callable[[], None] = lambda: None,
        period_done: Callable[[PeriodDone], None] | None = None,
    ) -> None:
        self._arm = arm
        self.cancelled, self.partial, self.alive = cancelled, partial, alive
        self.period_done = period_done
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
        from twolink_pin.simulation import simulate

        if request.law_version != self._law_version and isinstance(request.spec.law, str):
            from twolink_pin.controllers.loading import reload_controller

            self._law_version = request.law_version
            reload_controller(request.spec.law)
        start = time.perf_counter()
        robot, reference = self.arm(request.payload)
        spec = request.spec
        scenario = spec.build(robot, spec.read_parameters(robot))
        with watched(_Stream(self, request, scenario, reference, start)):
            result = simulate(*scenario, reference, spec.simulation)
        return self.measure(request, scenario, result, start)

    def measure(self, request: Request, scenario: Any, result: SimulationResult, start: float) -> Finished:
        """``result`` (of ``scenario``, built for ``request``) with its metrics: the run
        :meth:`__call__` finished, or its first periods; ``start``: when the run started
        (``time.perf_counter``)."""
        from twolink_pin.metrics import compute_metrics
        from twolink_pin.run_spec import gains_used, plant_description

        robot, _ = self.arm(request.payload)
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


__all__ = ["Finished", "Partial", "PeriodDone", "Request", "Runner"]
