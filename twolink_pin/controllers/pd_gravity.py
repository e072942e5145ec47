"""PD control with gravity compensation (a regulator; no model feedforward)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form
from twolink_pin.controllers.pd import pd_gains
from twolink_pin.model import RobotModel


@dataclass(frozen=True, eq=False)
class PDGravityGains(Gains):
    r"""Gains of :class:`PDGravity`.

    Attributes:
        kp: Position gain $K_p$ [N·m/rad], an nv × nv matrix; default $\omega^2 M(q_0)$.
        kd: Velocity gain $K_d$ [N·m·s/rad], an nv × nv matrix; default $2 \omega M(q_0)$.
    """

    kp: Any = gain(None, per="joint", matrix=True, unit="N·m/rad", doc="position gain Kp")
    kd: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="velocity gain Kd")


class PDGravity(Controller[PDGravityGains]):
    r"""PD plus gravity compensation:

    $$\tau = \hat g(q) - K_p e - K_d \dot e, \qquad e = q - q_d$$

    For a constant reference ($\dot q_d = 0$) and the exact gravity,
    $V = \tfrac12 \dot q^\top M \dot q + \tfrac12 e^\top K_p e$ gives $\dot V = -\dot q^\top K_d \dot q$ and LaSalle
    gives $e \to 0$ (Takegaki and Arimoto, "A new feedback method for dynamic control of
    manipulators", *J. Dyn. Sys., Meas., Control* 103(2), 1981). On a moving reference it
    lags (no feedforward of $M \ddot q_d + C \dot q_d$): compare ``pd``. Gains: every mode
    critically damped at ``home`` ($\omega$ = 10 rad/s: $K_p = \omega^2 M(q_0)$), as ``pd``.
    """

    name = "pd-gravity"
    title = "PD + gravity compensation"
    Gains = PDGravityGains

    def __init__(self, robot: RobotModel, gains: PDGravityGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self._kp, self._kd = applied_form(self.gains.kp), applied_form(self.gains.kd)

    def scaled_gains(self) -> dict[str, Any]:
        return pd_gains(self.robot)

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        feedback = self._kp(x.q - x.q_des) + self._kd(x.v - x.v_des)
        return LawOutput(terms.gravity(x.q) - feedback)
