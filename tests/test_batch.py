"""Tests of twolink_pin.batch, and of the two single-run engines it must match.

The batch engine against separate ``simulate`` calls (trajectories, metrics, divergence
times) for every controller kind with different offsets, gains and parameter errors; the
generated fast RK4 loop against the generic ``compute`` loop; the sampled-data (held) law
against an independent implementation and its O(dt) distance to the per-stage law; and a
3-joint arm with gravity for generality in nv.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import batch as batch_module
from twolink_pin import simulation
from twolink_pin.batch import BatchUnavailableError, robot_with_parameters, simulate_batch
from twolink_pin.controllers import (
    CONTROLLERS,
    Adaptive,
    AdaptiveFriction,
    AdaptiveFrictionGains,
    AdaptiveGains,
    ComputedTorque,
    Controller,
    PDFeedforward,
    PDGains,
    SlotineLiGains,
    WrongModel,
)
from twolink_pin.dynamics import Friction, model_with_parameters, polarisation_forest, regressor
from twolink_pin.errors import InvalidParameterError, SimulationDivergedError
from twolink_pin.metrics import compute_metrics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.model.parameters import ParameterMap
from twolink_pin.plant import Plant
from twolink_pin.scenarios import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import JointTrajectory, build_trajectory

ROBOT = load_robot()
TRAJECTORY = build_trajectory(ROBOT)
SHORT = SimulationConfig(duration=0.3)
# Trajectories and torques are O(1–100); float64 rounding differences between the
# engines' orders of operations stay ~1e-13, so 1e-9 is the issue's bar with margin.
TOL = 1e-9


def _controllers(name: str, robot: RobotModel = ROBOT) -> list[Controller]:
    """Four controllers of kind ``name`` that differ in gains and parameter errors."""
    p = robot.p
    wrong = robot_with_parameters(robot, p * np.array([1.2, 0.8, 1.1]))
    if name == "pd":
        return [
            PDFeedforward(robot),
            PDFeedforward(robot, PDGains(kp=(200.0, 150.0), kd=(30.0, 20.0))),
            PDFeedforward(wrong),
            PDFeedforward(wrong, PDGains(kp=(500.0, 400.0))),
        ]
    if name == "computed-torque":
        return [
            ComputedTorque(robot),
            ComputedTorque(robot, SlotineLiGains(k=(20.0, 60.0), lam=2.0)),
            ComputedTorque(wrong),
            ComputedTorque(wrong, SlotineLiGains(lam=8.0)),
        ]
    if name == "robust":
        return [
            WrongModel(robot),
            WrongModel(robot, model_scale=1.0),
            WrongModel(wrong, SlotineLiGains(lam=3.0), 0.3),
        ]
    if name == "adaptive":
        return [
            Adaptive(robot),
            Adaptive(robot, AdaptiveGains(initial_estimate=0.8, lam=3.0)),
            Adaptive(wrong, AdaptiveGains(k=(60.0, 90.0), gamma=(1.0, 0.3, 0.2))),
        ]
    friction = Friction.report()
    return [
        AdaptiveFriction(robot, friction=friction),
        AdaptiveFriction(robot, AdaptiveFrictionGains(friction_initial_estimate=0.5), friction),
        AdaptiveFriction(wrong, AdaptiveFrictionGains(lam=2.0), friction),
    ]


def _plant(name: str, robot: RobotModel = ROBOT, saturate: bool = False) -> Plant:
    return Plant(
        robot, friction=Friction.report() if name == "adaptive-friction" else None, saturate=saturate
    )


def _offsets(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-0.2, 0.2, (n, 2))


def _assert_run_equals(single: SimulationResult, batch, i: int) -> None:  # type: ignore[no-untyped-def]
    np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=TOL)
    np.testing.assert_allclose(batch.v[i], single.v, rtol=0, atol=TOL)
    np.testing.assert_allclose(batch.tau_command[i], single.tau_command, rtol=0, atol=TOL)
    if single.p_hat is not None:
        np.testing.assert_allclose(batch.p_hat[i], single.p_hat, rtol=0, atol=TOL)
        np.testing.assert_allclose(batch.p_hat_final[i], single.p_hat[-1], rtol=0, atol=TOL)
        np.testing.assert_array_equal(batch.p_true, single.p_true)
    metrics, mine = compute_metrics(single), batch.metrics.run(i)
    for kind in ("rms", "l2", "max"):
        for ours, theirs in zip(getattr(mine, kind), getattr(metrics, kind)):
            np.testing.assert_allclose(ours, theirs, rtol=TOL, atol=TOL)
    np.testing.assert_allclose(
        mine.final_period_max_abs_e, metrics.final_period_max_abs_e, rtol=TOL, atol=TOL
    )
    np.testing.assert_allclose(
        batch.metrics.peak_command[i], np.abs(single.tau_command).max(axis=0), rtol=TOL
    )
    first = [np.nan if x is None else x for x in single.first_exceeded_at]
    np.testing.assert_array_equal(batch.metrics.first_exceeded_at[i], first)


@pytest.mark.parametrize("name", ["adaptive", "adaptive-friction"])
def test_a_run_judges_the_estimates_against_the_plant_not_the_believed_model(name: str) -> None:
    """An adaptive law built on a model with parameter errors starts from its belief, but
    ``p_true`` (and so ``p_error``) is the plant's p and friction."""
    robot = load_robot()
    believed = robot_with_parameters(robot, np.asarray(robot.p) * np.array([1.2, 0.8, 1.1]))
    controller, plant = make_scenario(name, robot)
    wrong = type(controller)(believed, controller.gains)
    result = simulate(wrong, plant, TRAJECTORY, replace(SHORT, duration=0.01))
    n_p = len(robot.p)
    np.testing.assert_allclose(result.p_true[:n_p], robot.p, rtol=1e-12)
    np.testing.assert_allclose(wrong.true_parameters()[:n_p], believed.p, rtol=1e-12)
    assert np.abs(believed.p - np.asarray(robot.p)).max() > 0.05  # the two really differ
    if name == "adaptive-friction":
        np.testing.assert_array_equal(result.p_true[n_p:], plant.friction.parameters)
    np.testing.assert_allclose(result.p_error[0], result.p_hat[0] - result.p_true, rtol=0, atol=0)


