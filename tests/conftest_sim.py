"""Shared pieces of the closed-loop tests (imported explicitly, not a pytest conftest).

One robot and one reference trajectory for every test, the report's five scenarios run
once per session (:func:`run`, cached: a 30-s RK4 run costs 1.5 s for ``pd`` to 3.5 s for
``adaptive-friction``), a law evaluated at given states (:func:`evaluate`), a trivial law
for plant tests, and the Lyapunov function of the adaptive laws.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers import Adaptive, Controller, Gains, LawInput, LawOutput, Terms, gain
from twolink_pin.controllers.gains import one_row
from twolink_pin.dynamics import mass_matrix
from twolink_pin.model import RobotModel, example_robot_urdf, load_robot
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, law_input, simulate, terms_for
from twolink_pin.trajectory import JointTrajectory, default_trajectory

ROBOT: RobotModel = load_robot()
TRAJECTORY: JointTrajectory = default_trajectory(ROBOT)
CONTROLLER_NAMES = ("pd", "computed-torque", "robust", "adaptive", "adaptive-friction")
PENDULUM_URDF = "double_pendulum_description/urdf/double_pendulum.urdf"
"""example-robot-data's double pendulum: two revolute joints in a vertical plane, gravity."""


@functools.cache
def pendulum() -> RobotModel:
    """The double pendulum (gravity acts on both joints)."""
    return load_robot(str(example_robot_urdf(PENDULUM_URDF)))


@functools.cache
def run(
    name: str,
    duration: float = 30.0,
    dt: float = 1.0e-3,
    method: str = "rk4",
    friction_smoothing: float = 0.0,
    saturate: bool = False,
    q0_offset: tuple[float, ...] | None = None,
) -> SimulationResult:
    """The report's scenario ``name`` with these settings, simulated once per session."""
    controller, plant = make_scenario(name, ROBOT, saturate=saturate, friction_smoothing=friction_smoothing)
    config = SimulationConfig(duration=duration, dt=dt, method=method, q0_offset=q0_offset)
    return simulate(controller, plant, TRAJECTORY, config)


def evaluate(
    controller: Controller,
    q: np.ndarray,
    v: np.ndarray,
    q_des: np.ndarray,
    v_des: np.ndarray,
    a_des: np.ndarray,
    z: np.ndarray | None = None,
    t: float = 0.0,
) -> tuple[np.ndarray, np.ndarray | None]:
    """The law at one state (single-run terms): ``(τ, ż)`` of shapes (nv,), (nz,) or None."""
    z = np.atleast_1d(controller.initial_state()) if z is None else z
    x = law_input(
        controller, t, q[None], v[None], np.reshape(z, (1, -1)), q_des[None], v_des[None], a_des[None]
    )
    out = controller.compute(x, terms_for(controller))
    return out.tau[0], None if out.dz is None else out.dz[0]


@dataclass(frozen=True, eq=False)
class ConstantTorqueGains(Gains):
    """Gains of :class:`ConstantTorque`: the torque itself [N·m] (0 by default)."""

    torque: Any = gain(0.0, per="joint", unit="N·m", bound="any")


class ConstantTorque(Controller, register=False):
    """Open loop ``τ = τ_0`` [N·m] whatever the state (zero by default)."""

    name = "test-constant-torque"
    title = "constant torque (tests)"
    Gains = ConstantTorqueGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput(np.zeros_like(x.q) + self.gains.torque)


def slotine_li_s(result: SimulationResult, lam: float) -> np.ndarray:
    """``s = ė + λ e`` [rad/s] on the output grid, shape (K, nv)."""
    return result.edot + lam * result.e


def adaptive_lyapunov(result: SimulationResult, controller: Adaptive) -> np.ndarray:
    """``V = ½ sᵀ M(q) s + ½ p̃ᵀ Γ⁻¹ p̃`` [J] on the output grid, shape (K,).

    ``M`` is the plant's (Pinocchio, CRBA), ``Γ⁻¹ = diag(γ_i)`` and ``p̃ = p̂ − p`` over
    every estimated parameter (the friction ones included for ``adaptive-friction``).
    """
    assert result.p_hat is not None and result.p_true is not None
    data = ROBOT.create_data()
    s = slotine_li_s(result, float(controller.gains.lam))
    kinetic = np.array(
        [0.5 * s[k] @ mass_matrix(ROBOT.model, data, result.q[k]) @ s[k] for k in range(len(s))]
    )
    p_tilde = result.p_hat - result.p_true
    gamma = one_row(controller.gains.gamma, p_tilde.shape[1])
    return kinetic + 0.5 * np.einsum("ij,j,ij->i", p_tilde, gamma, p_tilde)
