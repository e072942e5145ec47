"""Cartesian impedance control with gravity compensation: a spring and damper on the frame."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.task_space import (
    TaskInertia,
    block_gain,
    desired_frame,
    null_space_torque,
    row_index,
    task_error,
    task_rows,
)
from twolink_pin.dynamics import joint_inertia
from twolink_pin.model import RobotModel

STIFFNESS_FREQUENCY = 10.0
"""ω [rad/s] of the robot-derived default stiffness ``k = ω² m`` and damping ``d = 2 ω m``,
``m`` the task inertia at ``home`` (mean eigenvalue of the position, resp. orientation,
block of Λ): the frame alone on its spring is critically damped near ω."""
POSTURE_FREQUENCY = 5.0
"""ω [rad/s] of the default null-space posture gains ``ω² diag M(q₀)``, ``2 ω diag M(q₀)``."""


@dataclass(frozen=True, eq=False)
class ImpedanceGains(Gains):
    r"""Gains of :class:`Impedance`: each a number (times I), 3 numbers (a diagonal), 9 numbers
    (a 3 × 3 matrix, row by row: ``--gain k=2000,0,0,0,2000,0,0,0,500``) or a symmetric
    positive-definite 3 × 3 matrix in world axes (or one per run). The CLI's names (``k``,
    ``d``, …) are the fields below; the law writes them $K$, $D$ (position rows: $K_p$,
    $D_p$; orientation: $K_o$, $D_o$) and $K_n$, $D_n$.

    Attributes:
        k: Translational stiffness $K_p$ [N/m]; default from the robot (see
            :data:`STIFFNESS_FREQUENCY`).
        d: Translational damping $D_p$ [N·s/m].
        k_rot: Rotational stiffness $K_o$ [N·m/rad].
        d_rot: Rotational damping $D_o$ [N·m·s/rad].
        kp_null: Posture stiffness [N·m/rad] per joint (null space of the task).
        kd_null: Posture damping [N·m·s/rad] per joint.
    """

    k: Any = gain(None, per="axis", matrix=True, unit="N/m", doc="translational stiffness K")
    d: Any = gain(None, per="axis", matrix=True, unit="N·s/m", doc="translational damping D")
    k_rot: Any = gain(None, per="axis", matrix=True, unit="N·m/rad", doc="rotational stiffness")
    d_rot: Any = gain(None, per="axis", matrix=True, unit="N·m·s/rad", doc="rotational damping")
    kp_null: Any = gain(None, per="joint", unit="N·m/rad", doc="posture stiffness")
    kd_null: Any = gain(None, per="joint", unit="N·m·s/rad", doc="posture damping")


class Impedance(Controller[ImpedanceGains]):
    r"""Cartesian impedance control with gravity compensation:

    $$\tau = \hat g(q) + J^\top\big(-K e - D \dot e\big)
    + N^\top\big(-K_n e_q - D_n \dot e_q\big)$$

    with the pose error $e = (p - p_d,\ \log(R R_d^\top))$, $\dot e = J \dot q - \dot x_d$,
    $e_q = q - q_d$ and $N^\top = I - J^\top \Lambda J \hat M^{-1}$,
    $\Lambda = (J \hat M^{-1} J^\top)^{-1}$ (the dynamically consistent null space, damped
    near singularities as in ``osc``). The frame behaves as a spring $K$ and damper $D$
    to its desired pose, with the arm's own task inertia (no inertia shaping, no model
    feedforward: it is a regulator, exact at rest). Under a constant external wrench $F$ on
    the frame, at rest $J^\top (F - K e) + N^\top \tau_n = 0$, and since $J \hat M^{-1} N^\top = 0$
    with $J$ of full row rank, $K e = F$: the frame settles at $e = K^{-1} F$.
    With the exact gravity, $V = \tfrac12 \dot q^\top M \dot q + \tfrac12 e^\top K e$ decreases
    for a constant desired pose (Hogan, "Impedance control: an approach to manipulation",
    *J. Dyn. Sys., Meas., Control* 107(1), 1985; Ott, *Cartesian Impedance Control of
    Redundant and Flexible-Joint Robots*, Springer 2008, ch. 3). The desired pose and twist
    are ``LawInput``'s ``x_des``, ``R_des``, ``twist_des`` (the SE(3) reference's, else the
    forward kinematics of the joint reference), the posture the joint reference itself;
    the task's rows are chosen as in ``osc`` (the twolink: position x, y).
    """

    name = "impedance"
    title = "Cartesian impedance + gravity compensation"
    Gains = ImpedanceGains
    task_space = True

    def __init__(self, robot: RobotModel, gains: ImpedanceGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self.rows = task_rows(robot)
        """The controlled rows of the world-aligned 6-D task (0–2 position, 3–5 orientation)."""
        g = self.gains
        self._K = block_gain(g.k, g.k_rot, self.rows)
        self._D = block_gain(g.d, g.d_rot, self.rows)
        self._redundant = len(self.rows) < robot.nv
        self._index = row_index(self.rows)  # a slice when the rows are consecutive: views
        self._inertia = TaskInertia(self.name)

    @property
    def stiffness(self) -> np.ndarray:
        """``K`` on the task's rows, shape (1 or N, k, k) [N/m, N·m/rad]."""
        return self._K

    @property
    def damped_evaluations(self) -> int:
        """Evaluations at which the task inertia was damped (near a singularity)."""
        return self._inertia.damped

    def scaled_gains(self) -> dict[str, Any]:
        robot = self.robot
        model, data, q = robot.model, robot.model.createData(), robot.home
        J = pin.computeFrameJacobian(
            model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        rows = task_rows(robot)
        A = J[rows] @ np.linalg.solve(M, J[rows].T)
        Lam = np.linalg.pinv(A)
        linear = rows[rows < 3]
        position_mass = float(np.mean(np.diag(Lam)[: len(linear)])) if len(linear) else 1.0
        angular = len(rows) - len(linear)
        rotation_inertia = float(np.mean(np.diag(Lam)[len(linear) :])) if angular else 1.0
        w, wn = STIFFNESS_FREQUENCY, POSTURE_FREQUENCY
        m = joint_inertia(model, q)
        return {
            "k": w**2 * position_mass,
            "d": 2 * w * position_mass,
            "k_rot": w**2 * rotation_inertia,
            "d_rot": 2 * w * rotation_inertia,
            "kp_null": wn**2 * m,
            "kd_null": 2 * wn * m,
        }

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        rows = self._index
        f = terms.frame(x.q, x.v)
        J = f.jacobian[:, rows]
        d = desired_frame(x)  # x_des, R_des, twist_des
        e = task_error(f.position, f.rotation, d.position, d.rotation, rows)
        e_dot = np.matvec(J, x.v) - d.twist[:, rows]
        force = -(np.matvec(self._K, e) + np.matvec(self._D, e_dot))
        tau = terms.gravity(x.q) + np.vecmat(force, J)
        if self._redundant:
            g = self.gains
            tau0 = -(g.kp_null * (x.q - x.q_des) + g.kd_null * (x.v - x.v_des))
            MinvJt = terms.solve_mass(x.q, J.transpose(0, 2, 1))
            Lam = self._inertia(np.matmul(J, MinvJt), x.t)
            tau = tau + null_space_torque(J, MinvJt, Lam, tau0)
        return LawOutput(tau)
