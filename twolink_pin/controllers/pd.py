"""PD control with model feedforward (report eq. 8)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form
from twolink_pin.dynamics import joint_space_inertia
from twolink_pin.model import RobotModel

NATURAL_FREQUENCY = 10.0
"""ω [rad/s] of the robot-derived default gains ``Kp = ω² M(q₀)``, ``Kd = 2 ω M(q₀)``: at the
home ``q₀`` every mode of the error dynamics ``M ë + K_d ė + K_p e = 0`` is critically damped
at ω, however the joints are coupled (the generalised eigenvalues of ``(K_p, M)`` are all ω²)."""


@dataclass(frozen=True, eq=False)
class PDGains(Gains):
    r"""Gains of :class:`PDFeedforward` (report: $K_p = \operatorname{diag}(350, 300)$,
    $K_d = \operatorname{diag}(40, 50)$). Each is an nv × nv symmetric positive-definite matrix:
    a number (times I), nv numbers (a diagonal) or nv² numbers (row by row).

    Attributes:
        kp: Position gain $K_p$ [N·m/rad]; default $\omega^2 M(q_0)$.
        kd: Velocity gain $K_d$ [N·m·s/rad]; default $2 \omega M(q_0)$.
    """

    kp: Any = gain(None, per="joint", matrix=True, unit="N·m/rad", doc="position gain Kp")
    kd: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="velocity gain Kd")


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

    def __init__(self, robot: RobotModel, gains: PDGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self._kp, self._kd = applied_form(self.gains.kp), applied_form(self.gains.kd)

    def scaled_gains(self) -> dict[str, Any]:
        return pd_gains(self.robot)

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        tau = terms.model(x.q, x.v, x.v_des, x.a_des)
        return LawOutput(tau - (self._kp(x.q - x.q_des) + self._kd(x.v - x.v_des)))


def pd_gains(robot: RobotModel) -> dict[str, Any]:
    """``Kp = ω² M(q₀)``, ``Kd = 2 ω M(q₀)`` at the robot's home (ω: :data:`NATURAL_FREQUENCY`)."""
    inertia = joint_space_inertia(robot.model, robot.home)
    return {"kp": NATURAL_FREQUENCY**2 * inertia, "kd": 2.0 * NATURAL_FREQUENCY * inertia}
