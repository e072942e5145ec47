"""Slotine–Li adaptive control that also estimates joint friction."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.base import StageKernel, literal
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA
from twolink_pin.dynamics import Friction, friction_regressor
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class AdaptiveFrictionGains(AdaptiveGains):
    """Gains of :class:`AdaptiveFriction` (the report's values).

    Attributes:
        gamma: ``γ`` for (p1, p2, p3, V1, V2, C1, C2); ``Γ = diag(1/γ_i)``.
        friction_initial_estimate: Friction estimates start at this factor × the true
            values (the report says only "close to their real values": we take 0.9).
    """

    k: tuple[float, ...] = (90.0, 90.0)
    gamma: tuple[float, ...] = (0.5, 0.15, 0.6, 1.7, 1.4, 2.5, 2.5)
    lam: float = DEFAULT_LAMBDA
    initial_estimate: float = 0.5
    friction_initial_estimate: float = 0.9

    def __post_init__(self) -> None:
        super().__post_init__()
        if not (math.isfinite(self.friction_initial_estimate) and self.friction_initial_estimate >= 0):
            raise InvalidParameterError(
                "friction_initial_estimate", self.friction_initial_estimate, "a finite factor >= 0"
            )


class AdaptiveFriction(Adaptive):
    r"""Adaptive control with viscous and Coulomb friction in the regressor::

        τ = [Y  Y_f] (p̂, f̂) − K s,    d(p̂, f̂)/dt = −Γ [Y  Y_f]ᵀ s,
        Y_f(q̇) = [diag(q̇), diag(sgn q̇)],  f̂ = (V̂_1..V̂_n, Ĉ_1..Ĉ_n)

    for the plant ``M q̈ + C q̇ + g + V q̇ + C_c sgn(q̇) = τ``. The friction model ``friction``
    gives the true values (report: V = (0.4, 0.2), C = (0.2, 0.1)) and the sign smoothing.
    """

    name = "adaptive-friction"

    def __init__(
        self, robot: RobotModel, gains: AdaptiveFrictionGains | None = None, friction: Friction | None = None
    ) -> None:
        self.friction = friction if friction is not None else Friction.report()
        if len(self.friction.viscous) != robot.nv:
            raise InvalidParameterError(
                "friction", self.friction, f"viscous and coulomb of length nv = {robot.nv}"
            )
        if gains is not None and not isinstance(gains, AdaptiveFrictionGains):
            raise InvalidParameterError(
                "gains",
                type(gains).__name__,
                "AdaptiveFrictionGains (it also sets the friction estimates' start)",
            )
        super().__init__(robot, gains if gains is not None else AdaptiveFrictionGains())

    def _true_parameters(self) -> np.ndarray:
        return np.concatenate([self.robot.p, self.friction.parameters])

    def parameters_of(self, robot: RobotModel, friction: Friction | None) -> np.ndarray:
        """The plant's p and friction ``(V, C)``; zeros for a plant without friction."""
        values = np.zeros(2 * robot.nv) if friction is None else friction.parameters
        return np.concatenate([super().parameters_of(robot, friction), values])

    @property
    def parameter_names(self) -> tuple[str, ...]:
        n = self.robot.nv
        return (
            *self.robot.parameter_map.names,
            *(f"V{i + 1}" for i in range(n)),
            *(f"C{i + 1}" for i in range(n)),
        )

    def initial_state(self) -> np.ndarray:
        assert isinstance(self.gains, AdaptiveFrictionGains)
        n_inertial = self.robot.parameter_map.size
        return np.concatenate(
            [
                self.gains.initial_estimate * self.p_true[:n_inertial],
                self.gains.friction_initial_estimate * self.p_true[n_inertial:],
            ]
        )

    def _extra_columns(self) -> tuple[list[str], list[dict[int, str]]] | None:
        if type(self).regressor is not AdaptiveFriction.regressor:
            return None
        nv, eps = self.robot.nv, self.friction.smoothing
        if eps == 0:
            lines = [f"c_sg{j} = (v{j} > 0.0) - (v{j} < 0.0)" for j in range(nv)]
        else:
            lines = [f"c_sg{j} = c_tanh(v{j} / {literal(eps)})" for j in range(nv)]
        columns = [{j: f"v{j}"} for j in range(nv)] + [{j: f"c_sg{j}"} for j in range(nv)]
        return lines, columns

    def stage_kernel(self) -> StageKernel | None:
        kernel = super().stage_kernel()
        if kernel is None:
            return None
        return StageKernel(kernel.lines, {**kernel.namespace, "c_tanh": math.tanh})

    def regressor(self, q: np.ndarray, v: np.ndarray, v_r: np.ndarray, a_r: np.ndarray) -> np.ndarray:
        return np.hstack([super().regressor(q, v, v_r, a_r), friction_regressor(v, self.friction.smoothing)])
