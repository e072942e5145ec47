"""Jacobian-transpose control, written as a user would: a task-space law in one file.

The end effector is pulled to its desired position by a spring and a damper, applied
through the Jacobian's transpose, with gravity compensation; every Pinocchio quantity comes
from ``terms`` (``terms.frame`` for the pose and Jacobian, ``terms.gravity`` for ĝ). Run it
with::

    twolink-pin simulate examples/jacobian_transpose.py:JacobianTranspose --robot ur5
    twolink-pin compare examples/jacobian_transpose.py:JacobianTranspose osc --robot ur5
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class JacobianTransposeGains(Gains):
    """Gains of :class:`JacobianTranspose`.

    Attributes:
        k: Stiffness ``K`` [N/m] of the spring on the position error (a number, 3 numbers or
            a symmetric positive-definite 3 × 3 matrix).
        d: Damping ``D`` [N·s/m] on the end effector's velocity error.
        d_joint: Joint damping [N·m·s/rad] (a redundant arm's self-motion has no other).
    """

    k: Any = gain(2000.0, per="axis", matrix=True, unit="N/m", doc="stiffness K")
    d: Any = gain(100.0, per="axis", matrix=True, unit="N·s/m", doc="damping D")
    d_joint: Any = gain(1.0, per="joint", unit="N·m·s/rad", doc="joint damping")


class JacobianTranspose(Controller):
    r"""Jacobian-transpose control with gravity compensation (Craig, *Introduction to
    Robotics*, 3rd ed., §11.7; Siciliano et al., *Robotics*, §8.6.1):

    $$\tau = J_p(q)^\top \big(K (p_d - p) + D (\dot p_d - J_p \dot q)\big) + \hat g(q) - D_q \dot q$$

    with $p$ the end effector's position [m], $J_p$ the linear rows of its world-aligned
    Jacobian and $p_d$, $\dot p_d$ the forward kinematics of the joint reference. No inverse
    kinematics and no inverse of $J$: at rest the arm settles where $J_p^\top K (p_d - p) = 0$.
    """

    name = "jacobian-transpose"
    title = "Jacobian transpose + gravity compensation"
    Gains = JacobianTransposeGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        now = terms.frame(x.q, x.v)  # pose, Jacobian (N, 6, nv), J̇ q̇: linear rows first
        want = terms.frame(x.q_des, x.v_des)  # the reference's frame, shape (1, ...)
        J = now.jacobian[:, :3]
        velocity_error = np.matvec(want.jacobian[:, :3], x.v_des) - np.matvec(J, x.v)
        force = np.matvec(g.k, want.position - now.position) + np.matvec(g.d, velocity_error)
        return LawOutput(np.vecmat(force, J) + terms.gravity(x.q) - g.d_joint * x.v)
