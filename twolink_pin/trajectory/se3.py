"""A periodic reference on SE(3): the end-effector frame through via poses, and its joint path.

**The pose path.** Via poses ``(p_k, R_k)`` at times ``T_k`` (the last equal to the first:
the reference repeats every period). Between two via poses the frame moves on the
geodesic of each factor with one rest-to-rest time scaling ``s(τ)``, ``τ = (t − T_k)/h_k``::

    p(t) = p_k + s(τ) (p_{k+1} − p_k)                  (a straight line)
    R(t) = R_k exp(s(τ) φ_k),  φ_k = log(R_kᵀ R_{k+1})  (rotation about one fixed axis)
    s(τ) = 35 τ⁴ − 84 τ⁵ + 70 τ⁶ − 20 τ⁷

so the twist and spatial acceleration, world-aligned with the linear rows first (the
convention of :class:`~twolink_pin.controllers.FrameTerms`), are exact closed forms::

    [ṗ; ω] = (ṡ/h) [Δp; R_k φ_k],      [p̈; ω̇] = (s̈/h²) [Δp; R_k φ_k]

``s`` has zero first, second and third derivatives at both ends, so position, velocity,
acceleration (and jerk) are continuous everywhere, at the via poses and across the period
(where they are all zero), and the path passes through every via pose exactly. Why not a
spline through the vias (``scipy.spatial.transform.RotationSpline``): the reference is
periodic and ``RotationSpline`` has no periodic end conditions, so its angular rate would
jump at every repetition; and a spline overshoots the corners of a polygon (a square would
come out rounded). The price of this choice: the frame stops at every via pose.

**The joint path** (for postures and joint-space laws): on each segment the pose depends on
``s`` alone, so the joint path is a geometric path ``q = Q_k(s)``: the 6-D inverse
kinematics (:func:`~twolink_pin.trajectory.pose_ik.solve_pose`) at :data:`IK_SAMPLES` + 1
values of ``s``, each seeded by the one before (one IK branch), interpolated by a quintic
B-spline in ``s``; then ``q̇ = Q' ṡ/h``, ``q̈ = Q'' (ṡ/h)² + Q' s̈/h²`` (and the jerk) follow
by the chain rule, exactly zero at the via poses like the pose path's. Its forward
kinematics equals the pose path to the interpolation error (see :attr:`PoseTrajectory.ik_error`,
below 1e-6 m and 1e-6 rad for the examples' paths).

**Position only** (``position_rows`` 2 or 3: an arm of fewer than 6 joints, e.g. the planar
twolink, a via file's ``path = "lines"``): the IK is the position's alone
(:func:`~twolink_pin.kinematics.solve_position`, on the first 2 or 3 coordinates); the position
path is the same straight lines, and the orientation :meth:`PoseTrajectory.pose` reports is the
geodesic between the via orientations given (the forward kinematics there) — a task on the
position rows alone (the twolink's) never reads it.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError, InverseKinematicsError
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.base import Trajectory, TrajectorySample
from twolink_pin.trajectory.polynomial import check_period, check_times
from twolink_pin.trajectory.pose_ik import solve_pose

if TYPE_CHECKING:
    from scipy.interpolate import BSpline

IK_SAMPLES = 32
"""Intervals of ``s`` per segment at which the joint path is solved by inverse kinematics."""
MAX_POSITION = 100.0
"""Largest coordinate of a via position [m]: no arm reaches further (a number beyond is a
typo or garbage; refused before the IK, naming the row and column)."""
CLOSURE_TOLERANCE = 1e-9
"""How far [m, rad] the last via pose may be from the first."""
JOINT_CLOSURE_TOLERANCE = 1e-6
"""How far [rad] the joint path may end from where it starts (then snapped to the start)."""


class PoseSample(NamedTuple):
    """The desired frame at K times (world-aligned, linear rows first)."""

    position: np.ndarray
    """Origin [m], shape (K, 3)."""
    rotation: np.ndarray
    """Orientation (the frame's axes in world coordinates), shape (K, 3, 3)."""
    twist: np.ndarray
    """``[ṗ; ω]`` [m/s; rad/s], shape (K, 6)."""
    accel: np.ndarray
    """``[p̈; ω̇]`` [m/s²; rad/s²] (classical acceleration), shape (K, 6)."""


def exp3_batch(w: np.ndarray) -> np.ndarray:
    """``exp([w]×)`` for rotation vectors ``w`` [rad], shape (K, 3) → (K, 3, 3) (Rodrigues)."""
    angle = np.linalg.norm(w, axis=1)
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    a = np.where(small, 1.0 - angle**2 / 6.0, np.sin(angle) / safe)
    b = np.where(small, 0.5 - angle**2 / 24.0, (1.0 - np.cos(angle)) / safe**2)
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


def time_scaling(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``s, ds/dτ, d²s/dτ², d³s/dτ³`` of the rest-to-rest septic at ``τ ∈ [0, 1]``."""
    t = tau
    s = t**4 * (35.0 + t * (-84.0 + t * (70.0 - 20.0 * t)))
    s1 = t**3 * (140.0 + t * (-420.0 + t * (420.0 - 140.0 * t)))
    s2 = t**2 * (420.0 + t * (-1680.0 + t * (2100.0 - 840.0 * t)))
    s3 = t * (840.0 + t * (-5040.0 + t * (8400.0 - 4200.0 * t)))
    return s, s1, s2, s3


class PoseTrajectory(Trajectory):
    """Periodic SE(3) reference of the end-effector frame through via poses (module doc);
    :meth:`sample` is its joint path, :meth:`pose` the pose, twist and acceleration.

    Build it with :func:`pose_trajectory`.
    """

    def __init__(
        self,
        times: np.ndarray,
        positions: np.ndarray,
        rotations: np.ndarray,
        via_q: np.ndarray,
        paths: Sequence[BSpline],
        period: float,
        ik_error: tuple[float, float],
    ) -> None:
        self.times = readonly(times)
        """Via-pose times [s], shape (n + 1,)."""
        self.positions = readonly(positions)
        """Via positions [m], shape (n + 1, 3)."""
        self.rotations = readonly(rotations)
        """Via orientations, shape (n + 1, 3, 3)."""
        self.via_q = readonly(via_q)
        """The joint configurations at the via poses [rad], shape (n + 1, nv)."""
        self.period = float(period)
        self.t0 = float(times[0])
        self.span = float(times[-1] - times[0])
        """Time from the first via pose to the last [s] (the rest of the period is a rest)."""
        self.ik_error = ik_error
        """Largest distance [m] and rotation angle [rad] between the joint path's forward
        kinematics and the pose path, measured midway between the IK samples."""
        self._paths = list(paths)
        self._dp = np.diff(positions, axis=0)
        self._axis = np.array(
            [R0 @ pin.log3(R0.T @ R1) for R0, R1 in itertools.pairwise(rotations)]
        )  # R_k φ_k: the segment's rotation axis times angle, in world axes
        self._phi = np.array([pin.log3(R0.T @ R1) for R0, R1 in itertools.pairwise(rotations)])

    @property
    def nv(self) -> int:
        return int(self.via_q.shape[1])

    def segment_path(self, k: int, s: np.ndarray, order: int = 0) -> np.ndarray:
        """Segment ``k``'s geometric joint path ``Q_k^{(order)}(s)`` at ``s ∈ [0, 1]`` (module
        docstring: its own parameter, whose time scaling the reference then applies), shape
        (len(s), nv): what a retiming keeps while it chooses the timing anew."""
        return np.asarray(self._paths[k](np.clip(np.asarray(s, dtype=float), 0.0, 1.0), order))

    @property
    def via_times(self) -> np.ndarray:
        return np.asarray(self.times)

    def _locate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Segment index, ``τ``, segment length ``h`` and a mask of times in the rest after the
        last via pose, for times ``t`` (1-D)."""
        tt = self.t0 + np.mod(np.atleast_1d(np.asarray(t, dtype=float)) - self.t0, self.period)
        k = np.clip(np.searchsorted(self.times, tt, side="right") - 1, 0, len(self.times) - 2)
        h = self.times[k + 1] - self.times[k]
        rest = tt >= self.times[-1]
        tau = np.where(rest, 0.0, np.clip((tt - self.times[k]) / h, 0.0, 1.0))
        k = np.where(rest, 0, k)
        return k, tau, h, rest

    def pose(self, t: float | np.ndarray) -> PoseSample:
        """The desired frame at times ``t`` [s] (shape (K, …) for K times, K = 1 for a scalar)."""
        k, tau, h, _ = self._locate(t)
        s, s1, s2, _ = time_scaling(tau)
        position = self.positions[k] + s[:, None] * self._dp[k]
        rotation = self.rotations[k] @ exp3_batch(s[:, None] * self._phi[k])
        rate = np.concatenate((self._dp[k], self._axis[k]), axis=1)
        twist = (s1 / h)[:, None] * rate
        accel = (s2 / h**2)[:, None] * rate
        return PoseSample(position, rotation, twist, accel)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        scalar = np.ndim(t) == 0
        k, tau, h, _ = self._locate(t)
        s, s1, s2, s3 = time_scaling(tau)
        n = len(tau)
        out = [np.empty((n, self.nv)) for _ in range(4)]
        for segment in np.unique(k):
            m = k == segment
            path = self._paths[segment]
            Q0, Q1, Q2, Q3 = (path(s[m], nu) for nu in range(4))
            d1, d2, d3 = (s1[m] / h[m])[:, None], (s2[m] / h[m] ** 2)[:, None], (s3[m] / h[m] ** 3)[:, None]
            out[0][m] = Q0
            out[1][m] = Q1 * d1
            out[2][m] = Q2 * d1**2 + Q1 * d2
            out[3][m] = Q3 * d1**3 + 3.0 * Q2 * d1 * d2 + Q1 * d3
        if scalar:
            return TrajectorySample(*(x[0] for x in out))
        return TrajectorySample(*out)


def _check_finite(name: str, values: np.ndarray, bound: float, unit: str) -> None:
    """Raise naming the first entry (row, column) of ``values`` that is not finite or beyond ``±bound``."""
    bad = ~np.isfinite(values) | (np.abs(values) > bound)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidParameterError(
            name + "".join(f"[{i}]" for i in index),
            float(values[index]),
            f"a finite number within ±{bound:g}{' ' + unit if unit else ''}",
        )


def pose_trajectory(
    robot: RobotModel,
    times: Sequence[float],
    positions: np.ndarray,
    rotations: np.ndarray,
    period: float | None = None,
    seed: np.ndarray | None = None,
    position_rows: int | None = None,
) -> PoseTrajectory:
    """The SE(3) reference of ``robot``'s end-effector frame through the via poses
    ``positions`` [m] (n, 3) and ``rotations`` (n, 3, 3) at ``times`` [s], repeated every
    ``period`` [s] (default the span; the frame rests at the last pose for the rest), its
    joint path solved from ``seed`` [rad] (default the robot's home); ``position_rows`` 2 or 3:
    the path's positions alone are solved for (the module docstring's "position only").

    Raises:
        InvalidParameterError: times, shapes, rotations or the closure are wrong.
        InverseKinematicsError: a pose on the path is out of reach or singular (the message
            says which segment and where on it).
    """
    times_t = tuple(float(t) for t in times)
    check_times(times_t, len(positions), "positions")
    check_period(period, times_t)
    P = np.asarray(positions, dtype=float)
    R = np.asarray(rotations, dtype=float)
    n = len(times_t)
    _check_via_poses(P, R, n)
    posture = robot.home if seed is None else np.asarray(seed, dtype=float)
    q = posture
    ik = _ik(robot, posture, position_rows)
    try:
        q = ik(P[0], R[0], q)
    except InverseKinematicsError as err:
        raise InverseKinematicsError(err.target, f"via pose 0: {err.reason}", err.q) from None
    paths = []
    via_q = [q]
    worst_p = worst_r = 0.0
    data = robot.model.createData()
    for k in range(n - 1):
        path, q, seg_p, seg_r = _segment_path(robot, data, P, R, k, q, ik, via_q[0] if k == n - 2 else None)
        paths.append(path)
        via_q.append(q)
        worst_p, worst_r = max(worst_p, seg_p), max(worst_r, seg_r if position_rows is None else 0.0)
    span = times_t[-1] - times_t[0]
    return PoseTrajectory(
        np.array(times_t),
        P,
        R,
        np.array(via_q),
        paths,
        span if period is None else period,
        (worst_p, worst_r),
    )


IK = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""``(position [m], rotation, seed [rad]) -> q [rad]``: a segment's inverse kinematics."""


def _ik(robot: RobotModel, posture: np.ndarray, position_rows: int | None) -> IK:
    """The 6-D pose IK (``position_rows`` None), or the position IK on the first 2 or 3 coordinates."""
    if position_rows is None:
        return lambda p, R, q: solve_pose(robot, p, R, q, posture=posture)
    if position_rows not in (2, 3):
        raise InvalidParameterError(
            "position_rows", position_rows, "2 (x, y), 3 (x, y, z) or None (the pose)"
        )
    from twolink_pin.kinematics import solve_position

    return lambda p, R, q: solve_position(robot, p[:position_rows], q)


def _check_via_poses(P: np.ndarray, R: np.ndarray, n: int) -> None:
    """Raise unless ``P`` [m] is (n, 3) and ``R`` (n, 3, 3), finite, of rotation matrices, and
    the last pose is the first again (the reference repeats)."""
    if P.shape != (n, 3) or R.shape != (n, 3, 3):
        raise InvalidParameterError(
            "via poses", f"{P.shape}, {R.shape}", f"positions ({n}, 3) and rotations ({n}, 3, 3)"
        )
    _check_finite("positions", P, MAX_POSITION, "m")
    _check_finite("rotations", R, 1.0 + 1e-9, "")
    for i, Ri in enumerate(R):
        if not np.allclose(Ri @ Ri.T, np.eye(3), atol=1e-9) or np.linalg.det(Ri) < 0:
            raise InvalidParameterError(f"rotations[{i}]", Ri.tolist(), "a rotation matrix")
    gap = max(float(np.abs(P[-1] - P[0]).max()), float(np.linalg.norm(pin.log3(R[0].T @ R[-1]))))
    if gap > CLOSURE_TOLERANCE:
        raise InvalidParameterError(
            f"via poses[{n - 1}]",
            f"{gap:.3g} m or rad from the first",
            "the first via pose again (the reference repeats)",
        )


def _segment_path(
    robot: RobotModel,
    data: pin.Data,
    P: np.ndarray,
    R: np.ndarray,
    k: int,
    q: np.ndarray,
    ik: IK,
    closing: np.ndarray | None,
) -> tuple[BSpline, np.ndarray, float, float]:
    """Segment k's joint path (via pose k → k + 1, the pose interpolated on SE(3)) from ``q``
    [rad]: the IK at :data:`IK_SAMPLES` + 1 points, a quintic spline through them, its end
    configuration (``closing``, the first via configuration, for the last segment, which must
    reach it) and its worst position [m] and orientation [rad] error between the points."""
    grid = np.linspace(0.0, 1.0, IK_SAMPLES + 1)
    phi = pin.log3(R[k].T @ R[k + 1])
    qs = []
    for s in grid:
        try:
            q = ik(P[k] + s * (P[k + 1] - P[k]), R[k] @ pin.exp3(s * phi), q)
        except InverseKinematicsError as err:
            raise InverseKinematicsError(
                err.target, f"segment {k} (via pose {k} → {k + 1}) at s = {s:.3g}: {err.reason}", err.q
            ) from None
        qs.append(q)
    if closing is not None:  # the closing pose: the first configuration again, or the path does not repeat
        gap = float(np.abs(qs[-1] - closing).max())
        if gap > JOINT_CLOSURE_TOLERANCE:
            raise InvalidParameterError(
                f"via poses[{k + 1}]",
                f"reached at a configuration {gap:.3g} rad from the first",
                f"the first configuration again (to {JOINT_CLOSURE_TOLERANCE:g} rad): the joint path must "
                "repeat too (the path crossed to another inverse-kinematics branch; add via poses or a seed)",
            )
        qs[-1] = closing
    from scipy.interpolate import make_interp_spline  # 0.8 s to import: only for pose paths

    path = make_interp_spline(grid, np.array(qs), k=5)
    worst_p = worst_r = 0.0
    mid = 0.5 * (grid[1:] + grid[:-1])
    for s, qm in zip(mid, path(mid), strict=True):
        pin.framesForwardKinematics(robot.model, data, qm)
        frame = data.oMf[robot.ee_frame_id]
        worst_p = max(worst_p, float(np.linalg.norm(frame.translation - (P[k] + s * (P[k + 1] - P[k])))))
        worst_r = max(worst_r, float(np.linalg.norm(pin.log3(frame.rotation.T @ R[k] @ pin.exp3(s * phi)))))
    return path, qs[-1], worst_p, worst_r
