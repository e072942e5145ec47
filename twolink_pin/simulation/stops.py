r"""Joint stops: each joint's position range as a hard, perfectly inelastic stop (``--joint-stops``).

Without stops a joint passes its range like any other position (the plant has no such
element: Pinocchio's ABA ignores the URDF's ``lower``/``upper``) and the run records the
crossing (:mod:`twolink_pin.limits.crossings`). With them, the engine calls
:class:`JointStops` on the state after every RK4 step (never inside a step: the four stages
integrate the free dynamics, so the step and its cost are those of the plain plant):

1. a joint beyond its range is put back at the bound it passed, ``q_j ← bound_j``;
2. the velocity into the stops is removed by the impulse of a perfectly inelastic contact
   at the stopped joints ``S`` (Gauss's principle: the smallest change of the motion, in the
   kinetic-energy metric, that stops them):

   $$\dot q^+ = \dot q - M^{-1}_{:S}\,\big(M^{-1}_{SS}\big)^{-1}\,\dot q_S,
   \qquad \dot q^+_S = 0,$$

   with $M^{-1}$ at the corrected position. The impulse acts at the stopped joints only
   ($M(\dot q^+ - \dot q)$ is zero on every other joint), so the other joints keep their
   momentum; a joint resting on its stop with the torque pushing it in is put back and
   stopped at every step, so it stays at the bound.

The kinetic energy removed at an impact is the kinetic energy of the motion into the stops,
with the effective inertia the other joints leave them:

$$\Delta E = \tfrac12\,\dot q_S^\top \big(M^{-1}_{SS}\big)^{-1} \dot q_S
\quad\big(\text{one joint: } \tfrac12\,\dot q_j^2 / (M^{-1})_{jj}\big),$$

plus the potential energy of putting ``q`` back by the overshoot of the step
(``O(|q̇_j| dt)``). The set ``S`` is the joints at a bound moving into it; a joint whose
impulse would pull it off its stop leaves ``S``, and one that the impulse drives into its
own stop joins it, until neither happens (an active-set solution of the contact's
complementarity problem; at most ``2 nv`` small solves, only in a step where a joint hits).

A step in which no joint is beyond its range costs two comparisons of ``(N, nv)`` arrays.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.limits import JointLimits


class JointStops:
    """The stops of ``limits``' position ranges on ``model`` (see the module docstring).

    Args:
        limits: The joints' ranges (``∓inf``: no stop on that side).
        model: The Pinocchio model whose inertia the impact uses.
    """

    def __init__(self, limits: JointLimits, model: pin.Model) -> None:
        self.lower = np.asarray(limits.position_lower, dtype=float)
        self.upper = np.asarray(limits.position_upper, dtype=float)
        self.model = model
        self.data = model.createData()

    def __call__(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The state of N runs (``q`` [rad], ``v`` [rad/s], each (N, nv)) with every joint
        beyond its range put back at its bound and the velocity into the stops removed (new
        arrays where anything changed; the same ones otherwise)."""
        below, above = q < self.lower, q > self.upper
        if not (below.any() or above.any()):
            return q, v
        q = np.clip(q, self.lower, self.upper)
        v = np.array(v, dtype=float)
        for i in np.flatnonzero((below | above).any(axis=1)):
            v[i] = self.impact(q[i], v[i])
        return q, v

    def impact(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The velocity [rad/s] after the inelastic impact at ``q`` [rad] (within the ranges)
        of the joints at a bound moving into it, ``v`` before (shape (nv,) each)."""
        at_lower, at_upper = q <= self.lower, q >= self.upper
        inverse = pin.computeMinverse(self.model, self.data, q)
        inverse = np.triu(inverse) + np.triu(inverse, 1).T  # Pinocchio may fill the upper triangle only
        into = lambda w: (at_upper & (w > 0)) | (at_lower & (w < 0))  # noqa: E731
        active = into(v)
        after = v
        for _ in range(2 * len(v) + 1):
            if not active.any():
                return v
            s = np.flatnonzero(active)
            impulse = -np.linalg.solve(inverse[np.ix_(s, s)], v[s])  # generalized impulse at S [N·m·s]
            pulling = (at_upper[s] & (impulse > 0)) | (at_lower[s] & (impulse < 0))
            if pulling.any():  # a stop cannot pull: that joint leaves the set
                active[s[pulling]] = False
                continue
            after = v + inverse[:, s] @ impulse
            after[s] = 0.0
            driven = into(after) & ~active
            if not driven.any():
                return after
            active |= driven
        return after


__all__ = ["JointStops"]
