"""Saving and loading: atomic file writes and simulation results as ``.npz``.

Every file the toolkit writes goes through :func:`atomic_write`: the content goes to a
temporary file in the target's directory, which then replaces the target in one
``os.replace``, so an error midway never leaves a half-written file.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
from collections.abc import Iterator
from dataclasses import fields
from pathlib import Path
from typing import IO, Any

import numpy as np

from twolink_pin.errors import OutputError
from twolink_pin.simulation import SimulationResult


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path``; on success move it onto ``path``."""
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(str(target.parent), f"cannot create the directory ({exc.strerror})") from exc
    if target.is_dir():
        raise OutputError(str(target), "is a directory; expected a file path")
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode, encoding=None if "b" in mode else "utf-8") as f:
            yield f
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_json(path: str | os.PathLike[str], obj: Any) -> Path:
    """Write ``obj`` as indented JSON, atomically."""
    with atomic_write(path) as f:
        json.dump(obj, f, indent=2, allow_nan=False)
        f.write("\n")
    return Path(path)


def save_result(result: SimulationResult, path: str | os.PathLike[str]) -> Path:
    """Save a :class:`SimulationResult` as a compressed ``.npz``, atomically."""
    arrays: dict[str, Any] = {}
    for entry in fields(result):
        value = getattr(result, entry.name)
        if value is None:
            continue
        arrays[entry.name] = np.asarray(value)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    with atomic_write(path, "wb") as f:
        f.write(buffer.getvalue())
    return Path(path)


def load_result(path: str | os.PathLike[str]) -> SimulationResult:
    """Load a result written by :func:`save_result`.

    Raises:
        OutputError: the file is missing or is not a saved simulation result.
    """
    try:
        with np.load(path, allow_pickle=False) as data:
            raw = {k: data[k] for k in data.files}
    except (OSError, ValueError) as exc:
        raise OutputError(str(path), f"cannot read a saved simulation result ({exc})") from exc
    names = {f.name for f in fields(SimulationResult)}
    missing = {"controller", "t", "q", "v", "q_des"} - raw.keys()
    if missing:
        raise OutputError(str(path), f"not a twolink-pin result: missing {sorted(missing)}")
    kwargs: dict[str, Any] = {}
    for name, value in raw.items():
        if name not in names:
            continue
        if name in ("controller", "method"):
            kwargs[name] = str(value)
        elif name in ("dt", "reference_period", "control_period"):
            kwargs[name] = float(value)
        elif name == "saturate":
            kwargs[name] = bool(value)
        elif name == "parameter_names":
            kwargs[name] = tuple(str(x) for x in value)
        else:
            array = np.array(value, dtype=float)
            array.setflags(write=False)
            kwargs[name] = array
    try:
        return SimulationResult(**kwargs)
    except TypeError as exc:
        raise OutputError(str(path), f"not a complete twolink-pin result ({exc})") from exc
