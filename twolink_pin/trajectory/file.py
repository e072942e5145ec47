"""Trajectory files: a reference as a small TOML or JSON file (``--trajectory FILE``).

Via points in joint space::

    times = [0.0, 1.0, 2.0, 3.0, 4.0]           # s, strictly increasing
    joints = [[0.0, -1.57, 1.57, -1.57, -1.57, 0.0], ...]   # rad, nv values per row
    period = 4.0                                # s, optional (default: the span)

or through end-effector positions of the robot's end-effector frame (solved by
:func:`~twolink_pin.trajectory.cartesian_via_q`, each point seeded by the one before)::

    times = [0.0, 1.0, 2.0, 3.0, 4.0]
    positions = [[0.45, 0.10, 0.40], ...]       # m: (x, y, z), or (x, y) for a planar arm
    seed = [0.0, -1.57, 1.57, -1.57, -1.57, 0.0]   # rad, optional IK seed (default: home)

or through end-effector poses: ``positions`` (3 coordinates) and, per row, the orientation
as roll, pitch, yaw [rad] (``R = Rz(yaw) Ry(pitch) Rx(roll)``, the URDF's ``rpy``, what
Pinocchio's ``rpy.rpyToMatrix`` builds; chosen over a quaternion because three angles are
what one writes by hand and need no normalisation; the last row may differ from the first by
2π, only the rotation must repeat)::

    times = [0.0, 2.0, 4.0, 6.0, 8.0]
    positions = [[0.45, 0.10, 0.40], ...]       # m
    rpy = [[3.14159, 0.0, -1.5708], ...]        # rad: roll, pitch, yaw of the end-effector frame

an SE(3) reference (:class:`~twolink_pin.trajectory.se3.PoseTrajectory`: straight lines and
one-axis rotations between the via poses, continuous velocity and acceleration; arms with
6 joints or more), whose desired pose, twist and acceleration task-space laws see, its joint
path solved by a 6-D inverse kinematics;

or samples of a motion (a ``samples`` table: :mod:`~twolink_pin.trajectory.samples_file`,
what a time-optimal retiming and an optimised trajectory save);

or a periodic finite Fourier series (:class:`~twolink_pin.trajectory.fourier.FourierTrajectory`,
Swevers et al. 1997; what ``twolink-pin excite`` writes), a table of its own::

    [fourier]
    period = 10.0                               # s: base frequency 1 / period
    harmonics = 5                               # optional: N, checked against a and b
    a = [[...5 values...], [...]]               # rad/s, sine coefficients, nv rows of N
    b = [[...5 values...], [...]]               # rad/s, cosine coefficients, nv rows of N
    offset = [0.0, 0.5]                         # rad, mean position per joint

A JSON file has the same keys. The file is read as a bounded regular file; every value is
checked against the robot: the number of joints, finite and strictly increasing times,
joint values within the joint limits (the message names the value and the limit), the
last via point equal to the first (the reference repeats every period), and the sampled
trajectory within the limits between via points too (a Fourier trajectory: over a period).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.documents import load_json, load_toml
from twolink_pin.errors import InputFileError, InvalidParameterError, InverseKinematicsError, require_type
from twolink_pin.files import read_input_file
from twolink_pin.limits import POSITION, joint_limits
from twolink_pin.limits.check import check_grid
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.cartesian import cartesian_via_q
from twolink_pin.trajectory.file_values import (
    MAX_ANGLE,
    MAX_TIME,
    check_trajectory_limits,
    check_within_limits,
    parse_numbers,
    shown,
)
from twolink_pin.trajectory.fourier import MAX_HARMONICS, MAX_PERIOD, MIN_PERIOD, FourierTrajectory
from twolink_pin.trajectory.polynomial import JointTrajectory
from twolink_pin.trajectory.sampled import SampledTrajectory
from twolink_pin.trajectory.se3 import MAX_POSITION, PoseTrajectory, pose_trajectory

MAX_TRAJECTORY_BYTES = 16 << 20
"""Largest trajectory file read (16 MiB: a ``samples`` table of a retimed UR5 path is about
1 MiB; via points need far less)."""
MAX_VIA_POINTS = 24
"""Most via points of one file: the polynomial through n points has degree n + 5, and
beyond about two dozen points its normal equations lose the digits the fit needs."""

MIN_TIME_STEP = 1e-3
"""Shortest interval between via points [s]."""

CLOSURE_TOLERANCE = 1e-6
"""How far [rad] the last via point may be from the first (in joint space)."""

KEYS = frozenset({"times", "joints", "positions", "rpy", "period", "seed"})
FOURIER_KEYS = frozenset({"period", "harmonics", "a", "b", "offset"})
"""Keys of a ``fourier`` table."""


def _load(path: Path) -> dict[str, Any]:
    data = read_input_file(path, MAX_TRAJECTORY_BYTES, "a trajectory file (.toml or .json)")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputFileError(
            str(path), f"is not UTF-8 (byte {err.start}); expected a UTF-8 text file"
        ) from None
    suffix = path.suffix.lower()
    if suffix == ".json":
        document = load_json(text, str(path))  # nesting bounded, repeated keys refused
    elif suffix == ".toml":
        document = load_toml(text, str(path))
    else:
        raise InputFileError(str(path), f"has the suffix {suffix!r}; expected .toml or .json")
    if not isinstance(document, dict):
        raise InputFileError(str(path), "expected a table (TOML) or an object (JSON) at the top level")
    return document


def read_trajectory_file(
    path: str | os.PathLike[str], robot: RobotModel
) -> JointTrajectory | FourierTrajectory | PoseTrajectory | SampledTrajectory:
    """The trajectory a TOML or JSON file describes for ``robot`` (see the module docstring).

    Raises:
        InputFileError: the file cannot be read or parsed.
        InvalidParameterError: a key or value is wrong (the message names it and says what
            was expected).
        InverseKinematicsError: an end-effector point is out of reach or singular.
    """
    require_type(path, (str, os.PathLike), "path", "a file path (str or pathlib.Path)")
    file = Path(os.fspath(path))
    document = _load(file)
    if "fourier" in document:
        return _fourier_trajectory(file, document, robot)
    if "samples" in document:
        from twolink_pin.trajectory.samples_file import read_samples

        return read_samples(file, document, robot)
    unknown = sorted(set(document) - KEYS)
    if unknown:
        raise InvalidParameterError(
            f"{file}: {unknown[0]}", shown(document[unknown[0]]), f"only the keys {sorted(KEYS)}"
        )
    times = _via_times(file, document)
    period = document.get("period")
    if period is not None and not (
        isinstance(period, (int, float)) and not isinstance(period, bool) and math.isfinite(period)
    ):
        raise InvalidParameterError(f"{file}: period", period, "a finite period [s]")
    if "rpy" in document and "positions" not in document:
        raise InvalidParameterError(
            f"{file}: rpy", shown(document["rpy"]), "orientations beside 'positions' (m)"
        )
    given = [key for key in ("joints", "positions") if key in document]
    if len(given) != 1:
        raise InvalidParameterError(
            f"{file}", given or None, "exactly one of 'joints' (rad) and 'positions' (m)"
        )
    key = given[0]
    rows: Sequence[Any] = document[key]
    if not isinstance(rows, list) or len(rows) != times.size:
        raise InvalidParameterError(
            f"{file}: {key}",
            f"{len(rows) if isinstance(rows, list) else type(rows).__name__} rows",
            f"one row per time ({times.size})",
        )
    if key == "joints":
        via_q = _joint_rows(file, rows, robot)
    else:
        points, seed = _position_rows(file, document, rows, robot)
        if "rpy" in document:
            return _pose_file(file, document, robot, times, points, seed, period)
        try:
            via_q = cartesian_via_q(robot, points, seed)
        except InverseKinematicsError as err:
            raise InverseKinematicsError(err.target, f"{file}: {err.reason}", err.q) from None
    closing = float(np.abs(via_q[-1] - via_q[0]).max())
    if closing > CLOSURE_TOLERANCE:
        raise InvalidParameterError(
            f"{file}: {key}[{len(rows) - 1}]",
            rows[-1],
            f"the first via point {rows[0]} again (to {CLOSURE_TOLERANCE:g} rad in joint space): the reference "
            "repeats every period, so it must end where it starts",
        )
    try:
        trajectory = JointTrajectory.from_via_q(
            tuple(times), via_q, None if period is None else float(period)
        )
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None
    check_trajectory_limits(robot, trajectory, f"{file}")
    return trajectory


def _via_times(file: Path, document: dict[str, Any]) -> np.ndarray:
    """The file's via-point times [s]: 2 to :data:`MAX_VIA_POINTS` of them, within
    ±:data:`MAX_TIME`, strictly increasing by at least :data:`MIN_TIME_STEP`."""
    if "times" not in document:
        raise InvalidParameterError(f"{file}: times", None, "a list of via-point times [s]")
    times = parse_numbers(file, "times", document["times"], "a list of times [s]")
    if times.ndim != 1 or not 2 <= times.size <= MAX_VIA_POINTS:
        raise InvalidParameterError(
            f"{file}: times", shown(document["times"]), f"a list of 2 to {MAX_VIA_POINTS} times [s]"
        )
    if np.any(np.abs(times) > MAX_TIME):
        k = int(np.flatnonzero(np.abs(times) > MAX_TIME)[0])
        raise InvalidParameterError(
            f"{file}: times[{k}]", float(times[k]), f"a time within ±{MAX_TIME:g} s (the longest simulation)"
        )
    steps = np.diff(times)
    if np.any(steps < MIN_TIME_STEP):
        k = int(np.flatnonzero(steps < MIN_TIME_STEP)[0])
        if steps[k] > 0:
            raise InvalidParameterError(
                f"{file}: times[{k + 1}]",
                float(times[k + 1]),
                f"at least {MIN_TIME_STEP:g} s after times[{k}] = {times[k]:.17g} s",
            )
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise InvalidParameterError(
            f"{file}: times[{k + 1}]",
            float(times[k + 1]),
            f"strictly increasing times: > times[{k}] = {times[k]:g} s",
        )
    return times


def _joint_rows(file: Path, rows: Sequence[Any], robot: RobotModel) -> np.ndarray:
    """The ``joints`` rows as via points [rad], shape (V, nv): nv finite numbers per row, within
    the URDF's limits and ±:data:`MAX_ANGLE`."""
    for k, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != robot.nv:
            raise InvalidParameterError(
                f"{file}: joints[{k}]",
                row,
                f"{robot.nv} joint positions [rad] for {robot.name} (nv = {robot.nv})",
            )
    via_q = parse_numbers(file, "joints", rows, f"rows of {robot.nv} joint positions [rad]")
    check_within_limits(robot, via_q, f"{file}: joints")  # the URDF's limits first: the better message
    parse_numbers(file, "joints", rows, f"rows of {robot.nv} joint positions [rad]", MAX_ANGLE, "rad")
    return via_q


