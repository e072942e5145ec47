"""PID control with model feedforward and an integrator that stops at the torque limits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller, StateVariable
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form
from twolink_pin.controllers.pd import NATURAL_FREQUENCY
from twolink_pin.dynamics import joint_space_inertia


@dataclass(frozen=True, eq=False)
class PIDGains(Gains):
    r"""Gains of :class:`PID`, each an nv × nv symmetric positive-definite matrix. Defaults
    place every closed-loop pole at $-\omega$ at the home $q_0$, with $M = M(q_0)$:
    $M s^3 + K_d s^2 + K_p s + K_i = M (s + \omega)^3$.

    Attributes:
        kp: Position gain $K_p$ [N·m/rad]; default $3 \omega^2 M$.
        ki: Integral gain $K_i$ [N·m/(rad·s)]; default $\omega^3 M$.
        kd: Velocity gain $K_d$ [N·m·s/rad]; default $3 \omega M$.
    """

    kp: Any = gain(None, per="joint", matrix=True, unit="N·m/rad", doc="position gain Kp")
    ki: Any = gain(None, per="joint", matrix=True, unit="N·m/(rad·s)", doc="integral gain Ki")
    kd: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="velocity gain Kd")


class PID(Controller[PIDGains]):
    r"""PID with model feedforward and conditional-integration anti-windup:

    $$\tau = \hat M(q)\,\ddot q_d + \hat C(q, \dot q)\,\dot q_d + \hat g(q)
    - K_p e - K_i \xi - K_d \dot e, \qquad
    \dot\xi_j = \begin{cases} 0 & |\tau_j| \ge \tau_{\max,j} \text{ and } \operatorname{sgn}(-(K_i e)_j) = \operatorname{sgn}\tau_j \\ e_j & \text{otherwise} \end{cases}$$

    with $e = q - q_d$ and the state $\xi = \int e\,dt$ [rad·s] (``∫e1`` …, starting at 0).
    With $K_i = 0$ it is ``pd``. The integral removes the steady error a constant
    disturbance (an unmodelled load, a wrong gravity model) leaves under PD:
    $e_\infty = K_p^{-1} d$ becomes $0$. Anti-windup by conditional integration ("clamping"):
    the integrator of a joint stops while the command is beyond the URDF torque limit
    and the integral term would push it further (Åström and Hägglund, *Advanced PID
    Control*, ISA 2006, §3.5; the law knows the limits whether or not the plant clips).
    Joints without a limit integrate always.
    """

    name = "pid"
    title = "PID + model feedforward, anti-windup"
    Gains = PIDGains

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._limits = np.array(self.robot.torque_limits, dtype=float)[None]
        g = self.gains
        self._kp, self._ki, self._kd = (applied_form(k) for k in (g.kp, g.ki, g.kd))

    def state_variables(self) -> tuple[StateVariable, ...]:
        return super().state_variables() + tuple(
            StateVariable(f"∫e{j + 1}", "rad·s", "integral") for j in range(self.robot.nv)
        )

    def scaled_gains(self) -> dict[str, Any]:
        m = joint_space_inertia(self.robot.model, self.robot.home)
        w = NATURAL_FREQUENCY
        return {"kp": 3.0 * w**2 * m, "ki": w**3 * m, "kd": 3.0 * w * m}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        e = x.q - x.q_des
        integral = self._ki(x.z)
        feedback = self._kp(e) + integral + self._kd(x.v - x.v_des)
        tau = terms.model(x.q, x.v, x.v_des, x.a_des) - feedback
        # -K_i e is the direction the integral term moves τ in: stop when that is outwards.
        winding = (np.abs(tau) >= self._limits) & (np.sign(-self._ki(e)) == np.sign(tau))
        return LawOutput(tau, np.where(winding, 0.0, e))
