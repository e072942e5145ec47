"""Direct force control: gravity compensation, the desired normal force with a PI on its error,
joint damping."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller, StateVariable
from twolink_pin.controllers.force_loop import contact_of, force_command
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.dynamics import joint_inertia

DAMPING_FREQUENCY = 5.0
"""ω [rad/s] of the default joint damping ``K_d = 2 ω diag M(q₀)``: about 0.1 m/s of free
approach per 10 N on the twolink."""


@dataclass(frozen=True, eq=False)
class ForceGains(Gains):
    r"""Gains of :class:`ForceControl`.

    Attributes:
        kp_f: Proportional force gain $k_{fp}$ [N/N]: the error's share added to $f_d$.
        ki_f: Integral force gain $k_{fi}$ [1/s]: removes the steady force error.
        i_max: Clamp of the integral term $|k_{fi} \xi|$ [N] (anti-windup).
        kd: Joint damping $K_d$ [N·m·s/rad] per joint; default $2 \omega \operatorname{diag} M(q_0)$
            (:data:`DAMPING_FREQUENCY`).
    """

    kp_f: Any = gain(0.5, unit="N/N", bound="nonnegative", doc="proportional force gain")
    ki_f: Any = gain(10.0, unit="1/s", bound="nonnegative", doc="integral force gain")
    i_max: Any = gain(20.0, unit="N", doc="clamp of the integral force term")
    kd: Any = gain(None, per="joint", unit="N·m·s/rad", bound="nonnegative", doc="joint damping Kd")


class ForceControl(Controller[ForceGains]):
    r"""Direct force control along a surface's normal (Lynch and Park, *Modern Robotics* §11.5,
    eq. 11.62, with the motion damped in the joints):

    $$\tau = \hat g(q) + J^\top F_c - K_d \dot q, \qquad
    F_c = -n\,\big(f_d + k_{fp}\, e_f + k_{fi}\, \xi\big), \qquad \dot \xi = e_f = f_d - f_n$$

    with $J$ the linear rows of the touching frame's world-aligned Jacobian, $n$ the surface's
    outward normal, $f_d$ the reference's normal force and $f_n = -n^\top F$ the normal force the
    sensor reads (:mod:`twolink_pin.controllers.force_loop`, which also holds the anti-windup:
    the integral stops at ``i_max``). At rest against the surface $J^\top F_c$ balances the
    contact and the integral drives $f_n \to f_d$; in free space the arm moves towards the
    surface at about $f_d / d$ [m/s], $d$ the joint damping seen at the end effector. It controls
    the force only: nothing holds the end effector's position along the surface (``hybrid``
    does). State: the integral $\xi$ [N·s]. It needs a plant whose scene has a surface.
    """

    name = "force"
    title = "Direct force control (PI on the normal force)"
    Gains = ForceGains
    force_control = True

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (*super().state_variables(), StateVariable("∫e_f", "N·s", "integral"))

    def scaled_gains(self) -> dict[str, Any]:
        return {"kd": 2.0 * DAMPING_FREQUENCY * joint_inertia(self.robot.model, self.robot.home)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        contact = contact_of(x, self.name)
        command = force_command(contact, x.z, g.kp_f, g.ki_f, g.i_max)
        J = terms.frame(x.q, x.v).jacobian[:, :3]
        tau = terms.gravity(x.q) + np.vecmat(command.force, J) - g.kd * x.v
        return LawOutput(tau, command.dxi)