def _position_rows(
    file: Path, document: dict[str, Any], rows: Sequence[Any], robot: RobotModel
) -> tuple[np.ndarray, np.ndarray | None]:
    """The ``positions`` rows as end-effector points [m], shape (V, 3) or (V, 2), and the
    IK's ``seed`` [rad] (None if the file gives none), checked."""
    width = {len(row) if isinstance(row, list) else -1 for row in rows}
    if len(width) != 1 or width.pop() not in (2, 3):
        raise InvalidParameterError(
            f"{file}: positions",
            rows,
            "rows of 3 coordinates (x, y, z) [m], or 2 (x, y) for a planar arm, all alike",
        )
    points = parse_numbers(file, "positions", rows, "end-effector positions [m]", MAX_POSITION, "m")
    seed = None
    if "seed" in document:
        seed = parse_numbers(
            file, "seed", document["seed"], f"{robot.nv} joint positions [rad]", MAX_ANGLE, "rad"
        )
        if seed.shape != (robot.nv,):
            raise InvalidParameterError(
                f"{file}: seed", shown(document["seed"]), f"{robot.nv} joint positions [rad]"
            )
        check_within_limits(robot, seed[None, :], f"{file}: seed")
    return points, seed


def _pose_file(
    file: Path,
    document: dict[str, Any],
    robot: RobotModel,
    times: np.ndarray,
    points: np.ndarray,
    seed: np.ndarray | None,
    period: Any,
) -> PoseTrajectory:
    """The SE(3) reference of a file with ``positions`` and ``rpy`` (see the module docstring)."""
    rows = document["rpy"]
    if (
        not isinstance(rows, list)
        or len(rows) != times.size
        or any(not isinstance(row, list) or len(row) != 3 for row in rows)
    ):
        raise InvalidParameterError(
            f"{file}: rpy", rows, f"one row (roll, pitch, yaw) [rad] per time ({times.size})"
        )
    rpy = parse_numbers(file, "rpy", rows, "rows of (roll, pitch, yaw) [rad]", MAX_ANGLE, "rad")
    if points.shape[1] != 3:
        raise InvalidParameterError(
            f"{file}: positions",
            shown(document["positions"]),
            "3 coordinates (x, y, z) [m] per row beside 'rpy'",
        )
    if robot.nv < 6:
        raise InvalidParameterError(
            f"{file}: rpy",
            rows[0],
            f"no orientations for {robot.name}: its {robot.nv} joints cannot set a full pose",
        )
    rotations = np.array([pin.rpy.rpyToMatrix(*row) for row in rpy])
    try:
        trajectory = pose_trajectory(
            robot, tuple(times), points, rotations, None if period is None else float(period), seed
        )
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None
    except InverseKinematicsError as err:
        raise InverseKinematicsError(err.target, f"{file}: {err.reason}", err.q) from None
    check_trajectory_limits(robot, trajectory, f"{file}")
    return trajectory


