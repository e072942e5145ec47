"""PD control with model feedforward (report eq. 8)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.dynamics import joint_inertia

NATURAL_FREQUENCY = 10.0
"""ω [rad/s] of the robot-derived default gains ``Kp = ω² I``, ``Kd = 2 ω I`` (critical
damping of each joint's inertia ``I = diag M(q₀)`` alone)."""


@dataclass(frozen=True, eq=False)
class PDGains(Gains):
    """Gains of :class:`PDFeedforward` (report: Kp = diag(350, 300), Kd = diag(40, 50)).

    Attributes:
        kp: Position gains ``Kp`` [N·m/rad], diagonal; default ``ω² diag M(q₀)``.
        kd: Velocity gains ``Kd`` [N·m·s/rad], diagonal; default ``2 ω diag M(q₀)``.
    """

    kp: Any = gain(None, per="joint", unit="N·m/rad", doc="position gain Kp")
    kd: Any = gain(None, per="joint", unit="N·m·s/rad", doc="velocity gain Kd")


class PDFeedforward(Controller[PDGains]):
    r"""PD with feedforward of the desired motion (report eq. 8)::

        τ = M(q) q̈_d + C(q, q̇) q̇_d + g(q) − Kp e − Kd ė

    (``g = 0`` for the horizontal twolink.) With ``V = ½ ėᵀ M ė + ½ eᵀ Kp e`` the report
    shows ``V̇ = −ėᵀ Kd ė`` (eqs. 9–10).
    """

    name = "pd"
    title = "PD + model feedforward"
    Gains = PDGains

    def scaled_gains(self) -> dict[str, Any]:
        inertia = joint_inertia(self.robot.model, self.robot.home)
        return {"kp": NATURAL_FREQUENCY**2 * inertia, "kd": 2.0 * NATURAL_FREQUENCY * inertia}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        tau = terms.model(x.q, x.v, x.v_des, x.a_des)
        return LawOutput(tau - (g.kp * (x.q - x.q_des) + g.kd * (x.v - x.v_des)))
