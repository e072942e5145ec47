"""Kinematics from Pinocchio frames, and the analytic inverse kinematics of a planar 2R arm.

* :func:`forward_kinematics` / :func:`jacobian`: the end effector's planar ``(x, y)`` [m]
  and ``∂(x, y)/∂q`` (the base frame's x-y plane);
* :func:`joint_positions`: every joint origin and the end effector in 3-D, for many
  configurations (what figures and the 3-D view draw);
* :func:`inverse_kinematics` / :func:`workspace`: both elbow branches of a planar 2R arm.

Angles [rad], positions [m].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, UnreachableTargetError
from twolink_pin.model import RobotModel


def _check_q(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
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
    configurations = np.asarray(q, dtype=float)
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


def _require_2r(robot: RobotModel) -> None:
    """Raise unless ``robot`` is a planar 2R arm in the sense of the analytic IK: its end
    effector at ``(L1 cos q1 + L2 cos(q1 + q2), L1 sin q1 + L2 sin(q1 + q2))`` in the base's
    x-y plane (checked numerically at eight seeded configurations, to 1e-9 m)."""
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
    xy = np.asarray(target, dtype=float)
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
