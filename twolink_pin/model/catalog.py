"""Robots by name: where each named robot's URDF is and its profile.

The catalog is a registry: a robot's own package adds its entry with :func:`register`
(the twolink's, :mod:`twolink_pin.twolink.profile`, when the package is imported), so this
module names no robot's code. :func:`resolve` turns what a user typed
(``--robot NAME|PATH.urdf``) into a URDF path and a profile.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.metadata
import os
from collections.abc import Callable
from pathlib import Path

from twolink_pin.errors import InvalidURDFError, require_type
from twolink_pin.model.profile import RobotProfile, generic_profile
from twolink_pin.model.profile_file import is_profile_path, read_profile_file, user_folder
from twolink_pin.model.urdf_profile import declared_profile


def share_folder(urdf: Path) -> Path:
    """The folder ``package://example-robot-data/...`` mesh paths are relative to."""
    for parent in urdf.parents:
        if parent.name == "example-robot-data":
            return parent.parent
    return urdf.parent


def example_robot_urdf(relative: str) -> Path:
    """Path of a URDF shipped by ``example-robot-data``.

    Args:
        relative: Path below the package's ``robots/`` folder, e.g.
            ``"double_pendulum_description/urdf/double_pendulum.urdf"``.

    Raises:
        InvalidURDFError: the distribution is not installed or has no such file.
    """
    require_type(relative, str, "relative", "a path inside example-robot-data's robots folder (str)")
    return _located("robots/" + relative.lstrip("/"))


@functools.cache
def _located(suffix: str) -> Path:
    """The installed file whose path ends in ``suffix``, looked up once per process: listing
    the distribution's ~1000 files costs ~0.1 s, and a URDF given by path is compared with
    every catalog robot's (:func:`resolve`). A failed lookup raises and is not remembered."""
    files = _distribution_files()
    if files is None:
        raise InvalidURDFError(
            suffix.removeprefix("robots/"),
            "example-robot-data",
            "not installed (pip install example-robot-data)",
        )
    for text, file in files:
        if text.endswith(suffix):
            return Path(str(file.locate()))
    raise InvalidURDFError(
        suffix.removeprefix("robots/"),
        "example-robot-data",
        f"no file ending in {suffix!r} in the installed distribution",
    )


@functools.cache
def _distribution_files() -> tuple[tuple[str, importlib.metadata.PackagePath], ...] | None:
    """example-robot-data's files with their paths as text, None if it is not installed."""
    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        return None
    return tuple((str(file), file) for file in files)


CATALOG: dict[str, Callable[[], tuple[Path, RobotProfile]]] = {}
"""Named robots: name → a function giving its URDF path and profile (located on use)."""
DEFAULT_ROBOT = "twolink"
"""The robot a command or :func:`~twolink_pin.model.load_robot` uses when none is named."""


def register(name: str, entry: Callable[[], tuple[Path, RobotProfile]]) -> None:
    """Add a named robot: ``entry()`` gives its URDF path and profile."""
    CATALOG[name] = entry


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


def names() -> tuple[str, ...]:
    """The catalog's robot names, the default robot first."""
    return tuple(sorted(CATALOG, key=lambda name: name != DEFAULT_ROBOT))


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
