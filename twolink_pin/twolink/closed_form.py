"""The report's closed-form twolink model: an independent cross-check, never the plant.

Pinocchio computes every term the toolkit uses; these formulas (course report, "Desired
Trajectory" and "Adaptive Controller" sections, with the Y3 sign corrected) exist so tests
and the report can compare against them. Parameters ``p = (p1, p2, p3)`` [kg·m²], link
lengths [m], angles [rad], rates [rad/s].
"""

from __future__ import annotations

import numpy as np


def forward_kinematics(q: np.ndarray, l1: float, l2: float) -> np.ndarray:
    """End-effector ``(x, y)`` [m] of the planar 2R arm (report eq. 1); q shape (..., 2)."""
    q = np.asarray(q, dtype=float)
    q1, q12 = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([l1 * np.cos(q1) + l2 * np.cos(q12), l1 * np.sin(q1) + l2 * np.sin(q12)], axis=-1)


def mass_matrix(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``M(q) = [[p1 + 2 p3 cos q2, p2 + p3 cos q2], [p2 + p3 cos q2, p2]]`` [kg·m²]."""
    c2 = np.cos(q[1])
    return np.array([[p[0] + 2 * p[2] * c2, p[1] + p[2] * c2], [p[1] + p[2] * c2, p[1]]])


def coriolis_matrix(q: np.ndarray, v: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``C(q, q̇) = p3 sin q2 [[−q̇2, −(q̇1 + q̇2)], [q̇1, 0]]`` [kg·m²/s]."""
    s2 = np.sin(q[1])
    return p[2] * s2 * np.array([[-v[1], -(v[0] + v[1])], [v[0], 0.0]])


def regressor(q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``[Y1 Y2 Y3]`` with ``Y p = M(q) a + C(q, v) w``, shape (2, 3).

    The report prints Y3's lower-left Coriolis entry as ``−q̇1 sin q2``; ``C`` above
    (and Pinocchio) give ``+q̇1 sin q2``, used here.
    """
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    y1 = np.array([a[0], 0.0])
    y2 = np.array([a[1], a[0] + a[1]])
    y3 = np.array(
        [
            2 * c2 * a[0] + c2 * a[1] - s2 * v[1] * w[0] - s2 * (v[0] + v[1]) * w[1],
            c2 * a[0] + s2 * v[0] * w[0],
        ]
    )
    return np.stack([y1, y2, y3], axis=1)
