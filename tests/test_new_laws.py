"""The built-in laws beyond the joint space: ``pd-gravity``, ``pid``, ``osc``, ``impedance``.

Each against what its design promises, computed independently:

* ``osc`` on the Panda with the exact model: the end effector's position error follows the
  designed ``ë + D ė + K e = 0`` — compared with that ODE's solution ``exp(A t) x₀`` — to
  1e-6 m, its orientation error obeys ``ω̃̇ + D ω̃ + K e_o = 0`` (finite differences), and the
  posture task leaves the task error unchanged;
* ``impedance`` under a constant wrench settles at ``e = K⁻¹ F``;
* ``pid`` removes the steady error of a constant disturbance that ``pd`` keeps, and that
  error is ``pd``'s ``K_p⁻¹ Jᵀ F``;
* ``pd-gravity`` holds a gravity-loaded arm at its set point;
* every new law runs on the twolink, the UR5 and the Panda, and a batch equals N single runs.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pinocchio as pin
import pytest
from scipy.linalg import expm

from twolink_pin.controllers import (
    PID,
    Impedance,
    OperationalSpace,
    OSCGains,
    PDFeedforward,
    PDGravity,
    load_controller,
)
from twolink_pin.disturbances import Wrench
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.studies.batch import simulate_batch
from twolink_pin.trajectory import Trajectory, TrajectorySample, default_trajectory

NEW_LAWS = ("pd-gravity", "pid", "osc", "impedance")


@functools.cache
def robot(name: str) -> RobotModel:
    return load_robot(name)


class Hold(Trajectory):
    """A constant reference ``q_d`` (a set point)."""

    def __init__(self, q: np.ndarray, period: float = 1.0) -> None:
        self.q = np.asarray(q, dtype=float)
        self.t0, self.period = 0.0, period

    @property
    def nv(self) -> int:
        return int(self.q.size)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        shape = (self.nv,) if np.ndim(t) == 0 else (np.size(t), self.nv)
        zero = np.zeros(shape)
        return TrajectorySample(np.broadcast_to(self.q, shape).copy(), zero, zero.copy(), zero.copy())


def _frame(r: RobotModel, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, rotation and world-aligned twist of the end effector at each row."""
    data = r.model.createData()
    P, R, W = np.empty((len(q), 3)), np.empty((len(q), 3, 3)), np.empty((len(q), 6))
    for i in range(len(q)):
        J = pin.computeFrameJacobian(r.model, data, q[i], r.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
        P[i], R[i] = data.oMf[r.ee_frame_id].translation, data.oMf[r.ee_frame_id].rotation
        W[i] = J @ v[i]
    return P, R, W


def _task_errors(r: RobotModel, result: SimulationResult) -> tuple[np.ndarray, ...]:
    P, R, W = _frame(r, np.asarray(result.q), np.asarray(result.v))
    Pd, Rd, Wd = _frame(r, np.asarray(result.q_des), np.asarray(result.v_des))
    e_o = np.array([pin.log3(R[i] @ Rd[i].T) for i in range(len(R))])
    return P - Pd, (W - Wd)[:, :3], e_o, (W - Wd)[:, 3:]


def _linear_response(
    K: np.ndarray, D: np.ndarray, e0: np.ndarray, de0: np.ndarray, t: np.ndarray
) -> np.ndarray:
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-K, -D]])
    x0 = np.concatenate([e0, de0])
    return np.array([(expm(A * s) @ x0)[:3] for s in t])


OSC_GAINS = OSCGains(
    kp=np.diag([100.0, 64.0, 144.0]),
    kd=np.diag([20.0, 12.0, 30.0]),
    kp_rot=((90.0, 10.0, 0.0), (10.0, 80.0, 0.0), (0.0, 0.0, 70.0)),
    kd_rot=18.0,
)


@functools.cache
def _osc_run(kp_null: float, kd_null: float) -> SimulationResult:
    r = robot("panda")
    law = OperationalSpace(r, OSCGains(**{**OSC_GAINS.values(), "kp_null": kp_null, "kd_null": kd_null}))
    config = SimulationConfig(duration=0.5, q0_offset=0.05, v0_offset=(0.1, -0.1, 0.0, 0.1, 0.0, -0.1, 0.1))
    return simulate(law, Plant(r), default_trajectory(r), config)


