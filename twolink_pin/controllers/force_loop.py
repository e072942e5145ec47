r"""What the force-control laws (``force``, ``hybrid``) share: the sensor's normal force, the force
error and its PI with anti-windup.

Sign conventions (:class:`~twolink_pin.controllers.contact_input.ContactInput`): the sensor reads
the wrench ``F`` the end effector applies to the surfaces; the surface's outward normal is ``n``
(towards the arm); the normal force the end effector presses with is ``f_n = −n·F[:3]`` [N], >= 0
in contact; the reference asks for ``f_d`` [N]. The force error is ``e_f = f_d − f_n`` and the
force the law commands along the normal, as a force applied to the surface, is

$$F_c = -n\,\big(f_d + k_{fp}\, e_f + k_{fi}\, \xi\big), \qquad \dot\xi = e_f$$

(Lynch and Park, *Modern Robotics*, eq. 11.62, on the normal direction). The integrator runs
only while the sensor reads a pressing force (``f_n > 0``: in contact; before contact the error
is ``f_d`` for as long as the approach lasts and the integral would wind up, then overshoot at
the impact), and stops while its term is at the clamp ``i_max`` [N] and the error would push it
further (conditional integration, as ``pid``'s anti-windup; with a noisy sensor ``f_n > 0`` half
of the time out of contact, and the clamp bounds what that winds up).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from twolink_pin.controllers.contact_input import ContactInput
from twolink_pin.controllers.law_io import LawInput
from twolink_pin.errors import InvalidParameterError


class ForceCommand(NamedTuple):
    """The normal-force loop's output for N runs."""

    force: np.ndarray
    """``F_c`` [N]: the force to apply to the surface, world axes, shape (N, 3)."""
    dxi: np.ndarray
    """``ξ̇`` [N] (the integrator's derivative, 0 while clamped), shape (N, 1)."""


def contact_of(x: LawInput, law: str) -> ContactInput:
    """``x.contact``, or a clear error: a force law runs against a scene's surface."""
    if x.contact is None:
        raise InvalidParameterError(
            f"law '{law}': LawInput.contact",
            None,
            "a contact: this law controls a contact force and runs only on a plant whose scene has a "
            "surface (--scene FILE or --wall …; PlantOptions.scene)",
        )
    return x.contact


def normal_force(contact: ContactInput) -> np.ndarray:
    """``f_n = −n·F[:3]`` [N], the normal force the end effector presses with, shape (N, 1)."""
    return -np.vecdot(contact.wrench[:, :3], contact.normal)[:, None]


def force_command(
    contact: ContactInput,
    xi: np.ndarray,
    kp: np.ndarray | float,
    ki: np.ndarray | float,
    i_max: np.ndarray | float,
) -> ForceCommand:
    """The PI on the normal force (see the module docstring): ``xi`` the integral ``ξ`` [N·s]
    (N, 1), ``kp`` [N/N], ``ki`` [1/s], ``i_max`` [N] (each a number or one per run)."""
    f_d = contact.force_des
    f_n = normal_force(contact)
    error = f_d - f_n
    integral = ki * xi
    magnitude = f_d + kp * error + integral
    # conditional integration: in contact only, and held while k_i ξ is at the clamp and e_f
    # pushes it further out
    held = (f_n <= 0.0) | ((np.abs(integral) >= i_max) & (np.sign(error) == np.sign(integral)))
    return ForceCommand(-magnitude * contact.normal, np.where(held, 0.0, error))


__all__ = ["ForceCommand", "contact_of", "force_command", "normal_force"]
