"""Symbolic kinematics of the tree: each body's pose and its Jacobian in its own frame.

With Pinocchio's convention, body j's frame is its parent's frame moved by the joint's
placement ``(R0_j, t_j)`` and then by the joint itself:

* revolute about the unit axis a: ``R(q) = I + sin q [a]× + (1 − cos q) [a]×²`` (Rodrigues);
* prismatic along a: a translation ``a q``.

:func:`body_jacobians` gives, for each body j, the velocity of its frame's origin and its
angular velocity **in its own frame**, ``[v; ω] = J_j q̇`` (3 × n each): column k of an
ancestor joint k (or j itself) is that joint's motion carried into frame j —
``ω = Rᵀ a_k``, ``v = Rᵀ (a_k × p)`` for a revolute joint, ``v = Rᵀ a_k`` for a prismatic one,
with ``(R, p)`` the pose of frame j in frame k. Working in the body's frame keeps each
column a function of the joints between k and j only (the world frame would bring in every
joint before k, whose terms cancel only after simplification). :func:`world_poses` gives
each body's pose in the base frame, for the potential energy.

Every product is reduced (:meth:`~twolink_pin.symbolic.trig_ring.TrigRing.reduce`).
"""

from __future__ import annotations

from typing import Any

from twolink_pin.symbolic.skeleton import Skeleton
from twolink_pin.symbolic.trig_ring import REVOLUTE, TrigRing

Vector = list[Any]
Matrix = list[list[Any]]


def mat_mul(ring: TrigRing, A: Matrix, B: Matrix) -> Matrix:
    """``A B`` of two 3 × 3 matrices."""
    return [
        [ring.reduce(sum((A[i][k] * B[k][j] for k in range(3)), ring.zero)) for j in range(3)]
        for i in range(3)
    ]


def mat_vec(ring: TrigRing, A: Matrix, x: Vector) -> Vector:
    """``A x``."""
    return [ring.reduce(sum((A[i][k] * x[k] for k in range(3)), ring.zero)) for i in range(3)]


def transpose(A: Matrix) -> Matrix:
    return [[A[j][i] for j in range(3)] for i in range(3)]


def cross(ring: TrigRing, a: Vector, b: Vector) -> Vector:
    """``a × b``."""
    return [
        ring.reduce(a[1] * b[2] - a[2] * b[1]),
        ring.reduce(a[2] * b[0] - a[0] * b[2]),
        ring.reduce(a[0] * b[1] - a[1] * b[0]),
    ]


def skew(ring: TrigRing, a: Vector) -> Matrix:
    """``[a]×``: ``[a]× x = a × x``."""
    z = ring.zero
    return [[z, -a[2], a[1]], [a[2], z, -a[0]], [-a[1], a[0], z]]


def identity(ring: TrigRing) -> Matrix:
    return [[ring.one if i == j else ring.zero for j in range(3)] for i in range(3)]


def axis_vector(ring: TrigRing, skeleton: Skeleton, j: int) -> Vector:
    """Joint j's axis (0-based) as constant polynomials."""
    return [ring.constant(x) for x in skeleton.joints[j].axis]


def local_transforms(ring: TrigRing, skeleton: Skeleton) -> list[tuple[Matrix, Vector]]:
    """Pose ``(R, p)`` of each body's frame in its parent body's frame."""
    out = []
    for j, joint in enumerate(skeleton.joints):
        R0 = [[ring.constant(x) for x in row] for row in joint.rotation]
        t = [ring.zero if name is None else ring.gen(name) for name in joint.length_names(j + 1)]
        a = axis_vector(ring, skeleton, j)
        if joint.kind == REVOLUTE:
            c, s = ring.cos(j + 1), ring.sin(j + 1)
            K = skew(ring, a)
            K2 = mat_mul(ring, K, K)
            eye = identity(ring)
            Rq = [[eye[r][k] + s * K[r][k] + (ring.one - c) * K2[r][k] for k in range(3)] for r in range(3)]
            out.append((mat_mul(ring, R0, Rq), t))
        else:
            slide = mat_vec(ring, R0, a)
            q = ring.gen(f"q{j + 1}")
            out.append((R0, [t[i] + slide[i] * q for i in range(3)]))
    return out


def world_poses(
    ring: TrigRing, skeleton: Skeleton, local: list[tuple[Matrix, Vector]]
) -> list[tuple[Matrix, Vector]]:
    """Pose ``(R, p)`` of each body's frame in the base frame."""
    out: list[tuple[Matrix, Vector]] = []
    for j, joint in enumerate(skeleton.joints):
        R, p = local[j]
        if joint.parent >= 0:
            Rp, pp = out[joint.parent]
            moved = mat_vec(ring, Rp, p)
            R, p = mat_mul(ring, Rp, R), [ring.reduce(pp[i] + moved[i]) for i in range(3)]
        out.append((R, p))
    return out


def body_jacobians(
    ring: TrigRing, skeleton: Skeleton, local: list[tuple[Matrix, Vector]]
) -> list[tuple[Matrix, Matrix]]:
    """``(Jv, Jω)`` of each body in its own frame, 3 × n each (see the module docstring)."""
    n = skeleton.n
    out = []
    for j in range(n):
        Jv = [[ring.zero] * n for _ in range(3)]
        Jw = [[ring.zero] * n for _ in range(3)]
        R, p = identity(ring), [ring.zero] * 3  # pose of frame j in frame k, starting at k = j
        k = j
        while k >= 0:
            a = axis_vector(ring, skeleton, k)
            Rt = transpose(R)
            if skeleton.joints[k].kind == REVOLUTE:
                w, v = mat_vec(ring, Rt, a), mat_vec(ring, Rt, cross(ring, a, p))
            else:
                w, v = [ring.zero] * 3, mat_vec(ring, Rt, a)
            for i in range(3):
                Jv[i][k], Jw[i][k] = v[i], w[i]
            Rk, pk = local[k]
            moved = mat_vec(ring, Rk, p)
            R, p = mat_mul(ring, Rk, R), [ring.reduce(pk[i] + moved[i]) for i in range(3)]
            k = skeleton.joints[k].parent
        out.append((Jv, Jw))
    return out
