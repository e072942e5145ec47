"""Run logs from ROS bags: ``sensor_msgs/JointState`` (and commanded torques) onto one grid.

A real arm's data come as ROS 2 bags (a bag folder with ``metadata.yaml``, or its ``.db3``
(SQLite) or ``.mcap`` file) or ROS 1 bags (``.bag``), read here with `rosbags
<https://gitlab.com/ternaris/rosbags>`_ (pure Python: no ROS install). What is read:

* **joint states** on ``topic`` (default :data:`DEFAULT_TOPIC`), ``sensor_msgs/JointState``:
  ``name``, ``position`` [rad], ``velocity`` [rad/s] (optional, a check only), ``effort``
  [N·m]. Joints are matched to the model **by name**, in each message (the order may differ
  from message to message); a joint of the model missing from the messages is refused, naming
  it and the joints the bag has; joints the model does not have (a gripper's fingers) are
  ignored and listed.
* **torques**: the joint states' ``effort`` (measured), or with ``torque_topic`` the commanded
  torques, either ``sensor_msgs/JointState`` (``effort``, matched by name) or
  ``std_msgs/Float64MultiArray`` (ros2_control's effort command: no names, taken in the
  model's joint order, no stamp: the bag's receive time).

**Resampling rule** (the identification filter needs one uniform grid):

1. each message's time is its ``header.stamp`` — the acquisition time the driver stamped —
   or, when that is zero, the time the bag recorded it (receive time: it includes transport
   delay, so the stamp is preferred); messages are sorted by that time (a bag stores them in
   arrival order: out of order by a few steps); time that repeats (two stamps at most half a
   step apart), runs backwards (a stamp :data:`MAX_GAP_STEPS` steps before one already read:
   a clock reset) or jumps (below) is refused, naming the messages and the time, as is a
   value that is not finite (the message, field and joint) or a joint named twice in one
   message;
2. the grid ``t_0 + k T`` is the stamps' own: each stamp gets its sample index (a step of
   ``n`` median steps counts ``n``: dropped messages keep their place) and ``t_0``, ``T`` are
   fitted to the stamps by least squares (zero-mean jitter averages out; the median step
   alone is biased by the drops), from the first stamp to the last; time is counted from
   the first stamp (an epoch time in seconds would lose 0.2 µs to rounding);
3. positions are interpolated onto the grid by a **cubic spline** through the stamped
   samples (error ``~ T⁴ q⁽⁴⁾/384``: 1e-11 of a 0.5-Hz motion at 2 kHz); torques
   **linearly** between the two stamps around the grid time (a torque jumps at a velocity
   reversal — Coulomb friction — and a spline would ring there), except where that joint's
   velocity (the spline's derivative) changes sign between them: then linearly from the two
   stamps on the grid time's side of the reversal, so the jump stays where it happened
   instead of being blended into one sample (the identification's Coulomb column jumps
   there too; blending cost 4e-5 of a Coulomb coefficient in the tests); logged velocities
   linearly (a check only); the commanded torques of another topic linearly at their own
   times (a command is held, not jumped, between updates);
4. a step longer than 1.5 ``T`` counts ``round(step / T) − 1`` **dropped messages** and is a
   **gap**; gaps are interpolated across up to :data:`MAX_GAP_STEPS` ``T`` and reported (time
   and length); a longer gap is refused, naming where it is (interpolating 10 steps of a
   2-kHz log spans 5 ms, under a tenth of the 20-Hz filter's period).

**Memory**: messages are streamed into arrays preallocated for the count the bag declares
(believed up to its size on disk), never kept as message objects: reading takes at most
:data:`~twolink_pin.identification.bag_checks.READ_MEMORY_FACTOR` × the bag's size on disk, and a bag larger than the memory
available (:func:`~twolink_pin.memory.available_memory`) divided by that is refused by its
size before it is opened.

:class:`BagSummary` says all of it, and :func:`read_bag` returns it with the
:class:`~twolink_pin.identification.data.RunLog`.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InputFileError
from twolink_pin.identification.bag_checks import (
    BAG_SUFFIXES,
    check_finite,
    check_time,
    one_line,
    size_checked,
)
from twolink_pin.identification.data import MAX_GAP_STEPS, MIN_SAMPLES, RunLog

DEFAULT_TOPIC = "/joint_states"
"""Topic of the joint states when none is given."""
GAP_STEPS = 1.5
"""A step between stamps longer than this many grid steps is a gap (messages dropped)."""
MIN_MESSAGE_BYTES = 16
"""Fewest bytes a stored message takes on disk: a bag's claimed message count is believed up
to its size on disk divided by this."""
JOINT_STATE = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")
MULTI_ARRAY = ("std_msgs/msg/Float64MultiArray", "std_msgs/Float64MultiArray")


@dataclass(frozen=True)
class BagSummary:
    """What was read from a bag and how it was put on one grid (see the module docstring)."""

    path: str
    """The bag."""
    storage: str
    """``"ROS 2 SQLite"``, ``"ROS 2 MCAP"`` or ``"ROS 1"``."""
    topic: str
    """The joint-state topic."""
    torque: str
    """Where the torques came from: ``"effort of /joint_states"`` or the torque topic."""
    messages: int
    """Joint-state messages read."""
    stamps: str
    """``"header.stamp"`` or ``"bag receive time"``."""
    period: float
    """Grid step ``T`` [s] (the median step between stamps)."""
    samples: int
    """Samples on the grid."""
    dropped: int
    """Messages missing from the stamps' sequence (``Σ round(step/T) − 1`` over gaps)."""
    gaps: tuple[tuple[float, float], ...]
    """(start [s from the first stamp], length [s]) of every step longer than 1.5 T."""
    jitter: float
    """Largest deviation of a stamp from the grid [s]."""
    ignored_joints: tuple[str, ...]
    """Joints in the messages that the model does not have."""
    start_ns: int = 0
    """The first stamp [ns since the epoch]: the log's t = 0."""

    def lines(self) -> list[str]:
        """The summary as text, for the command line."""
        out = [
            f"bag {self.path} ({self.storage}): {self.messages} messages on {self.topic}, time from {self.stamps}; "
            f"torques: {self.torque}",
            f"  resampled onto a {1 / self.period:.6g}-Hz grid (median step {self.period * 1e3:.6g} ms, {self.samples} samples; "
            f"largest stamp jitter {self.jitter * 1e3:.3g} ms): positions by cubic spline, torques linearly",
        ]
        if self.dropped or self.gaps:
            longest = max(self.gaps, key=lambda g: g[1])
            out.append(
                f"  {self.dropped} messages dropped in {len(self.gaps)} gaps (interpolated across); longest "
                f"{longest[1] * 1e3:.3g} ms at t = {longest[0]:.6g} s"
            )
        if self.ignored_joints:
            out.append(f"  joints not in the model, ignored: {', '.join(self.ignored_joints)}")
        return out