def test_osc_position_error_follows_the_designed_linear_dynamics() -> None:
    r = robot("panda")
    result = _osc_run(25.0, 10.0)
    e, de, _, _ = _task_errors(r, result)
    assert np.abs(e[0]).max() > 0.02  # a real initial error
    expected = _linear_response(
        np.diag([100.0, 64.0, 144.0]), np.diag([20.0, 12.0, 30.0]), e[0], de[0], result.t
    )
    assert np.abs(e - expected).max() < 1e-6
    assert np.abs(e[-1]).max() < 0.1 * np.abs(e[0]).max()


def test_osc_on_the_planar_twolink_controls_x_and_y_by_their_designed_dynamics() -> None:
    """The twolink's home (stretched along x) moves its tip in y only; the task is still the
    plane's x and y, each error following ``ë + D ė + K e = 0`` with its own gains (a task
    chosen at home alone left x to drift)."""
    r = robot("twolink")
    K, D = np.diag([100.0, 64.0, 1.0]), np.diag([20.0, 12.0, 1.0])
    law = OperationalSpace(r, OSCGains(kp=K, kd=D))
    q_d = np.array([0.6, 1.2])
    config = SimulationConfig(duration=0.6, q0_offset=(0.08, -0.1))
    result = simulate(law, Plant(r), Hold(q_d), config)
    e, de, _, _ = _task_errors(r, result)
    assert np.abs(e[0, :2]).min() > 0.01  # a real initial error in x and in y
    expected = _linear_response(K, D, e[0], de[0], result.t)
    assert np.abs(e[:, :2] - expected[:, :2]).max() < 1e-6
    assert np.abs(e[:, 2]).max() < 1e-12  # the plane


def test_osc_orientation_error_obeys_its_designed_dynamics() -> None:
    r = robot("panda")
    result = _osc_run(25.0, 10.0)
    _, _, e_o, w = _task_errors(r, result)
    K = np.array(OSC_GAINS.kp_rot)[0]
    dt = result.dt
    dw = (w[2:] - w[:-2]) / (2 * dt)  # central differences
    residual = dw + 18.0 * w[1:-1] + e_o[1:-1] @ K.T
    assert np.abs(e_o[0]).max() > 0.02
    assert np.abs(residual).max() < 1e-4 * np.abs(e_o[1:-1] @ K.T).max()
    assert np.abs(e_o[-1]).max() < 0.1 * np.abs(e_o[0]).max()


def test_osc_posture_task_leaves_the_task_error_unchanged() -> None:
    r = robot("panda")
    soft, stiff = _osc_run(1.0, 2.0), _osc_run(100.0, 20.0)
    assert np.abs(np.asarray(soft.q) - np.asarray(stiff.q)).max() > 1e-3  # the postures differ
    a, b = _task_errors(r, soft), _task_errors(r, stiff)
    assert np.abs(a[0] - b[0]).max() < 1e-9
    assert np.abs(a[2] - b[2]).max() < 1e-8


def test_impedance_settles_at_the_stiffness_inverse_times_the_wrench() -> None:
    r = robot("panda")
    force = np.array([12.0, -6.0, 9.0, 0.5, -0.3, 0.2])
    # K e = F at rest holds for any stiffness: isotropic blocks ω² m and 2 ω m (ω = 10 rad/s, m the
    # mean diagonal of the Panda's Λ blocks at home, 6.8 kg and 0.23 kg·m²), which settle within
    # the 6 s (the default's blocks, ω² times the Schur complements of Λ, leave a slow mode here)
    defaults = Impedance(r).gains
    law = Impedance(r, dataclasses.replace(defaults, k=680.0, d=136.0, k_rot=23.0, d_rot=4.6))
    plant = Plant(r, wrench=Wrench(tuple(force)))
    result = simulate(law, plant, Hold(r.home), SimulationConfig(duration=6.0, q0_offset=0.0))
    e, _, e_o, _ = _task_errors(r, result)
    K = np.zeros((6, 6))
    K[:3, :3] = law.gains.k[0]
    K[3:, 3:] = law.gains.k_rot[0]
    expected = np.linalg.solve(K, force)
    assert np.abs(expected[:3]).max() > 1e-3
    np.testing.assert_allclose(e[-1], expected[:3], rtol=0, atol=1e-6)
    np.testing.assert_allclose(e_o[-1], expected[3:], rtol=0, atol=1e-6)