def _fourier_trajectory(file: Path, document: dict[str, Any], robot: RobotModel) -> FourierTrajectory:
    """The Fourier trajectory of a file's ``fourier`` table (see the module docstring)."""
    others = sorted(set(document) - {"fourier"})
    if others:
        raise InvalidParameterError(
            f"{file}: {others[0]}", shown(document[others[0]]), "no other key beside a 'fourier' table"
        )
    table = document["fourier"]
    if not isinstance(table, dict):
        raise InvalidParameterError(f"{file}: fourier", table, "a table with period, a, b and offset")
    unknown = sorted(set(table) - FOURIER_KEYS)
    if unknown:
        raise InvalidParameterError(
            f"{file}: fourier.{unknown[0]}", table[unknown[0]], f"only the keys {sorted(FOURIER_KEYS)}"
        )
    for key in ("period", "a", "b", "offset"):
        if key not in table:
            raise InvalidParameterError(
                f"{file}: fourier.{key}", None, "a value (period [s], a, b [rad/s], offset [rad])"
            )
    period = table["period"]
    if isinstance(period, bool) or not (
        isinstance(period, (int, float)) and MIN_PERIOD <= period <= MAX_PERIOD
    ):
        raise InvalidParameterError(
            f"{file}: fourier.period", period, f"a period from {MIN_PERIOD:g} to {MAX_PERIOD:g} s"
        )
    a = parse_numbers(file, "fourier.a", table["a"], f"{robot.nv} rows of N sine coefficients [rad/s]")
    if a.ndim != 2 or a.shape[0] != robot.nv or not 1 <= a.shape[1] <= MAX_HARMONICS:
        raise InvalidParameterError(
            f"{file}: fourier.a",
            f"shape {a.shape}",
            f"{robot.nv} rows (one per joint of {robot.name}) of 1 to {MAX_HARMONICS} coefficients [rad/s]",
        )
    b = parse_numbers(file, "fourier.b", table["b"], f"{robot.nv} rows of N cosine coefficients [rad/s]")
    if b.shape != a.shape:
        raise InvalidParameterError(f"{file}: fourier.b", f"shape {b.shape}", f"shape {a.shape} like a")
    offset = parse_numbers(
        file, "fourier.offset", table["offset"], f"{robot.nv} mean positions [rad]", MAX_ANGLE, "rad"
    )
    if offset.shape != (robot.nv,):
        raise InvalidParameterError(
            f"{file}: fourier.offset", table["offset"], f"{robot.nv} mean joint positions [rad]"
        )
    harmonics = table.get("harmonics", a.shape[1])
    if isinstance(harmonics, bool) or harmonics != a.shape[1]:
        raise InvalidParameterError(
            f"{file}: fourier.harmonics",
            harmonics,
            f"the number of coefficients per row of a and b ({a.shape[1]})",
        )
    trajectory = FourierTrajectory(float(period), a, b, offset)
    t = check_grid(0.0, trajectory.period)
    q = trajectory.sample(t).q
    limits = joint_limits(robot)
    lower, upper = limits.position_lower, limits.position_upper
    over = limits.excess(POSITION, q) > 0
    if over.any():
        k, j = (int(i) for i in np.argwhere(over)[0])
        raise InvalidParameterError(
            f"{file}: fourier",
            f"q{j + 1}({t[k]:.4g} s) = {q[k, j]:.6g} rad",
            f"a motion within joint {j + 1}'s limits [{lower[j]:g}, {upper[j]:g}] rad over the period "
            "(smaller coefficients, or an offset further from the limit)",
        )
    return trajectory