def is_bag(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is read as a bag: a ``.db3``/``.mcap``/``.bag`` file or a folder."""
    file = Path(os.fspath(path))
    return file.suffix.lower() in BAG_SUFFIXES or file.is_dir()


def _bag_root(file: Path) -> tuple[Path, str]:
    """The path ``AnyReader`` opens and the storage's name."""
    if not file.exists():
        raise InputFileError(str(file), "does not exist (expected a ROS bag: a folder, .db3, .mcap or .bag)")
    if file.is_dir():
        if not (file / "metadata.yaml").is_file():
            raise InputFileError(str(file), "is a folder without metadata.yaml: not a ROS 2 bag")
        suffixes = {p.suffix.lower() for p in file.iterdir()}
        return file, "ROS 2 MCAP" if ".mcap" in suffixes else "ROS 2 SQLite"
    suffix = file.suffix.lower()
    if suffix == ".bag":
        return file, "ROS 1"
    storage = "ROS 2 MCAP" if suffix == ".mcap" else "ROS 2 SQLite"
    if (file.parent / "metadata.yaml").is_file():
        return file.parent, storage
    return file, storage


def _open(root: Path) -> Any:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    return AnyReader([root], default_typestore=get_typestore(Stores.ROS2_HUMBLE))


def _stamp(msg: Any) -> int:
    header = getattr(msg, "header", None)
    if header is None:
        return 0
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _connections(reader: Any, path: str, topic: str, types: tuple[str, ...]) -> list[Any]:
    """The connections of ``topic``, which must carry one of ``types``."""
    connections = [c for c in reader.connections if c.topic == topic]
    if not connections:
        topics = sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})
        raise InputFileError(path, f"has no topic {topic!r}; its topics are {', '.join(topics) or 'none'}")
    wrong = [c.msgtype for c in connections if c.msgtype not in types]
    if wrong:
        raise InputFileError(path, f"topic {topic!r} carries {wrong[0]}; expected {' or '.join(types[::2])}")
    return connections


