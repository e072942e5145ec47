"""Kinematics from Pinocchio frames, and the analytic inverse kinematics of a planar 2R arm.

* :func:`forward_kinematics` / :func:`jacobian`: the end effector's planar ``(x, y)`` [m]
  and ``∂(x, y)/∂q`` (the base frame's x-y plane);
* :func:`joint_positions`: every joint origin and the end effector in 3-D, for many
  configurations (what figures and the 3-D view draw);
* :func:`inverse_kinematics` / :func:`workspace`: both elbow branches of a planar 2R arm;
* :func:`end_effector_position` / :func:`position_jacobian` / :func:`solve_position`: the
  end effector in 3-D and a damped least-squares inverse kinematics for any arm.

Angles [rad], positions [m].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, InverseKinematicsError, UnreachableTargetError
from twolink_pin.model import RobotModel


def _check_q(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    if not isinstance(robot, RobotModel):
        raise InvalidParameterError("robot", type(robot).__name__, "a RobotModel (twolink_pin.load_robot)")
    try:
        q = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError("q", q, f"{robot.nq} joint angles [rad]") from None
    if q.shape != (robot.nq,):
        raise InvalidParameterError("q", q.tolist(), f"shape ({robot.nq},) but got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise InvalidParameterError("q", q.tolist(), "finite joint angles [rad]")
    return q


def forward_kinematics(robot: RobotModel, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """End-effector position ``(x, y)`` [m] at configuration ``q`` [rad] (Pinocchio frames)."""
    q = _check_q(robot, q)
    data = data if data is not None else robot.create_data()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.ee_frame_id].translation[:2].copy()


def jacobian(robot: RobotModel, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """Planar end-effector Jacobian ``∂(x, y)/∂q`` [m/rad], shape (2, nv), world-aligned."""
    q = _check_q(robot, q)
    data = data if data is not None else robot.create_data()
    J = pin.computeFrameJacobian(robot.model, data, q, robot.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    return J[:2, :].copy()


def joint_positions(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """Origins of every joint and of the end-effector frame [m] at each configuration.

    Args:
        q: Configurations [rad], shape (F, nq) (or (nq,) for one).

    Returns:
        Shape (F, njoints, 3): the ``njoints − 1`` moving joints in order, then the end
        effector (shape (njoints, 3) for a single configuration).
    """
    if not isinstance(robot, RobotModel):
        raise InvalidParameterError("robot", type(robot).__name__, "a RobotModel (twolink_pin.load_robot)")
    try:
        configurations = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError("q", q, f"configurations of shape (F, {robot.nq}) [rad]") from None
    single = configurations.ndim == 1
    configurations = np.atleast_2d(configurations)
    if configurations.shape[1] != robot.nq or not np.all(np.isfinite(configurations)):
        raise InvalidParameterError(
            "q", f"array of shape {configurations.shape}", f"finite configurations of shape (F, {robot.nq})"
        )
    data = robot.create_data()
    model = robot.model
    out = np.empty((len(configurations), model.njoints, 3))
    for k, qk in enumerate(configurations):
        pin.framesForwardKinematics(model, data, qk)
        for j in range(1, model.njoints):
            out[k, j - 1] = data.oMi[j].translation
        out[k, -1] = data.oMf[robot.ee_frame_id].translation
    return out[0] if single else out


class Workspace(NamedTuple):
    """Reachable annulus of a planar 2R arm."""

    r_min: float
    """Inner radius ``|L1 − L2|`` [m]."""
    r_max: float
    """Outer radius ``L1 + L2`` [m]."""


def workspace(robot: RobotModel) -> Workspace:
    """The annulus ``|L1 − L2| <= r <= L1 + L2`` of a planar 2R arm [m]."""
    _require_2r(robot)
    l1, l2 = robot.link_lengths
    return Workspace(abs(l1 - l2), l1 + l2)


PLANAR_2R_TOLERANCE = 1e-9
"""How closely [m] an arm's forward kinematics must follow the planar 2R formula for the
analytic inverse kinematics to apply."""


def is_planar_2r(robot: RobotModel) -> bool:
    """Whether the analytic planar 2R inverse kinematics applies to ``robot`` (see
    :func:`inverse_kinematics`)."""
    try:
        _require_2r(robot)
    except InvalidParameterError:
        return False
    return True


def _require_2r(robot: RobotModel) -> None:
    """Raise unless ``robot`` is a planar 2R arm in the sense of the analytic IK: its end
    effector at ``(L1 cos q1 + L2 cos(q1 + q2), L1 sin q1 + L2 sin(q1 + q2))`` in the base's
    x-y plane (checked numerically at eight seeded configurations, to 1e-9 m)."""
    if not isinstance(robot, RobotModel):
        raise InvalidParameterError("robot", type(robot).__name__, "a RobotModel (twolink_pin.load_robot)")
    if robot.nv != 2 or robot.nq != 2:
        raise InvalidParameterError(
            "robot", robot.name, f"a planar 2R arm (nv = 2) for the analytic IK; it has nv = {robot.nv}"
        )
    l1, l2 = (float(x) for x in robot.link_lengths)
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, (8, 2))
    points = joint_positions(robot, q)[:, -1, :]
    expected = np.column_stack(
        [l1 * np.cos(q[:, 0]) + l2 * np.cos(q.sum(axis=1)), l1 * np.sin(q[:, 0]) + l2 * np.sin(q.sum(axis=1))]
    )
    miss = float(np.abs(points[:, :2] - expected).max())
    height = float(np.ptp(points[:, 2]))
    if miss > PLANAR_2R_TOLERANCE or height > PLANAR_2R_TOLERANCE:
        raise InvalidParameterError(
            "robot",
            robot.name,
            "a planar 2R arm for the analytic IK (two revolute joints about z, the end effector at "
            f"L1 = {l1:.4g} m and L2 = {l2:.4g} m along the links' x axes); its forward kinematics misses "
            f"that formula by {max(miss, height):.3g} m",
        )


def inverse_kinematics(
    robot: RobotModel, target: tuple[float, float] | np.ndarray, tol: float = 1e-12
) -> np.ndarray:
    """Both elbow branches reaching ``target = (x, y)`` [m] (report eqs. 2–3).

    Returns:
        Shape (2, 2): row 0 is the ``q2 >= 0`` branch (the report's "first pair"), row 1
        the ``q2 <= 0`` branch [rad]. Within ``tol`` of the annulus boundary both rows are
        the same pose: the straight arm (q2 = 0) outside, the folded arm (q2 = ±π) inside.

    Raises:
        UnreachableTargetError: if ``target`` lies outside the annulus (beyond ``tol`` [m]).
        InvalidParameterError: if ``target`` is not two finite numbers.
    """
    _require_2r(robot)
    if not (isinstance(tol, (int, float)) and not isinstance(tol, bool) and math.isfinite(tol) and tol >= 0):
        raise InvalidParameterError("tol", tol, "a finite distance >= 0 m")
    try:
        xy = np.asarray(target, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError("target", target, "two finite coordinates (x, y) [m]") from None
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise InvalidParameterError(
            "target", np.asarray(target).tolist(), "two finite coordinates (x, y) [m]"
        )
    x, y = float(xy[0]), float(xy[1])
    l1, l2 = (float(v) for v in robot.link_lengths)
    r_min, r_max = workspace(robot)
    r = math.hypot(x, y)
    if r < r_min - tol or r > r_max + tol:
        raise UnreachableTargetError((x, y), r_min, r_max)
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    # On the boundary (within tol) snap to the straight or folded arm, so both branches
    # coincide exactly instead of differing by the rounding acos amplifies near ±1.
    if r >= r_max - tol or c2 >= 1.0:
        c2 = 1.0
    elif r <= r_min + tol or c2 <= -1.0:
        c2 = -1.0
    q2 = math.acos(c2)
    solutions = []
    for elbow in (q2, -q2):
        k1, k2 = l1 + l2 * math.cos(elbow), l2 * math.sin(elbow)
        solutions.append((math.atan2(y, x) - math.atan2(k2, k1), elbow))
    return np.array(solutions)


# ----------------------------------------------------------------------- any arm, numerically


def end_effector_position(robot: RobotModel, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """End-effector position ``(x, y, z)`` [m] in the base frame at ``q`` [rad]."""
    q = _check_q(robot, q)
    data = data if data is not None else robot.create_data()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.ee_frame_id].translation.copy()


def end_effector_pose(
    robot: RobotModel, q: np.ndarray, data: pin.Data | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The end-effector frame at ``q`` [rad]: its origin ``(x, y, z)`` [m], its rotation (its
    axes in base coordinates, 3 × 3) and that rotation as ``(roll, pitch, yaw)`` [rad] with
    ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (the URDF's convention, Pinocchio's ``rpy``: what a
    via-pose file's ``rpy`` rows hold)."""
    q = _check_q(robot, q)
    data = data if data is not None else robot.create_data()
    pin.framesForwardKinematics(robot.model, data, q)
    frame = data.oMf[robot.ee_frame_id]
    rotation = frame.rotation.copy()
    return frame.translation.copy(), rotation, np.asarray(pin.rpy.matrixToRpy(rotation)).copy()


def position_jacobian(robot: RobotModel, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """``∂(x, y, z)/∂q`` of the end effector [m/rad], shape (3, nv), base-frame axes."""
    q = _check_q(robot, q)
    data = data if data is not None else robot.create_data()
    J = pin.computeFrameJacobian(robot.model, data, q, robot.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    return J[:3, :].copy()


IK_TOLERANCE = 1e-10
"""Distance [m] at which :func:`solve_position` has reached its target."""
IK_MAX_ITERATIONS = 500
"""Iterations :func:`solve_position` takes at most."""
IK_RESTARTS = 4
"""Perturbed seeds (±0.2 rad, seeded) :func:`solve_position` tries when the seed does not reach."""
IK_MIN_SINGULAR_VALUE = 1e-3
"""Smallest singular value [m/rad] of the position Jacobian accepted at a solution: below
it the arm is (nearly) singular there, and a trajectory through the point would need
joint speeds out of proportion with the end effector's."""


def solve_position(
    robot: RobotModel,
    target: tuple[float, ...] | np.ndarray,
    q_seed: np.ndarray,
    *,
    tol: float = IK_TOLERANCE,
    max_iterations: int = IK_MAX_ITERATIONS,
    min_singular_value: float = IK_MIN_SINGULAR_VALUE,
) -> np.ndarray:
    """A configuration [rad] that puts the end effector at ``target`` [m], from ``q_seed``.

    Damped least squares on Pinocchio's frame Jacobian (Levenberg–Marquardt with the
    damping ``λ² = ½ |e|² + 1e-9 m²`` of Sugihara, 2011, which converges quadratically and
    stays bounded near singularities)::

        Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e,      q ← clip(q + α Δq, joint limits)

    with ``α`` halved until ``|e|`` decreases; if that stalls short of the target (a seed
    at a singularity), up to :data:`IK_RESTARTS` perturbed seeds are tried. ``target`` has three coordinates, or two
    (``x, y``: only the base's x-y plane is constrained, for a planar arm). A redundant
    arm moves as little as the damping allows from ``q_seed`` (seed each via point with
    the previous one for a smooth path).

    Raises:
        InverseKinematicsError: the target is not reached to ``tol`` (the message gives the
            closest distance reached: out of reach or beyond the joint limits), or is reached
            only at a configuration whose Jacobian has a singular value below
            ``min_singular_value`` [m/rad].
        InvalidParameterError: ``target`` is not 2 or 3 finite numbers, or ``q_seed`` not nq.
    """
    goal = _target_point(target)
    rows = goal.size
    q = _check_q(robot, q_seed)
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    q = np.clip(q, lower, upper)
    data = robot.create_data()
    # A seed exactly at a singularity (a straight arm) has no descent direction towards some
    # targets: up to IK_RESTARTS seeded perturbations of the seed are tried, then it gives up.
    rng = np.random.default_rng(0)
    q, e = _descend(robot, data, goal, q, tol, max_iterations)
    for _ in range(IK_RESTARTS):
        if float(np.linalg.norm(e)) <= tol:
            break
        seed = np.clip(q_seed + rng.uniform(-0.2, 0.2, robot.nq), lower, upper)
        q_try, e_try = _descend(robot, data, goal, seed, tol, max_iterations)
        if float(e_try @ e_try) < float(e @ e):
            q, e = q_try, e_try
    distance = float(np.linalg.norm(e))
    point = tuple(float(c) for c in goal)
    if distance > tol:
        raise InverseKinematicsError(
            point,
            f"not reached: the closest the end effector came is {distance:.3g} m away (outside the arm's "
            "reach, or beyond its joint limits from this seed)",
            tuple(float(x) for x in q),
        )
    sigma = float(np.linalg.svd(position_jacobian(robot, q, data)[:rows], compute_uv=False)[-1])
    if sigma < min_singular_value:
        raise InverseKinematicsError(
            point,
            f"reached only at a singular configuration (smallest singular value of the position Jacobian "
            f"{sigma:.3g} m/rad < {min_singular_value:g})",
            tuple(float(x) for x in q),
        )
    return q


def _target_point(target: tuple[float, ...] | np.ndarray) -> np.ndarray:
    """``target`` as 2 (x, y) or 3 (x, y, z) finite coordinates [m], or an error naming it."""
    try:
        goal = np.asarray(target, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(
            "target", target, "2 (x, y) or 3 (x, y, z) finite coordinates [m]"
        ) from None
    if goal.shape not in ((2,), (3,)) or not np.all(np.isfinite(goal)):
        raise InvalidParameterError(
            "target", np.asarray(target).tolist(), "2 (x, y) or 3 (x, y, z) finite coordinates [m]"
        )
    return goal


def _descend(
    robot: RobotModel, data: pin.Data, goal: np.ndarray, qk: np.ndarray, tol: float, max_iterations: int
) -> tuple[np.ndarray, np.ndarray]:
    """Damped least squares from ``qk`` [rad] (see :func:`solve_position`) until the error
    ``goal − x(q)`` [m] is within ``tol`` or no halved step decreases it; ``(q, error)``."""
    rows = goal.size
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit

    def residual(q: np.ndarray) -> np.ndarray:
        return goal - end_effector_position(robot, q, data)[:rows]

    e = residual(qk)
    for _ in range(max_iterations):
        if float(np.linalg.norm(e)) <= tol:
            break
        J = position_jacobian(robot, qk, data)[:rows]
        damping = 0.5 * float(e @ e) + 1e-9
        step = J.T @ np.linalg.solve(J @ J.T + damping * np.eye(rows), e)
        for _ in range(30):
            trial = np.clip(qk + step, lower, upper)
            e_trial = residual(trial)
            if float(e_trial @ e_trial) < float(e @ e):
                qk, e = trial, e_trial
                break
            step = 0.5 * step
        else:
            break  # no descent: a local minimum of the distance (out of reach, a limit, a singular seed)
    return qk, e
