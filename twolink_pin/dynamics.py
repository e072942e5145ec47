"""Rigid-body dynamics from Pinocchio, plus joint friction.

The equation of motion is ``M(q) q̈ + C(q, q̇) q̇ + g(q) + f(q̇) = τ``. Every rigid-body
term comes from Pinocchio on the loaded model:

=====================  ==========================================
``mass_matrix``        CRBA (``pin.crba``), symmetric
``coriolis_matrix``    ``pin.computeCoriolisMatrix`` (Christoffel form: Ṁ − 2C skew)
``inverse_dynamics``   RNEA (``pin.rnea``)
``forward_dynamics``   ABA (``pin.aba``, world convention)
``regressor``          ``pin.computeJointTorqueRegressor``, polarised (below)
=====================  ==========================================

Friction ``f`` is not in Pinocchio's algorithms; :class:`Friction` adds it explicitly.
All functions take the model and a ``pin.Data`` the caller owns (one per user).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model.parameters import N_BODY_PARAMETERS, ParameterMap, inertial_parameters


def mass_matrix(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """Joint-space inertia ``M(q)`` [kg·m²], shape (nv, nv), symmetric (CRBA)."""
    M = pin.crba(model, data, q)
    return np.triu(M) + np.triu(M, 1).T


def coriolis_matrix(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Coriolis/centrifugal matrix ``C(q, q̇)`` [kg·m²/s], shape (nv, nv), Christoffel form."""
    return pin.computeCoriolisMatrix(model, data, q, v).copy()


