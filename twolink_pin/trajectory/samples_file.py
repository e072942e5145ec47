"""The ``[samples]`` table of a trajectory file: a :class:`~twolink_pin.trajectory.sampled.SampledTrajectory`
(what ``trajectory --time-optimal --save`` and ``optimize --save`` write)::

    [samples]
    times = [0.0, 0.01, 0.01, 0.02, ...]        # s, non-decreasing; a time twice: an acceleration jump
    q = [[0.5, 1.2], ...]                       # rad, one row per time
    v = [[0.0, 0.0], ...]                       # rad/s
    a = [[12.1, -3.0], ...]                     # rad/s²
    tau = [[40.0, -2.2], ...]                   # N·m, optional: the torque it was designed with
    via_times = [0.0, 0.13, ...]                # s, optional: where figures mark via points

A JSON file has the same keys under ``"samples"``. Between two samples the reference is the
quintic with their positions, velocities and accelerations (exact for the spline ``optimize``
writes at its knots); it repeats every ``times[-1] − times[0]`` and must end where it starts.
Reading checks the shapes, finiteness and bounds of every value, the repeated times, the
closure, and the joint position range along a period, as for every trajectory file.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.sampled import SampledTrajectory

SAMPLE_KEYS = frozenset({"times", "q", "v", "a", "tau", "via_times"})
"""Keys of a ``samples`` table."""
MAX_SAMPLES = 100_000
"""Most samples of one file."""
MAX_RATE = 1e6
"""Largest velocity [rad/s] or acceleration [rad/s²] in a file: beyond, a typo or garbage."""
MAX_TORQUE = 1e9
"""Largest torque [N·m] in a file."""


def read_samples(file: Path, document: dict[str, Any], robot: RobotModel) -> SampledTrajectory:
    """The sampled trajectory of a file's ``samples`` table (module docstring).

    Raises:
        InvalidParameterError: a key or value is wrong (named with the file).
    """
    from twolink_pin.trajectory.file_values import (
        MAX_ANGLE,
        MAX_TIME,
        check_trajectory_limits,
        check_within_limits,
        parse_numbers,
        shown,
    )

    others = sorted(set(document) - {"samples"})
    if others:
        raise InvalidParameterError(
            f"{file}: {others[0]}", shown(document[others[0]]), "no other key beside a 'samples' table"
        )
    table = document["samples"]
    if not isinstance(table, dict):
        raise InvalidParameterError(f"{file}: samples", shown(table), "a table with times, q, v and a")
    unknown = sorted(set(table) - SAMPLE_KEYS)
    if unknown:
        raise InvalidParameterError(
            f"{file}: samples.{unknown[0]}", shown(table[unknown[0]]), f"only the keys {sorted(SAMPLE_KEYS)}"
        )
    for key in ("times", "q", "v", "a"):
        if key not in table:
            raise InvalidParameterError(
                f"{file}: samples.{key}", None, "times [s], q [rad], v [rad/s] and a [rad/s²]"
            )
    times = parse_numbers(file, "samples.times", table["times"], "a list of times [s]", MAX_TIME, "s")
    if times.ndim != 1 or not 2 <= times.size <= MAX_SAMPLES:
        raise InvalidParameterError(
            f"{file}: samples.times", f"{np.size(times)} values", f"a list of 2 to {MAX_SAMPLES} times [s]"
        )
    rows = {}
    for key, bound, unit in (
        ("q", MAX_ANGLE, "rad"),
        ("v", MAX_RATE, "rad/s"),
        ("a", MAX_RATE, "rad/s²"),
        ("tau", MAX_TORQUE, "N·m"),
    ):
        if key not in table:
            continue
        value = table[key]
        shape = f"{times.size} rows of {robot.nv} values [{unit}] for {robot.name}"
        if (
            not isinstance(value, list)
            or len(value) != times.size
            or any(not isinstance(r, list) or len(r) != robot.nv for r in value)
        ):
            raise InvalidParameterError(
                f"{file}: samples.{key}",
                f"{type(value).__name__} of {len(value) if isinstance(value, list) else 0} rows",
                shape,
            )
        rows[key] = parse_numbers(file, f"samples.{key}", value, shape, bound, unit)
    check_within_limits(robot, rows["q"], f"{file}: samples.q")
    via_times = None
    if "via_times" in table:
        via_times = parse_numbers(
            file, "samples.via_times", table["via_times"], "a list of times [s]", MAX_TIME, "s"
        )
        if via_times.ndim != 1:
            raise InvalidParameterError(
                f"{file}: samples.via_times", shown(table["via_times"]), "a list of times [s]"
            )
    try:
        trajectory = SampledTrajectory(times, rows["q"], rows["v"], rows["a"], rows.get("tau"), via_times)
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: samples.{err.name}", err.value, err.expected) from None
    check_trajectory_limits(robot, trajectory, f"{file}")
    return trajectory


def samples_table(trajectory: SampledTrajectory) -> dict[str, Any]:
    """The ``samples`` table of ``trajectory`` (module docstring), JSON-ready."""
    table: dict[str, Any] = {
        "times": trajectory.times.tolist(),
        "q": trajectory.q.tolist(),
        "v": trajectory.v.tolist(),
        "a": trajectory.a.tolist(),
    }
    if trajectory.tau is not None:
        table["tau"] = trajectory.tau.tolist()
    if trajectory.via_times.size:
        table["via_times"] = trajectory.via_times.tolist()
    return table


def write_samples(path: str | os.PathLike[str], trajectory: SampledTrajectory) -> Path:
    """Write ``trajectory`` as a ``samples`` file (atomically): TOML if ``path`` ends in
    ``.toml``, else JSON."""
    from twolink_pin.files import atomic_write, write_json

    table = samples_table(trajectory)
    if Path(os.fspath(path)).suffix.lower() != ".toml":
        return write_json(path, {"samples": table})
    with atomic_write(path) as f:
        f.write(
            "# samples: times [s] (a time twice: an acceleration jump), q [rad], v [rad/s], a [rad/s²],\n"
            "# tau [N·m] (the design torque), via_times [s]; quintic Hermite between samples, periodic\n"
        )
        f.write("[samples]\n")
        for key, value in table.items():
            f.write(f"{key} = {json.dumps(value)}\n")
    return Path(os.fspath(path))


__all__ = ["MAX_SAMPLES", "SAMPLE_KEYS", "read_samples", "samples_table", "write_samples"]
