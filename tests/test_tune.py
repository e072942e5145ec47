"""``tune`` without a browser: the latest-wins session, the controls read from a law's
``Gains`` declaration, and the ``simulate`` line that reproduces a run."""

from __future__ import annotations

import math
import threading

import pytest

from twolink_pin.cli.commands.common import run_spec
from twolink_pin.cli.parser import build_parser
from twolink_pin.cli.simulate_line import command_line, simulate_argv
from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench
from twolink_pin.run_spec import PlantOptions, RunSpec
from twolink_pin.simulation import SimulationConfig
from twolink_pin.tuning import LatestWins, gains_from, knobs_of

WAIT = 60.0
"""Bound on every wait [s]: a failure, never a pass, when it runs out."""


def test_a_burst_of_requests_runs_the_first_and_the_last_and_delivers_the_last_only() -> None:
    """Requests 2, 3, 4 arrive while 1 runs: 2 and 3 never start (superseded while waiting),
    1's outcome is stale (4 is newer) and dropped, 4's is delivered."""
    started, release = threading.Event(), threading.Event()
    delivered: list[tuple[int, int, object]] = []
    done = threading.Event()

    def work(x: int) -> int:
        if x == 1:
            started.set()
            assert release.wait(WAIT)
        return 10 * x

    def deliver(generation: int, request: int, outcome: object) -> None:
        delivered.append((generation, request, outcome))
        done.set()

    session: LatestWins[int, int] = LatestWins(work, deliver)
    try:
        session.submit(1)
        assert started.wait(WAIT)
        for x in (2, 3, 4):
            session.submit(x)
        release.set()
        assert done.wait(WAIT)
        assert session.idle(WAIT)
        assert delivered == [(4, 4, 40)]
        assert session.runs == 2
    finally:
        session.close()


def test_a_failed_run_is_delivered_as_its_exception_and_the_next_run_still_runs() -> None:
    outcomes: list[object] = []
    ready = threading.Semaphore(0)

    def work(x: int) -> float:
        return 1.0 / x

    def deliver(generation: int, request: int, outcome: object) -> None:
        outcomes.append(outcome)
        ready.release()

    session: LatestWins[int, float] = LatestWins(work, deliver)
    try:
        session.submit(0)
        assert ready.acquire(timeout=WAIT)
        session.submit(4)
        assert ready.acquire(timeout=WAIT)
        assert isinstance(outcomes[0], ZeroDivisionError)
        assert outcomes[1] == 0.25
    finally:
        session.close()


def _parsed(argv: list[str]) -> RunSpec:
    args = build_parser().parse_args(argv)
    return run_spec(args, args.controller)


@pytest.mark.parametrize(
    "spec",
    [
        RunSpec(law="pd", gains=(("kp", (0.1 + 0.2, 1 / 3)), ("kd", 7e-5)), simulation=SimulationConfig(4.0)),
        RunSpec(
            law="computed-torque",
            gains=(("k", (math.pi, math.e)),),
            lam=2 / 3,
            plant=PlantOptions(
                friction="on",
                saturate=True,
                friction_smoothing=1e-3,
                wrench=Wrench((-20.0, 0.1, 0.0), 1.0, 1.25),
                payload_step=PayloadStep(0.3, 2.0),
                sensor_noise=SensorNoise(1e-4, 1e-3, seed=7),
                delay=2,
            ),
            simulation=SimulationConfig(
                duration=2.5, dt=5e-4, q0_offset=(-0.1, 1 / 7), control_period=1e-3, method="rk4"
            ),
        ),
        RunSpec(
            law="pd",
            plant=PlantOptions(wrench=Wrench((0.0, -5.0, 0.0, 0.0, 0.0, 0.5), 0.5)),  # until the end
            simulation=SimulationConfig(duration=1.0, method="adaptive", q0_offset=-0.05),
        ),
        RunSpec(  # a gain that is a word (mpc's choices) is written as the word
            law="mpc", gains=(("horizon", 0.2), ("reference_ahead", "extrapolate"), ("on_infeasible", "fail"))
        ),
    ],
)
def test_the_simulate_line_parses_back_to_the_same_run(spec: RunSpec) -> None:
    """Every number as repr prints it: the parsed run equals the run, float for float."""
    argv = simulate_argv(spec)
    assert _parsed(argv) == spec
    assert command_line(argv).startswith("twolink-pin simulate ")


def test_the_simulate_line_carries_the_robot_payload_and_trajectory() -> None:
    argv = simulate_argv(
        RunSpec(law="pd"), robot="ur5", payload=0.1 + 0.2, trajectory="examples/ur5_square.toml"
    )
    args = build_parser().parse_args(argv)
    assert (args.robot, args.payload, args.trajectory) == ("ur5", 0.1 + 0.2, "examples/ur5_square.toml")


def test_a_quoted_line_keeps_a_path_with_spaces() -> None:
    import shlex

    line = command_line(simulate_argv(RunSpec(law="my laws/law.py:Law")))
    assert shlex.split(line)[2] == "my laws/law.py:Law"


