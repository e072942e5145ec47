"""Tracking controllers: one law per module, registered by name.

=====================  =====================================================
name                   law
=====================  =====================================================
``pd``                 :class:`PDFeedforward` (report eq. 8)
``computed-torque``    :class:`ComputedTorque` (Slotine–Li)
``robust``             :class:`WrongModel` (Slotine–Li on 0.5 × the model)
``adaptive``           :class:`Adaptive` (Slotine–Li adaptive)
``adaptive-friction``  :class:`AdaptiveFriction` (with friction estimates)
=====================  =====================================================
"""

from __future__ import annotations

from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.adaptive_friction import AdaptiveFriction, AdaptiveFrictionGains
from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA, ComputedTorque, SlotineLiGains
from twolink_pin.controllers.pd import PDFeedforward, PDGains
from twolink_pin.controllers.wrong_model import WrongModel

CONTROLLERS: dict[str, type[Controller]] = {
    cls.name: cls for cls in (PDFeedforward, ComputedTorque, WrongModel, Adaptive, AdaptiveFriction)
}
"""Controller classes by registry name, in the report's order."""

__all__ = [
    "CONTROLLERS",
    "DEFAULT_LAMBDA",
    "Adaptive",
    "AdaptiveFriction",
    "AdaptiveFrictionGains",
    "AdaptiveGains",
    "ComputedTorque",
    "Controller",
    "PDFeedforward",
    "PDGains",
    "SlotineLiGains",
    "WrongModel",
]
