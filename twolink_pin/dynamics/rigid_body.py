"""Rigid-body dynamics from Pinocchio.

The equation of motion is ``M(q) q̈ + C(q, q̇) q̇ + g(q) + f(q̇) = τ``. Every rigid-body
term comes from Pinocchio on the loaded model:

=====================  ==========================================
``mass_matrix``        CRBA (``pin.crba``), symmetric
``coriolis_matrix``    ``pin.computeCoriolisMatrix`` (Christoffel form: Ṁ − 2C skew)
``inverse_dynamics``   RNEA (``pin.rnea``)
``inverse_dynamics_rows``  RNEA at many samples in one call (``pin.rneaInParallel``)
``forward_dynamics``   ABA (``pin.aba``, world convention)
``regressor``          ``pin.computeJointTorqueRegressor``, polarised (below)
=====================  ==========================================

Friction ``f`` is not in Pinocchio's algorithms: :mod:`twolink_pin.dynamics.friction`.
All functions take the model and a ``pin.Data`` the caller owns (one per user), and check
their vectors first: one value per joint, finite (an :class:`InvalidParameterError` naming
the argument, never NaN results or a C++ signature dump).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError


def _model(model: Any, data: Any) -> None:
    if not isinstance(model, pin.Model):
        raise InvalidParameterError("model", type(model).__name__, "a pinocchio.Model (robot.model)")
    if not isinstance(data, pin.Data):
        raise InvalidParameterError("data", type(data).__name__, "a pinocchio.Data (model.createData())")


def _vector(name: str, value: Any, n: int, unit: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, f"{n} finite numbers [{unit}]") from None
    if array.shape != (n,):
        raise InvalidParameterError(
            name, f"shape {array.shape}", f"shape ({n},): one value per joint [{unit}]"
        )
    if not np.all(np.isfinite(array)):
        raise InvalidParameterError(name, array.tolist(), f"{n} finite numbers [{unit}]")
    return array


def mass_matrix(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """Joint-space inertia ``M(q)`` [kg·m²], shape (nv, nv), symmetric (CRBA)."""
    _model(model, data)
    M = pin.crba(model, data, _vector("q", q, model.nq, "rad"))
    return np.triu(M) + np.triu(M, 1).T


def coriolis_matrix(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Coriolis/centrifugal matrix ``C(q, q̇)`` [kg·m²/s], shape (nv, nv), Christoffel form."""
    _model(model, data)
    q, v = _vector("q", q, model.nq, "rad"), _vector("v", v, model.nv, "rad/s")
    return pin.computeCoriolisMatrix(model, data, q, v).copy()


