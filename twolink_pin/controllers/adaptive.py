"""Slotine–Li adaptive control with the regressor from Pinocchio."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twolink_pin.controllers.base import Controller, diagonal_gain, positive_scalar
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA
from twolink_pin.dynamics import regressor
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class AdaptiveGains:
    """Gains of :class:`Adaptive` (the report's values).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal.
        gamma: The report's ``γ_i``; the adaptation gain is ``Γ = diag(1/γ_i)``.
        lam: ``λ`` [1/s] (not in the report; our default 5).
        initial_estimate: ``p̂(0) = initial_estimate × p`` (report: 50 % underestimated).
    """

    k: tuple[float, ...] = (120.0, 120.0)
    gamma: tuple[float, ...] = (0.5, 0.15, 0.6)
    lam: float = DEFAULT_LAMBDA
    initial_estimate: float = 0.5

    def __post_init__(self) -> None:
        diagonal_gain("k", self.k)
        diagonal_gain("gamma", self.gamma)
        positive_scalar("lam", self.lam, "1/s")
        if not (math.isfinite(self.initial_estimate) and self.initial_estimate >= 0):
            raise InvalidParameterError("initial_estimate", self.initial_estimate, "a finite factor >= 0")


class Adaptive(Controller):
    r"""Slotine–Li adaptive control (report "Adaptive Controller")::

        τ = Y(q, q̇, q̇_r, q̈_r) p̂ − K s,      dp̂/dt = −Γ Yᵀ s,   Γ = diag(1/γ_i)

    ``Y p = M(q) q̈_r + C(q, q̇) q̇_r + g(q)``; ``Y = Y_π P`` with ``Y_π`` Pinocchio's
    ``computeJointTorqueRegressor`` polarised to ``w = q̇_r ≠ q̇``
    (:func:`twolink_pin.dynamics.regressor`) and ``P`` the robot's parameter map. With
    ``V = ½ sᵀ M s + ½ p̃ᵀ Γ⁻¹ p̃``, ``V̇ = −sᵀ K s <= 0``: ``s → 0`` (Barbalat), while
    ``p̃`` converges only if the motion is persistently exciting. The state ``z`` is ``p̂``.
    """

    name = "adaptive"

    def __init__(self, robot: RobotModel, gains: AdaptiveGains | None = None) -> None:
        super().__init__(robot)
        self.gains = gains if gains is not None else AdaptiveGains()
        self.k = diagonal_gain("k", self.gains.k, robot.nv)
        self.lam = self.gains.lam
        self.P = robot.parameter_map.matrix
        self.p_true = self._true_parameters()
        self.Gamma = 1.0 / diagonal_gain("gamma", self.gains.gamma, len(self.p_true))

    def _true_parameters(self) -> np.ndarray:
        """The estimated parameters' true values: the robot's ``p``."""
        return np.array(self.robot.p, dtype=float)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.robot.parameter_map.names)

    def true_parameters(self) -> np.ndarray:
        return self.p_true.copy()

    def initial_state(self) -> np.ndarray:
        return self.gains.initial_estimate * self.p_true

    def regressor(self, q: np.ndarray, v: np.ndarray, v_r: np.ndarray, a_r: np.ndarray) -> np.ndarray:
        """``Y(q, q̇, q̇_r, q̈_r)``, shape (nv, len(p̂))."""
        return regressor(self.model, self.data, q, v, v_r, a_r) @ self.P

    def compute(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_des: np.ndarray,
        v_des: np.ndarray,
        a_des: np.ndarray,
        z: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        e = q - q_des
        edot = v - v_des
        s = edot + self.lam * e
        Y = self.regressor(q, v, v_des - self.lam * e, a_des - self.lam * edot)
        tau = Y @ z - self.k * s
        return tau, -self.Gamma * (Y.T @ s)
