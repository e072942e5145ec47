"""Simulation results as ``.npz`` files: :func:`save_result` and :func:`load_result`."""

from __future__ import annotations

import io
import os
import zipfile
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InputFileError, OutputError
from twolink_pin.files import atomic_write, check_input_file
from twolink_pin.simulation.result import SimulationResult

MAX_RESULT_BYTES = 2**31
"""Largest result file :func:`load_result` reads (2 GiB)."""


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
        check_input_file(path, MAX_RESULT_BYTES, "a saved simulation result (.npz)")
    except InputFileError as exc:
        raise OutputError(exc.path, exc.reason) from None
    try:
        with np.load(path, allow_pickle=False) as data:
            raw = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
        raise OutputError(
            str(path), f"cannot read a saved simulation result ({type(exc).__name__}: {exc})"
        ) from exc
    names = {f.name for f in fields(SimulationResult)}
    missing = {"controller", "t", "q", "v", "q_des"} - raw.keys()
    if missing:
        raise OutputError(str(path), f"not a twolink-pin result: missing {sorted(missing)}")
    kwargs: dict[str, Any] = {}
    for name, value in raw.items():
        if name not in names:
            continue
        if name in ("controller", "method", "robot"):
            kwargs[name] = str(value)
        elif name in ("dt", "reference_period", "control_period"):
            kwargs[name] = float(value)
        elif name == "saturate":
            kwargs[name] = bool(value)
        elif name in ("parameter_names", "parameter_units", "parameter_kinds"):
            kwargs[name] = tuple(str(x) for x in value)
        else:
            array = np.array(value, dtype=float)
            array.setflags(write=False)
            kwargs[name] = array
    try:
        return SimulationResult(**kwargs)
    except TypeError as exc:
        raise OutputError(str(path), f"not a complete twolink-pin result ({exc})") from exc