class _Table:
    """A topic's messages as arrays, in the order read: times [ns] and one (rows, n) float64
    array per field, preallocated for the count the bag declares (bounded by its size on disk:
    a count is the bag's claim) and doubled if more come."""

    def __init__(self, capacity: int, width: int, fields: tuple[str, ...]) -> None:
        self.size = 0
        self.stamp = np.empty(capacity, dtype=np.int64)
        self.received = np.empty(capacity, dtype=np.int64)
        self.values = {name: np.empty((capacity, width)) for name in fields}

    def add(self, stamp: int, received: int) -> int:
        """A new row (its index), with its two times."""
        if self.size == self.stamp.size:
            grow = max(16, self.size)
            self.stamp = np.concatenate([self.stamp, np.empty(grow, dtype=np.int64)])
            self.received = np.concatenate([self.received, np.empty(grow, dtype=np.int64)])
            self.values = {
                k: np.concatenate([v, np.empty((grow, v.shape[1]))]) for k, v in self.values.items()
            }
        self.stamp[self.size], self.received[self.size] = stamp, received
        self.size += 1
        return self.size - 1

    def trimmed(self) -> _Table:
        """The table with its unused rows dropped (views, no copy)."""
        self.stamp, self.received = self.stamp[: self.size], self.received[: self.size]
        self.values = {k: v[: self.size] for k, v in self.values.items()}
        return self


