"""The numbers a trajectory file gives, checked: finite, within a bound, and within the
robot's joint limits (``file.py`` and ``samples_file.py`` both read through these)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import POSITION, joint_limits
from twolink_pin.limits.check import check_grid
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.base import Trajectory

MAX_TIME = 1e6
"""Largest via-point time [s] (the longest simulation): larger times overflow the polynomial."""
MAX_ANGLE = 100.0
"""Largest magnitude of an angle in a file (joint positions, seed, roll, pitch, yaw) [rad], as
of a command-line offset: beyond, a number is a typo or garbage (sin(1e300) is not an angle)."""


SHOWN = 6
"""A list longer than this is shown in a message by its length and its ends (:func:`shown`)."""


def shown(value: Any) -> Any:
    """``value`` as a message about it shows it: itself, or for a list longer than
    :data:`SHOWN`, its length and first and last items (a file with 40 000 via times printed
    them all in its one line)."""
    if not isinstance(value, (list, tuple)) or len(value) <= SHOWN:
        return value

    def item(v: Any) -> str:
        text = repr(v)
        return text if len(text) <= 40 else text[:37] + "…"

    return f"a list of {len(value)} items: {', '.join(item(v) for v in value[:3])}, …, {item(value[-1])}"


def _only_numbers(value: Any) -> bool:
    """Whether ``value`` is a number or nested lists of numbers (``true`` and ``"0.5"`` are not)."""
    if isinstance(value, list):
        return all(_only_numbers(v) for v in value)
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def parse_numbers(
    path: Path, key: str, value: Any, shape: str, bound: float | None = None, unit: str = ""
) -> np.ndarray:
    """``value`` as a float array; a number that is not finite or beyond ``±bound`` [unit] is
    refused naming its row and column (``rpy[2][0]``)."""
    if not _only_numbers(value):
        raise InvalidParameterError(
            f"{path}: {key}", shown(value), f"numbers (not booleans or strings): {shape}"
        )
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"{path}: {key}", shown(value), shape) from None
    bad = ~np.isfinite(array) | (np.abs(array) > (math.inf if bound is None else bound))
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        within = "" if bound is None else f" within ±{bound:g} {unit}"
        raise InvalidParameterError(
            f"{path}: {key}" + "".join(f"[{i}]" for i in index),
            float(array[index]),
            f"a finite number{within} ({shape})",
        )
    return array


def check_within_limits(robot: RobotModel, values: np.ndarray, what: str) -> None:
    """Raise unless every row of ``values`` [rad] (shape (n, nv)) is within the joint limits."""
    limits = joint_limits(robot)
    lower, upper = limits.position_lower, limits.position_upper
    for k, row in enumerate(values):
        for j, x in enumerate(row):
            if not lower[j] <= x <= upper[j]:
                raise InvalidParameterError(
                    f"{what}[{k}][{j}]",
                    float(x),
                    f"a position of joint {j + 1} ({robot.model.names[j + 1]}) within its limits "
                    f"[{lower[j]:g}, {upper[j]:g}] rad",
                )


def check_trajectory_limits(robot: RobotModel, trajectory: Trajectory, what: str = "trajectory") -> None:
    """Raise unless the trajectory stays within the joint limits over a period (on the limits' check
    grid, :func:`twolink_pin.limits.check.check_grid`: 1 ms apart)."""
    t = check_grid(trajectory.t0, trajectory.period)
    q = trajectory.sample(t).q
    limits = joint_limits(robot)
    lower, upper = limits.position_lower, limits.position_upper
    over = limits.excess(POSITION, q) > 0
    if over.any():
        k, j = (int(i) for i in np.argwhere(over)[0])
        raise InvalidParameterError(
            what,
            f"q{j + 1}({t[k]:.4g} s) = {q[k, j]:.6g} rad",
            f"a motion within joint {j + 1}'s limits [{lower[j]:g}, {upper[j]:g}] rad between the via points "
            "too (move the via points inwards, or space them further apart)",
        )


__all__ = [
    "MAX_ANGLE",
    "MAX_TIME",
    "SHOWN",
    "check_trajectory_limits",
    "check_within_limits",
    "parse_numbers",
    "shown",
]
