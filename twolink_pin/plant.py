"""The simulated arm: Pinocchio's forward dynamics plus friction and motor saturation.

``q̈ = ABA(q, q̇, sat(τ) − f(q̇))`` where ``f`` is the optional joint friction
(:class:`twolink_pin.dynamics.Friction`; Pinocchio ignores URDF friction) and ``sat``
clips to the URDF torque limits when ``saturate`` is on (off by default, as in the report).
The plant owns its own ``pin.Data``, separate from the controller's.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics import ABA_CONVENTION, Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


class Plant:
    """Forward dynamics of ``robot`` with optional friction and torque saturation."""

    def __init__(self, robot: RobotModel, friction: Friction | None = None, saturate: bool = False) -> None:
        if friction is not None and len(friction.viscous) != robot.nv:
            raise InvalidParameterError(
                "friction", friction, f"viscous and coulomb of length nv = {robot.nv}"
            )
        self.robot = robot
        self.model = robot.model
        self.data = robot.create_data()
        self.friction = friction
        self.saturate = bool(saturate)
        self.limits = np.array(robot.torque_limits, dtype=float)

    def applied_torque(self, tau: np.ndarray) -> np.ndarray:
        """Motor torque actually applied [N·m]: ``tau`` clipped to the limits if saturating."""
        return np.clip(tau, -self.limits, self.limits) if self.saturate else tau

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint acceleration [rad/s²] under commanded torque ``tau`` [N·m]."""
        tau = self.applied_torque(tau)
        if self.friction is not None:
            tau = tau - self.friction.torque(v)
        return pin.aba(self.model, self.data, q, v, tau, ABA_CONVENTION)

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Mechanical energy ``½ q̇ᵀ M q̇ + U(q)`` [J]."""
        return float(pin.computeKineticEnergy(self.model, self.data, q, v)) + float(
            pin.computePotentialEnergy(self.model, self.data, q)
        )
