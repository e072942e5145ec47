"""What is identified and the observation matrix that carries it.

The joint torques of an arm with viscous and Coulomb friction are linear in its base
parameters ``β`` (:class:`~twolink_pin.model.base_parameters.BaseParameterMap`) and in the
friction coefficients ``f = (V_1..V_n, C_1..C_n)``::

    τ = Y_β(q, q̇, q̈) β + diag(q̇) V + diag(sgn q̇) C = [Y_β  Y_f] θ,   θ = (β, f)

Stacking the rows of K samples gives the observation matrix ``W`` (``K n × n_θ``) and
``τ = W θ``. :class:`ParameterSet` names the entries of ``θ`` and builds ``W``; the twolink
is identified in its four base parameters (not the report's lumped p1..p3, which cannot
express ``link2.mcy``), any other robot in the base parameters that are its default map.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.base import FRICTION_UNITS
from twolink_pin.dynamics import Friction
from twolink_pin.model import RobotModel
from twolink_pin.model.base_parameters import BaseParameterMap


@dataclass(frozen=True)
class ParameterSet:
    """The parameters ``θ = (β, V, C)`` identified on a robot.

    Attributes:
        base: The robot's base-parameter map.
        nv: Number of joints.
        friction: Whether viscous and Coulomb friction per joint are identified too.
    """

    base: BaseParameterMap = field(repr=False)
    nv: int
    friction: bool = True

    @classmethod
    def of(cls, robot: RobotModel, friction: bool = True) -> ParameterSet:
        """The parameter set of ``robot``: its base parameters (its own map when that is the
        base map, else one computed from its model), plus friction if ``friction``."""
        base = robot.parameter_map if isinstance(robot.parameter_map, BaseParameterMap) else None
        return cls(base or BaseParameterMap(robot.model), robot.nv, friction)

    @property
    def size(self) -> int:
        """``n_θ``: base parameters plus ``2 nv`` friction coefficients if identified."""
        return self.base.size + (2 * self.nv if self.friction else 0)

    @property
    def names(self) -> tuple[str, ...]:
        """Names: the base parameters' (``link1.Izz + 0.1444 link2.m``, …), then ``V1..Vn``,
        ``C1..Cn``."""
        friction = (
            tuple(f"V{j + 1}" for j in range(self.nv)) + tuple(f"C{j + 1}" for j in range(self.nv))
            if self.friction
            else ()
        )
        return self.base.names + friction

    @property
    def units(self) -> tuple[str, ...]:
        """SI unit of each parameter."""
        friction = (
            (FRICTION_UNITS["viscous"],) * self.nv + (FRICTION_UNITS["coulomb"],) * self.nv
            if self.friction
            else ()
        )
        return self.base.units + friction

    @property
    def kinds(self) -> tuple[str, ...]:
        """``"inertial"`` or ``"friction"`` per parameter."""
        return ("inertial",) * self.base.size + ("friction",) * (2 * self.nv if self.friction else 0)

    def true_values(self, model: pin.Model, friction: Friction | None) -> np.ndarray:
        """``θ`` of ``model`` with joint friction ``friction`` (None: no friction)."""
        beta = self.base.values(model)
        if not self.friction:
            return beta
        return np.concatenate([beta, np.zeros(2 * self.nv) if friction is None else friction.parameters])

    def observation(
        self,
        model: pin.Model,
        q: np.ndarray,
        v: np.ndarray,
        a: np.ndarray,
        coulomb: np.ndarray | None = None,
    ) -> np.ndarray:
        """Regressor rows at K states: ``W`` of shape (K, nv, n_θ) with ``W[k] θ = τ_k``.

        Args:
            model: The Pinocchio model (its kinematics; the inertias do not matter).
            q: Positions [rad], (K, nv).
            v: Velocities [rad/s], (K, nv).
            a: Accelerations [rad/s²], (K, nv).
            coulomb: The Coulomb columns, (K, nv); default ``sgn v`` (a filtered log passes
                its filtered sign, :attr:`~twolink_pin.identification.filtering.FilteredLog.coulomb`).
        """
        q, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, v, a))
        data = model.createData()
        nb, nv = self.base.size, self.nv
        P = np.ascontiguousarray(self.base.matrix)
        W = np.zeros((q.shape[0], nv, self.size))
        for k in range(q.shape[0]):
            W[k, :, :nb] = pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k]) @ P
        if self.friction:
            j = np.arange(nv)
            W[:, j, nb + j] = v
            W[:, j, nb + nv + j] = np.sign(v) if coulomb is None else np.atleast_2d(coulomb)
        return W
