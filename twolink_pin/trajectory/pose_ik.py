"""Inverse kinematics of a full pose (position and orientation) of the end-effector frame.

:func:`solve_pose` is :func:`~twolink_pin.kinematics.solve_position` extended to six rows:
damped least squares (Levenberg–Marquardt with Sugihara's damping) on Pinocchio's
``LOCAL_WORLD_ALIGNED`` frame Jacobian, with the error

    e = (p_goal − p,  log(R_goal Rᵀ))      [m, rad], world axes, linear rows first

(the rotation vector that takes the current orientation to the goal, in world axes, so
that ``J_ω δq ≈ e_o`` to first order). Positions [m], angles [rad].
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, InverseKinematicsError
from twolink_pin.model import RobotModel

POSE_TOLERANCE = 1e-10
"""|e| [m, rad] at which :func:`solve_pose` stops."""
POSE_MAX_ITERATIONS = 500
"""Most damped least-squares steps of one solve."""
POSE_MIN_SINGULAR_VALUE = 1e-3
"""Smallest singular value of the 6-row Jacobian accepted at the solution."""


def pose_residual(
    robot: RobotModel, data: pin.Data, q: np.ndarray, position: np.ndarray, rotation: np.ndarray
) -> np.ndarray:
    """``(p_goal − p, log(R_goal Rᵀ))`` [m, rad] at ``q`` (world axes, linear first)."""
    pin.framesForwardKinematics(robot.model, data, q)
    frame = data.oMf[robot.ee_frame_id]
    return np.concatenate((position - frame.translation, pin.log3(rotation @ frame.rotation.T)))


def solve_pose(
    robot: RobotModel,
    position: np.ndarray,
    rotation: np.ndarray,
    q_seed: np.ndarray,
    *,
    tol: float = POSE_TOLERANCE,
    max_iterations: int = POSE_MAX_ITERATIONS,
    min_singular_value: float = POSE_MIN_SINGULAR_VALUE,
) -> np.ndarray:
    """A configuration [rad] that puts the end-effector frame at ``position`` [m] with the
    orientation ``rotation`` (3 × 3, its axes in world coordinates), from ``q_seed``.

    ``Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e`` with ``λ² = ½ |e|² + 1e-9``, ``q ← clip(q + α Δq)`` with
    ``α`` halved until ``|e|`` decreases. A redundant arm moves as little as the damping
    allows from ``q_seed`` (seed each pose with the previous one for a continuous path).

    Raises:
        InverseKinematicsError: the pose is not reached to ``tol`` (out of reach, beyond the
            joint limits from this seed, or the arm has fewer than 6 joints), or only at a
            configuration whose 6-row Jacobian has a singular value below ``min_singular_value``.
        InvalidParameterError: ``position`` is not 3 finite numbers or ``rotation`` not a
            rotation matrix.
    """
    goal = np.asarray(position, dtype=float)
    if goal.shape != (3,) or not np.all(np.isfinite(goal)):
        raise InvalidParameterError(
            "position", np.asarray(position).tolist(), "3 finite coordinates (x, y, z) [m]"
        )
    R = np.asarray(rotation, dtype=float)
    if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise InvalidParameterError("rotation", np.asarray(rotation).tolist(), "a 3 × 3 rotation matrix")
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    q = np.clip(np.asarray(q_seed, dtype=float), lower, upper)
    data = robot.model.createData()
    target = tuple(float(c) for c in goal)
    e = pose_residual(robot, data, q, goal, R)
    for _ in range(max_iterations):
        if float(np.linalg.norm(e)) <= tol:
            break
        J = pin.computeFrameJacobian(
            robot.model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        damping = 0.5 * float(e @ e) + 1e-9
        step = J.T @ np.linalg.solve(J @ J.T + damping * np.eye(6), e)
        for _ in range(30):
            trial = np.clip(q + step, lower, upper)
            e_trial = pose_residual(robot, data, trial, goal, R)
            if float(e_trial @ e_trial) < float(e @ e):
                q, e = trial, e_trial
                break
            step = 0.5 * step
        else:
            break
    distance = float(np.linalg.norm(e))
    if distance > tol:
        raise InverseKinematicsError(
            target,
            f"pose not reached: the closest the frame came is {float(np.linalg.norm(e[:3])):.3g} m and "
            f"{float(np.degrees(np.linalg.norm(e[3:]))):.3g} deg away (out of reach, beyond the joint limits from "
            "this seed, or an arm with fewer than 6 joints)",
            tuple(float(x) for x in q),
        )
    J = pin.computeFrameJacobian(
        robot.model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )
    sigma = float(np.linalg.svd(J, compute_uv=False)[-1])
    if sigma < min_singular_value:
        raise InverseKinematicsError(
            target,
            f"reached only at a singular configuration (smallest singular value of the frame Jacobian "
            f"{sigma:.3g} < {min_singular_value:g})",
            tuple(float(x) for x in q),
        )
    return q