# --- the batch equals the single runs -----------------------------------------------------------


@pytest.mark.parametrize("control_period", [None, 2e-3], ids=["per-stage", "held-2ms"])
@pytest.mark.parametrize("name", list(CONTROLLERS))
def test_batch_equals_separate_simulate_calls(name: str, control_period: float | None) -> None:
    """Each run of a batch (own gains, offsets, parameter errors) is ``simulate`` to 1e-9."""
    controllers = _controllers(name)
    offsets = _offsets(len(controllers), seed=len(name))
    config = replace(SHORT, control_period=control_period)
    plant = _plant(name)
    result = simulate_batch(
        controllers, plant, TRAJECTORY, config, q0_offsets=offsets, record=True, threads=1
    )
    assert not result.diverged.any()
    for i, controller in enumerate(controllers):
        single = simulate(controller, plant, TRAJECTORY, replace(config, q0_offset=tuple(offsets[i])))
        _assert_run_equals(single, result, i)


def test_batch_with_saturation_and_smooth_friction_equals_simulate() -> None:
    """Saturation and tanh friction enter the batch as in ``Plant`` (limits exceeded here)."""
    friction = Friction.report(smoothing=0.01)
    controllers = [
        AdaptiveFriction(ROBOT, AdaptiveFrictionGains(k=(400.0, 400.0)), friction),
        AdaptiveFriction(ROBOT, friction=friction),
    ]
    plant = Plant(ROBOT, friction=friction, saturate=True)
    offsets = np.array([[0.6, -0.6], [0.1, 0.1]])
    result = simulate_batch(controllers, plant, TRAJECTORY, SHORT, q0_offsets=offsets, record=True)
    assert result.limit_exceeded[0].any()
    for i, controller in enumerate(controllers):
        single = simulate(controller, plant, TRAJECTORY, replace(SHORT, q0_offset=tuple(offsets[i])))
        _assert_run_equals(single, result, i)