def gravity_torque(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """Gravity torque ``g(q)`` [N·m], shape (nv,) (zero for the horizontal twolink)."""
    _model(model, data)
    return pin.computeGeneralizedGravity(model, data, _vector("q", q, model.nq, "rad")).copy()


def inverse_dynamics(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """``τ = M(q) a + C(q, v) v + g(q)`` [N·m] by RNEA."""
    _model(model, data)
    q, v = _vector("q", q, model.nq, "rad"), _vector("v", v, model.nv, "rad/s")
    return pin.rnea(model, data, q, v, _vector("a", a, model.nv, "rad/s²")).copy()


def inverse_dynamics_rows(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``τ`` [N·m] of RNEA at each row of ``q`` [rad], ``v`` [rad/s], ``a`` [rad/s²], shape
    (K, nv): one ``pin.rneaInParallel`` call on one thread (a C++ loop over the rows, about
    8× faster than ``pin.rnea`` row by row from Python for the twolink), the same numbers as
    :func:`inverse_dynamics` row by row. The rows are checked finite (an
    :class:`InvalidParameterError` naming the argument)."""
    if not isinstance(model, pin.Model):
        raise InvalidParameterError("model", type(model).__name__, "a pinocchio.Model (robot.model)")
    rows = []
    for name, value, n, unit in (
        ("q", q, model.nq, "rad"),
        ("v", v, model.nv, "rad/s"),
        ("a", a, model.nv, "rad/s²"),
    ):
        array = np.asarray(value, dtype=float)
        if array.ndim != 2 or array.shape[1] != n or not np.all(np.isfinite(array)):
            raise InvalidParameterError(name, f"shape {array.shape}", f"(K, {n}) finite numbers [{unit}]")
        rows.append(np.asfortranarray(array.T))
    if len({r.shape[1] for r in rows}) != 1:
        raise InvalidParameterError("q, v, a", [r.shape[::-1] for r in rows], "the same number of rows")
    out = np.zeros_like(rows[1], order="F")
    if hasattr(pin, "rneaInParallel"):
        pin.rneaInParallel(1, pin.ModelPool(model, 1), rows[0], rows[1], rows[2], out)
    else:  # a Pinocchio built without OpenMP
        data = model.createData()
        for k in range(out.shape[1]):
            out[:, k] = pin.rnea(model, data, rows[0][:, k], rows[1][:, k], rows[2][:, k])
    return np.ascontiguousarray(out.T)


ABA_CONVENTION = pin.Convention.WORLD
"""ABA's frame convention everywhere here: same result as LOCAL to rounding, and its Python
call is ~10 % faster for the twolink (the plant's ABA is the simulator's largest cost)."""


def forward_dynamics(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, tau: np.ndarray
) -> np.ndarray:
    """``q̈ = M(q)⁻¹ (τ − C(q, v) v − g(q))`` [rad/s²] by ABA."""
    _model(model, data)
    q, v = _vector("q", q, model.nq, "rad"), _vector("v", v, model.nv, "rad/s")
    return pin.aba(model, data, q, v, _vector("tau", tau, model.nv, "N·m"), ABA_CONVENTION).copy()


def model_torque(
    model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """``M(q) a + C(q, v) w + g(q)`` [N·m]: RNEA plus the Coriolis matrix times ``w − v``.

    The model term of every law that multiplies ``C(q, q̇)`` by a velocity other than
    ``q̇`` (feedforward ``C q̇_d``, Slotine–Li ``C q̇_r``).
    """
    _model(model, data)
    q, v = _vector("q", q, model.nq, "rad"), _vector("v", v, model.nv, "rad/s")
    w, a = _vector("w", w, model.nv, "rad/s"), _vector("a", a, model.nv, "rad/s²")
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
    _model(model, data)
    q, v = _vector("q", q, model.nq, "rad"), _vector("v", v, model.nv, "rad/s")
    w, a = _vector("w", w, model.nv, "rad/s"), _vector("a", a, model.nv, "rad/s²")
    zero = np.zeros(model.nv)
    y = pin.computeJointTorqueRegressor(model, data, q, zero, a).copy()
    y += 0.25 * pin.computeJointTorqueRegressor(model, data, q, v + w, zero)
    y -= 0.25 * pin.computeJointTorqueRegressor(model, data, q, v - w, zero)
    # Gravity is in all three calls; the difference cancels it, so it counts once.
    return y


def joint_inertia(model: pin.Model, q: np.ndarray | None = None) -> np.ndarray:
    """``diag M(q)`` [kg·m²] at ``q`` [rad] (default Pinocchio's neutral configuration),
    armature included: the inertia each joint moves, the scale robot-derived default gains
    use on their own (a user's law; the built-in laws scale with the whole
    :func:`joint_space_inertia`)."""
    return np.array(np.diag(joint_space_inertia(model, q)), dtype=float)


def joint_space_inertia(model: pin.Model, q: np.ndarray | None = None) -> np.ndarray:
    """``M(q)`` [kg·m² for revolute joints], shape (nv, nv), symmetric, at ``q`` [rad] (default
    Pinocchio's neutral configuration), armature included: the whole inertia robot-derived
    default gains scale with (``K = κ M(q₀)`` at the robot's home: every mode of the closed loop
    at ``q₀`` then at the stated rate κ, however strongly the joints are coupled)."""
    if not isinstance(model, pin.Model):
        raise InvalidParameterError("model", type(model).__name__, "a pinocchio.Model (robot.model)")
    if q is not None:
        q = np.asarray(q, dtype=float)
        if q.shape != (model.nq,) or not np.all(np.isfinite(q)):
            raise InvalidParameterError("q", q.tolist(), f"{model.nq} finite joint positions [rad]")
    data = model.createData()
    M = pin.crba(model, data, pin.neutral(model) if q is None else q)
    return np.triu(M) + np.triu(M, 1).T