def test_pid_removes_the_steady_error_of_a_constant_disturbance_pd_keeps() -> None:
    r = robot("twolink")
    q_set = np.array([0.6, 0.9])
    plant = Plant(r, wrench=Wrench((4.0, -3.0, 0.0)))
    config = SimulationConfig(duration=6.0, q0_offset=0.0)
    pd = simulate(PDFeedforward(r), plant, Hold(q_set), config)
    pid = simulate(PID(r), plant, Hold(q_set), config)
    e_pd, e_pid = np.asarray(pd.e)[-1], np.asarray(pid.e)[-1]
    # pd's static error solves K_p e = J(q)ᵀ F at the final q
    data = r.model.createData()
    J = pin.computeFrameJacobian(r.model, data, np.asarray(pd.q)[-1], r.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    kp = np.asarray(PDFeedforward(r).gains.kp)[0]
    np.testing.assert_allclose(e_pd, np.linalg.solve(kp, J[:3].T @ np.array([4.0, -3.0, 0.0])), rtol=1e-6)
    assert np.abs(e_pd).max() > 5e-3
    assert np.abs(e_pid).max() < 1e-6
    assert pid.state_names == ("∫e1", "∫e2") and pid.state is not None


def test_pid_integrator_stops_beyond_the_torque_limits() -> None:
    """Sampled law (ż held per step): the integral moves by exactly 0 on the steps where the
    command is beyond the limit and the integral term pushes it further, by dt e elsewhere."""
    r = robot("twolink")
    limit = float(r.torque_limits[0])
    assert np.isfinite(limit)
    law = PID(r, PID.Gains(kp=(limit / 2, limit / 2), ki=(limit, limit), kd=(1.0, 1.0)))
    config = SimulationConfig(duration=1.0, q0_offset=(-2.5, 0.0), control_period=1e-3)
    result = simulate(law, Plant(r, saturate=True), Hold(np.array([2.5, 0.0])), config)
    tau, e = np.asarray(result.tau_command)[:-1, 0], np.asarray(result.e)[:-1, 0]
    step = np.diff(np.asarray(result.state)[:, 0])
    frozen = (np.abs(tau) >= limit) & (np.sign(-limit * e) == np.sign(tau))
    assert frozen.sum() > 10 and (~frozen).sum() > 10
    assert np.all(step[frozen] == 0.0)
    np.testing.assert_allclose(step[~frozen], result.dt * e[~frozen], rtol=1e-9, atol=1e-15)


def test_pd_gravity_holds_a_set_point_under_gravity() -> None:
    r = robot("ur5")
    q_set = r.home + 0.1
    result = simulate(PDGravity(r), Plant(r), Hold(q_set), SimulationConfig(duration=3.0, q0_offset=0.05))
    assert np.abs(np.asarray(result.e)[0]).max() == pytest.approx(0.05)
    assert np.abs(np.asarray(result.e)[-1]).max() < 1e-6


@pytest.mark.parametrize("name", ["twolink", "ur5", "panda"])
@pytest.mark.parametrize("law", NEW_LAWS)
def test_every_new_law_runs_on_every_robot_and_reduces_the_error(name: str, law: str) -> None:
    r = robot(name)
    controller = load_controller(law)(r)
    result = simulate(
        controller, Plant(r), Hold(r.home + 0.1), SimulationConfig(duration=1.5, q0_offset=0.05)
    )
    if law in ("osc", "impedance"):
        P, _, _ = _frame(r, np.asarray(result.q), np.asarray(result.v))
        Pd, _, _ = _frame(r, np.asarray(result.q_des), np.asarray(result.v_des))
        error = np.linalg.norm(P - Pd, axis=1)
    else:
        error = np.linalg.norm(np.asarray(result.e), axis=1)
    assert error[-1] < 0.2 * error[0]


@pytest.mark.parametrize(("law", "name"), [(law, "twolink") for law in NEW_LAWS] + [("osc", "panda")])
def test_batch_equals_single_runs(law: str, name: str) -> None:
    r = robot(name)
    cls = load_controller(law)
    trajectory = default_trajectory(r)
    offsets = np.array([np.full(r.nv, 0.05), np.zeros(r.nv), np.linspace(-0.1, 0.1, r.nv)])
    config = SimulationConfig(duration=0.2)
    batch = simulate_batch(cls(r), Plant(r), trajectory, config, q0_offsets=offsets, threads=1, record=True)
    assert batch.q is not None
    for i, offset in enumerate(offsets):
        single = simulate(
            cls(r), Plant(r), trajectory, SimulationConfig(duration=0.2, q0_offset=tuple(offset))
        )
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-9)
        if single.state is not None:
            assert batch.state_final is not None
            np.testing.assert_allclose(batch.state_final[i], single.state[-1], rtol=0, atol=1e-9)
