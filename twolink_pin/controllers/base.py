"""The controller interface: a small object with a stated law.

A controller maps time, state and the reference sample to joint torques. Its internal
state (parameter estimates of an adaptive law) is an explicit vector ``z`` that the
simulator integrates beside the plant's, so a run is reproducible and resettable:
:meth:`Controller.initial_state` gives ``z(0)`` and :meth:`Controller.compute` returns
``(τ, ż)``. Stateless laws use an empty ``z``.

Notation (report): ``e = q − q_d``, ``ė = q̇ − q̇_d``, ``s = ė + λ e``,
``q̇_r = q̇_d − λ e``, ``q̈_r = q̈_d − λ ė``.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

EMPTY = np.zeros(0)
EMPTY.setflags(write=False)


class Controller(abc.ABC):
    """Base class: one law, one ``pin.Data`` of its own, explicit state ``z``."""

    name: ClassVar[str]
    """Registry name, e.g. ``"pd"``."""

    def __init__(self, robot: RobotModel) -> None:
        self.robot = robot
        self.model = robot.model
        self.data = robot.create_data()

    def initial_state(self) -> np.ndarray:
        """``z(0)``: the controller's internal state at the start of a run (a copy)."""
        return EMPTY

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the estimated parameters held in ``z`` (empty if none)."""
        return ()

    def true_parameters(self) -> np.ndarray | None:
        """The plant's true values of the estimated parameters, or None."""
        return None

    @abc.abstractmethod
    def compute(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_des: np.ndarray,
        v_des: np.ndarray,
        a_des: np.ndarray,
        z: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Torque and state derivative.

        Args:
            q: Joint positions [rad]. v: Joint velocities [rad/s].
            q_des, v_des, a_des: Reference position [rad], velocity [rad/s], acceleration [rad/s²].
            z: Controller state (see :meth:`initial_state`).

        Returns:
            ``(τ [N·m], ż)``.
        """


def diagonal_gain(
    name: str, values: Sequence[float], nv: int | None = None, positive: bool = True
) -> np.ndarray:
    """Validate a diagonal gain and return it as an array.

    Raises:
        InvalidParameterError: wrong length, non-finite, or not strictly positive.
    """
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or (nv is not None and array.shape != (nv,)):
        expected = f"shape ({nv},)" if nv is not None else "a 1-D sequence"
        raise InvalidParameterError(name, tuple(values), f"{expected} but got shape {array.shape}")
    for x in array:
        if not math.isfinite(x) or (positive and x <= 0):
            raise InvalidParameterError(name, tuple(values), "finite values > 0")
    return array


def positive_scalar(name: str, value: float, unit: str) -> float:
    """Validate a finite, strictly positive scalar."""
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InvalidParameterError(name, value, f"a finite value > 0 {unit}")
    return float(value)
