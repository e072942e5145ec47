"""The twolink's own parameter map: Pinocchio's inertial parameters -> (p1, p2, p3).

The report writes the planar 2R arm's dynamics with three lumped parameters [kg·m²]::

    M(q) = [[p1 + 2 p3 cos q2, p2 + p3 cos q2],
            [p2 + p3 cos q2,   p2           ]]

With Pinocchio's per-body parameters (inertia about each joint axis, first moment in the
link frame) and ``L1`` the distance joint 1 -> joint 2 [m]::

    p1 = Izz1 + L1² m2 + Izz2,   p2 = Izz2,   p3 = L1 (m c_x)2

The regressor columns follow from which π direction produces each ``Y_i``:
``Y1 = Y_π e(Izz1)``, ``Y2 = Y_π (e(Izz2) - e(Izz1))``, ``Y3 = Y_π e(mcx2) / L1``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model.parameters import N_BODY_PARAMETERS, ParameterMap, inertial_parameters

_MASS, _MCX, _MCY, _IZZ = 0, 1, 2, 9


def _is_planar_2r(model: pin.Model) -> bool:
    if model.njoints != 3 or model.nq != 2 or model.nv != 2:
        return False
    for j in (1, 2):
        if model.joints[j].shortname() != "JointModelRZ":
            return False
    placement = model.jointPlacements[2]
    return bool(
        np.allclose(placement.rotation, np.eye(3))
        and abs(placement.translation[1]) < 1e-12
        and abs(placement.translation[2]) < 1e-12
        and placement.translation[0] > 0
    )


class TwoLinkLumpedMap(ParameterMap):
    """Lumped parameters ``p = (p1, p2, p3)`` [kg·m²] of a planar 2R arm about z."""

    names = ("p1", "p2", "p3")
    units = ("kg·m²", "kg·m²", "kg·m²")

    def __init__(self, model: pin.Model) -> None:
        if not self.applies_to(model):
            raise InvalidParameterError(
                "model", model.name, "two revolute-z joints with joint 2 on link 1's x axis (a planar 2R arm)"
            )
        self.l1 = float(model.jointPlacements[2].translation[0])
        """Distance joint 1 -> joint 2 [m]."""
        matrix = np.zeros((2 * N_BODY_PARAMETERS, 3))
        matrix[_IZZ, 0] = 1.0
        matrix[N_BODY_PARAMETERS + _IZZ, 1] = 1.0
        matrix[_IZZ, 1] = -1.0
        matrix[N_BODY_PARAMETERS + _MCX, 2] = 1.0 / self.l1
        matrix.setflags(write=False)
        self._matrix = matrix

    @staticmethod
    def applies_to(model: pin.Model) -> bool:
        """Whether ``model`` is a planar 2R arm this map describes."""
        return _is_planar_2r(model)

    @property
    def matrix(self) -> np.ndarray:
        return self._matrix

    def values(self, model: pin.Model) -> np.ndarray:
        """``(p1, p2, p3)`` [kg·m²] of ``model``.

        Raises:
            InvalidParameterError: if link 2's centre of mass is off its x axis (then the
                dynamics has ``sin q2`` terms that three parameters cannot express).
        """
        pi = inertial_parameters(model)
        body2 = pi[N_BODY_PARAMETERS:]
        if abs(body2[_MCY]) > 1e-12 * max(1.0, abs(body2[_MASS])):
            raise InvalidParameterError(
                "link 2 first moment m*c_y",
                float(body2[_MCY]),
                "0 kg·m (centre of mass on the link's x axis)",
            )
        izz1, izz2, m2, mcx2 = pi[_IZZ], body2[_IZZ], body2[_MASS], body2[_MCX]
        return np.array([izz1 + self.l1**2 * m2 + izz2, izz2, self.l1 * mcx2])
