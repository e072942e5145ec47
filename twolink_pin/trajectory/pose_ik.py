"""Inverse kinematics of a full pose (position and orientation) of the end-effector frame.

:func:`solve_pose` is :func:`~twolink_pin.kinematics.solve_position` extended to six rows:
damped least squares (Levenberg–Marquardt with Sugihara's damping) on Pinocchio's
``LOCAL_WORLD_ALIGNED`` frame Jacobian, with the error

    e = (p_goal − p,  log(R_goal Rᵀ))      [m, rad], world axes, linear rows first

(the rotation vector that takes the current orientation to the goal, in world axes, so
that ``J_ω δq ≈ e_o`` to first order). Positions [m], angles [rad].

**A redundant arm** (more than 6 joints, the Panda) reaches a pose on a whole curve of
configurations (its self-motion), and damped least squares from a seed lands on one that
depends on the seed: a path solved pose after pose drifts along that curve, and a closed
pose path does not close in joint space. Given a ``posture``, :func:`solve_pose` returns
instead the configuration on the self-motion curve nearest to it (a local minimum of
``½ |q − q_posture|²`` subject to the pose, found from the seed): after reaching the pose
it repeats the null-space step ``δq = (I − J⁺J)(q_posture − q)`` (the projected gradient,
the classic posture task of Liégeois 1977), each followed by re-reaching the pose, until
that step is below :data:`POSTURE_TOLERANCE`. The answer is then a function of the pose
alone (on one branch), so equal poses give equal configurations.
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
POSTURE_TOLERANCE = 1e-10
"""|(I − J⁺J)(q_posture − q)| [rad] at which the posture steps of a redundant arm stop."""
POSTURE_MAX_ITERATIONS = 200
"""Most null-space posture steps of one solve."""


def pose_residual(
    robot: RobotModel, data: pin.Data, q: np.ndarray, position: np.ndarray, rotation: np.ndarray
) -> np.ndarray:
    """``(p_goal − p, log(R_goal Rᵀ))`` [m, rad] at ``q`` (world axes, linear first)."""
    pin.framesForwardKinematics(robot.model, data, q)
    frame = data.oMf[robot.ee_frame_id]
    return np.concatenate((position - frame.translation, pin.log3(rotation @ frame.rotation.T)))


def _jacobian(robot: RobotModel, data: pin.Data, q: np.ndarray) -> np.ndarray:
    return pin.computeFrameJacobian(
        robot.model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )


def _reach(
    robot: RobotModel,
    data: pin.Data,
    q: np.ndarray,
    goal: np.ndarray,
    R: np.ndarray,
    tol: float,
    max_iterations: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Damped least-squares steps from ``q`` [rad] toward the pose; the last ``q`` and its error."""
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    e = pose_residual(robot, data, q, goal, R)
    for _ in range(max_iterations):
        if float(np.linalg.norm(e)) <= tol:
            break
        J = _jacobian(robot, data, q)
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
    return q, e


def _toward_posture(
    robot: RobotModel,
    data: pin.Data,
    q: np.ndarray,
    goal: np.ndarray,
    R: np.ndarray,
    posture: np.ndarray,
    tol: float,
    max_iterations: int,
) -> np.ndarray:
    """From ``q`` (at the pose), the configuration on the self-motion curve nearest ``posture``
    (module doc): null-space steps, each re-reaching the pose, while they bring ``q`` closer."""
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for _ in range(POSTURE_MAX_ITERATIONS):
        J = _jacobian(robot, data, q)
        g = posture - q
        step = g - J.T @ np.linalg.solve(J @ J.T, J @ g)
        if float(np.linalg.norm(step)) <= POSTURE_TOLERANCE:
            break
        for _ in range(30):
            trial, e = _reach(robot, data, np.clip(q + step, lower, upper), goal, R, tol, max_iterations)
            if float(np.linalg.norm(e)) <= tol and float(np.linalg.norm(posture - trial)) < float(
                np.linalg.norm(g)
            ):
                q = trial
                break
            step = 0.5 * step
        else:
            break
    return q


def solve_pose(
    robot: RobotModel,
    position: np.ndarray,
    rotation: np.ndarray,
    q_seed: np.ndarray,
    *,
    posture: np.ndarray | None = None,
    tol: float = POSE_TOLERANCE,
    max_iterations: int = POSE_MAX_ITERATIONS,
    min_singular_value: float = POSE_MIN_SINGULAR_VALUE,
) -> np.ndarray:
    """A configuration [rad] that puts the end-effector frame at ``position`` [m] with the
    orientation ``rotation`` (3 × 3, its axes in world coordinates), from ``q_seed``.

    ``Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e`` with ``λ² = ½ |e|² + 1e-9``, ``q ← clip(q + α Δq)`` with
    ``α`` halved until ``|e|`` decreases. A redundant arm moves as little as the damping
    allows from ``q_seed`` (seed each pose with the previous one for a continuous path);
    with a ``posture`` [rad] it ends at the configuration nearest ``posture`` among those
    that reach the pose (module doc), so that the answer depends on the pose and not on the
    seed's drift.

    Raises:
        InverseKinematicsError: the pose is not reached to ``tol`` (out of reach, beyond the
            joint limits from this seed, or the arm has fewer than 6 joints), or only at a
            configuration whose 6-row Jacobian has a singular value below ``min_singular_value``.
        InvalidParameterError: ``position`` is not 3 finite numbers, ``rotation`` not a
            rotation matrix or ``posture`` not ``nq`` finite angles.
    """
    goal = np.asarray(position, dtype=float)
    if goal.shape != (3,) or not np.all(np.isfinite(goal)):
        raise InvalidParameterError(
            "position", np.asarray(position).tolist(), "3 finite coordinates (x, y, z) [m]"
        )
    R = np.asarray(rotation, dtype=float)
    if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise InvalidParameterError("rotation", np.asarray(rotation).tolist(), "a 3 × 3 rotation matrix")
    if posture is not None:
        posture = np.asarray(posture, dtype=float)
        if posture.shape != (robot.nq,) or not np.all(np.isfinite(posture)):
            raise InvalidParameterError(
                "posture", np.asarray(posture).tolist(), f"{robot.nq} finite joint angles [rad]"
            )
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    data = robot.model.createData()
    target = tuple(float(c) for c in goal)
    q, e = _reach(
        robot, data, np.clip(np.asarray(q_seed, dtype=float), lower, upper), goal, R, tol, max_iterations
    )
    distance = float(np.linalg.norm(e))
    if distance > tol:
        raise InverseKinematicsError(
            target,
            f"pose not reached: the closest the frame came is {float(np.linalg.norm(e[:3])):.3g} m and "
            f"{float(np.degrees(np.linalg.norm(e[3:]))):.3g} deg away (out of reach, beyond the joint limits from "
            "this seed, or an arm with fewer than 6 joints)",
            tuple(float(x) for x in q),
        )
    if posture is not None and robot.nv > 6:
        q = _toward_posture(robot, data, q, goal, R, posture, tol, max_iterations)
    J = _jacobian(robot, data, q)
    sigma = float(np.linalg.svd(J, compute_uv=False)[-1])
    if sigma < min_singular_value:
        raise InverseKinematicsError(
            target,
            f"reached only at a singular configuration (smallest singular value of the frame Jacobian "
            f"{sigma:.3g} < {min_singular_value:g})",
            tuple(float(x) for x in q),
        )
    return q
