"""Shared pieces of the closed-loop tests (imported explicitly, not a pytest conftest).

One robot and one reference trajectory for every test, the report's five scenarios run
once per session (:func:`run`, cached: a 30-s RK4 run costs 3 s for ``pd`` to 10 s for
``adaptive-friction``), two trivial controllers for plant tests, and the Lyapunov
function of the adaptive laws.
"""

from __future__ import annotations

import functools

import numpy as np

from twolink_pin.controllers import Adaptive, Controller
from twolink_pin.dynamics import mass_matrix
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.scenarios import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import JointTrajectory, build_trajectory

ROBOT: RobotModel = load_robot()
TRAJECTORY: JointTrajectory = build_trajectory(ROBOT)
CONTROLLER_NAMES = ("pd", "computed-torque", "robust", "adaptive", "adaptive-friction")


@functools.cache
def run(
    name: str,
    duration: float = 30.0,
    dt: float = 1.0e-3,
    method: str = "rk4",
    friction_smoothing: float = 0.0,
    saturate: bool = False,
    q0_offset: tuple[float, ...] = (0.1, -0.1),
) -> SimulationResult:
    """The report's scenario ``name`` with these settings, simulated once per session."""
    controller, plant = make_scenario(name, ROBOT, saturate=saturate, friction_smoothing=friction_smoothing)
    config = SimulationConfig(duration=duration, dt=dt, method=method, q0_offset=q0_offset)
    return simulate(controller, plant, TRAJECTORY, config)


class ConstantTorque(Controller):
    """Open loop ``τ = τ_0`` [N·m] whatever the state (zero by default)."""

    name = "constant-torque"

    def __init__(self, robot: RobotModel, torque: tuple[float, ...] | None = None) -> None:
        super().__init__(robot)
        self.torque = np.zeros(robot.nv) if torque is None else np.array(torque, dtype=float)

    def compute(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_des: np.ndarray,
        v_des: np.ndarray,
        a_des: np.ndarray,
        z: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        return self.torque.copy(), z


def slotine_li_s(result: SimulationResult, lam: float) -> np.ndarray:
    """``s = ė + λ e`` [rad/s] on the output grid, shape (N, nv)."""
    return result.edot + lam * result.e


def adaptive_lyapunov(result: SimulationResult, controller: Adaptive) -> np.ndarray:
    """``V = ½ sᵀ M(q) s + ½ p̃ᵀ Γ⁻¹ p̃`` [J] on the output grid, shape (N,).

    ``M`` is the plant's (Pinocchio, CRBA), ``Γ⁻¹ = diag(γ_i)`` and ``p̃ = p̂ − p`` over
    every estimated parameter (the friction ones included for ``adaptive-friction``).
    """
    assert result.p_hat is not None and result.p_true is not None
    data = ROBOT.create_data()
    s = slotine_li_s(result, controller.lam)
    kinetic = np.array(
        [0.5 * s[k] @ mass_matrix(ROBOT.model, data, result.q[k]) @ s[k] for k in range(len(s))]
    )
    p_tilde = result.p_hat - result.p_true
    return kinetic + 0.5 * np.einsum("ij,j,ij->i", p_tilde, 1.0 / controller.Gamma, p_tilde)
