"""Tests of the one engine run N at a time (twolink_pin.studies.batch, simulation.terms).

* a batch of N runs equals N single runs, for every built-in law and the tutorial's law,
  with per-run offsets, gains and believed parameters, per-stage and held;
* a run's result does not depend on N, on which runs share its batch, or on the threads;
* the batch terms equal the single-run terms and independent forms of the same quantities
  (CRBA + Coriolis matrix + gravity; Pinocchio's regressor × the parameter map);
* diverging runs are flagged at the time a single run reports, the others finish;
* the held (sampled) law against a plainly written zero-order hold; a 3-joint arm with gravity.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ROBOT, TRAJECTORY, evaluate, pendulum

from twolink_pin.controllers import (
    Adaptive,
    AdaptiveGains,
    ComputedTorque,
    Controller,
    LawInput,
    PDFeedforward,
    PDGains,
    SlotineLiGains,
    load_controller,
)
from twolink_pin.dynamics import regressor
from twolink_pin.errors import InvalidParameterError, SimulationDivergedError
from twolink_pin.metrics import compute_metrics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate, terms_for
from twolink_pin.simulation.terms import BatchTerms, BatchUnavailableError, SingleRunTerms
from twolink_pin.studies.batch import BatchResult, simulate_batch
from twolink_pin.trajectory import JointTrajectory

SHORT = SimulationConfig(duration=0.3)
# Trajectories and torques are O(1–100); float64 rounding differences between orders of
# operations stay ~1e-13, so 1e-9 is the bar with margin (measured: 1e-16 to 1e-17).
TOL = 1e-9
LAWS = [
    "pd",
    "computed-torque",
    "robust",
    "adaptive",
    "adaptive-friction",
    "examples/sliding_mode.py:SlidingMode",
]
OFFSETS = np.array([[0.1, -0.1], [0.0, 0.0], [-0.2, 0.05], [0.05, 0.15]])


def _batched(spec: str, robot: RobotModel = ROBOT) -> tuple[Controller, Plant, list[Controller]]:
    """One law object with four gain sets and believed parameters per run, the plant, and the
    four single-run laws that are its rows."""
    base, plant = make_scenario(spec, robot)
    g = base.gains.values()
    scale = np.array([1.0, 0.7, 1.3, 0.9])[:, None]
    changes: dict[str, Any] = {}
    for name in ("kp", "kd", "k"):
        if g.get(name) is not None:
            value = np.asarray(g[name])  # a matrix gain (1, k, k): one matrix per run
            changes[name] = value * (scale[:, :, None] if value.ndim == 3 else scale)
    if "lam" in g:
        changes["lam"] = np.array([5.0, 3.0, 8.0, 5.0])
    p = np.asarray(robot.p) * np.array([1.0, 1.2, 0.8, 1.1])[:, None]
    kwargs = {"friction": plant.friction} if "friction" in type(base).estimates else {}
    law = type(base)(robot, replace(base.gains, **changes), model_parameters=p, **kwargs)
    singles = []
    for i in range(4):
        row = {
            k: np.asarray(v)[i]
            if np.ndim(v) in (2, 3)
            else (float(np.asarray(v)[i]) if np.ndim(v) == 1 and k == "lam" else v)
            for k, v in changes.items()
        }
        singles.append(type(base)(robot, replace(base.gains, **row), model_parameters=p[i], **kwargs))
    return law, plant, singles


def _assert_run_equals(single: SimulationResult, batch: BatchResult, i: int) -> None:
    assert batch.q is not None and batch.v is not None and batch.tau_command is not None
    np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=TOL)
    np.testing.assert_allclose(batch.v[i], single.v, rtol=0, atol=TOL)
    np.testing.assert_allclose(batch.tau_command[i], single.tau_command, rtol=0, atol=TOL)
    metrics = compute_metrics(single)
    for kind in ("rms", "l2", "max"):
        for signal in ("e", "edot", "tau"):
            np.testing.assert_allclose(
                getattr(getattr(batch.metrics, kind), signal)[i],
                getattr(getattr(metrics, kind), signal),
                rtol=1e-9,
                atol=1e-12,
            )
    np.testing.assert_allclose(
        batch.metrics.final_period_max_abs_e[i], metrics.final_period_max_abs_e, rtol=1e-9, atol=1e-15
    )
    if single.p_hat is not None:
        assert batch.p_hat_final is not None
        np.testing.assert_allclose(batch.p_hat_final[i], single.p_hat[-1], rtol=0, atol=TOL)
        np.testing.assert_array_equal(batch.p_true, single.p_true)


@pytest.mark.parametrize("control_period", [None, 2e-3], ids=["per-stage", "held-2ms"])
@pytest.mark.parametrize("spec", LAWS)
def test_batch_equals_separate_simulate_calls(spec: str, control_period: float | None) -> None:
    """Four runs with different offsets, gains, λ and believed parameters: each batch row is the
    single run of its own law object (trajectories to 1e-9 rad, metrics to 1e-9 relative)."""
    config = replace(SHORT, control_period=control_period)
    law, plant, singles = _batched(spec)
    batch = simulate_batch(law, plant, TRAJECTORY, config, q0_offsets=OFFSETS, record=True)
    assert batch.n_runs == 4 and not batch.diverged.any()
    for i, single_law in enumerate(singles):
        single = simulate(single_law, plant, TRAJECTORY, replace(config, q0_offset=tuple(OFFSETS[i])))
        _assert_run_equals(single, batch, i)


def test_a_run_does_not_depend_on_its_batch_nor_on_threads() -> None:
    """Run 3 of a batch of 600 on 2 threads, of a batch of 300, and alone: identical bits (the
    batch engine computes each run by the same code whatever N; sweeps rely on it)."""
    base, plant = make_scenario("adaptive-friction", ROBOT)
    rng = np.random.default_rng(1)
    offsets = rng.uniform(-0.1, 0.1, (600, 2))
    config = SimulationConfig(duration=0.2)
    big = simulate_batch(base, plant, TRAJECTORY, config, q0_offsets=offsets, threads=2)
    half = simulate_batch(base, plant, TRAJECTORY, config, q0_offsets=offsets[:300], threads=1)
    alone = simulate_batch(base, plant, TRAJECTORY, config, q0_offsets=offsets[3:5], threads=1)
    assert big.threads == 2 and half.threads == 1
    for kind in ("rms", "max"):
        a, b = getattr(big.metrics, kind).e, getattr(half.metrics, kind).e
        np.testing.assert_array_equal(a[:300], b)
        np.testing.assert_array_equal(a[3:5], getattr(alone.metrics, kind).e)
    assert big.p_hat_final is not None and half.p_hat_final is not None
    np.testing.assert_array_equal(big.p_hat_final[:300], half.p_hat_final)


def test_a_diverging_run_is_flagged_at_simulates_time_and_the_others_finish() -> None:
    """Run 1 has K = 1e9 (unstable at dt = 1 ms): it diverges at the time simulate reports; runs 0 and 2 match simulate."""
    k = np.stack([np.diag(row) for row in ([40.0, 50.0], [1e9, 1e9], [40.0, 50.0])])  # a matrix per run
    law = ComputedTorque(ROBOT, SlotineLiGains(k=k))
    plant = Plant(ROBOT)
    batch = simulate_batch(law, plant, TRAJECTORY, SHORT, record=True)
    with pytest.raises(SimulationDivergedError) as info:  # the step check would refuse it: run it anyway
        simulate(
            ComputedTorque(ROBOT, SlotineLiGains(k=(1e9, 1e9))),
            plant,
            TRAJECTORY,
            replace(SHORT, check_step=False),
        )
    np.testing.assert_array_equal(batch.diverged, [False, True, False])
    assert batch.diverged_at[1] == pytest.approx(info.value.time, abs=1e-12)
    assert batch.divergence[1] is not None and batch.divergence[0] is None
    assert np.isnan(batch.metrics.rms.e[1]).all() and np.isfinite(batch.metrics.rms.e[[0, 2]]).all()
    single = simulate(ComputedTorque(ROBOT), plant, TRAJECTORY, SHORT)
    _assert_run_equals(single, batch, 0)
    _assert_run_equals(single, batch, 2)


# --- the terms ------------------------------------------------------------------------------------------------


def _crba_coriolis_gravity(
    robot: RobotModel, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> np.ndarray:
    data = robot.model.createData()
    M = pin.crba(robot.model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    return (
        M @ a
        + pin.computeCoriolisMatrix(robot.model, data, q, v) @ w
        + pin.computeGeneralizedGravity(robot.model, data, q)
    )


@pytest.mark.parametrize("robot_of", [lambda: ROBOT, pendulum], ids=["twolink", "double-pendulum"])
def test_batch_terms_equal_single_terms_and_independent_forms(robot_of: Any) -> None:
    """For 7 states: BatchTerms.model (shared model) = SingleRunTerms.model = M a + C(q, v) w + g by
    CRBA/Coriolis/gravity; BatchTerms.regressor = SingleRunTerms.regressor = Y_π(q, v, w, a) P;
    and Y p = the model term (the map describes the dynamics)."""
    robot = robot_of()
    law = PDFeedforward(robot)
    rng = np.random.default_rng(0)
    q, v, w, a = (rng.uniform(-2, 2, (7, robot.nv)) for _ in range(4))
    batch = BatchTerms(law, 7, 1)
    single = SingleRunTerms(law)
    model_b, reg_b = batch.model(q, v, w, a), batch.regressor(q, v, w, a)
    data = robot.create_data()
    for i in range(7):
        expected = _crba_coriolis_gravity(robot, q[i], v[i], w[i], a[i])
        np.testing.assert_allclose(model_b[i], expected, rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(
            single.model(q[i : i + 1], v[i : i + 1], w[i : i + 1], a[i : i + 1])[0],
            expected,
            rtol=1e-12,
            atol=1e-10,
        )
        Y = regressor(robot.model, data, q[i], v[i], w[i], a[i]) @ robot.parameter_map.matrix
        np.testing.assert_allclose(reg_b[i], Y, rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(
            single.regressor(q[i : i + 1], v[i : i + 1], w[i : i + 1], a[i : i + 1])[0],
            Y,
            rtol=1e-10,
            atol=1e-9,
        )
        np.testing.assert_allclose(Y @ robot.p, expected, rtol=1e-10, atol=1e-9)


def test_per_run_believed_parameters_give_each_run_its_model_term() -> None:
    """model_parameters of shape (N, n_p): the batch model term of run i is Y p_i (i.e. the model
    term of a single law believing p_i)."""
    p = np.asarray(ROBOT.p) * np.array([[1.0], [0.5], [2.0]])
    law = PDFeedforward(ROBOT, model_parameters=p)
    rng = np.random.default_rng(2)
    q, v, w, a = (rng.uniform(-2, 2, (3, 2)) for _ in range(4))
    tau = terms_for(law, 3).model(q, v, w, a)
    for i in range(3):
        single = SingleRunTerms(PDFeedforward(ROBOT, model_parameters=p[i]))
        np.testing.assert_allclose(
            tau[i],
            single.model(q[i : i + 1], v[i : i + 1], w[i : i + 1], a[i : i + 1])[0],
            rtol=1e-11,
            atol=1e-11,
        )


def test_constant_regressor_columns_are_found_and_the_others_kept() -> None:
    """The twolink's p1 and p2 columns are constant matrices times a (no RNEA needed); p3's is not."""
    terms = BatchTerms(Adaptive(ROBOT), 4, 1)
    terms.regressor(*(np.zeros((4, 2)) for _ in range(4)))
    columns = terms._columns()
    assert sorted(columns.constant) == [0, 1] and columns.varying == [2]
    np.testing.assert_allclose(columns.constant[0].T, [[1.0, 0.0], [0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(columns.constant[1].T, [[0.0, 1.0], [1.0, 1.0]], atol=1e-12)


def test_law_evaluated_on_a_batch_equals_its_rows() -> None:
    """compute on (N, nv) arrays with BatchTerms equals compute on each row with SingleRunTerms."""
    law = load_controller("examples/sliding_mode.py:SlidingMode")(pendulum())
    rng = np.random.default_rng(4)
    q, v, qd, vd, ad = (rng.uniform(-1, 1, (5, 2)) for _ in range(5))
    out = law.compute(LawInput(0.0, q, v, np.zeros((5, 0)), qd[:1], vd[:1], ad[:1]), terms_for(law, 5))
    for i in range(5):
        tau, _ = evaluate(law, q[i], v[i], qd[0], vd[0], ad[0])
        np.testing.assert_allclose(out.tau[i], tau, rtol=1e-12, atol=1e-12)


# --- refusals -----------------------------------------------------------------------------------------------------


def test_inconsistent_run_counts_are_refused_naming_each() -> None:
    """Gains for 3 runs and offsets for 4: InvalidParameterError listing both counts."""
    law = PDFeedforward(ROBOT, PDGains(kp=np.full((3, 1), 100.0), kd=10.0))  # 100 I per run
    with pytest.raises(InvalidParameterError, match="one number of runs N") as info:
        simulate_batch(law, Plant(ROBOT), TRAJECTORY, SHORT, q0_offsets=OFFSETS)
    assert info.value.value == {"offsets[0]": 4, "the controller's per-run gains": 3}


def test_offsets_of_the_wrong_shape_or_not_finite_are_refused() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"q0_offsets = 'shape \(4, 3\)' is invalid: expected shape \(4, 2\)"
    ):
        simulate_batch(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, SHORT, q0_offsets=np.zeros((4, 3)))
    bad = OFFSETS.copy()
    bad[2, 1] = np.nan
    with pytest.raises(InvalidParameterError, match=r"q0_offsets\[2, 1\] = nan"):
        simulate_batch(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, SHORT, q0_offsets=bad)


def test_the_adaptive_step_method_and_per_run_gains_in_simulate_are_refused() -> None:
    with pytest.raises(InvalidParameterError, match="'rk4' \\(the batch engine is fixed-step\\)"):
        simulate_batch(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, replace(SHORT, method="adaptive"))
    with pytest.raises(InvalidParameterError, match="simulate_batch runs N"):
        simulate(
            PDFeedforward(ROBOT, PDGains(kp=np.full((2, 1), 100.0), kd=10.0)), Plant(ROBOT), TRAJECTORY, SHORT
        )


def test_missing_parallel_algorithms_give_an_explaining_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """A Pinocchio built without its parallel module: BatchUnavailableError naming what is missing."""
    monkeypatch.delattr(pin, "rneaInParallel")
    with pytest.raises(BatchUnavailableError, match="has no rneaInParallel") as info:
        simulate_batch(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, SHORT, runs=2)
    assert info.value.missing == ("rneaInParallel",)


# --- sampled-data control ---------------------------------------------------------------------------------


def _held_reference(controller: Controller, plant: Plant, config: SimulationConfig, every: int) -> np.ndarray:
    """Zero-order hold written out plainly: law at t_k (k multiple of ``every``), RK4 on the plant."""
    n = config.steps
    dt = config.duration / n
    ref = TRAJECTORY.sample(np.arange(n + 1) * dt)
    q = ref.q[0] + np.array([0.1, -0.1])
    v = ref.v[0].copy()
    z = np.atleast_1d(controller.initial_state())
    qs = [q]
    tau = dz = None
    for k in range(n):
        if k % every == 0:
            tau, dz = evaluate(controller, q, v, ref.q[k], ref.v[k], ref.a[k], z)
            dz = np.zeros(0) if dz is None else dz

        def f(x: np.ndarray, tau: Any = tau) -> np.ndarray:
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
    """τ and ż computed at t_k and held for ``every`` steps: the engine matches a plain loop."""
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
    coarse = np.abs(runs[0].q - runs[1].q[::2]).max()
    fine = np.abs(runs[1].q - runs[2].q[::2]).max()
    assert fine < coarse / 8


# --- generality in nv: a 3-joint arm with gravity -------------------------------------------------------------

_LIMIT = '<limit lower="-3.14" upper="3.14" effort="200" velocity="10"/>'


def three_link_urdf(path: Path) -> Path:
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
    robot = load_robot(three_link_urdf(tmp_path_factory.mktemp("arm3") / "arm3.urdf"))
    via = np.array([[0.0, 0.3, -0.5], [0.4, 0.6, -0.2], [0.0, 0.3, -0.5]])
    return robot, JointTrajectory.from_via_q((0.0, 1.0, 2.0), via)


@pytest.mark.parametrize("name", ["pd", "adaptive"])
def test_three_joint_arm_single_and_batch_agree(arm3: tuple[RobotModel, JointTrajectory], name: str) -> None:
    """A 3-joint arm with gravity and all 30 inertial parameters: batch rows equal single runs."""
    robot, trajectory = arm3
    config = SimulationConfig(duration=0.1, q0_offset=(0.05, -0.05, 0.02))
    law = (
        PDFeedforward(robot, PDGains(kp=100.0, kd=20.0))
        if name == "pd"
        else Adaptive(robot, AdaptiveGains(k=20.0, gamma=1.0))
    )
    plant = Plant(robot)
    single = simulate(law, plant, trajectory, config)
    batch = simulate_batch(law, plant, trajectory, config, runs=2, record=True)
    _assert_run_equals(single, batch, 1)


def test_both_batch_regressors_equal_pinocchios_regressor_on_the_ur5() -> None:
    """The UR5's 36 base-parameter columns, run by run (the default for many columns) and from
    2 RNEA per column over polarisation forests of at most FOREST_NV joints: both equal
    ``computeJointTorqueRegressor(q, v, a) P`` at w = v, and ``Y p₀`` is RNEA at any w
    (the Christoffel form against Pinocchio's Coriolis matrix)."""
    from twolink_pin.simulation.terms import FOREST_NV, _Regressor, _RegressorByRun

    ur5 = load_robot("ur5")
    model, P = ur5.model, ur5.parameter_map.matrix
    rng = np.random.default_rng(3)
    q, v, w, a = (rng.uniform(-1.5, 1.5, (5, ur5.nv)) for _ in range(4))
    by_run = np.stack(_RegressorByRun(model, ur5.parameter_map)(q, v, v, a), axis=2)
    forest = _Regressor(model, ur5.parameter_map, 1, 5)
    assert forest.terms is not None and all(2 * k * ur5.nv <= FOREST_NV for k, *_ in forest.terms.groups)
    by_rnea = np.stack(forest(q, v, v, a), axis=2)
    data = model.createData()
    for i in range(5):
        expected = pin.computeJointTorqueRegressor(model, data, q[i], v[i], a[i]) @ P
        scale = max(1.0, float(np.abs(expected).max()))
        assert np.abs(by_run[i] - expected).max() <= TOL * scale
        assert np.abs(by_rnea[i] - expected).max() <= TOL * scale
    p0 = ur5.parameter_map.values(model)
    tau = np.einsum("nij,j->ni", np.stack(_RegressorByRun(model, ur5.parameter_map)(q, v, w, a), axis=2), p0)
    for i in range(5):
        M = pin.crba(model, data, q[i])
        M = np.triu(M) + np.triu(M, 1).T
        C = pin.computeCoriolisMatrix(model, data, q[i], v[i])
        g = pin.computeGeneralizedGravity(model, data, q[i])
        assert np.abs(tau[i] - (M @ a[i] + C @ w[i] + g)).max() <= TOL * max(1.0, float(np.abs(tau[i]).max()))


def test_a_batch_result_carries_the_reference_it_ran() -> None:
    """``result.trajectory`` is the reference: the recorded errors ``q − q_d(t)`` from it give
    the batch's own RMS |e| (trapezoidal rule, as :mod:`twolink_pin.metrics` defines it)."""
    controller, plant = make_scenario("pd", ROBOT)
    result = simulate_batch(controller, plant, TRAJECTORY, SHORT, q0_offsets=OFFSETS, record=True)
    assert result.trajectory is TRAJECTORY
    assert result.q is not None
    e = result.q - result.trajectory.sample(result.t).q[None]  # (N, K, nv)
    duration = result.t[-1] - result.t[0]
    rms = np.sqrt(np.trapezoid(e**2, result.t, axis=1) / duration)
    np.testing.assert_allclose(rms, result.metrics.rms.e, rtol=1e-9)


def test_state_variable_is_exported_at_the_top_level() -> None:
    import twolink_pin
    from twolink_pin.controllers.base import StateVariable

    assert "StateVariable" in twolink_pin.__all__ and twolink_pin.StateVariable is StateVariable
