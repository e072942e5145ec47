"""The report's "Robust Controller": Slotine–Li with a deliberately wrong model."""

from __future__ import annotations

import math

from twolink_pin.controllers.computed_torque import ComputedTorque, SlotineLiGains
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


class WrongModel(ComputedTorque):
    r"""Slotine–Li control on a scaled model ``M̂ = β M``, ``Ĉ = β C``, ``ĝ = β g``::

        τ = β [M(q) q̈_r + C(q, q̇) q̇_r + g(q)] − K s      (report: β = 0.5)

    Despite the report's name "Robust Controller" there is no robustifying term (no
    switching or saturated ``−k sgn(s)`` term sized on the model error bound): it is law 2
    with every inertial parameter scaled by β, which shows what model error alone does.
    The tracking error stays bounded and periodic but does not vanish.
    """

    name = "robust"

    def __init__(
        self, robot: RobotModel, gains: SlotineLiGains | None = None, model_scale: float = 0.5
    ) -> None:
        super().__init__(robot, gains)
        if not (isinstance(model_scale, (int, float)) and math.isfinite(model_scale) and model_scale >= 0):
            raise InvalidParameterError("model_scale", model_scale, "a finite factor >= 0 on M, C and g")
        self.model_scale = float(model_scale)
