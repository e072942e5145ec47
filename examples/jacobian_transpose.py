"""Jacobian-transpose control, written as a user would: a task-space law in one file.

The end effector is pulled to its desired pose by a spring and a damper, applied through
the Jacobian's transpose, with gravity compensation; every Pinocchio quantity comes from
``terms`` (``terms.frame`` for the pose and Jacobian, ``terms.gravity`` for ĝ), the desired
pose and twist from ``x`` (``x.x_des``, ``x.R_des``, ``x.twist_des``). Run it with
(docs/task_space.md)::

    twolink-pin simulate examples/jacobian_transpose.py:JacobianTranspose --robot ur5 --trajectory examples/ur5_square_pose.toml
    twolink-pin compare examples/jacobian_transpose.py:JacobianTranspose osc --robot ur5 --trajectory examples/ur5_square_pose.toml
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain
from twolink_pin.controllers.task_space import pose_error


@dataclass(frozen=True, eq=False)
class JacobianTransposeGains(Gains):
    """Gains of :class:`JacobianTranspose`.

    Attributes:
        k: Stiffness ``K`` [N/m] of the spring on the position error (a number, 3 numbers or
            a symmetric positive-definite 3 × 3 matrix).
        d: Damping ``D`` [N·s/m] on the end effector's velocity error.
        k_rot: Rotational stiffness ``K_o`` [N·m/rad] on the orientation error.
        d_rot: Rotational damping ``D_o`` [N·m·s/rad] on the angular velocity error.
        d_joint: Joint damping [N·m·s/rad] (a redundant arm's self-motion has no other).
    """

    k: Any = gain(2000.0, per="axis", matrix=True, unit="N/m", doc="stiffness K")
    d: Any = gain(100.0, per="axis", matrix=True, unit="N·s/m", doc="damping D")
    k_rot: Any = gain(50.0, per="axis", matrix=True, unit="N·m/rad", doc="rotational stiffness K_o")
    d_rot: Any = gain(5.0, per="axis", matrix=True, unit="N·m·s/rad", doc="rotational damping D_o")
    d_joint: Any = gain(1.0, per="joint", unit="N·m·s/rad", doc="joint damping")


class JacobianTranspose(Controller):
    r"""Jacobian-transpose control with gravity compensation (Craig, *Introduction to
    Robotics*, 3rd ed., §11.7; Siciliano et al., *Robotics*, §8.6.1):

    $$\tau = J^\top \big(-K e - D \dot e\big) + \hat g(q) - D_q \dot q, \qquad e = \big(p - p_d,\ \log(R R_d^\top)\big), \quad \dot e = J \dot q - \dot x_d$$

    with $p$, $R$ the end effector's position [m] and orientation, $J$ its world-aligned
    Jacobian (linear rows first), $K = \mathrm{diag}(K_p, K_o)$, $D = \mathrm{diag}(D_p, D_o)$, and
    $p_d$, $R_d$, $\dot x_d = (\dot p_d, \omega_d)$ the desired pose and twist the engine passes in ``x`` (``task_space = True``):
    a file's via poses, or the forward kinematics of the joint reference. No inverse
    kinematics and no inverse of $J$: at rest the arm settles where $J^\top (K e) = 0$.
    """

    name = "jacobian-transpose"
    title = "Jacobian transpose + gravity compensation"
    Gains = JacobianTransposeGains
    task_space = True  # the engine fills x.x_des, x.R_des, x.twist_des, x.accel_des

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        now = terms.frame(x.q, x.v)  # pose, Jacobian (N, 6, nv), J̇ q̇: linear rows first
        e = pose_error(now.position, now.rotation, x.x_des, x.R_des)  # (N, 6): [p − p_d; log(R R_dᵀ)]
        e_dot = np.matvec(now.jacobian, x.v) - x.twist_des  # (N, 6): [ṗ − ṗ_d; ω − ω_d]
        force = -np.matvec(g.k, e[:, :3]) - np.matvec(g.d, e_dot[:, :3])
        moment = -np.matvec(g.k_rot, e[:, 3:]) - np.matvec(g.d_rot, e_dot[:, 3:])
        wrench = np.concatenate((force, moment), axis=1)  # [N; N·m], world axes
        return LawOutput(np.vecmat(wrench, now.jacobian) + terms.gravity(x.q) - g.d_joint * x.v)
