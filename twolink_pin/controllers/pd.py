"""PD control with model feedforward (report eq. 8)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twolink_pin.controllers.base import Controller, StageKernel, diagonal_gain, literal, model_term_kernel
from twolink_pin.dynamics import model_torque
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class PDGains:
    """Gains of :class:`PDFeedforward` (the report's values).

    Attributes:
        kp: Position gains ``Kp`` [N·m/rad], diagonal.
        kd: Velocity gains ``Kd`` [N·m·s/rad], diagonal.
    """

    kp: tuple[float, ...] = (350.0, 300.0)
    kd: tuple[float, ...] = (40.0, 50.0)

    def __post_init__(self) -> None:
        diagonal_gain("kp", self.kp)
        diagonal_gain("kd", self.kd, len(self.kp))


class PDFeedforward(Controller):
    r"""PD with feedforward of the desired motion (report eq. 8)::

        τ = M(q) q̈_d + C(q, q̇) q̇_d + g(q) − Kp e − Kd ė

    (``g = 0`` for the horizontal twolink.) With ``V = ½ ėᵀ M ė + ½ eᵀ Kp e`` the report
    shows ``V̇ = −ėᵀ Kd ė`` (eqs. 9–10). ``M``, ``C``, ``g`` come from Pinocchio on the
    controller's own Data.
    """

    name = "pd"

    def __init__(self, robot: RobotModel, gains: PDGains | None = None) -> None:
        super().__init__(robot)
        self.gains = gains if gains is not None else PDGains()
        self.kp = diagonal_gain("kp", self.gains.kp, robot.nv)
        self.kd = diagonal_gain("kd", self.gains.kd, robot.nv)

    def stage_kernel(self) -> StageKernel | None:
        if type(self).compute is not PDFeedforward.compute:
            return None
        nv = self.robot.nv
        lines, namespace = model_term_kernel(
            self.model, nv, [f"vd{j}" for j in range(nv)], [f"ad{j}" for j in range(nv)]
        )
        lines += [
            f"tau{j} = c_m{j} - ({literal(self.kp[j])} * (q{j} - qd{j}) + {literal(self.kd[j])} * (v{j} - vd{j}))"
            for j in range(nv)
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
        tau = model_torque(self.model, self.data, q, v, v_des, a_des)
        tau -= self.kp * (q - q_des) + self.kd * (v - v_des)
        return tau, z
