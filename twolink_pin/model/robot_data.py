"""Where example-robot-data's files are: a URDF below its ``robots/`` folder, and the folder
its ``package://`` mesh paths are relative to (looked up once per process)."""

from __future__ import annotations

import functools
import importlib.metadata
from pathlib import Path

from twolink_pin.errors import InvalidURDFError, require_type


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


__all__ = ["example_robot_urdf", "share_folder"]
