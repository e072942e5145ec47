"""Maps from Pinocchio's inertial parameters to a model's control parameters.

Pinocchio describes each body by ten inertial parameters
``π_i = [m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]`` (first moment
and inertia about the body frame's origin, SI units), and
``pin.computeJointTorqueRegressor`` returns ``Y_π(q, v, a)`` with
``Y_π π = M(q) a + C(q, v) v + g(q)``. Controllers work with a smaller vector ``p``:
a :class:`ParameterMap` gives the constant matrix ``P`` with ``Y_p = Y_π P`` and reads
``p`` from a model. This module holds the base class and the robot-independent map
(``p = π``); a robot's own map lives with that robot (the twolink's lumped p1, p2, p3 in
:mod:`twolink_pin.twolink.lumped_map`), and :func:`model_with_parameters` builds a model
whose dynamics has given parameters ``p``.
"""

from __future__ import annotations

import abc

import numpy as np
import pinocchio as pin

from twolink_pin.errors import require_type

N_BODY_PARAMETERS = 10
"""Inertial parameters per body in Pinocchio's ordering."""

BODY_PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
"""Pinocchio's order of a body's ten inertial parameters."""
BODY_PARAMETER_UNITS = ("kg", "kg·m", "kg·m", "kg·m", "kg·m²", "kg·m²", "kg·m²", "kg·m²", "kg·m²", "kg·m²")
"""Their SI units."""


def inertial_parameters(model: pin.Model) -> np.ndarray:
    """Stack Pinocchio's dynamic parameters of every moving body.

    Returns:
        π, shape ``(10 (njoints - 1),)``: per body ``[kg, kg·m (×3), kg·m² (×6)]``.
    """
    require_type(model, pin.Model, "model", "a pinocchio.Model (RobotModel.model)")
    return np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


class ParameterMap(abc.ABC):
    """A linear reparametrisation ``Y_p = Y_π P`` of a model's rigid-body dynamics."""

    names: tuple[str, ...]
    """Name of each entry of ``p``."""
    units: tuple[str, ...]
    """SI unit of each entry of ``p``."""

    @property
    @abc.abstractmethod
    def matrix(self) -> np.ndarray:
        """``P``, shape ``(10 (njoints - 1), len(names))``, constant."""

    @abc.abstractmethod
    def values(self, model: pin.Model) -> np.ndarray:
        """Read ``p`` from ``model`` (the true parameters of that model)."""

    @property
    def size(self) -> int:
        """Number of parameters ``len(p)``."""
        return len(self.names)


class InertialParameterMap(ParameterMap):
    """The identity map: ``p = π``, all ten parameters of every body (any robot)."""

    def __init__(self, model: pin.Model) -> None:
        n = N_BODY_PARAMETERS * (model.njoints - 1)
        self.names = tuple(
            f"{model.names[j]}.{name}" for j in range(1, model.njoints) for name in BODY_PARAMETER_NAMES
        )
        self.units = BODY_PARAMETER_UNITS * (model.njoints - 1)
        self._matrix = np.eye(n)
        self._matrix.setflags(write=False)

    @property
    def matrix(self) -> np.ndarray:
        return self._matrix

    def values(self, model: pin.Model) -> np.ndarray:
        return inertial_parameters(model)


def model_with_parameters(model: pin.Model, parameter_map: ParameterMap, p: np.ndarray) -> pin.Model:
    """A copy of ``model`` whose dynamics has the parameters ``p`` of ``parameter_map``.

    The inertial parameters become ``π' = π + P (p − p_model)``: since ``Y_π P = Y_p``,
    ``Y_π π' = Y_p p`` — a controller built on this model "believes" ``p``. The kinematics
    is unchanged. Used for parameter-estimate errors (``p = p_true ⊙ (1 + δ)``).

    Raises:
        InvalidParameterError: ``p`` has the wrong length or gives a body a non-finite
            inertia (e.g. a zero mass with a first moment).
    """
    from twolink_pin.errors import InvalidParameterError

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


def with_inertial_parameters(model: pin.Model, pi: np.ndarray) -> pin.Model:
    """A copy of ``model`` with every body's inertia set from ``pi`` (shape (10 nb,))."""
    copy = pin.Model(model)
    for j in range(1, model.njoints):
        copy.inertias[j] = pin.Inertia.FromDynamicParameters(
            np.array(pi[N_BODY_PARAMETERS * (j - 1) : N_BODY_PARAMETERS * j])
        )
    return copy
