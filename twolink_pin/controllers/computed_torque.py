"""Slotine–Li "modified computed torque" control."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.dynamics import joint_inertia

DEFAULT_LAMBDA = 5.0
"""λ [1/s]. The report never states its λ; 5 s⁻¹ is our documented default."""
SLIDING_RATE = 50.0
"""κ [1/s] of the robot-derived default ``K = κ diag M(q₀)``: each joint's ``s`` decays at
about κ on its own inertia."""


@dataclass(frozen=True, eq=False)
class SlotineLiGains(Gains):
    r"""Gains of :class:`ComputedTorque` (report: $K = \operatorname{diag}(40, 50)$, equal to PD's $K_d$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], diagonal; default $\kappa \operatorname{diag} M(q_0)$.
        lam: $\lambda$ [1/s] in $s = \dot e + \lambda e$ (not in the report; our default 5).
    """

    k: Any = gain(None, per="joint", unit="N·m·s/rad", doc="sliding gain K")
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

    def scaled_gains(self) -> dict[str, Any]:
        return {"k": SLIDING_RATE * joint_inertia(self.robot.model, self.robot.home)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        lam_e, edot = g.lam * (x.q - x.q_des), x.v - x.v_des
        tau = terms.model(x.q, x.v, x.v_des - lam_e, x.a_des - g.lam * edot)
        return LawOutput(tau - g.k * (edot + lam_e))
