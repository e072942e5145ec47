"""Slotine–Li "modified computed torque" control."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains, applied_form, apply_gain, gain
from twolink_pin.dynamics import joint_space_inertia
from twolink_pin.model import RobotModel

DEFAULT_LAMBDA = 5.0
"""λ [1/s]. The report never states its λ; 5 s⁻¹ is our documented default."""
SLIDING_RATE = 50.0
"""κ [1/s] of the robot-derived default ``K = κ M(q₀)``: at the home ``q₀`` every mode of
``M ṡ + K s = 0`` decays at exactly κ (the generalised eigenvalues of ``(K, M(q₀))``)."""


@dataclass(frozen=True, eq=False)
class SlotineLiGains(Gains):
    r"""Gains of :class:`ComputedTorque` (report: $K = \operatorname{diag}(40, 50)$, equal to PD's $K_d$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], an nv × nv symmetric positive-definite matrix (a
            number, nv numbers for a diagonal, nv² row by row); default $\kappa M(q_0)$.
        lam: $\lambda$ [1/s] in $s = \dot e + \lambda e$ (not in the report; our default 5).
    """

    k: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="sliding gain K")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")


class ComputedTorque(Controller[SlotineLiGains]):
    r"""Slotine–Li control with the exact model (report "Modified Computed Torque"):

    $$\tau = M(q)\,\ddot q_r + C(q, \dot q)\,\dot q_r + g(q) - K s$$

    with $e = q - q_d$, the sliding variable $s = \dot e + \lambda e$ and the reference
    $\dot q_r = \dot q_d - \lambda e$, $\ddot q_r = \ddot q_d - \lambda \dot e$.
    $V = \tfrac12 s^\top M s$ gives $\dot V = -s^\top K s$ (using that $\dot M - 2C$ is
    skew-symmetric), so $s \to 0$, and $e \to 0$ exponentially with rate $\lambda$ once on
    the surface $s = 0$. Slotine and Li, *Applied Nonlinear Control* (Prentice Hall,
    1991), chapter 9.
    """

    name = "computed-torque"
    title = "modified computed torque, Slotine–Li"
    Gains = SlotineLiGains

    def __init__(self, robot: RobotModel, gains: SlotineLiGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self._k = applied_form(self.gains.k)

    def scaled_gains(self) -> dict[str, Any]:
        return {"k": sliding_gain(self.robot)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        lam_e, edot = g.lam * (x.q - x.q_des), x.v - x.v_des
        tau = terms.model(x.q, x.v, x.v_des - lam_e, x.a_des - g.lam * edot)
        return LawOutput(tau - apply_gain(self._k, edot + lam_e))


def sliding_gain(robot: RobotModel) -> np.ndarray:
    """``K = κ M(q₀)`` [N·m·s/rad] at the robot's home (κ: :data:`SLIDING_RATE`), (nv, nv)."""
    return SLIDING_RATE * joint_space_inertia(robot.model, robot.home)
