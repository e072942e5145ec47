"""Touching the world: the surfaces of a scene and the Pinocchio plant's contact with them.

==================  ===================================================================
``scene.py``        :class:`Scene`, :class:`Surface`, :func:`read_scene`: the surfaces and their
                    contact properties (data, read once, beside the plant's options)
``compliant.py``    :class:`CompliantContact`: the Pinocchio plant's contact — a spring–damper
                    normal force with regularised Coulomb friction, N runs at once, and the
                    wrench the force sensor reads; :func:`check_start`
``stability.py``    the stiffness RK4 integrates at a step (:func:`largest_stable_stiffness`),
                    the contact as the joints see it (:func:`joint_stiffness`)
==================  ===================================================================

Each plant computes its own contact from the same :class:`Scene`; a law sees the measured
wrench through :attr:`~twolink_pin.controllers.LawInput.contact` whatever the plant.
"""

from __future__ import annotations

from twolink_pin.contact.compliant import CompliantContact, ContactForces, check_start
from twolink_pin.contact.scene import (
    DEFAULT_DAMPING,
    DEFAULT_RADIUS,
    DEFAULT_SLIP_VELOCITY,
    DEFAULT_STIFFNESS,
    Scene,
    Surface,
    read_scene,
)
from twolink_pin.contact.stability import (
    JointStiffness,
    joint_stiffness,
    largest_stable_step,
    largest_stable_stiffness,
)

__all__ = [
    "DEFAULT_DAMPING",
    "DEFAULT_RADIUS",
    "DEFAULT_SLIP_VELOCITY",
    "DEFAULT_STIFFNESS",
    "CompliantContact",
    "ContactForces",
    "JointStiffness",
    "Scene",
    "Surface",
    "check_start",
    "joint_stiffness",
    "largest_stable_step",
    "largest_stable_stiffness",
    "read_scene",
]
