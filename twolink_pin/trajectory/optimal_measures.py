"""What an optimal reference is measured by (:mod:`twolink_pin.trajectory.optimal`), each
computed here from its samples, not taken from the solver.

- :func:`effort_integral`: ``∫ τᵀτ dt`` over one period (RNEA on a fine grid, trapezoid);
- :func:`pose_error`: the end effector's largest error at the via times against the via poses;
- :func:`hull_excursion`: how far the end effector leaves the convex hull of its positions at
  the via points (a least-effort motion may take the tool far from where the task is);
- :func:`violation`: the largest excess over any limit, as a fraction of it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics.rigid_body import inverse_dynamics_rows
from twolink_pin.limits import POSITION, LimitsCheck
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction
    from twolink_pin.trajectory.optimal_spline import Vias

HULL_SAMPLES = 2001
"""Instants over one period at which :func:`hull_excursion` measures the end effector."""
HULL_TOLERANCE = 1e-6
"""How closely :func:`hull_distance` finds the distance [m] (a point inside: up to 6e-7 m)."""


def effort_integral(
    robot: RobotModel,
    trajectory: Trajectory,
    friction: Friction | None = None,
    samples: int = 4001,
    *,
    start: float | None = None,
    duration: float | None = None,
) -> float:
    """``∫ τᵀτ dt`` over one period [N²·m²·s] (or from ``start`` over ``duration`` [s]): RNEA
    (plus ``friction``) on ``samples`` evenly spaced instants, trapezoid."""
    t0 = trajectory.t0 if start is None else start
    t = t0 + np.linspace(0.0, trajectory.period if duration is None else duration, samples)
    ref = trajectory.sample(t)
    tau = inverse_dynamics_rows(robot.model, ref.q, ref.v, ref.a)
    if friction is not None:
        tau = tau + friction.torque(ref.v)
    return float(np.trapezoid((tau**2).sum(axis=1), t))


def pose_error(robot: RobotModel, trajectory: SampledTrajectory, vias: Vias) -> tuple[float, float] | None:
    """The end effector's largest position [m] and rotation [rad] error at the via times
    (None for joint via points)."""
    if vias.poses is None:
        return None
    q = trajectory.sample(trajectory.via_times).q
    data = robot.create_data()
    worst_p = worst_r = 0.0
    for qk, p, R in zip(q, *vias.poses, strict=True):
        pin.framesForwardKinematics(robot.model, data, qk)
        frame = data.oMf[robot.ee_frame_id]
        worst_p = max(worst_p, float(np.linalg.norm(frame.translation - p)))
        worst_r = max(worst_r, float(np.linalg.norm(pin.log3(R.T @ frame.rotation))))
    return worst_p, worst_r


class HullExcursion(NamedTuple):
    """How far the end effector leaves the convex hull of its via positions."""

    distance: float
    """The largest distance from the hull [m] (0: it stays inside)."""
    time: float
    """When [s]."""
    position: np.ndarray
    """Where the end effector is then [m], shape (3,)."""


def _positions(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """The end effector's position [m] at each row of ``q``, shape (K, 3): the joints'
    placements and that one frame's (every frame's cost 4× as much on the twolink)."""
    model, data, frame = robot.model, robot.create_data(), robot.ee_frame_id
    out = np.empty((q.shape[0], 3))
    for k, qk in enumerate(q):
        pin.forwardKinematics(model, data, qk)
        out[k] = pin.updateFramePlacement(model, data, frame).translation
    return out


def hull_distance(corners: np.ndarray, point: np.ndarray) -> float:
    """The distance [m] from ``point`` (3,) to the convex hull of ``corners`` (K, 3): the
    nearest convex combination ``Σ λ_k c_k`` (``λ >= 0``, ``Σ λ = 1``; a hull of any
    dimension: a segment, a polygon, a solid), a QP solved by DAQP with its proximal iterations
    (``‖Σ λ_k c_k − p‖²`` is only semidefinite in ``λ``), to about :data:`HULL_TOLERANCE`."""
    import daqp  # the trajectory optimiser's QP solver (twolink_pin.optimal.active_set)

    K = corners.shape[0]
    A = np.vstack([np.ones((1, K)), np.eye(K)])
    upper = np.concatenate([[1.0], np.full(K, 1e30)])
    lower = np.concatenate([[1.0], np.zeros(K)])
    sense = np.zeros(K + 1, dtype=np.int32)
    sense[0] = 5  # the equality Σ λ = 1
    weights, _, _, _ = daqp.solve(
        corners @ corners.T, -corners @ point, A, upper, lower, sense, eps_prox=1e-6
    )
    return float(np.linalg.norm(corners.T @ np.asarray(weights) - point))


def _polyline_distance(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Each point's distance [m] from the polyline through ``corners`` in order, shape (N,):
    at least its distance from their hull (the polyline lies in it)."""
    a, b = corners[:-1], corners[1:]
    d = b - a
    length2 = np.maximum((d * d).sum(axis=1), 1e-300)
    along = np.clip(np.einsum("nkj,kj->nk", points[:, None, :] - a[None], d) / length2, 0.0, 1.0)
    nearest = a[None] + along[:, :, None] * d[None]
    return np.sqrt(((points[:, None, :] - nearest) ** 2).sum(axis=2)).min(axis=1)


def hull_excursion(robot: RobotModel, trajectory: Trajectory, via_q: np.ndarray) -> HullExcursion:
    """The end effector's largest distance from the convex hull of its positions at the joint
    via points ``via_q`` (K, nv), over one period of ``trajectory`` at :data:`HULL_SAMPLES`
    instants. Exact QPs (:func:`hull_distance`) at the instants in decreasing order of their
    distance from the via points' polyline (an upper bound), until no instant left can beat
    the largest found."""
    corners = _positions(robot, np.asarray(via_q, dtype=float))
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, HULL_SAMPLES)
    where = _positions(robot, trajectory.sample(t).q)
    bound = (
        _polyline_distance(corners, where)
        if corners.shape[0] > 1
        else np.linalg.norm(where - corners, axis=1)
    )
    best, k_best = -1.0, 0
    for k in np.argsort(-bound, kind="stable"):
        if bound[k] <= best:
            break
        distance = hull_distance(corners, where[k])
        if distance > best:
            best, k_best = distance, int(k)
    return HullExcursion(max(best, 0.0), float(t[k_best]), where[k_best])


def violation(check: LimitsCheck) -> float | None:
    """The largest excess over a limit, a fraction of it (of the range for a position); None
    for a robot without limits."""
    worst = -np.inf
    for kind in check.kinds:
        given = check.limits.given(kind.kind)
        if not given.any():
            continue
        lower, upper = check.limits.bounds(kind.kind)
        scale = (upper - lower) if kind.kind is POSITION else upper
        worst = max(worst, float(np.max(-kind.margin[given] / scale[given])))
    return worst if np.isfinite(worst) else None


__all__ = [
    "HULL_SAMPLES",
    "HULL_TOLERANCE",
    "HullExcursion",
    "effort_integral",
    "hull_distance",
    "hull_excursion",
    "pose_error",
    "violation",
]
