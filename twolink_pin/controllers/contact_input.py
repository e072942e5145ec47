"""What a law measures of its contact with the world: :class:`ContactInput`, the force sensor's
reading beside the force reference (:attr:`~twolink_pin.controllers.LawInput.contact`)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class ContactInput(NamedTuple):
    """The contact a law sees at one evaluation, for N runs: filled by the engine when the
    plant's scene has surfaces (:mod:`twolink_pin.contact`), else ``LawInput.contact`` is None.

    Sign: the sensor reads the wrench the end effector applies **to the surfaces** (Lynch and
    Park's ``F_tip``); pressing with ``f_d`` [N] on a surface of outward normal ``n`` is the
    force ``−f_d n``, and at rest ``τ = ĝ + Jᵀ F`` reads ``F``.
    """

    wrench: np.ndarray
    """The measured contact wrench [N; N·m], world axes, about the touching frame's origin (the
    end effector's by default), linear rows first, shape (N, 6): the plant's contact plus the
    sensor's noise, if any."""
    normal: np.ndarray
    """The unit outward normal (towards the arm) of the surface the force reference is on (the
    scene's only surface unless the reference names one), world axes, shape (1, 3)."""
    force_des: np.ndarray
    """The desired normal force on that surface [N], >= 0 when pressing, shape (1, 1): the
    reference's (:class:`~twolink_pin.trajectory.ForceReference`), 0 without one."""


__all__ = ["ContactInput"]
