"""OpenMP's wait policy (set before Pinocchio loads), the default thread count and its override,
and the batch's progress display."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from twolink_pin import default_trajectory, load_robot, make_scenario, openmp, simulate_batch
from twolink_pin.errors import InvalidParameterError
from twolink_pin.simulation import SimulationConfig, default_threads

PROBE = (
    "import os, sys, warnings\n"
    "warnings.simplefilter('error')\n"
    "{before}\n"
    "import twolink_pin\n"
    "print(os.environ.get('OMP_WAIT_POLICY'), 'pinocchio' in sys.modules)\n"
)


def _probe(before: str = "", **env: str) -> subprocess.CompletedProcess[str]:
    environ = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"} | env
    return subprocess.run(
        [sys.executable, "-c", PROBE.format(before=before)], capture_output=True, text=True, env=environ
    )


def test_importing_the_package_sets_the_passive_wait_policy_before_pinocchio_loads() -> None:
    done = _probe()
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["PASSIVE", "True"]  # set, and pinocchio was loaded after it


def test_a_wait_policy_the_user_chose_is_kept() -> None:
    done = _probe(OMP_WAIT_POLICY="ACTIVE")
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[0] == "ACTIVE"


def test_pinocchio_imported_first_keeps_its_policy_and_the_default_threads_count_spinning() -> None:
    done = _probe("import pinocchio")
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["None", "True"]  # too late to set: left alone, no warning
    check = "from twolink_pin import openmp; print(openmp.passive_wait())"
    environ = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    done = subprocess.run(
        [sys.executable, "-c", "import pinocchio\n" + check], capture_output=True, text=True, env=environ
    )
    assert done.stdout.split() == ["False"], done.stderr


def test_the_thread_override_wins_and_a_bad_one_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(openmp.THREADS_VARIABLE, "3")
    assert default_threads() == 3
    for bad in ("0", "-1", "two", "1.5"):
        monkeypatch.setenv(openmp.THREADS_VARIABLE, bad)
        with pytest.raises(InvalidParameterError, match=f"TWOLINK_PIN_THREADS = '{bad}' is invalid"):
            default_threads()


def test_the_default_is_the_cores_this_process_may_use_less_busy_ones_when_threads_spin(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(openmp.THREADS_VARIABLE, raising=False)
    cores = len(os.sched_getaffinity(0))
    monkeypatch.setattr(openmp, "passive_wait", lambda: True)
    monkeypatch.setattr(os, "getloadavg", lambda: (50.0, 50.0, 50.0))
    assert default_threads() == cores  # sleeping threads take nothing from the others
    monkeypatch.setattr(openmp, "passive_wait", lambda: False)
    assert default_threads() == 1  # spinning threads on a machine that is full
    monkeypatch.setattr(os, "getloadavg", lambda: (1.0, 1.0, 1.0))  # this process alone
    assert default_threads() == cores
    monkeypatch.setattr(os, "getloadavg", lambda: (cores + 0.0, 0.0, 0.0))  # one core taken by others
    assert default_threads() == max(1, cores - 1)


def _batch(progress: object) -> None:
    robot = load_robot()
    controller, plant = make_scenario("pd", robot)
    simulate_batch(
        controller,
        plant,
        default_trajectory(robot),
        SimulationConfig(duration=0.3),
        q0_offsets=np.zeros((3, 2)),
        progress=progress,  # type: ignore[arg-type]
    )


def test_progress_true_shows_a_bar_to_the_last_step_and_false_or_no_terminal_nothing(
    capsys: pytest.CaptureFixture[str],
) -> None:
    seen: list[tuple[int, int]] = []
    _batch(lambda done, total: seen.append((done, total)))
    assert seen[-1] == (300, 300) and [d for d, _ in seen] == sorted(d for d, _ in seen)
    _batch(True)
    err = capsys.readouterr().err
    assert "3 runs" in err and "300/300" in err
    _batch(False)
    _batch(None)  # the default: stderr here is not a terminal
    assert capsys.readouterr().err == ""
