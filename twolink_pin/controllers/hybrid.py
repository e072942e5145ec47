"""Hybrid motion/force control (Raibert–Craig, in Khatib's operational space): position along a
surface, force across it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller, StateVariable
from twolink_pin.controllers.force_loop import contact_of, force_command
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.task_space import (
    TaskInertia,
    block_gain,
    null_space_torque,
    posture_acceleration,
    row_index,
    task_acceleration,
    task_rows,
)
from twolink_pin.model import RobotModel

MOTION_FREQUENCY = 20.0
"""ω [rad/s] of the default motion gains ``K = ω² I``, ``D = 2 ω I`` (critical damping): stiff
enough that friction along the surface moves the end effector by a fraction of a millimetre."""
POSTURE_FREQUENCY = 5.0
"""ω [rad/s] of the default posture gains."""


@dataclass(frozen=True, eq=False)
class HybridGains(Gains):
    r"""Gains of :class:`Hybrid`: the motion gains acceleration-level as ``osc``'s (a number, 3
    numbers, 9 numbers or a symmetric positive-definite 3 × 3 matrix in world axes), the force
    gains as ``force``'s.

    Attributes:
        kp: Position stiffness $K$ [1/s²] (along the surface); default $\omega^2$
            (:data:`MOTION_FREQUENCY`).
        kd: Position damping $D$ [1/s] (along the surface); default $2\omega$.
        kp_rot: Orientation stiffness $K_o$ [1/s²]; default $\omega^2$.
        kd_rot: Orientation damping $D_o$ [1/s]; default $2\omega$.
        kp_null: Posture stiffness per joint [1/s²]; default $\omega_n^2$ (:data:`POSTURE_FREQUENCY`).
        kd_null: Posture damping per joint [1/s]; default $2\omega_n$.
        kp_f: Proportional force gain $k_{fp}$ [N/N].
        ki_f: Integral force gain $k_{fi}$ [1/s].
        i_max: Clamp of the integral force term [N] (anti-windup).
        d_n: Damping along the normal $d_n$ [1/s], times the arm's effective mass there.
    """

    kp: Any = gain(MOTION_FREQUENCY**2, per="axis", matrix=True, unit="1/s²", doc="position stiffness K")
    kd: Any = gain(2 * MOTION_FREQUENCY, per="axis", matrix=True, unit="1/s", doc="position damping D")
    kp_rot: Any = gain(MOTION_FREQUENCY**2, per="axis", matrix=True, unit="1/s²", doc="orientation stiffness")
    kd_rot: Any = gain(2 * MOTION_FREQUENCY, per="axis", matrix=True, unit="1/s", doc="orientation damping")
    kp_null: Any = gain(POSTURE_FREQUENCY**2, per="joint", unit="1/s²", doc="posture stiffness")
    kd_null: Any = gain(2 * POSTURE_FREQUENCY, per="joint", unit="1/s", doc="posture damping")
    kp_f: Any = gain(3.0, unit="N/N", bound="nonnegative", doc="proportional force gain")
    ki_f: Any = gain(15.0, unit="1/s", bound="nonnegative", doc="integral force gain")
    i_max: Any = gain(20.0, unit="N", doc="clamp of the integral force term")
    d_n: Any = gain(20.0, unit="1/s", bound="nonnegative", doc="damping along the normal")


class Hybrid(Controller[HybridGains]):
    r"""Hybrid motion/force control: Raibert and Craig's selection in the surface's frame
    ("Hybrid position/force control of manipulators", *J. Dyn. Sys., Meas., Control* 103(2),
    1981), in the operational space (Khatib, *IEEE J. Robotics and Automation* 3(1), 1987;
    Lynch and Park, *Modern Robotics* §11.6):

    $$\tau = J^\top\Big(P\,\Lambda\,\big(S\,a^* - \dot J \dot q\big) + F_c\Big) + \hat C \dot q + \hat g
    + N^\top \hat M\big(\ddot q_d - K_n e_q - D_n \dot e_q\big)$$

    $$a^* = \ddot x_d - D \dot e - K e, \qquad
    F_c = -n\,\big(f_d + k_{fp}\, e_f + k_{fi}\, \xi\big) - m_n d_n\, (n^\top \dot p)\, n$$

    The selection $S = \operatorname{diag}(I - n n^\top, I)$ keeps the motion task's position
    rows along the surface (normal $n$) and its orientation rows; $a^*$ is ``osc``'s task
    acceleration to the reference (the reference across the surface is not used: the force
    sets it). $P = I - a\,(a^\top \Lambda^{-1} a)^{-1} a^\top \Lambda^{-1}$, $a = (n, 0)$, is the
    dynamically consistent projection: the motion force $P \Lambda (\ldots)$ leaves the
    contact force alone, $a^\top \Lambda^{-1} P = 0$ (on a rigid surface the contact force is
    then $f_d$ plus the force loop's correction, whatever the motion along it). $F_c$ is
    ``force``'s PI on the normal force (:mod:`twolink_pin.controllers.force_loop`: integral in
    contact only, clamped) plus a damping of the normal velocity scaled by the arm's effective
    mass along the normal $m_n = (a^\top \Lambda^{-1} a)^{-1}$ [kg] (it sets the speed of the
    force-driven approach, about $f_d / (m_n d_n)$, and damps the impact). At rest in contact
    the integral drives the normal force to $f_d$ whatever the surface's stiffness. Task rows,
    $\Lambda$ (damped near singularities) and the null-space posture as ``osc``. State: the
    integral $\xi$ [N·s]. It needs a plant whose scene has a surface.
    """

    name = "hybrid"
    title = "Hybrid motion/force (Raibert–Craig, operational space)"
    Gains = HybridGains
    task_space = True
    force_control = True

    def __init__(self, robot: RobotModel, gains: HybridGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self.rows = task_rows(robot)
        """The controlled rows of the world-aligned 6-D task (0–2 position, 3–5 orientation)."""
        g = self.gains
        self._K = block_gain(g.kp, g.kp_rot, self.rows)
        self._D = block_gain(g.kd, g.kd_rot, self.rows)
        self._linear = self.rows[self.rows < 3]
        self._redundant = len(self.rows) < robot.nv
        self._index = row_index(self.rows)
        self._inertia = TaskInertia(self.name)
        self._last: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (*super().state_variables(), StateVariable("∫e_f", "N·s", "integral"))

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        contact = contact_of(x, self.name)
        S, a = self._selection(contact.normal)
        task = task_acceleration(x, terms, self._index, self._K, self._D)
        J = task.jacobian
        MinvJt = terms.solve_mass(x.q, J.transpose(0, 2, 1))
        inverse = np.matmul(J, MinvJt)  # Λ⁻¹ = J M⁻¹ Jᵀ
        Lam = self._inertia(inverse, x.t)
        w = np.matvec(Lam, np.matvec(S, task.desired) - task.drift)  # Λ (S a* − J̇ q̇)
        m_n = 1.0 / np.vecdot(np.matvec(inverse, a), a)[:, None]  # (aᵀ Λ⁻¹ a)⁻¹ [kg], (N, 1)
        force = w - m_n * np.vecdot(np.matvec(inverse, w), a)[:, None] * a  # P Λ (…): a new array
        command = force_command(contact, x.z, g.kp_f, g.ki_f, g.i_max)
        normal_speed = np.vecdot(np.matvec(J, x.v), a)[:, None]  # n·ṗ [m/s]
        force[:, : len(self._linear)] += command.force[:, self._linear]
        force -= (g.d_n * m_n * normal_speed) * a
        tau = np.vecmat(force, J) + terms.bias(x.q, x.v)
        if self._redundant:
            tau0 = np.matvec(terms.mass(x.q), posture_acceleration(x, g.kp_null, g.kd_null))
            tau = tau + null_space_torque(J, MinvJt, Lam, tau0)
        return LawOutput(tau, command.dxi)

    def _selection(self, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``S = diag(I − n nᵀ, I)`` (1, k, k) and ``a = (n, 0)`` (1, k) on the task's rows for the
        surface's ``normal`` (1, 3) (kept for the last normal seen: the run's surface)."""
        last = self._last
        if last is not None and last[0] is normal:
            return last[1], last[2]
        k, linear = len(self.rows), self._linear
        a = np.zeros((1, k))
        a[0, : len(linear)] = normal[0, linear]
        S = np.eye(k)[None] - a[:, :, None] * a[:, None, :]
        S.setflags(write=False)
        a.setflags(write=False)
        self._last = (normal, S, a)
        return S, a
