"""The report's "Robust Controller": Slotine–Li with a deliberately wrong model."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA, sliding_gain
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form, applied_scalar
from twolink_pin.model import RobotModel


@dataclass(frozen=True, eq=False)
class WrongModelGains(Gains):
    r"""Gains of :class:`WrongModel` (report: $K = \operatorname{diag}(40, 50)$, $\beta = 0.5$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], an nv × nv matrix; default $\kappa M(q_0)$.
        lam: $\lambda$ [1/s] in $s = \dot e + \lambda e$.
        model_scale: $\beta$, the factor on the model terms (report: 0.5), >= 0.
    """

    k: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="sliding gain K")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")
    model_scale: Any = gain(0.5, bound="nonnegative", doc="β: M̂ = β M, Ĉ = β C, ĝ = β g")


class WrongModel(Controller[WrongModelGains]):
    r"""Slotine–Li control on a scaled model $\hat M = \beta M$, $\hat C = \beta C$, $\hat g = \beta g$:

    $$\tau = \beta \left[ M(q)\,\ddot q_r + C(q, \dot q)\,\dot q_r + g(q) \right] - K s$$

    (report: $\beta = 0.5$), with $s$, $\dot q_r$ and $\ddot q_r$ as in :class:`ComputedTorque`.
    Despite the report's name "Robust Controller" there is no robustifying term (no
    switching or saturated $-k \operatorname{sgn}(s)$ term sized on the model error bound,
    as in Slotine and Li, *Applied Nonlinear Control*, chapter 7): it is law 2 with every
    inertial parameter scaled by $\beta$, which shows what model error alone does. The
    tracking error stays bounded and periodic but does not vanish.
    """

    name = "robust"
    title = "Slotine–Li law with M̂ = β M, Ĉ = β C (report: β = 0.5)"
    Gains = WrongModelGains

    def __init__(self, robot: RobotModel, gains: WrongModelGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        g = self.gains
        self._k, self._lam, self._beta = (
            applied_form(g.k),
            applied_scalar(g.lam),
            applied_scalar(g.model_scale),
        )

    def scaled_gains(self) -> dict[str, Any]:
        return {"k": sliding_gain(self.robot)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        lam = self._lam
        lam_e, edot = lam * (x.q - x.q_des), x.v - x.v_des
        tau = terms.model(x.q, x.v, x.v_des - lam_e, x.a_des - lam * edot)
        return LawOutput(self._beta * tau - self._k(edot + lam_e))
