"""Inverse dynamics and its derivatives at many points: what a trajectory optimiser linearises.

The optimisation core (:mod:`twolink_pin.optimal`) sees the robot's dynamics through one
callable, ``(q, v, a) -> InverseDynamicsTerms``, batched over K points (arrays of shape
(K, nv)), so that the same core runs on Pinocchio directly (offline: :class:`RneaDerivatives`,
here) or on what a control law is allowed to ask for (the simulation's ``Terms``: a law never
calls Pinocchio itself).

:class:`RneaDerivatives` calls Pinocchio's ``computeRNEADerivatives`` (Carpentier & Mansard,
*Analytical derivatives of rigid body dynamics algorithms*, RSS 2018) at each point:
``τ = RNEA(q, q̇, q̈)`` and ``∂τ/∂q``, ``∂τ/∂q̇``, ``∂τ/∂q̈ = M(q)``, on the model it is given (a
robot's model carries its payload), plus a joint friction ``f(q̇)`` when given: its
viscous part adds ``diag(V)`` to ``∂τ/∂q̇``, its Coulomb part ``C tanh(q̇/ε)`` adds
``diag(C (1 − tanh²)/ε)`` (with the exact sign, ε = 0, the derivative is 0 off ``q̇ = 0``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics.friction import Friction
from twolink_pin.errors import InvalidParameterError


class InverseDynamicsTerms(NamedTuple):
    """Inverse dynamics at K points (see the module docstring)."""

    tau: np.ndarray
    """``τ(q, q̇, q̈)`` [N·m], shape (K, nv)."""
    dtau_dq: np.ndarray
    """``∂τ/∂q`` [N·m/rad], shape (K, nv, nv)."""
    dtau_dv: np.ndarray
    """``∂τ/∂q̇`` [N·m·s/rad], shape (K, nv, nv)."""
    M: np.ndarray
    """``∂τ/∂q̈ = M(q)`` [kg·m²], shape (K, nv, nv), symmetric."""


InverseDynamics = Callable[[np.ndarray, np.ndarray, np.ndarray], InverseDynamicsTerms]
"""``(q [rad], q̇ [rad/s], q̈ [rad/s²])``, each (K, nv) → :class:`InverseDynamicsTerms`."""


class RneaDerivatives:
    """The :data:`InverseDynamics` of a Pinocchio model (its own ``Data``), with an optional
    joint friction (module docstring).

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

    def __call__(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> InverseDynamicsTerms:
        q, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, v, a))
        K, nv = q.shape
        tau = np.empty((K, nv))
        dq, dv, M = np.empty((K, nv, nv)), np.empty((K, nv, nv)), np.empty((K, nv, nv))
        model, data = self.model, self.data
        for k in range(K):
            dq[k], dv[k], M[k] = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
            tau[k] = data.tau
        if self.friction is not None:
            tau += self.friction.torque(v)
            viscous = np.asarray(self.friction.viscous)
            coulomb = np.asarray(self.friction.coulomb)
            slope = np.broadcast_to(viscous, v.shape).copy()
            if self.friction.smoothing > 0:
                eps = self.friction.smoothing
                slope += coulomb * (1.0 - np.tanh(v / eps) ** 2) / eps
            j = np.arange(nv)
            dv[:, j, j] += slope
        return InverseDynamicsTerms(tau, dq, dv, M)


__all__ = ["InverseDynamics", "InverseDynamicsTerms", "RneaDerivatives"]
