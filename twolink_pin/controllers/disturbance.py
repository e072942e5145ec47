"""The torque a law's model misses, estimated from the velocity it predicted and the one measured.

A law that computes its torque on a believed model, ``τ = M̂ q̈* + b̂ − d̂`` for the acceleration
``q̈*`` it wants, gets ``q̈*`` only if its model is right and nothing pushes the arm. What its
model misses — a mass it does not know, a hand leaning on the arm — is one torque ``d``,
``M̂ q̈ + b̂ = τ + d``. A disturbance observer (Ohnishi's, in the state-observer form of an
extended-state observer; Pannocchia & Rawlings 2003 for its use in offset-free MPC) estimates
it: it predicts the velocity error ``ê`` the arm should have under ``τ`` and ``d̂``, compares
it with the measured ``q̇ − q̇_d``, and integrates the gap into ``d̂``::

    ê̇ = M̂⁻¹(τ − b̂ + d̂) − q̈_d + 2 ω_o (q̇ − q̇_d − ê)
    d̂̇ = ω_o² M̂(q₀) (q̇ − q̇_d − ê)

For a constant ``d`` the error ``(gap, d − d̂)`` obeys ``g̈ + 2 ω_o ġ + ω_o² M̂⁻¹ M̂(q₀) g = 0``
(``M̂⁻¹ M̂(q₀)`` has positive eigenvalues: stable for every pose, critically damped at ω_o at
the home pose), so ``d̂ → d`` exactly — integral action. The law then asks for ``τ − d̂``: its
plan and its limits hold on the arm as it is, not as it is believed.

The estimate is of the velocity *error*, so that it starts exact at 0 when the run starts on
the reference's velocity (the default: ``v0_offset`` 0) without knowing the initial state.
Its state ``(d̂, ê)`` is part of the law's ``z`` (recorded: ``dhat_j`` [N·m], ``ehat_j`` [rad/s]).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twolink_pin.controllers.base import StateVariable
from twolink_pin.dynamics import mass_matrix
from twolink_pin.model import RobotModel


class DisturbanceObserver:
    """The observer of the module docstring for a law on ``robot`` believing ``parameters``.

    Args:
        robot: The law's robot.
        parameters: The parameters its model believes, (n_p,) or one row per run (N, n_p).
        rate: ``ω_o`` [rad/s], a number or one per run (N, 1); 0: no observer.
        first: The column of ``d̂`` in the law's ``z`` (``ê`` follows it).
    """

    def __init__(self, robot: RobotModel, parameters: np.ndarray, rate: Any, first: int) -> None:
        nv = robot.nv
        rate = np.asarray(rate, dtype=float).reshape(-1, 1)
        self.on = bool((rate > 0).any())
        """Whether any run observes (else the law skips it: ``d̂`` stays 0)."""
        inertia = _believed_inertia(robot, parameters) if self.on else np.zeros((1, nv, nv))
        self._gain_e, self._gain_d = 2.0 * rate, (rate * rate)[:, :, None] * inertia
        self._single = self._gain_d[0].T.copy() if self._gain_d.shape[0] == 1 else None  # Γᵀ for every run
        self.columns = (slice(first, first + nv), slice(first + nv, first + 2 * nv))
        """The columns of ``d̂`` and ``ê`` in ``z``."""

    @staticmethod
    def state_variables(nv: int) -> list[StateVariable]:
        """``dhat_j`` [N·m] (kind ``disturbance``), then ``ehat_j`` [rad/s] (kind ``observer``)."""
        return [StateVariable(f"dhat_{j + 1}", "N·m", "disturbance") for j in range(nv)] + [
            StateVariable(f"ehat_{j + 1}", "rad/s", "observer") for j in range(nv)
        ]

    def estimate(self, z: np.ndarray) -> np.ndarray:
        """``d̂`` [N·m], (N, nv), from the law's state."""
        return z[:, self.columns[0]]

    def derivative(self, gap: np.ndarray, relative: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(d̂̇, ê̇)``, each (N, nv), from the ``gap`` (N, nv) between the measured velocity
        error and the estimate, ``q̇ − q̇_d − ê`` [rad/s] (:meth:`gap`), and the acceleration the
        applied torque gives on the model with ``d̂``, relative to the reference's:
        ``M̂⁻¹(τ − b̂ + d̂) − q̈_d`` [rad/s²] (N, nv)."""
        single = self._single
        drift = gap @ single if single is not None else np.matvec(self._gain_d, gap)  # 2-D: numpy's fast path
        return drift, relative + self._gain_e * gap

    def gap(self, z: np.ndarray, velocity_error: np.ndarray) -> np.ndarray:
        """``q̇ − q̇_d − ê`` [rad/s], (N, nv), for the measured ``q̇ − q̇_d`` (N, nv)."""
        return velocity_error - z[:, self.columns[1]]


def _believed_inertia(robot: RobotModel, parameters: np.ndarray) -> np.ndarray:
    """``M̂(q₀)`` [kg·m²] at the robot's home on the believed parameters, (1 or N, nv, nv)."""
    from twolink_pin.model.parameters import model_with_parameters

    out = []
    for p in np.atleast_2d(parameters):
        model = model_with_parameters(robot.model, robot.parameter_map, p)
        out.append(mass_matrix(model, model.createData(), robot.home))
    return np.stack(out)