def test_one_and_two_threads_give_identical_bits() -> None:
    """Thread count changes who computes a column, not what (512 runs: two threads used)."""
    controllers = [PDFeedforward(ROBOT) for _ in range(512)]
    offsets = _offsets(512, seed=3)
    config = SimulationConfig(duration=0.02)
    one = simulate_batch(controllers, Plant(ROBOT), TRAJECTORY, config, q0_offsets=offsets, threads=1)
    two = simulate_batch(controllers, Plant(ROBOT), TRAJECTORY, config, q0_offsets=offsets, threads=2)
    assert (one.threads, two.threads) == (1, 2)
    for a, b in zip(one.metrics.rms, two.metrics.rms):
        np.testing.assert_array_equal(a, b)


def test_a_diverging_run_is_flagged_at_simulates_time_and_the_others_finish() -> None:
    """Kd = 3000 with dt = 5 ms is beyond RK4's stability: that run diverges, alone."""
    config = SimulationConfig(duration=0.5, dt=5e-3)
    stiff = PDFeedforward(ROBOT, PDGains(kd=(3000.0, 3000.0)))
    controllers = [PDFeedforward(ROBOT), stiff, PDFeedforward(ROBOT)]
    result = simulate_batch(controllers, Plant(ROBOT), TRAJECTORY, config, record=True)
    with pytest.raises(SimulationDivergedError) as info:
        simulate(stiff, Plant(ROBOT), TRAJECTORY, config)
    np.testing.assert_array_equal(result.diverged, [False, True, False])
    assert result.diverged_at[1] == pytest.approx(info.value.time, abs=1e-12)
    assert np.all(np.isnan(result.metrics.rms.e[1]))
    _assert_run_equals(simulate(controllers[2], Plant(ROBOT), TRAJECTORY, config), result, 2)


# --- the batch's Pinocchio terms -----------------------------------------------------------------------


class _FirstTwoLumped(ParameterMap):
    """p1, p2 only: p3's dynamics is outside the map, so ``τ(π₀) ≠ Y_p p₀``."""

    names = ("p1", "p2")

    @property
    def matrix(self) -> np.ndarray:
        return ROBOT.parameter_map.matrix[:, :2]

    def values(self, model: pin.Model) -> np.ndarray:
        return ROBOT.parameter_map.values(model)[:2]


@pytest.mark.parametrize(
    ("parameter_map", "needs_base"), [(ROBOT.parameter_map, False), (_FirstTwoLumped(), True)]
)
def test_regressor_columns_from_rnea_equal_pinocchios_regressor_times_p(
    parameter_map: ParameterMap, needs_base: bool
) -> None:
    """``τ(π₀ + P_j) − τ(π₀)`` (non-physical column inertias) is column j of ``Y_π P``, both
    with τ(π₀) recovered from the columns (a complete map) and computed on a base model."""
    rng = np.random.default_rng(0)
    n = 5
    q, v, w, a = (rng.uniform(-2, 2, (n, 2)) for _ in range(4))
    engine = batch_module._Regressor(ROBOT.model, parameter_map, 1, n)
    assert (engine.weights is None) == needs_base
    columns = engine(q, v, w, a)
    data = ROBOT.create_data()
    for i in range(n):
        expected = regressor(ROBOT.model, data, q[i], v[i], w[i], a[i]) @ parameter_map.matrix
        got = np.stack([c[i] for c in columns], axis=1)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_polarised_model_term_equals_rnea_plus_coriolis_with_gravity(arm3) -> None:  # type: ignore[no-untyped-def]
    """``RNEA(q, (v+w)/2, a) − RNEA₀(q, (v−w)/2, 0) = M a + C(q, v) w + g`` on an arm with
    gravity, both terms in one call on the forest of the batch engine."""
    robot, _ = arm3
    model, data = robot.model, robot.create_data()
    forest = polarisation_forest([model])
    forest_data = forest.createData()
    rng = np.random.default_rng(1)
    for _ in range(10):
        q, v, w, a = (rng.uniform(-2, 2, 3) for _ in range(4))
        expected = pin.rnea(model, data, q, v, a) + pin.computeCoriolisMatrix(model, data, q, v) @ (w - v)
        tau = pin.rnea(forest, forest_data, np.r_[q, q], np.r_[(v + w) / 2, (v - w) / 2], np.r_[a, 0 * a])
        got = tau[:3] - tau[3:]
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
        assert np.abs(pin.computeGeneralizedGravity(model, data, q)).max() > 0.1  # gravity counted