def test_controls_follow_the_gains_declaration() -> None:
    """pd on the twolink: kp and kd per joint (the report's values), each with a scale; the
    labels carry the names ``twolink-pin controllers`` prints and the units; the defaults
    give back the gains exactly and a scale multiplies every joint's value."""
    from twolink_pin.controllers import CONTROLLERS

    gains = {"kp": [350.0, 300.0], "kd": [40.0, 50.0]}
    knobs = knobs_of(CONTROLLERS["pd"].Gains, gains)
    assert [k.label for k in knobs] == [
        "kp joint 1 [N·m/rad]",
        "kp joint 2 [N·m/rad]",
        "kp × (all)",
        "kd joint 1 [N·m·s/rad]",
        "kd joint 2 [N·m·s/rad]",
        "kd × (all)",
    ]
    # the range: 0 … 4 × the default; the first step: to the log grid's next value (350 → 400, 300 → 350)
    assert [(k.low, k.high, k.step) for k in knobs[:2]] == [(0.0, 1400.0, 50.0), (0.0, 1200.0, 50.0)]
    assert {k.rule.kind for k in knobs} == {"log"}
    assert gains_from(knobs, {}) == {"kp": (350.0, 300.0), "kd": (40.0, 50.0)}
    assert gains_from(knobs, {2: 0.5, 3: 41.0}) == {"kp": (175.0, 150.0), "kd": (41.0, 50.0)}


def test_a_scalar_gain_is_one_control_and_a_signed_one_ranges_both_ways() -> None:
    from dataclasses import dataclass
    from typing import Any

    from twolink_pin import Gains, gain

    @dataclass(frozen=True, eq=False)
    class G(Gains):
        lam: Any = gain(5.0, unit="1/s")
        bias: Any = gain(-2.0, bound="any", unit="N·m")

    knobs = knobs_of(G, {"lam": 5.0, "bias": -2.0})
    assert [(k.label, k.low, k.high, k.step, k.rule.kind) for k in knobs] == [
        ("lam [1/s]", 0.0, 20.0, 0.5, "log"),  # 5 → 5.5: the grid's next value
        ("bias [N·m]", -8.0, 8.0, 0.1, "linear"),  # a signed gain: a twentieth of its default
    ]


def test_a_matrix_gain_is_its_diagonal_and_a_scale() -> None:
    from twolink_pin.controllers import CONTROLLERS

    k = [[[300.0, 0.0, 0.0], [0.0, 200.0, 0.0], [0.0, 0.0, 100.0]]]
    knobs = knobs_of(CONTROLLERS["impedance"].Gains, {"k": k})
    assert [kn.label for kn in knobs] == ["k axis x [N/m]", "k axis y [N/m]", "k axis z [N/m]", "k × (all)"]
    assert gains_from(knobs, {3: 2.0}) == {"k": (600.0, 400.0, 200.0)}


def test_a_refused_gain_on_the_command_line_is_one_line_and_exit_2_before_serving() -> None:
    import subprocess
    import sys

    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "twolink_pin_entry",
            "tune",
            "pd",
            "--gain",
            "kp=-1",
            "--no-browser",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 2
    assert done.stdout == ""  # no URL: nothing was served
    assert done.stderr.strip().splitlines() == [
        "twolink-pin: error: kp = -1.0 is invalid: expected a symmetric positive-definite matrix gain "
        "[N·m/rad]: a number s (s I), k numbers (a diagonal), k² numbers (a (k, k) matrix, row by row), "
        "a (k, k) matrix, or one (k, k) matrix per run (N, k, k)"
    ]


def test_the_tuner_runs_a_changed_gain_and_its_line_reproduces_the_run() -> None:
    """In-process, no browser: the tuner's first run, then kd × 1.5; the second line carries
    the new gains, and the run its command line describes (parsed as the CLI does) has the
    same metrics, float for float."""
    import queue
    import shlex

    from twolink_pin.cli.output import jsonable
    from twolink_pin.metrics import compute_metrics
    from twolink_pin.model import load_robot
    from twolink_pin.simulation import simulate
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.tuning import Tuner

    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    lines: queue.Queue[dict[str, object]] = queue.Queue()
    tuner = Tuner(
        RunSpec(law="pd", simulation=SimulationConfig(duration=0.3)),
        0.0,
        lambda payload: (robot, reference),
        lambda spec, payload: command_line(simulate_argv(spec, None, payload)),
        lambda spec, payload: {},
        lines.put,
    )
    try:
        first = lines.get(timeout=WAIT)
        assert first["gains"] == {"kp": [350.0, 300.0], "kd": [40.0, 50.0]}
        tuner.panel.sliders[-1].value = 1.5  # kd × (all)
        tuner.changed()
        line = lines.get(timeout=WAIT)
    finally:
        tuner.close()
    assert line["gains"] == {"kp": [350.0, 300.0], "kd": [60.0, 75.0]}
    spec = _parsed(shlex.split(str(line["command"]))[1:])
    result = simulate(*spec.build(robot), reference, spec.simulation)
    assert jsonable(compute_metrics(result).as_dict()) == jsonable(line["metrics"])
    assert line["metrics"] != first["metrics"]


