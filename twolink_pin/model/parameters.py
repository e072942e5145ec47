"""Maps from Pinocchio's inertial parameters to a model's control parameters.

Pinocchio describes each body by ten inertial parameters
``π_i = [m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]`` (first moment
and inertia about the body frame's origin, SI units), and
``pin.computeJointTorqueRegressor`` returns ``Y_π(q, v, a)`` with
``Y_π π = M(q) a + C(q, v) v + g(q)``. Controllers work with a smaller vector ``p``:
a :class:`ParameterMap` gives the constant matrix ``P`` with ``Y_p = Y_π P`` and reads
``p`` from a model. This module holds the base class and the robot-independent map
(``p = π``); a robot's own lumped map lives in its own module (``twolink.py``).
"""

from __future__ import annotations

import abc

import numpy as np
import pinocchio as pin

N_BODY_PARAMETERS = 10
"""Inertial parameters per body in Pinocchio's ordering."""

BODY_PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def inertial_parameters(model: pin.Model) -> np.ndarray:
    """Stack Pinocchio's dynamic parameters of every moving body.

    Returns:
        π, shape ``(10 (njoints - 1),)``: per body ``[kg, kg·m (×3), kg·m² (×6)]``.
    """
    return np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


class ParameterMap(abc.ABC):
    """A linear reparametrisation ``Y_p = Y_π P`` of a model's rigid-body dynamics."""

    names: tuple[str, ...]
    """Name of each entry of ``p``."""

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
        self._matrix = np.eye(n)
        self._matrix.setflags(write=False)

    @property
    def matrix(self) -> np.ndarray:
        return self._matrix

    def values(self, model: pin.Model) -> np.ndarray:
        return inertial_parameters(model)