def gravity_torque(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """Gravity torque ``g(q)`` [N·m], shape (nv,) (zero for the horizontal twolink)."""
    return pin.computeGeneralizedGravity(model, data, q).copy()


def inverse_dynamics(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """``τ = M(q) a + C(q, v) v + g(q)`` [N·m] by RNEA."""
    return pin.rnea(model, data, q, v, a).copy()


ABA_CONVENTION = pin.Convention.WORLD
"""ABA's frame convention everywhere here: same result as LOCAL to rounding, and its Python
call is ~10 % faster for the twolink (the plant's ABA is the simulator's largest cost)."""


def forward_dynamics(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, tau: np.ndarray
) -> np.ndarray:
    """``q̈ = M(q)⁻¹ (τ − C(q, v) v − g(q))`` [rad/s²] by ABA."""
    return pin.aba(model, data, q, v, tau, ABA_CONVENTION).copy()


def model_torque(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """``M(q) a + C(q, v) w + g(q)`` [N·m]: RNEA plus the Coriolis matrix times ``w − v``.

    The model term of every law that multiplies ``C(q, q̇)`` by a velocity other than
    ``q̇`` (feedforward ``C q̇_d``, Slotine–Li ``C q̇_r``).
    """
    tau = pin.rnea(model, data, q, v, a).copy()
    tau += pin.computeCoriolisMatrix(model, data, q, v) @ (w - v)
    return tau


def regressor(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """Inertial regressor ``Y_π`` with ``Y_π π = M(q) a + C(q, v) w + g(q)``.

    Pinocchio's ``computeJointTorqueRegressor(q, v, a)`` only gives the case ``w = v``.
    Slotine–Li control needs ``w = q̇_r ≠ v``. Because ``C`` is the Christoffel matrix,
    ``C(q, v) w = Γ(v, w)`` is a symmetric bilinear form with ``Γ(x, x) = C(q, x) x``, so
    by polarisation ``Γ(v, w) = [Γ(v + w, v + w) − Γ(v − w, v − w)] / 4`` and::

        Y_π(q, v, w, a) = Y(q, 0, a) + [Y(q, v + w, 0) − Y(q, v − w, 0)] / 4

    Args:
        q: Configuration [rad]. v: Velocity in ``C(q, v)`` [rad/s].
        w: Velocity multiplied by ``C`` [rad/s]. a: Acceleration [rad/s²].

    Returns:
        ``Y_π``, shape (nv, 10 (njoints − 1)).
    """
    zero = np.zeros(model.nv)
    y = pin.computeJointTorqueRegressor(model, data, q, zero, a).copy()
    y += 0.25 * pin.computeJointTorqueRegressor(model, data, q, v + w, zero)
    y -= 0.25 * pin.computeJointTorqueRegressor(model, data, q, v - w, zero)
    # Gravity is in all three calls; the difference cancels it, so it counts once.
    return y


def polarisation_pair(model: pin.Model) -> pin.Model:
    """Two copies of ``model`` side by side, so that one call evaluates the polarisation.

    By polarisation of the Christoffel form (see :func:`regressor`), the model term of
    every law is ``M(q) a + C(q, v) w + g(q) = RNEA(q, (v+w)/2, a) − RNEA₀(q, (v−w)/2, 0)``,
    RNEA₀ without gravity: RNEA (or the regressor) at two inputs, ``A = (q, (v+w)/2, a)``
    with gravity and ``B = (q, (v−w)/2, 0)`` without. Each call from
    Python costs ~0.6 µs of binding overhead, more than RNEA's own work on a small arm, so
    the fast simulator makes one call on a model holding both: copy A (joints ``0..nv−1``)
    and copy B (joints ``nv..2nv−1``), both attached to the universe. Gravity is shared by
    the copies, so the pair has **half** the model's gravity and copy B is mounted upside
    down (turned by π about an axis normal to gravity, which leaves its M and C unchanged
    and reverses the gravity it feels). Then, for ``Q = (q, q)``, ``V = ((v+w)/2, (v−w)/2)``,
    ``A = (a, 0)``::

        τ_A − τ_B = M a + C(q, v) w + g/2 + g/2          (RNEA on the pair)
        Y_A − Y_B = Y_π(q, v, w, a)                      (regressor: diagonal blocks)

    Raises:
        ValueError: ``nq != nv`` (the input layout above needs one coordinate per joint).
    """
    return polarisation_forest([model])


def polarisation_forest(models: Sequence[pin.Model]) -> pin.Model:
    """The :func:`polarisation_pair` of each of ``models``, all in one model: copies
    ``A_0, B_0, A_1, B_1, ...`` (joints ``2 i nv ..`` and ``(2 i + 1) nv ..``).

    The models must share their kinematics and gravity (e.g. differ only in inertias, as
    the batch engine's regressor columns do); the first one's gravity is used.

    Raises:
        ValueError: no model, or ``nq != nv``.
    """
    if not models:
        raise ValueError("expected at least one model, got none")
    first = models[0]
    if first.nq != first.nv:
        raise ValueError(f"expected a model with nq == nv, got nq = {first.nq}, nv = {first.nv}")
    g = np.array(first.gravity.linear, dtype=float)
    axis = np.cross(g, [1.0, 0.0, 0.0])
    if np.linalg.norm(axis) < 1e-9 * max(1.0, float(np.linalg.norm(g))):
        axis = np.cross(g, [0.0, 1.0, 0.0])
    norm = float(np.linalg.norm(axis))
    u = axis / norm if norm > 0 else np.array([1.0, 0.0, 0.0])
    flipped = pin.SE3(2.0 * np.outer(u, u) - np.eye(3), np.zeros(3))  # rotation by π about u
    forest = _renamed(models[0], "0a/")
    for i, model in enumerate(models):
        if i > 0:
            forest = pin.appendModel(forest, _renamed(model, f"{i}a/"), 0, pin.SE3.Identity())
        forest = pin.appendModel(forest, _renamed(model, f"{i}b/"), 0, flipped)
    forest.gravity = pin.Motion(0.5 * first.gravity.vector)
    forest.armature = np.concatenate([m.armature for m in models for _ in range(2)])
    return forest


def _renamed(model: pin.Model, prefix: str) -> pin.Model:
    """A copy of ``model`` with ``prefix`` on every joint and frame name but the universe's."""
    copy = pin.Model(model)
    for j in range(1, copy.njoints):
        copy.names[j] = prefix + copy.names[j]
    for i in range(1, len(copy.frames)):
        frame = copy.frames[i]
        frame.name = prefix + frame.name
        copy.frames[i] = frame
    return copy


def model_with_parameters(model: pin.Model, parameter_map: ParameterMap, p: np.ndarray) -> pin.Model:
    """A copy of ``model`` whose dynamics has the parameters ``p`` of ``parameter_map``.

    The inertial parameters become ``π' = π + P (p − p_model)``: since ``Y_π P = Y_p``,
    ``Y_π π' = Y_p p`` — a controller built on this model "believes" ``p``. The kinematics
    is unchanged. Used for parameter-estimate errors (``p = p_true ⊙ (1 + δ)``).

    Raises:
        InvalidParameterError: ``p`` has the wrong length or gives a body a non-finite
            inertia (e.g. a zero mass with a first moment).
    """
    p = np.asarray(p, dtype=float)
    if p.shape != (parameter_map.size,) or not np.all(np.isfinite(p)):
        raise InvalidParameterError(
            "p",
            p.tolist(),
            f"{parameter_map.size} finite values {parameter_map.names} but got shape {p.shape}",
        )
    pi = inertial_parameters(model) + parameter_map.matrix @ (p - parameter_map.values(model))
    copy = pin.Model(model)
    for j in range(1, model.njoints):
        body = pi[N_BODY_PARAMETERS * (j - 1) : N_BODY_PARAMETERS * j].copy()
        inertia = pin.Inertia.FromDynamicParameters(body)
        if not (np.all(np.isfinite(inertia.toDynamicParameters())) and inertia.mass > 0):
            raise InvalidParameterError(
                "p", p.tolist(), f"parameters giving body {j} a finite inertia with a mass > 0 kg"
            )
        copy.inertias[j] = inertia
    return copy


@dataclass(frozen=True)
class Friction:
    """Joint friction ``f_i(q̇_i) = V_i q̇_i + C_i sgn(q̇_i)``.

    Attributes:
        viscous: ``V`` per joint [N·m·s/rad], >= 0.
        coulomb: ``C`` per joint [N·m], >= 0.
        smoothing: Velocity scale ε [rad/s] of the smooth sign ``tanh(q̇/ε)``; 0 (default)
            uses the exact sign, right with a fixed-step integrator. A positive ε lets an
            adaptive-step integrator pass through sticking without stalling.
    """

    viscous: tuple[float, ...]
    coulomb: tuple[float, ...]
    smoothing: float = 0.0

    def __post_init__(self) -> None:
        if len(self.viscous) != len(self.coulomb):
            raise InvalidParameterError(
                "coulomb", self.coulomb, f"one value per joint, like viscous (length {len(self.viscous)})"
            )
        for name, values in (("viscous", self.viscous), ("coulomb", self.coulomb)):
            for x in values:
                if not (math.isfinite(x) and x >= 0):
                    raise InvalidParameterError(name, values, "finite values >= 0")
        if not (math.isfinite(self.smoothing) and self.smoothing >= 0):
            raise InvalidParameterError("smoothing", self.smoothing, "a finite velocity >= 0 rad/s")

    @classmethod
    def report(cls, smoothing: float = 0.0) -> Friction:
        """The report's friction: V = (0.4, 0.2) N·m·s/rad, C = (0.2, 0.1) N·m."""
        return cls(viscous=(0.4, 0.2), coulomb=(0.2, 0.1), smoothing=smoothing)

    @property
    def parameters(self) -> np.ndarray:
        """``(V_1..V_n, C_1..C_n)``, matching :func:`friction_regressor`'s columns."""
        return np.array(self.viscous + self.coulomb)

    def torque(self, v: np.ndarray) -> np.ndarray:
        """Friction torque ``f(q̇)`` [N·m] at joint velocity ``v`` [rad/s]."""
        return np.asarray(self.viscous) * v + np.asarray(self.coulomb) * smooth_sign(v, self.smoothing)


def smooth_sign(v: np.ndarray, smoothing: float) -> np.ndarray:
    """``sgn(v)`` if ``smoothing == 0`` else ``tanh(v / smoothing)``."""
    return np.sign(v) if smoothing == 0 else np.tanh(v / smoothing)


def friction_regressor(v: np.ndarray, smoothing: float = 0.0) -> np.ndarray:
    """``[diag(q̇), diag(sgn q̇)]``, shape (nv, 2 nv): ``f(q̇) = Y_f (V, C)``."""
    return np.hstack([np.diag(v), np.diag(smooth_sign(v, smoothing))])
