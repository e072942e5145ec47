"""The inverse dynamics and its analytical derivatives at K states (Pinocchio).

``τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`` and ``∂τ/∂q``, ``∂τ/∂q̇``, ``∂τ/∂q̈ = M(q)`` from
``pin.computeRNEADerivatives`` (Carpentier and Mansard, "Analytical derivatives of rigid body
dynamics algorithms", RSS 2018): what an optimiser over joint trajectories linearises the
torque with. One call per state; the results are copied out of the ``Data`` (Pinocchio
returns views of it that the next call overwrites).

The optimisation core (:mod:`twolink_pin.optimal`) sees the robot's dynamics through one
callable, :data:`InverseDynamics` (``(q, q̇, q̈) -> InverseDynamicsDerivatives``, batched over
K states), so that it runs on Pinocchio directly (offline: :class:`RneaDerivatives`) or on
what a control law may ask for (a law's ``Terms.inverse_dynamics_derivatives``: a law never
calls Pinocchio itself).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics.friction import Friction
from twolink_pin.errors import InvalidParameterError


class InverseDynamicsDerivatives(NamedTuple):
    """τ and its derivatives at K states (leading axes as the states')."""

    tau: np.ndarray
    """Joint torques [N·m], shape (..., nv)."""
    dtau_dq: np.ndarray
    """``∂τ/∂q`` [N·m/rad], shape (..., nv, nv)."""
    dtau_dv: np.ndarray
    """``∂τ/∂q̇`` [N·m·s/rad], shape (..., nv, nv)."""
    mass: np.ndarray
    """``∂τ/∂q̈ = M(q)`` [kg·m²], symmetric, shape (..., nv, nv)."""


def inverse_dynamics_derivatives(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> InverseDynamicsDerivatives:
    """τ and its derivatives at the states ``(q, v, a)``, each of shape (K, nv) [rad, rad/s,
    rad/s²] (no checks: a hot path of the optimiser; the caller's arrays are finite)."""
    k, nv = q.shape
    tau = np.empty((k, nv))
    dq, dv, mass = (np.empty((k, nv, nv)) for _ in range(3))
    derivatives = pin.computeRNEADerivatives
    for i in range(k):
        d_q, d_v, m = derivatives(model, data, q[i], v[i], a[i])
        dq[i], dv[i], mass[i], tau[i] = d_q, d_v, m, data.tau
    return InverseDynamicsDerivatives(tau, dq, dv, mass)


InverseDynamics = Callable[[np.ndarray, np.ndarray, np.ndarray], InverseDynamicsDerivatives]
"""``(q [rad], q̇ [rad/s], q̈ [rad/s²])``, each (K, nv) → :class:`InverseDynamicsDerivatives`
(each (K, nv) or (K, nv, nv)): what the optimisation core linearises."""


class RneaDerivatives:
    """The :data:`InverseDynamics` of a Pinocchio model (its own ``Data``), with an optional
    joint friction: its viscous part adds ``diag(V)`` to ``∂τ/∂q̇``, its Coulomb part
    ``C tanh(q̇/ε)`` adds ``diag(C (1 − tanh²)/ε)`` (with the exact sign, ε = 0, the derivative
    is 0 off ``q̇ = 0``).

    Args:
        model: The model (``robot.model``: its payload included); ``nq == nv``.
        friction: Joint friction added to the torque, or None.
    """

    def __init__(self, model: pin.Model, friction: Friction | None = None) -> None:
        if not isinstance(model, pin.Model):
            raise InvalidParameterError("model", type(model).__name__, "a pinocchio.Model (robot.model)")
        if model.nq != model.nv:
            raise InvalidParameterError(
                "model", f"nq = {model.nq}, nv = {model.nv}", "one coordinate per joint (nq == nv)"
            )
        if friction is not None and len(friction.viscous) != model.nv:
            raise InvalidParameterError(
                "friction", friction, f"one viscous and one Coulomb value per joint ({model.nv})"
            )
        self.model = model
        self.data = model.createData()
        self.friction = friction

    def __call__(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> InverseDynamicsDerivatives:
        q, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, v, a))
        terms = inverse_dynamics_derivatives(self.model, self.data, q, v, a)
        if self.friction is None:
            return terms
        tau = terms.tau + self.friction.torque(v)
        viscous, coulomb = np.asarray(self.friction.viscous), np.asarray(self.friction.coulomb)
        slope = np.broadcast_to(viscous, v.shape).copy()
        if self.friction.smoothing > 0:
            eps = self.friction.smoothing
            slope += coulomb * (1.0 - np.tanh(v / eps) ** 2) / eps
        dv = terms.dtau_dv.copy()
        j = np.arange(q.shape[1])
        dv[:, j, j] += slope
        return InverseDynamicsDerivatives(tau, terms.dtau_dq, dv, terms.mass)


__all__ = ["InverseDynamics", "InverseDynamicsDerivatives", "RneaDerivatives", "inverse_dynamics_derivatives"]
