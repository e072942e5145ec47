"""A plant that pushes back: wrench, payload step, sensor noise, delay (twolink_pin.disturbances).

Each event against an independent construction:

* a plant whose events never act equals the plain engine bit for bit;
* a payload step at t = 0 equals the plant loaded with ``load_robot(payload=m)``;
* the noisy measurement: the recorded command is the law evaluated at the true state plus
  the draws of ``default_rng([seed, stream])``;
* the delay: the command applied at step k is the law's output at the state of step k − d;
* after a payload step the adaptive law re-converges and computed torque does not;
* a batch equals N single runs with every event at once;
* the CLI options (``simulate``, ``compare``) give the library's run, and bad values one
  line and exit 2.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest
from conftest_sim import ROBOT, TRAJECTORY

from twolink_pin.cli import main
from twolink_pin.controllers import LawInput, load_controller
from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench
from twolink_pin.errors import InvalidParameterError
from twolink_pin.metrics import compute_metrics
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate, terms_for
from twolink_pin.studies.batch import simulate_batch

SHORT = SimulationConfig(duration=0.3)


def _law(name: str = "pd") -> object:
    return make_scenario(name, ROBOT).controller


def test_events_that_never_act_leave_the_plain_engine_bit_for_bit() -> None:
    for law in ("pd", "adaptive"):
        plain = simulate(_law(law), Plant(ROBOT), TRAJECTORY, SHORT)
        late = Plant(ROBOT, wrench=Wrench((5.0, 1.0, 0.0), 10.0, 11.0), payload_step=PayloadStep(1.0, 10.0))
        assert late.has_events and not Plant(ROBOT).has_events
        events = simulate(_law(law), late, TRAJECTORY, SHORT)
        np.testing.assert_array_equal(events.q, plain.q)
        np.testing.assert_array_equal(events.tau_command, plain.tau_command)
        if plain.p_hat is not None:
            np.testing.assert_array_equal(events.p_hat, plain.p_hat)


def test_a_payload_step_at_zero_is_the_loaded_robot() -> None:
    loaded = load_robot(payload=0.7)
    reference = simulate(_law(), Plant(loaded), TRAJECTORY, SHORT)
    stepped = simulate(_law(), Plant(ROBOT, payload_step=PayloadStep(0.7, 0.0)), TRAJECTORY, SHORT)
    np.testing.assert_allclose(stepped.q, reference.q, rtol=0, atol=1e-12)
    unloaded = simulate(_law(), Plant(ROBOT), TRAJECTORY, SHORT)
    assert np.abs(np.asarray(unloaded.q) - np.asarray(reference.q)).max() > 1e-4


def test_the_law_sees_the_true_state_plus_the_seeded_noise() -> None:
    law = _law()
    noise = SensorNoise(1e-3, 2e-2, seed=7, stream=3)
    config = SimulationConfig(duration=0.1, control_period=1e-3)
    result = simulate(law, Plant(ROBOT, sensor_noise=noise), TRAJECTORY, config)
    draws = np.random.default_rng([7, 3]).standard_normal((101, 4))
    terms = terms_for(law)
    for k in (0, 1, 50, 100):
        x = LawInput(
            float(result.t[k]),
            np.asarray(result.q)[k : k + 1] + 1e-3 * draws[k, :2],
            np.asarray(result.v)[k : k + 1] + 2e-2 * draws[k, 2:],
            np.zeros((1, 0)),
            np.asarray(result.q_des)[k : k + 1],
            np.asarray(result.v_des)[k : k + 1],
            np.asarray(result.a_des)[k : k + 1],
        )
        np.testing.assert_allclose(
            result.tau_command[k], law.compute(x, terms).tau[0], rtol=1e-12, atol=1e-12
        )
    same = simulate(law, Plant(ROBOT, sensor_noise=noise), TRAJECTORY, config)
    np.testing.assert_array_equal(same.q, result.q)
    other = simulate(law, Plant(ROBOT, sensor_noise=SensorNoise(1e-3, 2e-2, seed=8)), TRAJECTORY, config)
    assert np.abs(np.asarray(other.tau_command) - np.asarray(result.tau_command)).max() > 1e-3


@pytest.mark.parametrize(("law", "delay"), [("adaptive", 1), ("pd", 5)])
def test_the_delayed_command_is_the_law_at_the_earlier_state(law: str, delay: int) -> None:
    controller = _law(law)
    result = simulate(controller, Plant(ROBOT, delay=delay), TRAJECTORY, SimulationConfig(duration=0.1))
    terms = terms_for(controller)
    q, v = np.asarray(result.q), np.asarray(result.v)
    z = np.asarray(result.state) if result.state is not None else np.zeros((len(q), 0))
    qd, vd, ad = (np.asarray(x) for x in (result.q_des, result.v_des, result.a_des))

    def output(k: int) -> np.ndarray:
        s = slice(k, k + 1)
        x = LawInput(float(result.t[k]), q[s], v[s], z[s], qd[s], vd[s], ad[s])
        return controller.compute(x, terms).tau[0]

    for k in (0, delay - 1):
        np.testing.assert_allclose(result.tau_command[k], output(0), rtol=1e-12, atol=1e-12)
    for k in (delay, delay + 1, 60, 100):
        np.testing.assert_allclose(result.tau_command[k], output(k - delay), rtol=1e-12, atol=1e-12)


def test_adaptive_reconverges_after_a_payload_step_computed_torque_does_not() -> None:
    """1 kg picked up at 2 s; the laws start on the exact model. Computed torque keeps the
    error the payload causes; the adaptive law (Γ 20 × the report's) drives it down and its
    estimates towards the loaded arm's parameters."""
    plant = Plant(ROBOT, payload_step=PayloadStep(1.0, 2.0))
    config = SimulationConfig(duration=20.0, q0_offset=0.0)
    adaptive = simulate(
        make_scenario(
            "adaptive", ROBOT, gains={"initial_estimate": 1.0, "gamma": (0.025, 0.0075, 0.03)}
        ).controller,
        plant,
        TRAJECTORY,
        config,
    )
    ct = simulate(_law("computed-torque"), plant, TRAJECTORY, config)

    def period_max(result: SimulationResult, start: float, length: float = TRAJECTORY.period) -> float:
        t = np.asarray(result.t)
        return float(np.abs(np.asarray(result.e)[(t >= start) & (t < start + length)]).max())

    assert period_max(ct, 0.0, 2.0) < 1e-5 and period_max(adaptive, 0.0, 2.0) < 1e-5  # exact until 2 s
    first, last = period_max(ct, 4.0), period_max(ct, 16.0)
    assert first > 5e-4 and abs(last - first) < 0.05 * first  # computed torque keeps its error
    assert period_max(adaptive, 16.0) < 0.5 * period_max(adaptive, 4.0)
    assert period_max(adaptive, 16.0) < 0.2 * last
    loaded = np.asarray(load_robot(payload=1.0).p)
    assert adaptive.p_hat is not None
    before = np.abs(np.asarray(adaptive.p_hat)[round(2.0 / adaptive.dt)] - loaded).sum()
    after = np.abs(np.asarray(adaptive.p_hat)[-1] - loaded).sum()
    assert after < 0.3 * before


@functools.cache
def _events_plant() -> Plant:
    return Plant(
        ROBOT,
        wrench=Wrench((3.0, -2.0, 0.0), 0.05, 0.2),
        payload_step=PayloadStep(0.5, 0.1),
        sensor_noise=SensorNoise(1e-4, 1e-3, seed=2),
        delay=2,
    )


@pytest.mark.parametrize("law", ["pd", "adaptive", "pid"])
def test_batch_equals_single_runs_with_every_event(law: str) -> None:
    cls = load_controller(law)
    offsets = np.array([[0.1, -0.1], [0.0, 0.0], [-0.05, 0.2]])
    batch = simulate_batch(
        cls(ROBOT), _events_plant(), TRAJECTORY, SHORT, q0_offsets=offsets, threads=1, record=True
    )
    assert batch.q is not None
    for r, offset in enumerate(offsets):
        plant = _events_plant()
        single_plant = Plant(
            ROBOT,
            wrench=plant.wrench,
            payload_step=plant.payload_step,
            sensor_noise=SensorNoise(1e-4, 1e-3, seed=2, stream=r),
            delay=2,
        )
        single = simulate(
            cls(ROBOT), single_plant, TRAJECTORY, SimulationConfig(duration=0.3, q0_offset=tuple(offset))
        )
        np.testing.assert_allclose(batch.q[r], single.q, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.tau_command[r], single.tau_command, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.metrics.rms.e[r], compute_metrics(single).rms.e, rtol=1e-12)


def test_bad_events_are_refused_with_what_was_expected() -> None:
    with pytest.raises(InvalidParameterError, match=r"wrench\.force"):
        Wrench((1.0, 2.0))
    with pytest.raises(InvalidParameterError, match=r"wrench\.stop"):
        Wrench((1.0, 2.0, 3.0), 2.0, 1.0)
    with pytest.raises(InvalidParameterError, match=r"payload_step\.mass"):
        PayloadStep(-1.0, 1.0)
    with pytest.raises(InvalidParameterError, match=r"sensor_noise\.sigma_q"):
        SensorNoise(float("nan"))
    with pytest.raises(InvalidParameterError, match="delay"):
        Plant(ROBOT, delay=-1)
    with pytest.raises(InvalidParameterError, match=r"wrench\.frame"):
        Plant(ROBOT, wrench=Wrench((1.0, 0.0, 0.0), frame="no_such_frame"))
    with pytest.raises(InvalidParameterError, match="method"):
        simulate(_law(), Plant(ROBOT, delay=1), TRAJECTORY, SimulationConfig(duration=0.1, method="adaptive"))


def test_cli_options_give_the_librarys_run(capsys: pytest.CaptureFixture[str]) -> None:
    argv = [
        "simulate",
        "pd",
        "--duration",
        "0.2",
        "--wrench",
        "3,-2,0@0.05:0.15",
        "--payload-step",
        "0.5@0.1",
    ]
    argv += ["--sensor-noise", "1e-4,1e-3", "--noise-seed", "4", "--delay", "2", "--json"]
    assert main(argv) == 0
    payload = json.loads(capsys.readouterr().out)
    plant = Plant(
        ROBOT,
        wrench=Wrench((3.0, -2.0, 0.0), 0.05, 0.15),
        payload_step=PayloadStep(0.5, 0.1),
        sensor_noise=SensorNoise(1e-4, 1e-3, seed=4),
        delay=2,
    )
    expected = compute_metrics(simulate(_law(), plant, TRAJECTORY, SimulationConfig(duration=0.2)))
    np.testing.assert_allclose(payload["metrics"]["rms"]["e"], expected.rms.e, rtol=1e-12)


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("--wrench", "1,2@0:1"),
        ("--wrench", "1,2,3@1"),
        ("--wrench", "1,2,3@2:1"),
        ("--payload-step", "2"),
        ("--payload-step", "-1@2"),
        ("--sensor-noise", "1,2,3,4"),
        ("--sensor-noise", "-0.1"),
        ("--delay", "-2"),
    ],
)
def test_cli_refuses_bad_values_in_one_line(
    capsys: pytest.CaptureFixture[str], option: str, value: str
) -> None:
    with pytest.raises(SystemExit) as info:
        main(["simulate", "pd", "--duration", "0.01", option, value])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and option in err and "Traceback" not in err


