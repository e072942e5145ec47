"""PD control with gravity compensation (a regulator; no model feedforward)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.pd import NATURAL_FREQUENCY
from twolink_pin.dynamics import joint_inertia


@dataclass(frozen=True, eq=False)
class PDGravityGains(Gains):
    r"""Gains of :class:`PDGravity`.

    Attributes:
        kp: Position gains $K_p$ [N·m/rad], diagonal; default $\omega^2 \operatorname{diag} M(q_0)$.
        kd: Velocity gains $K_d$ [N·m·s/rad], diagonal; default $2 \omega \operatorname{diag} M(q_0)$.
    """

    kp: Any = gain(None, per="joint", unit="N·m/rad", doc="position gain Kp")
    kd: Any = gain(None, per="joint", unit="N·m·s/rad", doc="velocity gain Kd")


class PDGravity(Controller[PDGravityGains]):
    r"""PD plus gravity compensation:

    $$\tau = \hat g(q) - K_p e - K_d \dot e, \qquad e = q - q_d$$

    For a constant reference ($\dot q_d = 0$) and the exact gravity,
    $V = \tfrac12 \dot q^\top M \dot q + \tfrac12 e^\top K_p e$ gives $\dot V = -\dot q^\top K_d \dot q$ and LaSalle
    gives $e \to 0$ (Takegaki and Arimoto, "A new feedback method for dynamic control of
    manipulators", *J. Dyn. Sys., Meas., Control* 103(2), 1981). On a moving reference it
    lags (no feedforward of $M \ddot q_d + C \dot q_d$): compare ``pd``. Gains: each joint
    critically damped on its own inertia at ``home`` ($\omega$ = 10 rad/s), as ``pd``.
    """

    name = "pd-gravity"
    title = "PD + gravity compensation"
    Gains = PDGravityGains

    def scaled_gains(self) -> dict[str, Any]:
        inertia = joint_inertia(self.robot.model, self.robot.home)
        return {"kp": NATURAL_FREQUENCY**2 * inertia, "kd": 2.0 * NATURAL_FREQUENCY * inertia}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        return LawOutput(terms.gravity(x.q) - (g.kp * (x.q - x.q_des) + g.kd * (x.v - x.v_des)))
