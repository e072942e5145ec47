"""The report's "Robust Controller": Slotine–Li with a deliberately wrong model."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA, SLIDING_RATE
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.dynamics import joint_inertia


@dataclass(frozen=True, eq=False)
class WrongModelGains(Gains):
    """Gains of :class:`WrongModel` (report: K = diag(40, 50), β = 0.5).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal; default ``κ diag M(q₀)``.
        lam: ``λ`` [1/s] in ``s = ė + λ e``.
        model_scale: ``β``, the factor on the model terms (report: 0.5), >= 0.
    """

    k: Any = gain(None, per="joint", unit="N·m·s/rad", doc="sliding gain K")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")
    model_scale: Any = gain(0.5, bound="nonnegative", doc="β: M̂ = β M, Ĉ = β C, ĝ = β g")


class WrongModel(Controller[WrongModelGains]):
    r"""Slotine–Li control on a scaled model ``M̂ = β M``, ``Ĉ = β C``, ``ĝ = β g``::

        τ = β [M(q) q̈_r + C(q, q̇) q̇_r + g(q)] − K s      (report: β = 0.5)

    Despite the report's name "Robust Controller" there is no robustifying term (no
    switching or saturated ``−k sgn(s)`` term sized on the model error bound): it is law 2
    with every inertial parameter scaled by β, which shows what model error alone does.
    The tracking error stays bounded and periodic but does not vanish.
    """

    name = "robust"
    title = "Slotine–Li law with M̂ = β M, Ĉ = β C (report: β = 0.5)"
    Gains = WrongModelGains

    def scaled_gains(self) -> dict[str, Any]:
        return {"k": SLIDING_RATE * joint_inertia(self.robot.model, self.robot.home)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        lam_e, edot = g.lam * (x.q - x.q_des), x.v - x.v_des
        tau = terms.model(x.q, x.v, x.v_des - lam_e, x.a_des - g.lam * edot)
        return LawOutput(g.model_scale * tau - g.k * (edot + lam_e))
