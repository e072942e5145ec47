"""The named robots' registry: name → a function giving the robot's URDF path and profile.

A robot's own package adds its entry (:func:`register`); :mod:`~twolink_pin.model.catalog`
resolves what a user typed against it, and a profile file may name a registered robot as its
URDF (:mod:`~twolink_pin.model.profile_file`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from twolink_pin.model.profile import RobotProfile

CATALOG: dict[str, Callable[[], tuple[Path, RobotProfile]]] = {}
"""Named robots: name → a function giving its URDF path and profile (located on use)."""
DEFAULT_ROBOT = "twolink"
"""The robot a command or :func:`~twolink_pin.model.load_robot` uses when none is named."""


def register(name: str, entry: Callable[[], tuple[Path, RobotProfile]]) -> None:
    """Add a named robot: ``entry()`` gives its URDF path and profile."""
    CATALOG[name] = entry


def names() -> tuple[str, ...]:
    """The catalog's robot names, the default robot first."""
    return tuple(sorted(CATALOG, key=lambda name: name != DEFAULT_ROBOT))


__all__ = ["CATALOG", "DEFAULT_ROBOT", "names", "register"]
