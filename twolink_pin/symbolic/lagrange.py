"""M(q), C(q, q̇) and g(q) from the Lagrangian, term by term in the inertial parameters.

Body j's kinetic energy, with ``v``, ``ω`` the velocity of its frame's origin and its angular
velocity in its own frame, ``m`` its mass, ``h = m c`` its first moment and ``I_O`` its
inertia about the frame's origin (Pinocchio's ten parameters
``π_j = [m, h_x, h_y, h_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]``), is

    T_j = ½ m vᵀv + vᵀ(ω × h) + ½ ωᵀ I_O ω,

linear in π_j. With ``v = Jv q̇``, ``ω = Jω q̇`` (:func:`~twolink_pin.symbolic.kinematics.body_jacobians`)
``M(q) = Σ_j Σ_i π_{j,i} M^{(j,i)}(q)``, where

* ``M^{(m)} = Jvᵀ Jv``;
* ``M^{(h_e)} = S + Sᵀ``, ``S = Jωᵀ [e]× Jv`` (e the unit vector of x, y or z);
* ``M^{(I_ab)} = Jω_aᵀ Jω_b + Jω_bᵀ Jω_a`` (a ≠ b), ``Jω_aᵀ Jω_a`` (a = b), Jω_a the row a of Jω.

The potential energy ``V = −Σ_j g_wᵀ (m p_j + R_j h)`` (``g_w`` gravity in the base frame,
``(R_j, p_j)`` body j's pose) gives ``g(q) = ∂V/∂q`` the same way.

``C(q, q̇)`` is built from the **Christoffel symbols** of M (:func:`christoffel`):

    C_kj = Σ_i ½ (∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k) q̇_i,

the factorisation for which ``Ṁ − 2C`` is skew-symmetric (:func:`skew_defect` checks it
exactly) and ``C(q, v) w = C(q, w) v``; so ``M q̈ + C q̇ + g`` is the inverse dynamics, and
``M q̈_r + C(q, q̇) q̇_r + g`` the Slotine–Li form the adaptive laws use.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from twolink_pin.symbolic.kinematics import (
    Matrix,
    Vector,
    body_jacobians,
    local_transforms,
    mat_vec,
    skew,
    transpose,
    world_poses,
)
from twolink_pin.symbolic.skeleton import Skeleton
from twolink_pin.symbolic.trig_ring import TrigRing

_INERTIA_ROWS = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))
"""Rows (a, b) of I_xx, I_xy, I_yy, I_xz, I_yz, I_zz in Pinocchio's order."""


def _products(ring: TrigRing, A: Matrix, B: Matrix, n: int) -> Matrix:
    """``Aᵀ B`` of two 3 × n matrices."""
    return [
        [ring.reduce(sum((A[i][r] * B[i][c] for i in range(3)), ring.zero)) for c in range(n)]
        for r in range(n)
    ]


def _symmetrised(M: Matrix, n: int) -> Matrix:
    return [[M[r][c] + M[c][r] for c in range(n)] for r in range(n)]


def _body_mass_matrices(ring: TrigRing, Jv: Matrix, Jw: Matrix, n: int) -> list[Matrix]:
    """``M^{(π_i)}`` of one body's ten parameters."""
    out = [_products(ring, Jv, Jv, n)]
    for e in range(3):
        unit = [ring.one if i == e else ring.zero for i in range(3)]
        E = skew(ring, unit)
        EJv = [
            [ring.reduce(sum((E[i][k] * Jv[k][c] for k in range(3)), ring.zero)) for c in range(n)]
            for i in range(3)
        ]
        out.append(_symmetrised(_products(ring, Jw, EJv, n), n))
    for a, b in _INERTIA_ROWS:
        rows = [[ring.reduce(Jw[a][r] * Jw[b][c]) for c in range(n)] for r in range(n)]
        out.append(rows if a == b else _symmetrised(rows, n))
    return out


def standard_terms(ring: TrigRing, skeleton: Skeleton) -> tuple[list[Matrix], list[Vector]]:
    """``(M^{(π)}, g^{(π)})`` for every standard parameter (10 per body, Pinocchio's order):
    ``M(q) = Σ π_i M^{(i)}``, ``g(q) = Σ π_i g^{(i)}``."""
    n = skeleton.n
    local = local_transforms(ring, skeleton)
    world = world_poses(ring, skeleton, local)
    gravity = [ring.constant(x) * ring.gen("g") for x in skeleton.gravity_direction]
    masses: list[Matrix] = []
    gravities: list[Vector] = []
    for (Jv, Jw), (R, p) in zip(body_jacobians(ring, skeleton, local), world):
        masses += _body_mass_matrices(ring, Jv, Jw, n)
        in_body = mat_vec(ring, transpose(R), gravity)
        potentials = [-ring.reduce(sum((gravity[i] * p[i] for i in range(3)), ring.zero))]
        potentials += [-in_body[e] for e in range(3)] + [ring.zero] * 6
        gravities += [[ring.dq(V, k) for k in range(1, n + 1)] for V in potentials]
    return masses, gravities


def christoffel(ring: TrigRing, M: Matrix) -> Matrix:
    """``C(q, q̇)`` of ``M`` by the Christoffel symbols (module docstring), in ``dq1..dqn``."""
    n = len(M)
    rates = ring.rates("dq")
    dM = [[[ring.dq(M[r][c], i) for i in range(1, n + 1)] for c in range(n)] for r in range(n)]
    half = ring.constant(Fraction(1, 2))
    return [
        [
            ring.reduce(
                half
                * sum(((dM[k][j][i] + dM[k][i][j] - dM[i][j][k]) * rates[i] for i in range(n)), ring.zero)
            )
            for j in range(n)
        ]
        for k in range(n)
    ]


def skew_defect(ring: TrigRing, M: Matrix, C: Matrix) -> Any:
    """``N + Nᵀ`` with ``N = Ṁ − 2C``: the zero polynomial in every entry when ``Ṁ − 2C`` is
    skew-symmetric; returns the first nonzero entry, or None. (For a tilted arm, whose
    constants are inexact, an entry whose coefficients are all below the ring's tolerance
    times Ṁ's largest counts as zero.)"""
    n = len(M)
    two = ring.constant(Fraction(2))
    Mdot = [[ring.time_derivative(M[r][c]) for c in range(n)] for r in range(n)]
    N = [[Mdot[r][c] - two * C[r][c] for c in range(n)] for r in range(n)]
    scale = max((abs(float(x)) for row in Mdot for p in row for x in p.itercoeffs()), default=0.0)
    for r in range(n):
        for c in range(r, n):
            entry = ring.reduce(N[r][c] + N[c][r])
            if ring.tolerance is not None:
                if all(abs(float(x)) <= ring.tolerance * scale for x in entry.itercoeffs()):
                    continue
            if entry != ring.zero:
                return entry
    return None


def regressor_column(ring: TrigRing, M: Matrix, C: Matrix, g: Vector) -> Vector:
    """``M q̈ + C(q, q̇) w + g`` of one parameter: ``Y(q, q̇, w, q̈)``'s column (``w = q̇``:
    the inverse dynamics' regressor)."""
    n = len(M)
    a, w = ring.rates("ddq"), ring.rates("w")
    return [
        ring.reduce(sum((M[r][c] * a[c] + C[r][c] * w[c] for c in range(n)), ring.zero) + g[r])
        for r in range(n)
    ]
