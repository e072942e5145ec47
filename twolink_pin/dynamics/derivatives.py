"""The inverse dynamics and its analytical derivatives at K states (Pinocchio).

``τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`` and ``∂τ/∂q``, ``∂τ/∂q̇``, ``∂τ/∂q̈ = M(q)`` from
``pin.computeRNEADerivatives`` (Carpentier and Mansard, "Analytical derivatives of rigid body
dynamics algorithms", RSS 2018): what an optimiser over joint trajectories linearises the
torque with. One call per state; the results are copied out of the ``Data`` (Pinocchio
returns views of it that the next call overwrites).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin


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
