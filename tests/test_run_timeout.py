"""``--timeout`` bounds each simulation (twolink_pin.simulation.deadline), not the command.

The laws here loop forever (no finite sleep): the bound itself is the only signal, so the
tests do not depend on the machine's speed.
"""

from __future__ import annotations

import gc
import json
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest_sim import ROBOT, TRAJECTORY

from twolink_pin.cli import main
from twolink_pin.controllers import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains
from twolink_pin.errors import ControllerError
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.deadline import RunTimeout, bounded, per_run_limit

SPINNER = Path(__file__).parent / "corpus" / "laws" / "misbehaving.py"


class SpinsAtStep(Controller, register=False):
    """PD until the simulated time passes ``t_stop``, then a busy loop that never ends (and
    swallows ``Exception``, as careless user code does)."""

    name = "test-spins-later"
    title = "spins later"
    Gains = Gains
    t_stop = 0.02

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        while x.t >= self.t_stop:
            try:
                pass
            except Exception:  # the point: it cannot swallow the bound
                pass
        return LawOutput(-100.0 * (x.q - x.q_des) - 20.0 * (x.v - x.v_des))


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_a_law_that_never_returns_is_stopped_naming_the_law_and_the_bound(method: str) -> None:
    law = SpinsAtStep(ROBOT)
    config = SimulationConfig(duration=0.1, method=method)
    previous = signal.getsignal(signal.SIGALRM)
    with per_run_limit(1.0), pytest.raises(ControllerError) as caught:
        simulate(law, Plant(ROBOT), TRAJECTORY, config)
    message = str(caught.value)
    assert "test-spins-later" in message and "SpinsAtStep" in message and "--timeout 1 s" in message
    assert caught.value.time >= SpinsAtStep.t_stop  # stopped where it spins, not before
    # the timer is disarmed and the handler restored: the next run is not cut short
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0
    assert signal.getsignal(signal.SIGALRM) is previous
    with per_run_limit(60.0):  # a bound again, but one a busy machine cannot reach in 0.1 s of PD
        plain = simulate(make_scenario("pd", ROBOT).controller, Plant(ROBOT), TRAJECTORY, config)
    assert plain.t[-1] == pytest.approx(0.1)


def test_without_a_bound_nothing_is_armed() -> None:
    with per_run_limit(None):
        simulate(
            make_scenario("pd", ROBOT).controller, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.01)
        )
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0


def test_compare_stops_the_run_that_never_returns_and_keeps_the_others(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "c"
    argv = ["compare", "pd", f"{SPINNER}:Spinner", "computed-torque", "--duration", "0.05"]
    code = main([*argv, "--timeout", "1", "--no-plot", "--out", str(out)])
    assert code == 1
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip() and not x.startswith("compare:")]
    assert len(err) == 1 and "--timeout 1 s" in err[0] and "Spinner" in err[0] and "Traceback" not in err[0]
    table = json.loads((out / "comparison.json").read_text())
    assert set(table["failed"]) == {"corpus-spinner"} and "--timeout 1 s" in table["failed"]["corpus-spinner"]
    # the two laws around it ran to the end: their rows equal the runs made alone
    assert set(table["controllers"]) == {"pd", "computed-torque"}
    for name in ("pd", "computed-torque"):
        alone = simulate(
            make_scenario(name, ROBOT).controller, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.05)
        )
        e = np.asarray(alone.q) - np.asarray(alone.q_des)
        np.testing.assert_allclose(table["controllers"][name]["max"]["e"], np.abs(e).max(axis=0), rtol=1e-12)


def test_a_sweep_on_dask_workers_stops_the_chunk_that_never_returns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A worker runs its task in a thread (no signal reaches it): the client bounds the chunk,
    names the law and the bound, kills the LocalCluster's workers and writes nothing. The law
    sleeps a day, so only the bound can end the run (no dependence on the machine's speed)."""
    pytest.importorskip("distributed")
    out = tmp_path / "s"
    argv = ["sweep", f"{SPINNER}:Sleeper", "--samples", "4", "--duration", "0.05", "--workers", "1"]
    code = main([*argv, "--timeout", "2", "--no-plot", "--out", str(out)])
    assert code == 1
    err = [x for x in capsys.readouterr().err.splitlines() if x.startswith("twolink-pin")]
    assert len(err) == 1, err
    assert "corpus-sleeper" in err[0] and "Sleeper" in err[0] and "--timeout 2 s" in err[0]
    assert "runs 0–3" in err[0] and "Dask worker" in err[0] and "workers were stopped" in err[0]
    assert not out.exists()


@pytest.mark.parametrize("seconds", [1e-9, 1e-6, 1e-4])
def test_a_bound_that_fires_while_it_is_armed_gives_the_same_error(seconds: float) -> None:
    """A bound of 1e-9 s fires before the guarded block starts (inside ``setitimer``): the same
    ControllerError naming the law and the bound as a large one, never a bare RunTimeout, and
    SIGALRM's handler is restored afterwards."""
    handler = signal.getsignal(signal.SIGALRM)
    controller, plant = make_scenario("pd", ROBOT)
    for _ in range(20):
        with per_run_limit(seconds), pytest.raises(ControllerError, match=r"within --timeout .* s"):
            simulate(controller, plant, TRAJECTORY, SimulationConfig(duration=60.0))
        assert signal.getsignal(signal.SIGALRM) is handler
        assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_alarm_swallowed_inside_a_gc_callback_still_ends_the_block() -> None:
    """Python drops an exception raised inside a gc callback (hypothesis and distributed install
    such callbacks): the alarm that fires there fires again, so the block still ends with the
    bound's error instead of running on unbounded. The callback spins (Python code, so the
    signal is handled inside it) for much longer than the bound."""

    def spin(phase: str, info: dict) -> None:
        if phase == "start":
            end = time.monotonic() + 0.5
            while time.monotonic() < end:
                pass

    dropped: list[type[BaseException] | None] = []
    # Python hands the dropped exception to sys.unraisablehook. pytest's own hook imports
    # tracemalloc the first time, and the alarm firing again during that import broke the hook
    # ("Failed to process unraisable exception", once on a busy machine): this test's hook
    # only records what was dropped.
    hook, sys.unraisablehook = sys.unraisablehook, lambda u: dropped.append(u.exc_type)
    gc.callbacks.append(spin)
    try:
        with pytest.raises(RunTimeout), per_run_limit(0.02), bounded():
            gc.collect()  # the alarm fires inside spin and is dropped
            gc.callbacks.remove(spin)
            for _ in range(600_000):  # the only way out in time is the alarm firing again
                time.sleep(1e-4)
    finally:
        sys.unraisablehook = hook
        if spin in gc.callbacks:
            gc.callbacks.remove(spin)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert RunTimeout in dropped, dropped  # the first alarm was indeed swallowed in the callback