def write_trajectory_file(
    path: str | os.PathLike[str],
    trajectory: JointTrajectory | FourierTrajectory | PoseTrajectory | SampledTrajectory,
) -> Path:
    """Write ``trajectory`` as a trajectory file (atomically): its joint via points, an SE(3)
    reference's via poses (positions, rpy, and its first configuration as the seed), a
    Fourier trajectory's ``fourier`` table, or a sampled one's ``samples`` table
    (:mod:`~twolink_pin.trajectory.samples_file`); TOML if ``path`` ends in ``.toml``, else JSON."""
    from twolink_pin.files import atomic_write, write_json

    if isinstance(trajectory, SampledTrajectory):
        from twolink_pin.trajectory.samples_file import write_samples

        return write_samples(path, trajectory)

    toml = Path(os.fspath(path)).suffix.lower() == ".toml"
    if isinstance(trajectory, PoseTrajectory):
        poses = {
            "times": trajectory.times.tolist(),
            "positions": trajectory.positions.tolist(),
            "rpy": [pin.rpy.matrixToRpy(R).tolist() for R in trajectory.rotations],
            "period": trajectory.period,
            "seed": trajectory.via_q[0].tolist(),
        }
        if not toml:
            return write_json(path, poses)
        with atomic_write(path) as f:
            f.write("# via poses: times [s], positions [m], rpy [rad], period [s], seed [rad]\n")
            for key, value in poses.items():
                f.write(f"{key} = {json.dumps(value)}\n")
        return Path(os.fspath(path))
    if isinstance(trajectory, FourierTrajectory):
        table = trajectory.as_dict()
        if not toml:
            return write_json(path, {"fourier": table})
        with atomic_write(path) as f:
            f.write("# a periodic finite Fourier series: a, b [rad/s], offset [rad], period [s]\n")
            f.write("[fourier]\n")
            for key, value in table.items():
                f.write(f"{key} = {json.dumps(value)}\n")
        return Path(os.fspath(path))
    if toml:
        with atomic_write(path) as f:
            f.write("# joint via points: times [s], joints [rad], period [s]\n")
            f.write(f"times = {json.dumps(trajectory.times.tolist())}\n")
            f.write(f"joints = {json.dumps(trajectory.via_q.tolist())}\n")
            f.write(f"period = {json.dumps(trajectory.period)}\n")
        return Path(os.fspath(path))
    return write_json(
        path,
        {
            "times": trajectory.times.tolist(),
            "joints": trajectory.via_q.tolist(),
            "period": trajectory.period,
        },
    )