def _capacity(connections: list[Any], disk_bytes: int) -> int:
    claimed = sum(int(getattr(c, "msgcount", 0) or 0) for c in connections)
    return max(16, min(claimed, disk_bytes // MIN_MESSAGE_BYTES + 1))


def _read_states(
    reader: Any, path: str, topic: str, names: list[str], efforts: bool, disk_bytes: int
) -> tuple[_Table, bool, tuple[str, ...]]:
    """The joint states on ``topic`` streamed into a :class:`_Table` (``position``,
    ``velocity`` and, with ``efforts``, ``effort`` of the model's joints), whether every
    message logs velocities, and the joints not in the model."""
    connections = _connections(reader, path, topic, JOINT_STATE)
    fields = ("position", "velocity", "effort") if efforts else ("position", "velocity")
    table = _Table(_capacity(connections, disk_bytes), len(names), fields)
    has_v = True
    ignored: dict[str, None] = {}
    cache: dict[tuple[str, ...], tuple[np.ndarray, tuple[str, ...]]] = {}
    for k, (connection, received, raw) in enumerate(reader.messages(connections=connections)):
        msg = reader.deserialize(raw, connection.msgtype)
        row = table.add(_stamp(msg), int(received))
        key = tuple(msg.name)
        if key not in cache:
            cache[key] = _columns(path, topic, names, list(key), k)
            ignored |= dict.fromkeys(cache[key][1])
        index = cache[key][0]
        table.values["position"][row] = _field(path, topic, msg, "position", index, len(key), k)
        if has_v and len(msg.velocity) == len(key):
            table.values["velocity"][row] = np.asarray(msg.velocity, dtype=float)[index]
        else:
            has_v = False
        if efforts:
            table.values["effort"][row] = _field(path, topic, msg, "effort", index, len(key), k)
    if not has_v:  # velocities are optional (a check only): a bag that lacks them in any message
        del table.values["velocity"]  # has none — its rows were never written, not checked either
    return table.trimmed(), has_v, tuple(ignored)


def _read_commands(reader: Any, path: str, topic: str, names: list[str], disk_bytes: int) -> _Table:
    """The commanded torques on ``topic`` streamed into a :class:`_Table` (field ``effort``):
    ``sensor_msgs/JointState`` matched by name, or ``std_msgs/Float64MultiArray`` in the
    model's joint order."""
    connections = _connections(reader, path, topic, JOINT_STATE + MULTI_ARRAY)
    table = _Table(_capacity(connections, disk_bytes), len(names), ("effort",))
    for k, (connection, received, raw) in enumerate(reader.messages(connections=connections)):
        msg = reader.deserialize(raw, connection.msgtype)
        row = table.add(_stamp(msg), int(received))
        if hasattr(msg, "name"):
            index, _ = _columns(path, topic, names, list(msg.name), k)
            table.values["effort"][row] = _field(path, topic, msg, "effort", index, len(msg.name), k)
        else:
            data = np.asarray(msg.data, dtype=float)
            if data.size != len(names):
                raise InputFileError(
                    path,
                    f"{topic} message {k}: {data.size} values; expected {len(names)} (the model's joints in order)",
                )
            table.values["effort"][row] = data
    return table.trimmed()


def _columns(
    path: str, topic: str, names: list[str], message_names: list[str], k: int
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Index of each model joint in a message's ``name`` list, and the message's other joints."""
    twice = [n for n, count in Counter(message_names).items() if count > 1]
    if twice:
        raise InputFileError(
            path,
            f"{topic} message {k}: joint {twice[0]!r} is named twice in one message "
            f"(the message names {', '.join(repr(n) for n in message_names)}); expected each joint once",
        )
    where = {n: i for i, n in enumerate(message_names)}
    missing = [n for n in names if n not in where]
    if missing:
        extra = [n for n in message_names if n not in set(names)]
        raise InputFileError(
            path,
            f"{topic} message {k}: no joint{'s' if len(missing) > 1 else ''} {', '.join(repr(m) for m in missing)} "
            f"of the model (the messages name {', '.join(repr(n) for n in message_names) or 'no joints'}"
            + (f"; not in the model: {', '.join(repr(n) for n in extra)}" if extra else "")
            + ")",
        )
    return np.array([where[n] for n in names]), tuple(n for n in message_names if n not in set(names))


def _field(path: str, topic: str, msg: Any, name: str, index: np.ndarray, size: int, k: int) -> np.ndarray:
    values = np.asarray(getattr(msg, name), dtype=float)
    if values.size != size:
        raise InputFileError(
            path,
            f"{topic} message {k}: {values.size} {name} values for {size} names"
            + (
                " (the bag logs no efforts: give the torques with --torque-topic)" if name == "effort" else ""
            ),
        )
    return values[index]


def _grid(
    path: str, topic: str, t: np.ndarray, messages: np.ndarray
) -> tuple[np.ndarray, float, int, tuple[tuple[float, float], ...]]:
    """The uniform grid of stamped times ``t`` [s] (sorted, distinct; ``messages[i]`` is the
    index of the message at ``t[i]``): grid, step, dropped, gaps."""
    steps = np.diff(t)
    period = float(np.median(steps))
    index = np.concatenate([[0], np.cumsum(np.maximum(np.round(steps / period), 1))])
    period, origin = np.polyfit(index, t, 1)  # the stamps' own grid: t_k ≈ origin + period × index_k
    long = np.flatnonzero(steps > GAP_STEPS * period)
    gaps = tuple((float(t[i] - t[0]), float(steps[i])) for i in long)
    dropped = int(sum(round(steps[i] / period) - 1 for i in long))
    too_long = np.flatnonzero(steps > MAX_GAP_STEPS * period)
    if too_long.size:
        i = int(too_long[0])
        raise InputFileError(
            path,
            f"{topic} messages {int(messages[i])} and {int(messages[i + 1])}: time jumps: a gap of "
            f"{steps[i] * 1e3:.6g} ms ({steps[i] / period:.1f} steps of {period * 1e3:.6g} ms) after "
            f"t = {t[i] - t[0]:.6g} s: more than {MAX_GAP_STEPS:g} steps cannot be interpolated honestly "
            "(cut the bag into the parts without such gaps)",
        )
    first = math.ceil((t[0] - origin) / period - 1e-9)
    last = math.floor((t[-1] - origin) / period + 1e-9)
    return origin + period * np.arange(first, last + 1), float(period), dropped, gaps


def _interpolate(t: np.ndarray, x: np.ndarray, grid: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(grid, t, x[:, j]) for j in range(x.shape[1])])


def _torques_on_grid(
    t: np.ndarray, tau: np.ndarray, grid: np.ndarray, v_stamps: np.ndarray, v_grid: np.ndarray
) -> np.ndarray:
    """Torques at the grid times: linear between the two stamps around each grid time, except
    where a joint's velocity changes sign between them (its Coulomb friction jumps there): then
    linear from the two stamps on the grid time's side of the reversal (extrapolated by less
    than a step), so that the jump stays at the reversal instead of being blended into a sample."""
    last = t.size - 2
    a = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, last)
    out = np.empty((grid.size, tau.shape[1]))
    for j in range(tau.shape[1]):
        lo, hi = a.copy(), a + 1
        sign = np.sign(v_stamps[:, j])
        flip = sign[lo] != sign[hi]
        before = flip & (np.sign(v_grid[:, j]) == sign[lo]) & (lo >= 1)
        after = flip & ~before & (hi <= last)
        lo[before], hi[before] = lo[before] - 1, lo[before]
        lo[after], hi[after] = hi[after], hi[after] + 1
        slope = (tau[hi, j] - tau[lo, j]) / (t[hi] - t[lo])
        out[:, j] = tau[lo, j] + slope * (grid - t[lo])
    return out


def _read(
    root: Path, file: Path, topic: str, names: list[str], torque_topic: str | None
) -> tuple[_Table, bool, tuple[str, ...], _Table | None]:
    """The joint states (and commanded torques) of the bag, streamed into arrays."""
    where = str(file)
    disk = size_checked(root, file)
    try:
        reader = _open(root)
        reader.open()
        try:
            states, has_v, ignored = _read_states(reader, where, topic, names, torque_topic is None, disk)
            commands = _read_commands(reader, where, torque_topic, names, disk) if torque_topic else None
        finally:
            reader.close()
    except InputFileError:
        raise
    except Exception as exc:  # rosbags raises its own errors (and sqlite3's, struct's) for broken bags
        raise InputFileError(where, f"is not a readable ROS bag ({one_line(exc)})") from None
    return states, has_v, ignored, commands


def read_bag(
    path: str | os.PathLike[str],
    joint_names: list[str] | tuple[str, ...],
    topic: str = DEFAULT_TOPIC,
    torque_topic: str | None = None,
) -> tuple[RunLog, BagSummary]:
    """A run log of the joints ``joint_names`` (the model's order) from a ROS bag (module
    docstring), and what was done to it.

    Raises:
        InputFileError: not a readable bag, too large for the memory available, no such topic
            or the wrong message type, a model joint missing from the messages or named twice
            (the message), a value that is not finite (the message, its time, the field and the
            joint), time that repeats or runs backwards (the messages), no efforts and no
            torque topic, too few messages, or a gap too long to interpolate across (where it is).
    """
    from scipy.interpolate import CubicSpline

    file = Path(os.fspath(path))
    root, storage = _bag_root(file)
    where = str(file)
    names = list(joint_names)
    states, has_v, ignored, commands = _read(root, file, topic, names, torque_topic)
    if states.size < MIN_SAMPLES:
        raise InputFileError(
            where, f"has {states.size} messages on {topic}; identification needs at least {MIN_SAMPLES}"
        )
    use_stamp = bool(np.all(states.stamp != 0))
    times = states.stamp if use_stamp else states.received
    what = "stamp" if use_stamp else "receive time"
    check_finite(where, topic, states.values, times, names)
    order = check_time(where, topic, times, what)
    t0 = int(times[order[0]])
    t = (times[order] - t0) * 1e-9
    grid, period, dropped, gaps = _grid(where, topic, t, order)
    q = states.values["position"][order]
    spline = CubicSpline(t, q, axis=0)
    del q
    if commands is None:
        tau = states.values["effort"][order]
    else:
        tau = _command_torques(where, torque_topic or "", commands, names, t0, t)
    tau_grid = _torques_on_grid(t, tau, grid, spline(t, 1), spline(grid, 1))
    del tau
    v_grid = _interpolate(t, states.values["velocity"][order], grid) if has_v else None
    log = RunLog(t=grid, q=spline(grid), tau=tau_grid, v=v_grid, source=f"{where} ({topic})")
    summary = BagSummary(
        path=where,
        storage=storage,
        topic=topic,
        torque=f"effort of {topic}" if torque_topic is None else f"commanded, {torque_topic}",
        messages=states.size,
        stamps="header.stamp" if use_stamp else "bag receive time",
        period=period,
        samples=int(grid.size),
        dropped=dropped,
        gaps=gaps,
        jitter=float(np.max(np.abs(t - grid[0] - period * np.round((t - grid[0]) / period)))),
        ignored_joints=tuple(ignored),
        start_ns=t0,
    )
    return log, summary


def _command_torques(
    where: str, topic: str, commands: _Table, names: list[str], t0: int, t: np.ndarray
) -> np.ndarray:
    """The commanded torques at the joint states' times ``t`` [s from ``t0`` ns], linearly
    (each command at its stamp, or the bag's receive time where it has none)."""
    if commands.size < 2:
        raise InputFileError(
            where, f"has {commands.size} messages on {topic}; expected commanded torques over the run"
        )
    times = np.where(commands.stamp != 0, commands.stamp, commands.received)
    check_finite(where, topic, commands.values, times, names)
    order = check_time(where, topic, times, "time")
    tc = (times[order] - t0) * 1e-9
    if tc[0] > t[0] + 1e-9 or tc[-1] < t[-1] - 1e-9:
        raise InputFileError(
            where,
            f"{topic} covers {tc[0]:.6g}–{tc[-1]:.6g} s of the joint states' 0–{t[-1]:.6g} s: the torques must span the run",
        )
    return _interpolate(tc, commands.values["effort"][order], t)
