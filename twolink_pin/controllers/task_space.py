"""What the task-space laws (``osc``, ``qp-osc``, ``impedance``) share: the task's rows, the pose
error, the desired task and posture accelerations, the damped task-space inertia and the
dynamically consistent null-space projection.

Conventions are those of :class:`~twolink_pin.controllers.FrameTerms`: world-aligned, linear
rows first. The orientation error is ``e_o = log(R R_dᵀ)`` — the rotation vector [rad] that
takes the desired orientation to the actual one, in world axes — so that ``e_o ≈ ∫(ω − ω_d)``
for small errors.

**The task.** A frame that can move in 6 DOF (its Jacobian has rank 6 near the robot's
``home``) is controlled in position and orientation (6 rows). Otherwise (the planar twolink, a
3-joint arm) the task is the frame's position along the world axes it moves in (the twolink:
x and y); orientation is left to the joints. This is :func:`task_rows`' choice; it looks near
``home``, not at it, because a home can be singular (the twolink's, stretched along x, moves
its tip in y only).

**Singularities.** ``Λ = (J M⁻¹ Jᵀ)⁻¹`` is formed as ``S B⁻¹ S`` from ``J M⁻¹ Jᵀ`` normalised to
a unit diagonal, ``B = S J M⁻¹ Jᵀ S`` with ``S = diag(J M⁻¹ Jᵀ)^(-1/2)`` (so that its eigenvalues
have no unit whatever the rows' units: 1/kg for a force, 1/(kg·m²) for a moment). Write
``B = U diag(s) Uᵀ``. When ``s_min < ε`` (:data:`SINGULAR_RATIO`) Λ becomes
``S U diag(s / (s² + ρ²)) Uᵀ S`` with ``ρ² = ε² − s_min²`` (damped least squares with a damping
that grows from 0 at the threshold, Nakamura and Hanafusa, *J. Dyn. Sys., Meas., Control*
108(3), 1986; Chiaverini, *IEEE Trans. Robot. Autom.* 13(3), 1997), and the law warns once
(:class:`SingularityWarning`) and counts the damped evaluations.

The eigenvalues are computed only for the runs that may need the damping: every run's ``B⁻¹``
is first taken by LU (``numpy.linalg.inv``, a third of ``eigh``'s cost on a 6 × 6), and a run
whose inverse has a Frobenius norm ``‖B⁻¹‖_F ≤ 1/ε`` keeps it — every eigenvalue of a symmetric
``B`` then has ``|s| ≥ 1/‖B⁻¹‖_F ≥ ε``, so it would not be damped (:func:`certified_inverse`).
The rest (``s_min < √k ε`` at most: the bound is within ``√k`` of ``1/s_min``) take the
eigen-decomposition above, damped or not as ``s_min`` says. Each run's path depends on its own
matrix only: a batch still equals its single runs bit for bit.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.law_io import LawInput, Terms
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.small_linalg import inv

SINGULAR_RATIO = 1e-3
"""ε: the task inertia is damped when the smallest eigenvalue of ``J M⁻¹ Jᵀ`` normalised to a
unit diagonal is below ε (its largest is at most k: a condition number above about 1000 k)."""
_CERTIFIED = SINGULAR_RATIO**-2
"""``1/ε²``: the bound on ``‖B⁻¹‖_F²`` that certifies no eigenvalue below ε (:func:`certified_inverse`)."""
_HALF_SKEW = np.zeros((9, 3))
"""``E.reshape(9) @ _HALF_SKEW = (E₂₁ − E₁₂, E₀₂ − E₂₀, E₁₀ − E₀₁) / 2`` (row-major 3 × 3): one
product whose entries are exactly ``0.5 (a − b)`` (the ±½ products are exact, the zeros add
nothing)."""
_HALF_SKEW[[7, 2, 3], [0, 1, 2]] = 0.5
_HALF_SKEW[[5, 6, 1], [0, 1, 2]] = -0.5
_HALF_SKEW.setflags(write=False)
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


GENERIC_OFFSETS_RAD = (0.0, 0.3, -0.45)
"""Offsets [rad] added to every joint of ``home`` (alternating in sign along the chain) where
:func:`task_rows` looks at the Jacobian: a home that is itself singular (the twolink
stretched along x) would hide a direction the arm moves in everywhere else."""


def task_rows(robot: RobotModel) -> np.ndarray:
    """The rows of the 6-D frame Jacobian the law controls (see the module docstring): those
    of the configuration of :data:`GENERIC_OFFSETS_RAD` where the most rows move."""
    data = robot.model.createData()
    signs = np.where(np.arange(robot.nv) % 2 == 0, 1.0, -1.0)
    best = np.arange(0)
    for offset in GENERIC_OFFSETS_RAD:
        q = pin.integrate(robot.model, robot.home, offset * signs)
        rows = _moving_rows(
            pin.computeFrameJacobian(
                robot.model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            ),
            robot.nv,
        )
        if len(rows) > len(best):
            best = rows
    return best


def _moving_rows(J: np.ndarray, nv: int) -> np.ndarray:
    """All 6 rows where ``J`` has rank 6, else the independent linear rows that move."""
    if nv >= 6 and np.linalg.matrix_rank(J, tol=1e-9 * max(1.0, np.abs(J).max())) == 6:
        return np.arange(6)
    linear = J[:3]
    moving = np.flatnonzero(np.linalg.norm(linear, axis=1) > 1e-9 * max(1.0, np.abs(linear).max()))
    if np.linalg.matrix_rank(linear[moving]) < len(moving):  # e.g. a 1-joint arm: keep the first rows
        moving = moving[: np.linalg.matrix_rank(linear[moving])]
    return moving


def rotation_error(R: np.ndarray, R_des: np.ndarray) -> np.ndarray:
    """``log(R R_dᵀ)`` [rad] in world axes, shape (N, 3), for (N, 3, 3) and (1 or N, 3, 3)."""
    E = np.matmul(R, R_des.transpose(0, 2, 1))
    if E.shape[0] == 1:  # one run (the engine's N = 1, at every RK4 stage): the same bits on floats
        return _one_rotation_error(E)
    # The skew part (E₂₁ − E₁₂, E₀₂ − E₂₀, E₁₀ − E₀₁) / 2 from E's rows of 9 (few numpy calls:
    # this runs at every RK4 stage of a task-space law).
    w = E.reshape(-1, 9).dot(_HALF_SKEW)
    sin = np.sqrt(np.add.reduce(w * w, axis=1))  # |w|, as numpy.linalg.norm computes it
    cos = 0.5 * (E.trace(0, 1, 2) - 1.0)  # (E₀₀ + E₁₁) + E₂₂
    angle = np.arctan2(sin, cos)
    factor = 1.0 + angle * angle / 6.0  # θ / sin θ: its series near 0, else the quotient
    np.divide(angle, sin, out=factor, where=sin > 1e-9)
    out = factor[:, None] * w
    if np.maximum.reduce(angle) > np.pi - 1e-6:  # near π the skew part vanishes
        for i in np.flatnonzero(angle > np.pi - 1e-6):
            out[i] = pin.log3(E[i])
    return out


def _one_rotation_error(E: np.ndarray) -> np.ndarray:
    """:func:`rotation_error` of one run from ``E = R R_dᵀ`` (1, 3, 3), on Python floats: the
    same operations in the same order as the batch's numpy calls (``0.5 a − 0.5 b`` as the
    product with :data:`_HALF_SKEW` rounds it, the squares summed left to right, the trace
    ``(E₀₀ + E₁₁) + E₂₂``), and numpy's own ``arctan2`` (its SIMD loop rounds differently from
    ``math.atan2``), so a single run equals its row of a batch bit for bit, but for the sign of a zero component
    (the batch's product adds +0 terms; tests/test_single_run_paths.py)."""
    e0, e1, e2, e3, e4, e5, e6, e7, e8 = E.reshape(9).tolist()
    w0, w1, w2 = 0.5 * e7 - 0.5 * e5, 0.5 * e2 - 0.5 * e6, 0.5 * e3 - 0.5 * e1
    sin = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    angle = float(np.arctan2(sin, 0.5 * (e0 + e4 + e8 - 1.0)))
    if angle > np.pi - 1e-6:  # near π the skew part vanishes
        return np.array([pin.log3(E[0])])
    factor = angle / sin if sin > 1e-9 else 1.0 + angle * angle / 6.0
    return np.array([[factor * w0, factor * w1, factor * w2]])


def pose_error(
    position: np.ndarray, rotation: np.ndarray, position_des: np.ndarray, rotation_des: np.ndarray
) -> np.ndarray:
    """``(p − p_d, log(R R_dᵀ))`` [m, rad], shape (N, 6)."""
    return np.concatenate((position - position_des, rotation_error(rotation, rotation_des)), axis=1)


def row_index(rows: np.ndarray) -> slice | np.ndarray:
    """``rows`` as a slice when they are consecutive (a view, cheaper than fancy indexing at
    every RK4 stage: the twolink's 0:2, a 6-D task's 0:6), else the array itself."""
    if rows.size and np.array_equal(rows, np.arange(rows[0], rows[0] + rows.size)):
        return slice(int(rows[0]), int(rows[0]) + rows.size)
    return rows


def task_error(
    position: np.ndarray,
    rotation: np.ndarray,
    position_des: np.ndarray,
    rotation_des: np.ndarray,
    rows: slice | np.ndarray,
) -> np.ndarray:
    """:func:`pose_error` on the task's ``rows`` (increasing, as :func:`task_rows` gives them,
    or their :func:`row_index`), shape (N, k); the orientation error is computed only when a
    row needs it."""
    last = rows.stop - 1 if isinstance(rows, slice) else (rows[-1] if rows.size else -1)
    if last >= 3:
        return pose_error(position, rotation, position_des, rotation_des)[:, rows]
    return (position - position_des)[:, rows]  # a position task (the twolink: x, y)


def block_gain(linear: np.ndarray, angular: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The (R, k, k) gain on the task rows from (R, 3, 3) linear and angular blocks."""
    runs = max(linear.shape[0], angular.shape[0])
    K = np.zeros((runs, 6, 6))
    K[:, :3, :3] = linear
    K[:, 3:, 3:] = angular
    out = np.ascontiguousarray(K[:, rows][:, :, rows])
    out.setflags(write=False)
    return out


def certified_inverse(B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``B⁻¹`` (N, k, k) for symmetric (N, k, k) ``B``, and per run whether the inverse certifies
    that no eigenvalue of ``B`` is below ``ε`` in magnitude (:data:`SINGULAR_RATIO`):
    ``‖B⁻¹‖_F² ≤ 1/ε²`` (the Frobenius norm bounds the spectral radius ``1/|s|_min``). A run whose
    LU meets an exact zero pivot gets no inverse (``inf``) and no certificate."""
    try:
        inverse = inv(B)  # numpy.linalg.inv's LAPACK call, without its wrapper
    except np.linalg.LinAlgError:  # an exactly singular run stops the batch's inv: run by run
        inverse = np.full_like(B, np.inf)
        for i, b in enumerate(B):
            with contextlib.suppress(np.linalg.LinAlgError):
                inverse[i] = np.linalg.inv(b)
    flat = inverse.reshape(inverse.shape[0], -1)
    return inverse, np.vecdot(flat, flat) <= _CERTIFIED


class TaskInertia:
    """``Λ = (J M⁻¹ Jᵀ)⁻¹``, damped near singularities, for a law named ``law``."""

    def __init__(self, law: str) -> None:
        self.law = law
        self.damped = 0
        """Evaluations at which Λ was damped."""
        self._warned = False

    def __call__(self, A: np.ndarray, t: float) -> np.ndarray:
        """Λ from ``A = J M⁻¹ Jᵀ`` (N, k, k) at time ``t`` [s]."""
        scale = 1.0 / np.sqrt(A.diagonal(0, 1, 2))  # the rows' units (1/kg, 1/(kg·m²)) out
        S = scale[:, :, None] * scale[:, None, :]  # S_ij = scale_i scale_j
        B = A * S
        core, certain = certified_inverse(B)
        # some run may be near a singularity (one run: its flag, without a reduction)
        if not (certain[0] if certain.shape[0] == 1 else np.logical_and.reduce(certain)):
            uncertain = ~certain
            core[uncertain] = self._eigen_inverse(B[uncertain], t)
        return core * S

    def _eigen_inverse(self, B: np.ndarray, t: float) -> np.ndarray:
        """``U diag(s / (s² + ρ²)) Uᵀ`` for (n, k, k) ``B = U diag(s) Uᵀ`` (the module doc)."""
        s, U = np.linalg.eigh(B)
        if np.minimum.reduce(np.abs(s[:, 0])) < SINGULAR_RATIO:  # ρ² > 0 for some run
            rho2 = np.maximum(SINGULAR_RATIO**2 - s[:, :1] ** 2, 0.0)
            near = rho2[:, 0] > 0
            self.damped += 1
            if not self._warned:
                self._warned = True
                warnings.warn(
                    f"{self.law}: near a singularity at t = {t:.4g} s (the smallest eigenvalue of the "
                    f"normalised J M⁻¹ Jᵀ is {float(np.min(s[near, 0])):.3g} < {SINGULAR_RATIO:g}): the task "
                    "inertia is damped and the task no longer tracked exactly",
                    SingularityWarning,
                    stacklevel=4,
                )
            inverse = s / (s * s + rho2)
        else:  # ρ = 0 for every run: s / (s² + 0), the same bits without the sum
            inverse = s / (s * s)
        return np.matmul(U * inverse[:, None, :], U.transpose(0, 2, 1))


class TaskAcceleration(NamedTuple):
    """The task's kinematics at the state and the acceleration the task asks for, each on the
    task's rows (N runs)."""

    jacobian: np.ndarray
    """``J`` [m/rad; 1], shape (N, k, nv)."""
    drift: np.ndarray
    """``J̇ q̇`` [m/s²; rad/s²], shape (N, k)."""
    desired: np.ndarray
    """``ẍ* = ẍ_d − D ė − K e`` [m/s²; rad/s²], shape (N, k): the task acceleration that makes
    the error obey ``ë + D ė + K e = 0`` (:class:`~twolink_pin.controllers.osc.OperationalSpace`)."""


def task_acceleration(
    x: LawInput, terms: Terms, rows: slice | np.ndarray, K: np.ndarray, D: np.ndarray
) -> TaskAcceleration:
    """The end effector's Jacobian and ``J̇ q̇`` on ``rows`` (a :func:`row_index`) and the desired
    task acceleration ``ẍ* = ẍ_d − D (J q̇ − ẋ_d) − K e`` with ``e`` the :func:`task_error`, for
    the stiffness ``K`` [1/s²] and damping ``D`` [1/s], (R, k, k) (:func:`block_gain`)."""
    f = terms.frame(x.q, x.v)
    J = f.jacobian[:, rows]
    d = desired_frame(x)  # x_des, R_des, twist_des, accel_des
    e = task_error(f.position, f.rotation, d.position, d.rotation, rows)
    e_dot = np.matvec(J, x.v) - d.twist[:, rows]
    desired = d.accel[:, rows] - np.matvec(D, e_dot) - np.matvec(K, e)
    return TaskAcceleration(J, f.drift[:, rows], desired)


def posture_acceleration(x: LawInput, kp_null: np.ndarray | float, kd_null: np.ndarray | float) -> np.ndarray:
    """``q̈_d − K_n (q − q_d) − D_n (q̇ − q̇_d)`` [rad/s²], shape (N, nv): the joint acceleration
    the posture task asks for (the joint reference is the posture), ``K_n`` [1/s²] and ``D_n``
    [1/s] per joint."""
    return x.a_des - kp_null * (x.q - x.q_des) - kd_null * (x.v - x.v_des)


def null_space_torque(J: np.ndarray, MinvJt: np.ndarray, Lam: np.ndarray, tau0: np.ndarray) -> np.ndarray:
    """``Nᵀ τ₀ = τ₀ − Jᵀ Λ J M⁻¹ τ₀``: the part of ``τ₀`` that produces no task acceleration
    (Khatib's dynamically consistent null space), shape (N, nv)."""
    task_force = np.matvec(Lam, np.vecmat(tau0, MinvJt))  # Λ (M⁻¹Jᵀ)ᵀ τ₀ = Λ J M⁻¹ τ₀
    return tau0 - np.vecmat(task_force, J)
