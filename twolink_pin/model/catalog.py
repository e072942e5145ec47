"""Robots by name: where each named robot's URDF is and its profile.

The catalog is a registry: a robot's own package adds its entry with :func:`register`
(the twolink's, :mod:`twolink_pin.twolink.profile`, when the package is imported), so this
module names no robot's code. :func:`resolve` turns what a user typed
(``--robot NAME|PATH.urdf``) into a URDF path and a profile. The registry itself is
:mod:`~twolink_pin.model.registry` and example-robot-data's files are found by
:mod:`~twolink_pin.model.robot_data` (both re-exported here): a profile file that names a
catalog robot reads them without importing this module, which reads profile files.
"""

from __future__ import annotations

import dataclasses
import functools
import os
from pathlib import Path

from twolink_pin.errors import InvalidURDFError
from twolink_pin.model.profile import RobotProfile, generic_profile
from twolink_pin.model.profile_file import is_profile_path, read_profile_file, user_folder
from twolink_pin.model.registry import CATALOG, DEFAULT_ROBOT, names, register
from twolink_pin.model.robot_data import example_robot_urdf, share_folder
from twolink_pin.model.urdf_profile import declared_profile


def register_folder(folder: Path) -> None:
    """Add every profile file (``NAME.toml``, :mod:`~twolink_pin.model.profile_file`) of
    ``folder`` under its name (read once, when the robot is first used)."""
    for file in sorted(folder.glob("*.toml")):
        register(file.stem, functools.cache(functools.partial(read_profile_file, file, file.stem)))


def user_profiles() -> dict[str, Path]:
    """The user's profile files (:func:`~twolink_pin.model.profile_file.user_folder`) by name:
    ``--robot NAME`` finds them after the catalog's."""
    folder = user_folder()
    if not folder.is_dir():
        return {}
    return {file.stem: file for file in sorted(folder.glob("*.toml")) if file.is_file()}


def package_folder() -> Path:
    """The package's own profiles (``robots/*.toml``, installed as ``twolink_pin.robots``)."""
    from importlib import resources

    return Path(str(resources.files("twolink_pin.robots")))


def resolve(robot: str | os.PathLike[str] | None) -> tuple[Path, RobotProfile]:
    """The URDF path and profile of ``robot``: a catalog name, a profile of the user's folder by
    name, a profile file (``.toml``, :mod:`~twolink_pin.model.profile_file`), or a path to a URDF
    file.

    A path to a catalog robot's own URDF gets that robot's profile, and so does a file that
    declares it (``<twolink_pin profile="NAME"/>``, written by ``--write-urdf``:
    :mod:`twolink_pin.model.urdf_profile`); any other file the generic profile
    (:func:`~twolink_pin.model.profile.generic_profile`).

    Raises:
        InvalidURDFError: an unknown name (the message lists the valid ones).
    """
    text = DEFAULT_ROBOT if robot is None else os.fspath(robot)
    if "\0" in text or not text:
        raise InvalidURDFError(
            repr(text)[:80], "robot", "expected a robot name or a path (non-empty, no NUL byte)"
        )
    if text in CATALOG:
        return CATALOG[text]()
    if is_profile_path(text):
        return read_profile_file(text)
    mine = user_profiles().get(text)
    if mine is not None:
        return read_profile_file(mine)
    path = Path(text)
    looks_like_path = path.suffix.lower() in (".urdf", ".xml") or os.sep in text or path.exists()
    if not looks_like_path:
        raise InvalidURDFError(
            text,
            "robot",
            f"no robot of that name; named robots are {', '.join(names() + tuple(user_profiles()))}, or give "
            "a path to a .urdf or a profile .toml file",
        )
    for entry in CATALOG.values():
        own, profile = entry()
        try:
            if path.exists() and own.exists() and path.samefile(own):
                return path, profile
        except OSError:
            continue
    declared = declared_profile(path)
    if declared in CATALOG:
        profile = CATALOG[declared]()[1]
        return path, dataclasses.replace(profile, source=f"{path} (declares the profile of {declared})")
    return path, generic_profile(path)


def catalog_profile_name(profile: RobotProfile) -> str | None:
    """The catalog name whose profile ``profile`` is (a catalog robot, or a file declaring one),
    else None (a URDF of yours with the generic profile)."""
    entry = CATALOG.get(profile.name)
    if entry is None or entry()[1].description != profile.description:
        return None
    return profile.name


__all__ = [
    "CATALOG",
    "DEFAULT_ROBOT",
    "catalog_profile_name",
    "example_robot_urdf",
    "names",
    "package_folder",
    "register",
    "register_folder",
    "resolve",
    "share_folder",
    "user_profiles",
]