def test_model_with_parameters_gives_the_map_those_parameters() -> None:
    """The copy's map values are ``p`` and its RNEA is ``Y_p p`` (a controller believing p)."""
    p = ROBOT.p * np.array([1.3, 0.7, 1.1])
    model = model_with_parameters(ROBOT.model, ROBOT.parameter_map, p)
    np.testing.assert_allclose(ROBOT.parameter_map.values(model), p, rtol=1e-12)
    q, v, a = np.array([0.3, 1.2]), np.array([0.5, -0.4]), np.array([1.0, 2.0])
    Y = regressor(ROBOT.model, ROBOT.create_data(), q, v, v, a) @ ROBOT.parameter_map.matrix
    np.testing.assert_allclose(pin.rnea(model, model.createData(), q, v, a), Y @ p, rtol=1e-12)


# --- refusals ---------------------------------------------------------------------------------------


def test_mixed_controller_kinds_are_refused_naming_the_kind() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"controllers\[1\] = 'ComputedTorque'.*one kind \(PDFeedforward\)"
    ):
        simulate_batch([PDFeedforward(ROBOT), ComputedTorque(ROBOT)], Plant(ROBOT), TRAJECTORY, SHORT)


def test_a_controller_without_a_vectorised_law_is_refused() -> None:
    class Zero(PDFeedforward):
        name = "zero"

    with pytest.raises(InvalidParameterError, match="no vectorised law"):
        simulate_batch([Zero(ROBOT)], Plant(ROBOT), TRAJECTORY, SHORT)


def test_offsets_of_the_wrong_shape_are_refused_with_the_shapes() -> None:
    with pytest.raises(InvalidParameterError, match=r"shape \(3, 2\).*expected shape \(2, 2\)"):
        simulate_batch(
            [PDFeedforward(ROBOT)] * 2, Plant(ROBOT), TRAJECTORY, SHORT, q0_offsets=np.zeros((3, 2))
        )


def test_the_adaptive_step_method_is_refused() -> None:
    with pytest.raises(InvalidParameterError, match="'rk4'"):
        simulate_batch([PDFeedforward(ROBOT)], Plant(ROBOT), TRAJECTORY, SimulationConfig(method="adaptive"))


def test_a_controller_model_beyond_the_parameter_map_is_refused() -> None:
    """Link 2's centre of mass off its x axis cannot be expressed by (p1, p2, p3)."""
    model = pin.Model(ROBOT.model)
    body = model.inertias[2].toDynamicParameters()
    body[2] = 0.05  # m c_y
    model.inertias[2] = pin.Inertia.FromDynamicParameters(body)
    odd = replace(ROBOT, model=model)
    with pytest.raises(InvalidParameterError, match="m\\*c_y"):
        simulate_batch([PDFeedforward(ROBOT), PDFeedforward(odd)], Plant(ROBOT), TRAJECTORY, SHORT)


def test_missing_parallel_algorithms_give_an_explaining_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(pin, "abaInParallel")
    with pytest.raises(BatchUnavailableError, match=r"no abaInParallel.*without its parallel module") as info:
        simulate_batch([PDFeedforward(ROBOT)], Plant(ROBOT), TRAJECTORY, SHORT)
    assert info.value.missing == ("abaInParallel",)


# --- the single-run engines: generated fast loop == generic loop ------------------------------------------


def _generic(monkeypatch: pytest.MonkeyPatch, *args, **kwargs) -> SimulationResult:  # type: ignore[no-untyped-def]
    with monkeypatch.context() as m:
        m.setattr(simulation, "_fast_rk4", lambda *a, **k: None)
        return simulate(*args, **kwargs)


