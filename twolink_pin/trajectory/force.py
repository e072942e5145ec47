"""A force reference: the normal force [N] the end effector should press on a surface, over time.

A reference may carry one (:attr:`Trajectory.force_reference
<twolink_pin.trajectory.Trajectory.force_reference>`, set by :func:`with_force`): a via file's
``force`` column (one value per via time, and optionally ``force_surface``, the scene surface it
is on), or a constant (:meth:`ForceReference.constant`). Between its times the force is
interpolated linearly (a force step is a ramp between two via times); it repeats with the
trajectory's period, as the motion does. A law that controls a force
(:attr:`~twolink_pin.controllers.Controller.force_control`) reads it as
``LawInput.contact.force_des``; the contact metrics measure every law against it.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from twolink_pin.errors import InvalidParameterError

MAX_FORCE = 1e6
"""Largest desired force [N] accepted."""
T = TypeVar("T")
"""A reference (:class:`~twolink_pin.trajectory.Trajectory`): not imported here, the base
class names :class:`ForceReference` as its attribute's type."""


@dataclass(frozen=True)
class ForceReference:
    """A desired normal force ``f_d(t)`` [N] on one surface (see the module docstring).

    Attributes:
        times: Strictly increasing times [s] (one time: a constant force).
        values: The force at each time [N], each in [0, :data:`MAX_FORCE`] (pressing).
        surface: The scene's surface the force is on (None: the scene's only surface).
        period: The force repeats every ``period`` [s] (None: held after the last time).
    """

    times: tuple[float, ...]
    values: tuple[float, ...]
    surface: str | None = None
    period: float | None = None

    def __post_init__(self) -> None:
        times = _floats("force reference: times", self.times, "a list of times [s]")
        values = _floats("force reference: force", self.values, f"forces in [0, {MAX_FORCE:g}] N")
        if not times or len(values) != len(times):
            raise InvalidParameterError(
                "force reference: force", list(values), f"one force [N] per time ({len(times)})"
            )
        bad = [i for i, x in enumerate(values) if not 0 <= x <= MAX_FORCE]
        if bad:
            raise InvalidParameterError(
                f"force reference: force[{bad[0]}]",
                values[bad[0]],
                f"a normal force in [0, {MAX_FORCE:g}] N (pressing on the surface)",
            )
        if any(b <= a for a, b in itertools.pairwise(times)):
            raise InvalidParameterError(
                "force reference: times", list(times), "strictly increasing times [s]"
            )
        period = self.period
        if period is not None and not (
            isinstance(period, (int, float)) and not isinstance(period, bool) and 0 < period < math.inf
        ):
            raise InvalidParameterError("force reference: period", period, "a period > 0 s, or None")
        if self.surface is not None and not (isinstance(self.surface, str) and self.surface):
            raise InvalidParameterError("force reference: surface", self.surface, "a surface's name, or None")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "period", None if period is None else float(period))

    @classmethod
    def constant(cls, force: float, surface: str | None = None) -> ForceReference:
        """``force`` [N] at all times."""
        return cls((0.0,), (force,), surface)

    def sample(self, t: float | np.ndarray) -> np.ndarray:
        """``f_d`` [N] at time(s) ``t`` [s], shape of ``t``."""
        t = np.asarray(t, dtype=float)
        if self.period is not None:
            t = self.times[0] + np.mod(t - self.times[0], self.period)
        return np.interp(t, self.times, self.values)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (``ForceReference(**d)`` reads it back)."""
        return {
            "times": list(self.times),
            "values": list(self.values),
            "surface": self.surface,
            "period": self.period,
        }


def _floats(name: str, value: Any, expected: str) -> tuple[float, ...]:
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise InvalidParameterError(name, value, expected)
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise InvalidParameterError(name, list(value), f"finite numbers: {expected}")
        out.append(float(x))
    return tuple(out)


def with_force(trajectory: T, reference: ForceReference | None) -> T:
    """A copy of ``trajectory`` that carries ``reference`` (None: carries none)."""
    if reference is not None and not isinstance(reference, ForceReference):
        raise InvalidParameterError("force reference", type(reference).__name__, "a ForceReference or None")
    out = copy.copy(trajectory)
    object.__setattr__(out, "force_reference", reference)
    return out


__all__ = ["MAX_FORCE", "ForceReference", "with_force"]