def test_compare_takes_the_plants_events(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    argv = ["compare", "pd", "pid", "--duration", "0.2", "--no-plot", "--out", str(tmp_path / "c")]
    argv += ["--wrench", "3,-2,0@0.05:", "--json"]
    assert main(argv) == 0
    payload = json.loads(capsys.readouterr().out)
    plant = Plant(ROBOT, wrench=Wrench((3.0, -2.0, 0.0), 0.05))
    for law in ("pd", "pid"):
        expected = compute_metrics(simulate(_law(law), plant, TRAJECTORY, SimulationConfig(duration=0.2)))
        np.testing.assert_allclose(payload["controllers"][law]["rms"]["e"], expected.rms.e, rtol=1e-12)


@pytest.mark.parametrize(
    ("engine", "integrator"), [("pinocchio", "rk4"), ("mujoco", "rk4"), ("mujoco", "euler")]
)
def test_saturation_clips_the_motors_torque_never_the_wrench(engine: str, integrator: str) -> None:
    """With ``--saturate`` and a wrench whose ``Jᵀ F`` is beyond the effort limits, each plant's
    ``q̈`` is Pinocchio's ABA on ``clip(τ) + Jᵀ F`` (the wrench is the world's, not a motor's):
    at an RK4 stage, and over a step that MuJoCo's Euler takes itself (``v ← v + dt q̈``)."""
    import pinocchio as pin

    from twolink_pin.plant_options import PlantOptions
    from twolink_pin.simulation.events import PlantEvents
    from twolink_pin.simulation.rk4 import Steps

    force = np.array([0.0, 800.0, 0.0, 0.0, 0.0, 30.0])  # [N, N·m]: beyond both limits
    extra = {"integrator": integrator} if engine == "mujoco" else {}
    options = PlantOptions(engine=engine, saturate=True, wrench=Wrench(tuple(force), 0.0, 1.0), **extra)  # type: ignore[arg-type]
    plant = options.plant(ROBOT, estimates_friction=False)
    q, v, tau = np.array([[0.3, 0.8]]), np.array([[0.1, -0.2]]), np.array([[500.0, -90.0]])
    model, data = ROBOT.model, ROBOT.model.createData()
    J = pin.computeFrameJacobian(model, data, q[0], ROBOT.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    pushed = J.T @ force
    assert (np.abs(pushed) > plant.limits).all()  # the wrench alone is beyond every limit
    expected = pin.aba(model, data, q[0], v[0], np.clip(tau[0], -plant.limits, plant.limits) + pushed)
    accel = PlantEvents(plant, 1, None, ROBOT.nv).accel_at(0.1)
    if integrator == "euler":
        dt = 1e-4
        _, v1, _ = accel.held_step(q, v, np.zeros((1, 0)), tau, np.zeros((1, 0)), Steps.of(dt), 0)  # type: ignore[attr-defined]
        np.testing.assert_allclose((v1[0] - v[0]) / dt, expected, rtol=1e-8, atol=1e-8)
    else:
        np.testing.assert_allclose(accel(q, v, tau)[0], expected, rtol=1e-10, atol=1e-8)
