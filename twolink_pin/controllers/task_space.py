"""What the task-space laws (``osc``, ``impedance``) share: the task's rows, the pose error,
the damped task-space inertia and the dynamically consistent null-space projection.

Conventions are those of :class:`~twolink_pin.controllers.FrameTerms`: world-aligned, linear
rows first. The orientation error is ``e_o = log(R R_dᵀ)`` — the rotation vector [rad] that
takes the desired orientation to the actual one, in world axes — so that ``e_o ≈ ∫(ω − ω_d)``
for small errors.

**The task.** A frame that can move in 6 DOF at the robot's ``home`` (its Jacobian has rank 6
there) is controlled in position and orientation (6 rows). Otherwise (the planar twolink, a
3-joint arm) the task is the frame's position along the world axes it moves at ``home`` (the
twolink: x and y); orientation is left to the joints. This is :func:`task_rows`' choice.

**Singularities.** ``Λ = (J M⁻¹ Jᵀ)⁻¹`` is formed from the eigen-decomposition of
``J M⁻¹ Jᵀ`` normalised to a unit diagonal, ``S J M⁻¹ Jᵀ S = U diag(s) Uᵀ`` with
``S = diag(J M⁻¹ Jᵀ)^(-1/2)`` (so that its eigenvalues have no unit whatever the rows'
units: 1/kg for a force, 1/(kg·m²) for a moment); when ``s_min < ε``
(:data:`SINGULAR_RATIO`) it becomes ``S U diag(s / (s² + ρ²)) Uᵀ S`` with ``ρ² = ε² − s_min²``
(damped least squares with a damping that grows from 0 at the threshold, Nakamura and Hanafusa, *J. Dyn. Sys., Meas.,
Control* 108(3), 1986; Chiaverini, *IEEE Trans. Robot. Autom.* 13(3), 1997), and the law warns
once (:class:`SingularityWarning`) and counts the damped evaluations.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.base import LawInput
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

SINGULAR_RATIO = 1e-3
"""ε: the task inertia is damped when the smallest eigenvalue of ``J M⁻¹ Jᵀ`` normalised to a
unit diagonal is below ε (its largest is at most k: a condition number above about 1000 k)."""
AXES = ("x", "y", "z", "rx", "ry", "rz")
"""Names of the six task rows (world axes; linear first)."""


class SingularityWarning(UserWarning):
    """A task-space law damped its task inertia near a singularity."""


class DesiredFrame(NamedTuple):
    """The desired end-effector frame of a :class:`~twolink_pin.controllers.LawInput`
    (world-aligned, linear rows first), each ``(1, …)``."""

    position: np.ndarray
    """``x_des`` [m], (1, 3)."""
    rotation: np.ndarray
    """``R_des``, (1, 3, 3)."""
    twist: np.ndarray
    """``twist_des`` [m/s; rad/s], (1, 6)."""
    accel: np.ndarray
    """``accel_des`` [m/s²; rad/s²], (1, 6)."""


def desired_frame(x: LawInput) -> DesiredFrame:
    """``x``'s desired frame; a clear error when the engine did not fill it (the law does not
    declare ``task_space = True``)."""
    if x.x_des is None or x.R_des is None or x.twist_des is None or x.accel_des is None:
        raise InvalidParameterError(
            "LawInput.x_des",
            None,
            "the desired frame, which the engine fills only for a law that declares task_space = True "
            "(or build the input with twolink_pin.simulation.law_input)",
        )
    return DesiredFrame(x.x_des, x.R_des, x.twist_des, x.accel_des)


def task_rows(robot: RobotModel) -> np.ndarray:
    """The rows of the 6-D frame Jacobian the law controls (see the module docstring)."""
    data = robot.model.createData()
    J = pin.computeFrameJacobian(
        robot.model, data, robot.home, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )
    if robot.nv >= 6 and np.linalg.matrix_rank(J, tol=1e-9 * max(1.0, np.abs(J).max())) == 6:
        return np.arange(6)
    linear = J[:3]
    moving = np.flatnonzero(np.linalg.norm(linear, axis=1) > 1e-9 * max(1.0, np.abs(linear).max()))
    if np.linalg.matrix_rank(linear[moving]) < len(moving):  # e.g. a 1-joint arm: keep the first rows
        moving = moving[: np.linalg.matrix_rank(linear[moving])]
    return moving


def rotation_error(R: np.ndarray, R_des: np.ndarray) -> np.ndarray:
    """``log(R R_dᵀ)`` [rad] in world axes, shape (N, 3), for (N, 3, 3) and (1 or N, 3, 3)."""
    E = R @ np.swapaxes(R_des, -1, -2)
    w = 0.5 * np.stack((E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0], E[:, 1, 0] - E[:, 0, 1]), axis=1)
    sin = np.linalg.norm(w, axis=1)
    cos = 0.5 * (E[:, 0, 0] + E[:, 1, 1] + E[:, 2, 2] - 1.0)
    angle = np.arctan2(sin, cos)
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(sin > 1e-9, angle / sin, 1.0 + angle**2 / 6.0)
    out = factor[:, None] * w
    for i in np.flatnonzero(angle > np.pi - 1e-6):  # near π the skew part vanishes
        out[i] = pin.log3(E[i])
    return out


def pose_error(
    position: np.ndarray, rotation: np.ndarray, position_des: np.ndarray, rotation_des: np.ndarray
) -> np.ndarray:
    """``(p − p_d, log(R R_dᵀ))`` [m, rad], shape (N, 6)."""
    return np.concatenate((position - position_des, rotation_error(rotation, rotation_des)), axis=1)


def block_gain(linear: np.ndarray, angular: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The (R, k, k) gain on the task rows from (R, 3, 3) linear and angular blocks."""
    runs = max(linear.shape[0], angular.shape[0])
    K = np.zeros((runs, 6, 6))
    K[:, :3, :3] = linear
    K[:, 3:, 3:] = angular
    out = np.ascontiguousarray(K[:, rows][:, :, rows])
    out.setflags(write=False)
    return out


