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
    r"""Gains of :class:`PDFeedforward` (report: $K_p = \operatorname{diag}(350, 300)$,
    $K_d = \operatorname{diag}(40, 50)$).

    Attributes:
        kp: Position gains $K_p$ [N·m/rad], diagonal; default $\omega^2 \operatorname{diag} M(q_0)$.
        kd: Velocity gains $K_d$ [N·m·s/rad], diagonal; default $2 \omega \operatorname{diag} M(q_0)$.
    """

    kp: Any = gain(None, per="joint", unit="N·m/rad", doc="position gain Kp")
    kd: Any = gain(None, per="joint", unit="N·m·s/rad", doc="velocity gain Kd")


class PDFeedforward(Controller[PDGains]):
    r"""PD with feedforward of the desired motion (report eq. 8):

    $$\tau = M(q)\,\ddot q_d + C(q, \dot q)\,\dot q_d + g(q) - K_p e - K_d \dot e$$

    with the tracking error $e = q - q_d$ ($g = 0$ for the horizontal twolink). With
    $V = \tfrac12 \dot e^\top M \dot e + \tfrac12 e^\top K_p e$ the report shows
    $\dot V = -\dot e^\top K_d \dot e$ (eqs. 9–10). The law is the "PD plus feedforward"
    of Spong, Hutchinson and Vidyasagar, *Robot Modeling and Control* (Wiley), chapter on
    multivariable control.
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
