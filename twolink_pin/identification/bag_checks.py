"""The checks a ROS bag passes before and while it is read (:mod:`~twolink_pin.identification.bags`
reads it): its size on disk against the memory available, its ``metadata.yaml`` in one line,
every value finite, and time that neither repeats nor runs backwards. Each refusal is an
:class:`~twolink_pin.errors.InputFileError` naming the file, the topic, the message, the joint
or the time.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from twolink_pin.errors import InputFileError
from twolink_pin.identification.data import MAX_GAP_STEPS

BAG_SUFFIXES = (".db3", ".mcap", ".bag")
"""File suffixes read as bags (a folder with ``metadata.yaml`` is a ROS 2 bag too)."""
MAX_BAG_BYTES = 16 << 30
"""Largest bag file read (16 GiB)."""
READ_MEMORY_FACTOR = 3.0
"""Memory reading a bag may take, as a multiple of its size on disk (measured: below 2 for
joint states: ``tests/test_bags.py``, tracemalloc); a bag larger than the memory available divided
by this is refused before it is read."""
MAX_METADATA_BYTES = 1 << 20
"""Largest ``metadata.yaml`` of a ROS 2 bag read (1 MiB)."""


def check_finite(
    path: str, topic: str, values: Mapping[str, np.ndarray], times: np.ndarray, names: list[str]
) -> None:
    """Every value read is a finite number; else the message, its time, the field and the joint."""
    for field_name, column in values.items():
        bad = ~np.isfinite(column)
        if bad.any():
            k, j = (int(i) for i in np.argwhere(bad)[0])
            raise InputFileError(
                path,
                f"{topic} message {k} (t = {(times[k] - times.min()) * 1e-9:.9g} s): {field_name} of joint "
                f"{names[j]!r} is {float(column[k, j])!r}; expected a finite number",
            )


def check_time(path: str, topic: str, times: np.ndarray, what: str) -> np.ndarray:
    """The order that sorts ``times`` [ns] (message order), after refusing time that runs
    backwards by more than a reordering in transport (:data:`MAX_GAP_STEPS` steps), repeats,
    or comes twice for one step (two stamps at most half a step apart)."""
    order = np.argsort(times, kind="stable")
    sorted_times = times[order]
    steps = np.diff(sorted_times)
    positive = steps[steps > 0]
    if positive.size == 0:
        raise InputFileError(path, f"{topic}: every message has the same {what} t = {times[0] * 1e-9:.9g} s")
    period = float(np.median(positive))
    latest = np.maximum.accumulate(times)
    back = latest[:-1] - times[1:]
    if np.any(back > MAX_GAP_STEPS * period):
        k = int(np.flatnonzero(back > MAX_GAP_STEPS * period)[0]) + 1
        j = int(np.argmax(times[:k]))
        raise InputFileError(
            path,
            f"{topic} message {k}: time goes backwards: its {what} is {(times[j] - times[k]) * 1e-9:.6g} s before "
            f"that of message {j} (t = {(times[j] - sorted_times[0]) * 1e-9:.9g} s); messages may arrive out of "
            f"order by at most {MAX_GAP_STEPS:g} steps of {period * 1e-6:.6g} ms",
        )
    close = np.flatnonzero(steps <= 0.5 * period)
    if close.size:
        i = int(close[0])
        a, b = sorted(int(m) for m in order[i : i + 2])
        at = f"t = {(sorted_times[i] - sorted_times[0]) * 1e-9:.9g} s"
        raise InputFileError(
            path,
            f"{topic} messages {a} and {b}: time {'repeats' if b == a + 1 and steps[i] == 0 else 'repeats or goes backwards'}: "
            + (
                f"both have the {what} {at}"
                if steps[i] == 0
                else f"their {what}s are {steps[i] * 1e-6:.6g} ms apart at {at}, at most half the "
                f"{period * 1e-6:.6g}-ms step"
            )
            + "; expected one message per step",
        )
    return order


def size_checked(root: Path, file: Path) -> int:
    """The bag's size on disk [bytes], after refusing what
    would block the reader (a FIFO or device named like a bag), a bag too large for the memory
    available, and a ``metadata.yaml`` that is no YAML (in one line: where and why)."""
    from twolink_pin.files import check_input_file
    from twolink_pin.memory import available_memory

    stored = [p for p in root.iterdir() if p.suffix.lower() in BAG_SUFFIXES] if root.is_dir() else [root]
    disk = sum(check_input_file(part, MAX_BAG_BYTES, "a ROS bag").stat().st_size for part in stored)
    available = available_memory()
    if available is not None and READ_MEMORY_FACTOR * disk > available:
        raise InputFileError(
            str(file),
            f"is {disk / 2**20:.4g} MiB on disk; reading it needs up to {READ_MEMORY_FACTOR:g} × that "
            f"({READ_MEMORY_FACTOR * disk / 2**20:.4g} MiB) and {available / 2**20:.4g} MiB of memory are "
            "available: cut the bag (ros2 bag convert / rosbag filter), or free memory",
        )
    if root.is_dir():
        check_metadata(root / "metadata.yaml")
    return disk


def check_metadata(path: Path) -> None:
    """Refuse a ``metadata.yaml`` that is not a bounded regular UTF-8 YAML file, in one line."""
    from ruamel.yaml import YAML
    from ruamel.yaml.error import MarkedYAMLError, YAMLError

    from twolink_pin.files import read_input_file

    raw = read_input_file(path, MAX_METADATA_BYTES, "a ROS 2 bag's metadata.yaml")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputFileError(str(path), f"is not UTF-8 text (byte {err.start})") from None
    try:
        document = YAML(typ="safe").load(text)
    except MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        raise InputFileError(str(path), f"is not valid YAML ({where}{err.problem or err.context})") from None
    except YAMLError as err:
        raise InputFileError(str(path), f"is not valid YAML ({one_line(err)})") from None
    if not isinstance(document, dict) or "rosbag2_bagfile_information" not in document:
        raise InputFileError(
            str(path), "has no rosbag2_bagfile_information mapping: not a ROS 2 bag's metadata"
        )


def one_line(exc: BaseException) -> str:
    """An exception as one short line (a reader's message may span many)."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:300]}{'…' if len(text) > 300 else ''}"


__all__ = [
    "BAG_SUFFIXES",
    "MAX_BAG_BYTES",
    "MAX_METADATA_BYTES",
    "READ_MEMORY_FACTOR",
    "check_finite",
    "check_metadata",
    "check_time",
    "one_line",
    "size_checked",
]
