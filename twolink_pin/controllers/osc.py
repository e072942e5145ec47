"""Operational-space control (Khatib): the end effector's pose error made a linear system."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller
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

TASK_FREQUENCY = 10.0
"""ω [rad/s] of the default task gains ``K = ω² I``, ``D = 2 ω I`` (critical damping)."""
POSTURE_FREQUENCY = 5.0
"""ω [rad/s] of the default posture gains (half the task's)."""


@dataclass(frozen=True, eq=False)
class OSCGains(Gains):
    r"""Gains of :class:`OperationalSpace`: acceleration-level, so the same on every robot.
    Each task gain is a number (times I), 3 numbers (a diagonal), 9 numbers (a 3 × 3 matrix,
    row by row: ``--gain kp=1500,0,0,0,1500,0,0,0,800``) or a symmetric positive-definite
    3 × 3 matrix in world axes (or one per run). The CLI's names (``kp``, ``kd``, …) are the
    fields below; the law writes them $K_p$, $D_p$, $K_o$, $D_o$, $K_n$, $D_n$.

    Attributes:
        kp: Position stiffness $K_p$ [1/s²]; default $\omega^2$, $\omega$ = 10 rad/s.
        kd: Position damping $D_p$ [1/s]; default $2\omega$.
        kp_rot: Orientation stiffness $K_o$ [1/s²]; default $\omega^2$.
        kd_rot: Orientation damping $D_o$ [1/s]; default $2\omega$.
        kp_null: Posture stiffness per joint [1/s²]; default $\omega_n^2$, $\omega_n$ = 5 rad/s.
        kd_null: Posture damping per joint [1/s]; default $2\omega_n$.
    """

    kp: Any = gain(TASK_FREQUENCY**2, per="axis", matrix=True, unit="1/s²", doc="position stiffness Kp")
    kd: Any = gain(2 * TASK_FREQUENCY, per="axis", matrix=True, unit="1/s", doc="position damping Dp")
    kp_rot: Any = gain(
        TASK_FREQUENCY**2, per="axis", matrix=True, unit="1/s²", doc="orientation stiffness Ko"
    )
    kd_rot: Any = gain(2 * TASK_FREQUENCY, per="axis", matrix=True, unit="1/s", doc="orientation damping Do")
    kp_null: Any = gain(POSTURE_FREQUENCY**2, per="joint", unit="1/s²", doc="posture stiffness")
    kd_null: Any = gain(2 * POSTURE_FREQUENCY, per="joint", unit="1/s", doc="posture damping")


class OperationalSpace(Controller[OSCGains]):
    r"""Operational-space control with a posture task in the dynamically consistent null space:

    $$\tau = J^\top \Lambda \big(\ddot x_d - D \dot e - K e - \dot J \dot q\big)
    + \hat C \dot q + \hat g + N^\top \hat M \big(\ddot q_d - K_n e_q - D_n \dot e_q\big)$$

    $$\Lambda = (J \hat M^{-1} J^\top)^{-1}, \qquad
    N^\top = I - J^\top \Lambda J \hat M^{-1}$$

    with the frame's pose error $e = (p - p_d,\ \log(R R_d^\top))$, $\dot e = J \dot q - \dot x_d$,
    and the joint error $e_q = q - q_d$. With the exact model, $\ddot x = J \ddot q + \dot J \dot q$
    gives the decoupled task dynamics $\ddot e_p + D_p \dot e_p + K_p e_p = 0$ for the
    position (exactly) and $\dot{\tilde\omega} + D_o \tilde\omega + K_o e_o = 0$ for the
    orientation ($\tilde\omega = \omega - \omega_d$; $\dot e_o = \tilde\omega$ to first order);
    the posture torque produces no task acceleration, $J \hat M^{-1} N^\top = 0$. The desired
    pose, twist and acceleration are ``LawInput``'s ``x_des``, ``R_des``, ``twist_des``,
    ``accel_des``: the SE(3) reference's (via poses), else the forward kinematics of the joint
    reference ($x_d = f(q_d)$, $\dot x_d = J(q_d) \dot q_d$,
    $\ddot x_d = J(q_d) \ddot q_d + \dot J \dot q_d$); the joint reference is the posture. Khatib, "A unified approach for motion and force
    control of robot manipulators: the operational space formulation", *IEEE J. Robotics and
    Automation* 3(1), 1987; null space: Khatib, *Int. J. Robotics Research* 14(1), 1995.

    Choices (see :mod:`twolink_pin.controllers.task_space`): the task is the full pose when
    the frame can move in 6 DOF, else the position along the axes it can move (the twolink:
    x, y); near a singularity $\Lambda$ is damped and the law warns
    (:class:`~twolink_pin.controllers.task_space.SingularityWarning`, counted in
    ``damped_evaluations``). Without redundancy ($k = n_v$) there is no posture task.
    """

    name = "osc"
    title = "operational-space control (Khatib)"
    Gains = OSCGains
    task_space = True

    def __init__(self, robot: RobotModel, gains: OSCGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self.rows = task_rows(robot)
        """The controlled rows of the world-aligned 6-D task (0–2 position, 3–5 orientation)."""
        g = self.gains
        self._K = block_gain(g.kp, g.kp_rot, self.rows)
        self._D = block_gain(g.kd, g.kd_rot, self.rows)
        self._redundant = len(self.rows) < robot.nv
        self._index = row_index(self.rows)  # a slice when the rows are consecutive: views
        self._inertia = TaskInertia(self.name)

    @property
    def damped_evaluations(self) -> int:
        """Evaluations at which the task inertia was damped (near a singularity)."""
        return self._inertia.damped

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        task = task_acceleration(x, terms, self._index, self._K, self._D)
        J = task.jacobian
        MinvJt = terms.solve_mass(x.q, J.transpose(0, 2, 1))
        Lam = self._inertia(np.matmul(J, MinvJt), x.t)
        tau = np.vecmat(np.matvec(Lam, task.desired - task.drift), J) + terms.bias(x.q, x.v)
        if self._redundant:
            g = self.gains
            tau0 = np.matvec(terms.mass(x.q), posture_acceleration(x, g.kp_null, g.kd_null))
            tau = tau + null_space_torque(J, MinvJt, Lam, tau0)
        return LawOutput(tau)
