"""The task-space tutorial's law (examples/jacobian_transpose.py): its torque against the same
law written with Pinocchio directly, and it settles the UR5's end effector on a set point."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.controllers import load_controller
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, law_input, simulate, terms_for
from twolink_pin.trajectory import Trajectory, TrajectorySample

JacobianTranspose = load_controller("examples/jacobian_transpose.py:JacobianTranspose")
UR5 = load_robot("ur5")


class Hold(Trajectory):
    """A constant reference (a set point)."""

    def __init__(self, q: np.ndarray) -> None:
        self.q, self.t0, self.period = np.asarray(q, dtype=float), 0.0, 1.0

    @property
    def nv(self) -> int:
        return int(self.q.size)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        shape = (self.nv,) if np.ndim(t) == 0 else (np.size(t), self.nv)
        zero = np.zeros(shape)
        return TrajectorySample(np.broadcast_to(self.q, shape).copy(), zero, zero.copy(), zero.copy())


def test_torque_is_the_jacobian_transpose_law() -> None:
    """The law's torque against τ = Jᵀ(K e_x + D ė_x) + ĝ − D_q q̇ written with Pinocchio directly:
    the desired pose from the forward kinematics of the joint reference (what ``law_input``,
    like the engine, passes), the orientation error ``log(R_d Rᵀ)``."""
    law = JacobianTranspose(
        UR5,
        JacobianTranspose.Gains(k=((900.0, 50.0, 0.0), (50.0, 700.0, 0.0), (0.0, 0.0, 800.0)), k_rot=30.0),
    )
    terms = terms_for(law)
    model, data = UR5.model, UR5.model.createData()
    rng = np.random.default_rng(3)
    K = np.array([[900.0, 50.0, 0.0], [50.0, 700.0, 0.0], [0.0, 0.0, 800.0]])
    for _ in range(5):
        q, v, qd, vd, ad = rng.uniform(-1.5, 1.5, (5, 6))
        J = pin.computeFrameJacobian(model, data, q, UR5.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
        p, R = data.oMf[UR5.ee_frame_id].translation.copy(), data.oMf[UR5.ee_frame_id].rotation.copy()
        Jd = pin.computeFrameJacobian(model, data, qd, UR5.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
        pd, Rd = data.oMf[UR5.ee_frame_id].translation.copy(), data.oMf[UR5.ee_frame_id].rotation.copy()
        g = pin.computeGeneralizedGravity(model, data, q)
        twist_error = Jd @ vd - J @ v
        force = K @ (pd - p) + 100.0 * twist_error[:3]
        moment = 30.0 * pin.log3(Rd @ R.T) + 5.0 * twist_error[3:]
        expected = J.T @ np.concatenate((force, moment)) + g - 1.0 * v
        x = law_input(law, 0.0, q[None], v[None], np.zeros((1, 0)), qd[None], vd[None], ad[None])
        np.testing.assert_allclose(law.compute(x, terms).tau[0], expected, rtol=1e-10, atol=1e-9)


def test_it_settles_the_end_effector_on_a_set_point() -> None:
    home = UR5.home
    target = home + np.array([0.2, -0.2, 0.2, 0.0, 0.1, 0.0])
    result = simulate(
        JacobianTranspose(UR5),
        Plant(UR5),
        Hold(target),
        SimulationConfig(duration=3.0, q0_offset=tuple(home - target)),
    )
    model, data = UR5.model, UR5.model.createData()

    def position(q: np.ndarray) -> np.ndarray:
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[UR5.ee_frame_id].translation.copy()

    start = np.linalg.norm(position(np.asarray(result.q)[0]) - position(target))
    end = np.linalg.norm(position(np.asarray(result.q)[-1]) - position(target))
    assert start > 0.05 and end < 0.01 * start