def test_reload_controller_reads_the_saved_file_again(tmp_path: object) -> None:
    """``--watch``'s reload: the class after an edit is the edited one (load_controller alone
    keeps the module it imported first)."""
    from pathlib import Path

    from twolink_pin.controllers.loading import load_controller, reload_controller

    law = Path(str(tmp_path)) / "edited_law.py"
    source = (Path(__file__).resolve().parents[1] / "examples" / "sliding_mode.py").read_text()
    law.write_text(source.replace('name = "sliding-mode"', 'name = "sliding-mode-watched"'))
    first = load_controller(f"{law}:SlidingMode")
    law.write_text(
        source.replace('name = "sliding-mode"', 'name = "sliding-mode-watched"').replace(
            'title = "sliding mode with a boundary layer"', 'title = "edited"'
        )
    )
    assert load_controller(f"{law}:SlidingMode") is first
    again = reload_controller(f"{law}:SlidingMode")
    assert again.title == "edited" and first.title == "sliding mode with a boundary layer"


def _blocking_pd(at: float, blocked: threading.Event, release: threading.Event, seen: list[float]) -> type:
    """PD + feedforward whose first run stops at t ≥ ``at`` [s] until ``release`` is set
    (``seen``: the times that first run evaluated)."""
    from twolink_pin.controllers.pd import PDFeedforward

    class BlockingPD(PDFeedforward):
        def compute(self, x, terms):  # type: ignore[no-untyped-def]
            if not hasattr(self, "first"):
                self.first = not blocked.is_set()
            if self.first:
                seen.append(float(x.t))
            if x.t >= at and not blocked.is_set():
                blocked.set()
                assert release.wait(WAIT)
            return super().compute(x, terms)

    return BlockingPD


def test_a_change_cancels_the_run_in_flight_and_only_the_newer_run_is_shown() -> None:
    """Run 1's law blocks at t = 0.2 s until run 2 (kd × 1.5) has been asked for: run 1 then
    stops at its next block of samples (cancelled, its last law time well before the end),
    never reaches the JSON lines or the page; run 2's result is the one shown."""
    import queue

    from twolink_pin.model import load_robot
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.tuning import Tuner

    blocked, release, seen = threading.Event(), threading.Event(), []
    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    lines: queue.Queue[dict[str, object]] = queue.Queue()
    law = _blocking_pd(0.2, blocked, release, seen)
    tuner = Tuner(
        RunSpec(law=law, simulation=SimulationConfig(duration=1.0)),
        0.0,
        lambda payload: (robot, reference),
        lambda spec, payload: "twolink-pin simulate …",
        lambda spec, payload: {},
        lines.put,
    )
    try:
        assert blocked.wait(WAIT)
        tuner.panel.sliders[-1].value = 1.5  # kd × (all)
        tuner.changed()
        release.set()
        line = lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        status = tuner.status.content
    finally:
        tuner.close()
    assert line["run"] == 2 and line["gains"] == {"kp": [350.0, 300.0], "kd": [60.0, 75.0]}
    assert lines.empty()
    assert tuner.session.cancelled == 1 and tuner.session.runs == 2
    assert 0.2 <= max(seen) < 0.3  # run 1 stopped at the end of its block (128 steps of 1 ms)
    assert status.startswith("run 2: 1 s simulated")


def test_a_long_run_publishes_the_part_simulated_so_far_and_it_is_the_results_prefix() -> None:
    """The law waits at t = 0.3 s: what was published before that covers t < 0.3 s only and
    equals the finished run's first samples exactly (q, q_des, τ)."""
    import numpy as np

    from twolink_pin.model import load_robot
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.tuning.runner import Partial, Request, Runner

    blocked, release, seen = threading.Event(), threading.Event(), []
    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    parts: list[Partial] = []
    runner = Runner(
        lambda payload: (robot, reference), partial=parts.append, stream_after=0.0, stream_period=0.0
    )
    law = _blocking_pd(0.3, blocked, release, seen)
    request = Request(RunSpec(law=law, simulation=SimulationConfig(duration=0.6)), 0.0)
    finished: list[object] = []
    worker = threading.Thread(target=lambda: finished.append(runner(request)))
    worker.start()
    try:
        assert blocked.wait(WAIT)
        before = list(parts)
    finally:
        release.set()
        worker.join(WAIT)
    assert before and float(before[-1].t[-1]) < 0.3
    assert len(before[-1].t) == 256  # two blocks of 128 samples
    result = finished[0].result  # type: ignore[attr-defined]
    for part in (before[-1], parts[-1]):
        k = len(part.t)
        assert np.array_equal(part.t, result.t[:k])
        assert np.array_equal(part.q, result.q[:k])
        assert np.array_equal(part.q_des, result.q_des[:k])
        assert np.array_equal(part.tau_command, result.tau_command[:k])
    assert len(parts[-1].t) == len(result.t)
