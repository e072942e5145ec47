"""Simulation results as ``.npz`` files: :func:`save_result` and :func:`load_result`."""

from __future__ import annotations

import io
import json
import os
import zipfile
from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InputFileError
from twolink_pin.files import atomic_write, check_input_file
from twolink_pin.simulation.result import SimulationResult

MAX_RESULT_BYTES = 2**31
"""Largest result file :func:`load_result` reads (2 GiB)."""


RECORD = "run_record"
"""Entry of a saved result that holds what produced it (JSON text: the robot as given, its
payload, the trajectory file, the run's :class:`~twolink_pin.run_spec.RunSpec`)."""


def save_result(
    result: SimulationResult, path: str | os.PathLike[str], record: Mapping[str, Any] | None = None
) -> Path:
    """Save a :class:`SimulationResult` as a compressed ``.npz``, atomically; ``record``
    (JSON-ready data: what produced the run) is saved beside it (:func:`load_record`)."""
    arrays: dict[str, Any] = {}
    if record is not None:
        arrays[RECORD] = np.asarray(json.dumps(dict(record)))
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


MAX_RESULT_VALUES = 2 * 10**8
"""Most numbers :func:`load_result` unpacks (1.6 GB of float64): the sizes the arrays' headers
claim are checked against it before anything is decompressed (a zip bomb or a forged header
is refused, not allocated)."""
REQUIRED = ("controller", "t", "q", "v", "q_des")


def claimed_values(path: str | os.PathLike[str]) -> int:
    """Numbers the archive's arrays claim to hold, from their ``.npy`` headers (read without
    decompressing the data)."""
    total = 0
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            with archive.open(info) as member:
                version = np.lib.format.read_magic(member)
                shape, _, dtype = (
                    np.lib.format.read_array_header_1_0(member)
                    if version == (1, 0)
                    else np.lib.format.read_array_header_2_0(member)
                )
                count = int(np.prod(shape, dtype=np.float64)) if shape else 1
                total += count * max(1, dtype.itemsize // 8)
                if total > MAX_RESULT_VALUES:
                    return total
    return total


def _check_arrays(path: str, kwargs: dict[str, Any]) -> None:
    """The run's arrays agree: t strictly increasing and finite, q, v, q_des of shape (N, nq)."""
    t = kwargs["t"]
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputFileError(path, "its t is not a finite, strictly increasing list of at least 2 times [s]")
    for name in ("q", "v", "q_des", "v_des", "tau", "q_measured", "v_measured"):
        if name not in kwargs:
            continue
        array = kwargs[name]
        if array.ndim != 2 or array.shape[0] != t.size:
            raise InputFileError(
                path, f"its {name} has shape {array.shape}; expected ({t.size}, nq): one row per time in t"
            )
        if not np.all(np.isfinite(array)):
            row = int(np.argwhere(~np.isfinite(array))[0][0])
            raise InputFileError(path, f"its {name} is not finite at t = {t[row]:g} s (row {row})")
    if kwargs["q_des"].shape != kwargs["q"].shape:
        raise InputFileError(path, f"its q_des has shape {kwargs['q_des'].shape}, q {kwargs['q'].shape}")


def load_result(path: str | os.PathLike[str]) -> SimulationResult:
    """Load a result written by :func:`save_result`.

    Raises:
        InputFileError: the file is missing, too large (in the sizes its arrays claim, see
            :data:`MAX_RESULT_VALUES`), not a saved simulation result, or its arrays disagree
            (the message names the file and the array).
    """
    name = os.fspath(path)
    check_input_file(path, MAX_RESULT_BYTES, "a saved simulation result (.npz)")
    try:
        claimed = claimed_values(path)
        if claimed > MAX_RESULT_VALUES:
            raise InputFileError(
                name, f"its arrays claim more than {MAX_RESULT_VALUES:g} numbers; refusing to unpack it"
            )
        with np.load(path, allow_pickle=False) as data:
            raw = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, MemoryError) as exc:
        raise InputFileError(
            name, f"cannot read a saved simulation result ({type(exc).__name__}: {str(exc)[:200]})"
        ) from exc
    names = {f.name for f in fields(SimulationResult)}
    missing = set(REQUIRED) - raw.keys()
    if missing:
        raise InputFileError(name, f"not a twolink-pin result: missing {sorted(missing)}")
    kwargs: dict[str, Any] = {}
    try:
        for key, value in raw.items():
            if key not in names:
                continue
            if key in ("controller", "method", "robot"):
                kwargs[key] = str(value)
            elif key in ("dt", "reference_period", "control_period"):
                kwargs[key] = float(value)
            elif key in ("saturate", "position_stops"):
                kwargs[key] = bool(value)
            elif key in (
                "parameter_names",
                "parameter_units",
                "parameter_kinds",
                "state_names",
                "state_units",
                "joint_names",
            ):
                kwargs[key] = tuple(str(x) for x in value)
            else:
                array = np.array(value, dtype=float)
                array.setflags(write=False)
                kwargs[key] = array
    except (TypeError, ValueError) as exc:
        raise InputFileError(name, f"holds a value of the wrong kind ({str(exc)[:200]})") from exc
    _check_arrays(name, kwargs)
    try:
        return SimulationResult(**kwargs)
    except TypeError as exc:
        raise InputFileError(name, f"not a complete twolink-pin result ({exc})") from exc


def load_record(path: str | os.PathLike[str]) -> dict[str, Any] | None:
    """What produced the result saved in ``path`` (:func:`save_result`'s ``record``), or None
    for a file that records nothing (an older one). Call after :func:`load_result` (which
    checks the file)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            if RECORD not in data.files:
                return None
            value = json.loads(str(data[RECORD]))
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
        raise InputFileError(os.fspath(path), f"its run record cannot be read ({str(exc)[:200]})") from exc
    if not isinstance(value, dict):
        raise InputFileError(os.fspath(path), "its run record is not a JSON object")
    return value
