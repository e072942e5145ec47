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
    """Gains of :class:`ComputedTorque` (report: K = diag(40, 50), equal to PD's Kd).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal; default ``κ diag M(q₀)``.
        lam: ``λ`` [1/s] in ``s = ė + λ e`` (not in the report; our default 5).
    """

    k: Any = gain(None, per="joint", unit="N·m·s/rad", doc="sliding gain K")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")


class ComputedTorque(Controller[SlotineLiGains]):
    r"""Slotine–Li control with the exact model (report "Modified Computed Torque")::

        τ = M(q) q̈_r + C(q, q̇) q̇_r + g(q) − K s,
        s = ė + λ e,  q̇_r = q̇_d − λ e,  q̈_r = q̈_d − λ ė

    ``V = ½ sᵀ M s`` gives ``V̇ = −sᵀ K s`` (using Ṁ − 2C skew-symmetric), so ``s → 0``
    and ``e → 0`` exponentially with rate λ once on the surface.
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
