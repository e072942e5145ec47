"""What the engine asks of a reference: desired q, q̇, q̈ (and jerk) at any time, periodic."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.trajectory.force import ForceReference


class TrajectorySample(NamedTuple):
    """Desired motion at one or more times; each array has shape (nv,) or (N, nv)."""

    q: np.ndarray
    """Position [rad]."""
    v: np.ndarray
    """Velocity [rad/s]."""
    a: np.ndarray
    """Acceleration [rad/s²]."""
    jerk: np.ndarray
    """Jerk [rad/s³]."""


class Trajectory(abc.ABC):
    """A periodic joint reference.

    Attributes:
        t0: Start of the first period [s].
        period: Repetition period [s].
    """

    t0: float
    period: float
    force_reference: ForceReference | None = None
    """The normal force [N] the end effector should press on a surface over time, or None
    (:mod:`twolink_pin.trajectory.force`; set by :func:`~twolink_pin.trajectory.force.with_force`)."""

    @property
    @abc.abstractmethod
    def nv(self) -> int:
        """Number of joints."""

    @abc.abstractmethod
    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        """Desired q, q̇, q̈ and jerk at time(s) ``t`` [s]: shape (nv,) for a scalar ``t``,
        (N, nv) for N times."""

    @property
    def via_times(self) -> np.ndarray:
        """Times [s] of the via points figures mark (none unless the reference has some)."""
        return np.zeros(0)

    def __call__(self, t: float | np.ndarray) -> TrajectorySample:
        return self.sample(t)