@pytest.mark.parametrize("control_period", [None, 1e-3, 3e-3], ids=["per-stage", "held-1ms", "held-3ms"])
@pytest.mark.parametrize("name", list(CONTROLLERS))
def test_fast_loop_equals_the_compute_loop(
    monkeypatch: pytest.MonkeyPatch, name: str, control_period
) -> None:  # type: ignore[no-untyped-def]
    """The generated float loop computes what ``Controller.compute`` + ``Plant`` state, to 1e-12."""
    config = SimulationConfig(duration=0.25, control_period=control_period)  # 250 steps: 3 ms does not divide
    controller, plant = make_scenario(name, ROBOT, saturate=True)
    fast = simulate(controller, plant, TRAJECTORY, config)
    slow = _generic(monkeypatch, controller, plant, TRAJECTORY, config)
    for field in ("q", "v", "tau_command", "tau"):
        np.testing.assert_allclose(getattr(fast, field), getattr(slow, field), rtol=0, atol=1e-12)
    if slow.p_hat is not None:
        np.testing.assert_allclose(fast.p_hat, slow.p_hat, rtol=0, atol=1e-12)
    assert fast.control_period == control_period


def test_a_subclass_overriding_compute_is_not_run_through_the_parents_kernel() -> None:
    class Doubled(ComputedTorque):
        def compute(self, q, v, q_des, v_des, a_des, z):  # type: ignore[no-untyped-def]
            tau, z = super().compute(q, v, q_des, v_des, a_des, z)
            return 2 * tau, z

    assert Doubled(ROBOT).stage_kernel() is None
    assert ComputedTorque(ROBOT).stage_kernel() is not None


def test_divergence_in_the_fast_loop_raises_like_the_generic_one(monkeypatch: pytest.MonkeyPatch) -> None:
    config = SimulationConfig(duration=0.5, dt=5e-3)
    stiff = PDFeedforward(ROBOT, PDGains(kd=(3000.0, 3000.0)))
    with pytest.raises(SimulationDivergedError) as fast:
        simulate(stiff, Plant(ROBOT), TRAJECTORY, config)
    with pytest.raises(SimulationDivergedError) as slow:
        _generic(monkeypatch, stiff, Plant(ROBOT), TRAJECTORY, config)
    assert str(fast.value) == str(slow.value)


# --- sampled-data control ---------------------------------------------------------------------------------


def _held_reference(controller: Controller, plant: Plant, config: SimulationConfig, every: int) -> np.ndarray:
    """Zero-order hold written out plainly: law at t_k (k multiple of ``every``), RK4 on the plant."""
    n = config.steps
    dt = config.duration / n
    ref = TRAJECTORY.sample(np.arange(n + 1) * dt)
    q = ref.q[0] + np.asarray(config.q0_offset)
    v = ref.v[0].copy()
    z = controller.initial_state()
    qs = [q]
    tau = dz = None
    for k in range(n):
        if k % every == 0:
            tau, dz = controller.compute(q, v, ref.q[k], ref.v[k], ref.a[k], z)

        def f(x: np.ndarray, tau=tau) -> np.ndarray:  # type: ignore[no-untyped-def]
            return np.concatenate([x[2:], plant.acceleration(x[:2], x[2:], tau)])

        x = np.concatenate([q, v])
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * (k2 + k3) + k4)
        q, v, z = x[:2], x[2:], z + dt * dz
        qs.append(q)
    return np.array(qs)


@pytest.mark.parametrize("name", ["pd", "adaptive"])
@pytest.mark.parametrize("every", [1, 4])
def test_held_law_equals_an_independent_zero_order_hold(name: str, every: int) -> None:
    """τ and ż computed at t_k and held for ``every`` steps: the simulator matches a plain loop."""
    config = SimulationConfig(duration=0.2, control_period=every * 1e-3)
    controller, plant = make_scenario(name, ROBOT)
    result = simulate(controller, plant, TRAJECTORY, config)
    np.testing.assert_allclose(
        result.q, _held_reference(controller, plant, config, every), rtol=0, atol=1e-12
    )


