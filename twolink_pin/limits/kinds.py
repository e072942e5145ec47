"""The four kinds of joint limit, each defined once.

A kind says which quantity of a motion it bounds and in what unit; the bounds themselves
are read from the robot (:mod:`twolink_pin.limits.joint_limits`). Checks of a reference,
the crossings of a run, the retiming, the optimiser and the constrained laws all go
through these four objects, so a fifth kind (jerk, say) is one more object here.

* ``position`` (q, rad): the URDF's ``<limit lower upper>``;
* ``velocity`` (q̇, rad/s): the URDF's ``<limit velocity>`` (0: none);
* ``acceleration`` (q̈, rad/s²): the robot's profile (a URDF has none);
* ``effort`` (τ, N·m): the URDF's ``<limit effort>`` (0: none).

The position limit bounds ``q`` between two values; the others are symmetric boxes
``|x| <= limit``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Motion(NamedTuple):
    """A motion sampled at K instants: what the limits are checked against.

    Every array has shape (K, nv); ``tau`` may be None when no torque is known (a motion
    checked for its kinematic limits only).
    """

    t: np.ndarray
    """Times [s], shape (K,)."""
    q: np.ndarray
    """Joint positions [rad]."""
    v: np.ndarray
    """Joint velocities [rad/s]."""
    a: np.ndarray | None
    """Joint accelerations [rad/s²] (None: not known, e.g. a recorded run)."""
    tau: np.ndarray | None
    """Joint torques [N·m] (None: not known)."""


class LimitKind(NamedTuple):
    """One kind of joint limit.

    Attributes:
        name: ``position``, ``velocity``, ``acceleration`` or ``effort``.
        symbol: How the quantity is written (``q``, ``q̇``, ``q̈``, ``τ``).
        unit: SI unit of the quantity for a revolute joint.
        order: The time derivative of ``q`` it bounds (0, 1, 2); None for the torque,
            which the robot's inverse dynamics gives.
        symmetric: Whether the bounds are ``±limit`` (all but position).
    """

    name: str
    symbol: str
    unit: str
    order: int | None
    symmetric: bool

    def of(self, motion: Motion) -> np.ndarray | None:
        """The quantity this kind bounds along ``motion``, shape (K, nv), or None when the
        motion does not carry it."""
        return (motion.q, motion.v, motion.a, motion.tau)[3 if self.order is None else self.order]


POSITION = LimitKind("position", "q", "rad", 0, False)
VELOCITY = LimitKind("velocity", "q̇", "rad/s", 1, True)
ACCELERATION = LimitKind("acceleration", "q̈", "rad/s²", 2, True)
EFFORT = LimitKind("effort", "τ", "N·m", None, True)
KINDS: tuple[LimitKind, ...] = (POSITION, VELOCITY, ACCELERATION, EFFORT)
"""Every kind, in the order tables show them."""
BY_NAME = {kind.name: kind for kind in KINDS}
"""Each kind by its name."""


def kind_named(name: str) -> LimitKind:
    """The kind called ``name``.

    Raises:
        InvalidParameterError: ``name`` is not one of the four.
    """
    from twolink_pin.errors import InvalidParameterError

    try:
        return BY_NAME[name]
    except KeyError:
        raise InvalidParameterError("limit kind", name, f"one of {', '.join(BY_NAME)}") from None