class TaskInertia:
    """``Λ = (J M⁻¹ Jᵀ)⁻¹``, damped near singularities, for a law named ``law``."""

    def __init__(self, law: str) -> None:
        self.law = law
        self.damped = 0
        """Evaluations at which Λ was damped."""
        self._warned = False

    def __call__(self, A: np.ndarray, t: float) -> np.ndarray:
        """Λ from ``A = J M⁻¹ Jᵀ`` (N, k, k) at time ``t`` [s]."""
        scale = 1.0 / np.sqrt(np.einsum("nii->ni", A))  # the rows' units (1/kg, 1/(kg·m²)) out
        s, U = np.linalg.eigh(A * scale[:, :, None] * scale[:, None, :])
        rho2 = np.maximum(SINGULAR_RATIO**2 - s[:, :1] ** 2, 0.0)
        near = rho2[:, 0] > 0
        if near.any():
            self.damped += 1
            if not self._warned:
                self._warned = True
                warnings.warn(
                    f"{self.law}: near a singularity at t = {t:.4g} s (the smallest eigenvalue of the "
                    f"normalised J M⁻¹ Jᵀ is {float(np.min(s[near, 0])):.3g} < {SINGULAR_RATIO:g}): the task "
                    "inertia is damped and the task no longer tracked exactly",
                    SingularityWarning,
                    stacklevel=3,
                )
        inverse = s / (s * s + rho2)
        core = np.matmul(U * inverse[:, None, :], np.swapaxes(U, -1, -2))
        return core * scale[:, :, None] * scale[:, None, :]


def null_space_torque(J: np.ndarray, MinvJt: np.ndarray, Lam: np.ndarray, tau0: np.ndarray) -> np.ndarray:
    """``Nᵀ τ₀ = τ₀ − Jᵀ Λ J M⁻¹ τ₀``: the part of ``τ₀`` that produces no task acceleration
    (Khatib's dynamically consistent null space), shape (N, nv)."""
    task_force = np.matvec(Lam, np.vecmat(tau0, MinvJt))  # Λ (M⁻¹Jᵀ)ᵀ τ₀ = Λ J M⁻¹ τ₀
    return tau0 - np.vecmat(task_force, J)