def test_held_law_at_the_step_differs_from_the_per_stage_law_by_order_dt() -> None:
    """Halving dt (control period = dt) halves the gap to the per-stage law: first order."""
    controller, plant = make_scenario("computed-torque", ROBOT)
    gaps = []
    for dt in (2e-3, 1e-3):
        per_stage = simulate(controller, plant, TRAJECTORY, SimulationConfig(duration=1.0, dt=dt))
        held = simulate(
            controller, plant, TRAJECTORY, SimulationConfig(duration=1.0, dt=dt, control_period=dt)
        )
        gaps.append(np.abs(held.q - per_stage.q).max())
    assert gaps[1] > 0
    assert 1.6 < gaps[0] / gaps[1] < 2.5


def test_held_law_converges_in_dt_for_a_fixed_control_period() -> None:
    """With the law fixed at 4 ms, the plant's RK4 error falls ~16× per halving of dt."""
    controller, plant = make_scenario("pd", ROBOT)
    runs = [
        simulate(controller, plant, TRAJECTORY, SimulationConfig(duration=0.4, dt=dt, control_period=4e-3))
        for dt in (2e-3, 1e-3, 5e-4)
    ]
    coarse = np.abs(runs[0].q[::1] - runs[1].q[::2]).max()
    fine = np.abs(runs[1].q - runs[2].q[::2]).max()
    assert fine < coarse / 8


@pytest.mark.parametrize(
    ("changes", "text"),
    [
        ({"control_period": 1.5e-3}, "whole multiple of dt = 0.001 s"),
        ({"control_period": 0.0}, "a finite value > 0 s"),
        ({"control_period": 1e-3, "method": "adaptive"}, "sampled-data needs 'rk4'"),
    ],
)
def test_bad_control_periods_are_refused_with_the_rule(changes: dict, text: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(InvalidParameterError, match=text):
        SimulationConfig(**changes)


# --- generality in nv: a 3-joint arm with gravity -------------------------------------------------------------

_LIMIT = '<limit lower="-3.14" upper="3.14" effort="200" velocity="10"/>'


def _three_link_urdf(path: Path) -> Path:
    """A 3-joint arm (yaw, pitch, pitch) in gravity: nothing planar, every π column used."""
    links = []
    for i, (axis, xyz) in enumerate((("0 0 1", "0 0 0"), ("0 1 0", "0 0 0.2"), ("0 1 0", "0.3 0 0")), 1):
        links.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{_LIMIT}</joint>'
            f'<link name="l{i}"><inertial><origin xyz="0.1 0.01 0.02"/><mass value="{2.0 / i}"/>'
            f'<inertia ixx="0.05" ixy="0.001" ixz="0" iyy="0.04" iyz="0" izz="0.03"/></inertial></link>'
        )
    path.write_text(
        '<?xml version="1.0"?>\n<robot name="arm3"><link name="l0"/>' + "".join(links) + "</robot>\n"
    )
    return path


@pytest.fixture(scope="module")
def arm3(tmp_path_factory: pytest.TempPathFactory) -> tuple[RobotModel, JointTrajectory]:
    robot = load_robot(_three_link_urdf(tmp_path_factory.mktemp("arm3") / "arm3.urdf"))
    via = np.array([[0.0, 0.3, -0.5], [0.4, 0.6, -0.2], [0.0, 0.3, -0.5]])
    return robot, JointTrajectory.from_via_q((0.0, 1.0, 2.0), via)


@pytest.mark.parametrize("name", ["pd", "adaptive"])
def test_three_joint_arm_fast_generic_and_batch_agree(
    monkeypatch: pytest.MonkeyPatch, arm3, name: str
) -> None:  # type: ignore[no-untyped-def]
    robot, trajectory = arm3
    config = SimulationConfig(duration=0.1, q0_offset=(0.05, -0.05, 0.02))
    make = (
        (lambda: PDFeedforward(robot, PDGains(kp=(100.0,) * 3, kd=(20.0,) * 3)))
        if name == "pd"
        else (lambda: Adaptive(robot, AdaptiveGains(k=(20.0,) * 3, gamma=(1.0,) * 30)))
    )
    plant = Plant(robot)
    fast = simulate(make(), plant, trajectory, config)
    slow = _generic(monkeypatch, make(), plant, trajectory, config)
    np.testing.assert_allclose(fast.q, slow.q, rtol=0, atol=1e-12)
    batch = simulate_batch([make(), make()], plant, trajectory, config, record=True)
    _assert_run_equals(fast, batch, 1)
