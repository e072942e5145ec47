"""The report's five runs: a controller with its gains and the plant it drives.

:func:`make_scenario` pairs each controller name with the plant of the report's
experiment: the friction controller runs on the arm with the report's friction
(V = (0.4, 0.2) N·m·s/rad, C = (0.2, 0.1) N·m); the others on the frictionless arm.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

from twolink_pin.controllers import CONTROLLERS, Controller
from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.adaptive_friction import AdaptiveFriction, AdaptiveFrictionGains
from twolink_pin.controllers.computed_torque import ComputedTorque, SlotineLiGains
from twolink_pin.controllers.wrong_model import WrongModel
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.plant import Plant


class Scenario(NamedTuple):
    """A controller and the plant it drives."""

    controller: Controller
    """The control law (own Data)."""
    plant: Plant
    """The simulated arm (own Data)."""


def make_scenario(
    name: str,
    robot: RobotModel,
    lam: float | None = None,
    saturate: bool = False,
    friction_smoothing: float = 0.0,
) -> Scenario:
    """The report's experiment for controller ``name`` with its default gains.

    Args:
        name: One of :data:`twolink_pin.controllers.CONTROLLERS`.
        robot: The arm (plant and controller models are built from it).
        lam: ``λ`` [1/s] for the Slotine–Li laws (default 5); ignored by ``pd``.
        saturate: Clip torques at the URDF limits in the plant.
        friction_smoothing: ε [rad/s] of ``tanh(q̇/ε)`` for Coulomb friction (0: exact sgn).
    """
    if name not in CONTROLLERS:
        raise InvalidParameterError("controller", name, f"one of {', '.join(CONTROLLERS)}")
    friction = None
    controller: Controller
    if name == "adaptive-friction":
        friction = Friction.report(smoothing=friction_smoothing)
        gains_f = AdaptiveFrictionGains() if lam is None else replace(AdaptiveFrictionGains(), lam=lam)
        controller = AdaptiveFriction(robot, gains_f, friction)
    elif name == "adaptive":
        controller = Adaptive(robot, AdaptiveGains() if lam is None else replace(AdaptiveGains(), lam=lam))
    elif name in ("computed-torque", "robust"):
        gains = SlotineLiGains() if lam is None else replace(SlotineLiGains(), lam=lam)
        controller = ComputedTorque(robot, gains) if name == "computed-torque" else WrongModel(robot, gains)
    else:
        controller = CONTROLLERS[name](robot)
    return Scenario(controller, Plant(robot, friction=friction, saturate=saturate))
