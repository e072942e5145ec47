"""Slotine–Li "modified computed torque" control."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twolink_pin.controllers.base import (
    Controller,
    StageKernel,
    diagonal_gain,
    literal,
    model_term_kernel,
    positive_scalar,
)
from twolink_pin.dynamics import model_torque
from twolink_pin.model import RobotModel

DEFAULT_LAMBDA = 5.0
"""λ [1/s]. The report never states its λ; 5 s⁻¹ is our documented default."""


@dataclass(frozen=True)
class SlotineLiGains:
    """Gains of :class:`ComputedTorque` and :class:`WrongModel` (the report's values).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal (report: equal to PD's ``Kd``).
        lam: ``λ`` [1/s] in ``s = ė + λ e`` (not in the report; our default 5).
    """

    k: tuple[float, ...] = (40.0, 50.0)
    lam: float = DEFAULT_LAMBDA

    def __post_init__(self) -> None:
        diagonal_gain("k", self.k)
        positive_scalar("lam", self.lam, "1/s")


class ComputedTorque(Controller):
    r"""Slotine–Li control with the exact model (report "Modified Computed Torque")::

        τ = M(q) q̈_r + C(q, q̇) q̇_r + g(q) − K s,
        s = ė + λ e,  q̇_r = q̇_d − λ e,  q̈_r = q̈_d − λ ė

    ``V = ½ sᵀ M s`` gives ``V̇ = −sᵀ K s`` (using Ṁ − 2C skew-symmetric), so ``s → 0``
    and ``e → 0`` exponentially with rate λ once on the surface.
    """

    name = "computed-torque"
    model_scale = 1.0
    """Factor on the model terms (1: exact model)."""

    def __init__(self, robot: RobotModel, gains: SlotineLiGains | None = None) -> None:
        super().__init__(robot)
        self.gains = gains if gains is not None else SlotineLiGains()
        self.k = diagonal_gain("k", self.gains.k, robot.nv)
        self.lam = self.gains.lam

    def stage_kernel(self) -> StageKernel | None:
        if type(self).compute is not ComputedTorque.compute:
            return None
        nv, lam = self.robot.nv, literal(self.lam)
        lines = []
        for j in range(nv):
            lines.append(f"c_e{j} = q{j} - qd{j}")
            lines.append(f"c_ed{j} = v{j} - vd{j}")
        model_lines, namespace = model_term_kernel(
            self.model,
            nv,
            [f"vd{j} - {lam} * c_e{j}" for j in range(nv)],
            [f"ad{j} - {lam} * c_ed{j}" for j in range(nv)],
        )
        lines += model_lines
        scale = "" if self.model_scale == 1.0 else f"{literal(self.model_scale)} * "
        lines += [
            f"tau{j} = {scale}c_m{j} - {literal(self.k[j])} * (c_ed{j} + {lam} * c_e{j})" for j in range(nv)
        ]
        return StageKernel(tuple(lines), namespace)

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
        tau = model_torque(self.model, self.data, q, v, v_des - self.lam * e, a_des - self.lam * edot)
        if self.model_scale != 1.0:
            tau *= self.model_scale
        tau -= self.k * (edot + self.lam * e)
        return tau, z
