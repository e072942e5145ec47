"""tune shows each finished period of a run in flight (issue 38, items 1 and 5): the runner
publishes the run cut at the end of each reference period but the last, measured by the
final table's definitions; those metrics equal the metrics of a separate ``simulate`` of
that many periods (a second run: the engine's steps do not depend on the duration)."""

from __future__ import annotations

import numpy as np
import pytest

from twolink_pin.metrics import compute_metrics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import Trajectory, default_trajectory
from twolink_pin.tuning.periods import cut_run, period_ends, periods_of
from twolink_pin.tuning.runner import Finished, PeriodDone, Request, Runner

Arm = tuple[RobotModel, Trajectory]
DT = 2e-3
"""A coarser step than the default: the test's runs stay short [s]."""


@pytest.fixture(scope="module")
def arm() -> Arm:
    robot = load_robot("twolink")
    return robot, default_trajectory(robot)


def run_periods(arm: Arm, law: str, periods: int) -> tuple[list[PeriodDone], Finished]:
    """A run of ``periods`` periods of ``law`` through the tuner's runner: its period
    partials and the finished run."""
    reference = arm[1]
    period = float(reference.period)
    shown: list[PeriodDone] = []
    runner = Runner(lambda payload: arm, period_done=shown.append)
    spec = RunSpec(law=law, simulation=SimulationConfig(duration=periods * period, dt=DT))
    return shown, runner(Request(spec, 0.0))


def one_period(arm: Arm, law: str) -> SimulationResult:
    """A separate ``simulate`` of the first period only (the second method)."""
    robot, reference = arm
    spec = RunSpec(law=law, simulation=SimulationConfig(duration=float(reference.period), dt=DT))
    scenario = spec.build(robot, spec.read_parameters(robot))
    return simulate(*scenario, reference, spec.simulation)


def assert_same_metrics(got: object, want: object) -> None:
    """Every field of two :class:`~twolink_pin.metrics.Metrics` (nested tuples: norms,
    crossings with their names) equal to rtol 1e-12 (NaN where never crossed)."""
    for a, b in zip(got, want, strict=True):  # type: ignore[call-overload]
        if isinstance(a, tuple):
            assert_same_metrics(a, b)
        elif isinstance(a, str):
            assert a == b
        else:
            np.testing.assert_allclose(
                np.asarray(a, dtype=float), np.asarray(b, dtype=float), rtol=1e-12, atol=0
            )


def test_the_first_period_of_a_three_period_run_measures_as_a_one_period_simulate(
    arm: Arm,
) -> None:
    """pd on the twolink, 3 periods: two period partials (k = 1, 2 of 3); the first's result is
    the first period of a separate one-period ``simulate`` (same samples) and its metrics are
    ``compute_metrics`` of that run (rtol 1e-12), its "last period" row included; the second
    ends at t = 2 T and is the finished run's first two periods."""
    shown, finished = run_periods(arm, "pd", 3)
    assert [(p.k, p.periods) for p in shown] == [(1, 3), (2, 3)]
    alone = one_period(arm, "pd")
    first = shown[0].done
    assert len(first.result.t) == len(alone.t)
    for name in ("t", "q", "v", "tau_command", "tau", "q_des", "v_des"):
        np.testing.assert_allclose(getattr(first.result, name), getattr(alone, name), rtol=1e-12, atol=1e-12)
    assert_same_metrics(first.metrics, compute_metrics(alone))
    period = float(arm[1].period)
    assert shown[1].done.result.t[-1] == pytest.approx(2 * period)
    cut = cut_run(finished, 2)
    assert cut is not None
    assert_same_metrics(shown[1].done.metrics, cut.metrics)


def test_an_adaptive_laws_estimates_cut_at_a_period_are_a_one_period_runs(arm: Arm) -> None:
    """The law's state (estimates, their true values) laid out as ``simulate`` lays it out."""
    shown, _ = run_periods(arm, "adaptive", 2)
    alone = one_period(arm, "adaptive")
    first = shown[0].done.result
    assert first.p_hat is not None and alone.p_hat is not None
    np.testing.assert_allclose(first.p_hat, alone.p_hat, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(first.p_true, alone.p_true)
    assert first.parameter_names == alone.parameter_names
    assert first.state_names == alone.state_names


def test_period_ends_are_the_samples_at_k_periods_before_the_runs_end() -> None:
    assert period_ends(12.0, 1e-3, 4.0) == [4000, 8000]
    assert period_ends(10.0, 1e-3, 4.0) == [4000, 8000]  # the third period is cut short
    assert period_ends(4.0, 1e-3, 4.0) == []
    assert periods_of(10.0, 4.0) == 3 and periods_of(12.0, 4.0) == 3 and periods_of(1.0, float("inf")) == 0


class Recorded:
    """Stands for the page's status line: keeps every text it is given."""

    def __init__(self) -> None:
        self.texts: list[str] = []

    @property
    def content(self) -> str:
        return self.texts[-1] if self.texts else ""

    @content.setter
    def content(self, text: str) -> None:
        self.texts.append(text)


def test_a_superseded_run_never_shows_its_period_and_the_newer_runs_periods_show(arm: Arm) -> None:
    """Run 1's law waits at t = 4.01 s, in the block of samples that ends its first period,
    until run 2 has been asked for: run 1's first period is never shown (it is cancelled at
    the end of that block); run 2's is, before run 2's complete line."""
    import queue
    import threading

    from twolink_pin.controllers.pd import PDFeedforward
    from twolink_pin.tuning import Tuner

    blocked, release = threading.Event(), threading.Event()

    class WaitingPD(PDFeedforward):
        def compute(self, x, terms):
            if float(np.max(x.t)) >= 4.01 and not blocked.is_set():
                blocked.set()
                assert release.wait(60.0)
            return super().compute(x, terms)

    lines: queue.Queue[dict[str, object]] = queue.Queue()
    tuner = Tuner(
        RunSpec(law=WaitingPD, simulation=SimulationConfig(duration=8.0, dt=DT)),
        0.0,
        lambda payload: arm,
        lambda spec, payload: "twolink-pin simulate …",
        lambda spec, payload: {},
        lines.put,
    )
    status = Recorded()
    tuner.status = status
    try:
        assert blocked.wait(60.0)
        tuner.panel.sliders[-1].value = 1.5  # kd × (all)
        tuner.changed()
        release.set()
        line = lines.get(timeout=60.0)
        assert tuner.session.idle(60.0)
    finally:
        tuner.close()
    assert line["run"] == 2 and tuner.session.cancelled == 1
    assert not [text for text in status.texts if text.startswith("run 1")]
    shown = [i for i, text in enumerate(status.texts) if text.startswith("run 2: period 1 of 2 shown")]
    done = [i for i, text in enumerate(status.texts) if text.startswith("run 2: 8 s simulated")]
    assert shown and done and shown[0] < done[0]
