"""ROS bags and run logs with one defect each, written by rosbags' own writers (setup steps).

The motion is the same in every file: the twolink's two joints on slow sines (0.5 and 0.4 rad),
2000 samples at 1 kHz, torques ``2 q + 0.1 q̇`` N·m: a log that ``identify`` accepts when it has
no defect. A defect changes one thing: a non-finite position, velocity, effort or command at
one message, a joint named twice in one message, a stamp that repeats, runs backwards or jumps,
a broken ``metadata.yaml``.
"""

from __future__ import annotations

import functools
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

SAMPLES = 2000
STEP = 1e-3
"""Samples and their step [s]."""
START_NS = 1_000_000_000_000_000_000
"""The first stamp [ns since the epoch]."""


def _motion() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    t = STEP * np.arange(SAMPLES)
    q = np.column_stack([0.5 * np.sin(2 * np.pi * 0.5 * t), 0.4 * np.sin(2 * np.pi * 0.7 * t)])
    v = np.column_stack(
        [0.5 * np.pi * np.cos(2 * np.pi * 0.5 * t), 0.56 * np.pi * np.cos(2 * np.pi * 0.7 * t)]
    )
    return t, q, v, 2 * q + 0.1 * v


@functools.cache
def _bag(defect: str, kind: str) -> dict[str, bytes]:
    """The files of a bag of ``kind`` (``ros1``: one ``.bag``; ``sqlite3``: a ROS 2 folder) with
    ``defect``, by name."""
    t, q, v, tau = _motion()
    names = [["joint1", "joint2"]] * SAMPLES
    stamps = START_NS + np.round(t * 1e9).astype(np.int64)
    received = START_NS + np.arange(SAMPLES, dtype=np.int64) * 1_000_000 + 500_000
    command_nan = defect == "nan-command"
    if defect == "nan-position":
        q[500, 1] = np.nan
    elif defect == "inf-effort":
        tau[700, 0] = np.inf
    elif defect == "nan-velocity":
        v[800, 0] = -np.nan
    elif defect == "joint-twice":
        names = (
            [["joint1", "joint2"]] * 300 + [["joint1", "joint2", "joint1"]] + [["joint1", "joint2"]] * 1699
        )
    elif defect == "time-repeats":
        stamps[1000:] -= 1_000_000  # message 1000 repeats message 999's stamp
    elif defect == "time-backwards":
        stamps[1000:] -= 50_000_000  # 50 steps back: the clock was reset
    elif defect == "time-backwards-received":
        stamps[1000:] -= 49_500_000  # stored in stamp order: read as interleaved half-steps
        received = stamps.copy()
    elif defect == "time-near-repeat":
        stamps[1000:] -= 1_600_000  # 1.6 steps back: two stamps 0.4 step apart
    elif defect == "time-jumps":
        stamps[1000:] += 3600 * 10**9  # an hour forwards
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / ("run.bag" if kind == "ros1" else "run")
        _write(out, kind, names, stamps, received, q, v, tau, command_nan)
        files = [out] if kind == "ros1" else sorted(out.iterdir())
        return {f.name: f.read_bytes() for f in files}


def _write(
    out: Path,
    kind: str,
    names: list[list[str]],
    stamps: np.ndarray,
    received: np.ndarray,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    command_nan: bool,
) -> None:
    from rosbags.typesys import Stores, get_typestore

    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        store = get_typestore(Stores.ROS1_NOETIC)
        writer: object = Writer1(out)
        serialize = store.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        store = get_typestore(Stores.ROS2_HUMBLE)
        writer = Writer(out, version=8, storage_plugin=StoragePlugin.SQLITE3)
        serialize = store.serialize_cdr
    JointState, Header, Time = (
        store.types[n]
        for n in ("sensor_msgs/msg/JointState", "std_msgs/msg/Header", "builtin_interfaces/msg/Time")
    )
    Multi, Layout = (
        store.types["std_msgs/msg/Float64MultiArray"],
        store.types["std_msgs/msg/MultiArrayLayout"],
    )
    with writer as w:  # type: ignore[attr-defined]
        states = w.add_connection("/joint_states", JointState.__msgtype__, typestore=store)
        commands = w.add_connection("/commands", Multi.__msgtype__, typestore=store)
        for k in range(len(names)):
            sec, nanosec = divmod(int(stamps[k]), 10**9)
            stamp = Time(sec=sec, nanosec=nanosec)
            header = (
                Header(seq=k, stamp=stamp, frame_id="")
                if kind == "ros1"
                else Header(stamp=stamp, frame_id="")
            )
            width = len(names[k])
            msg = JointState(
                header=header,
                name=names[k],
                position=np.resize(q[k], width),
                velocity=np.resize(v[k], width),
                effort=np.resize(tau[k], width),
            )
            w.write(states, int(received[k]), serialize(msg, JointState.__msgtype__))
            command = tau[k].copy()
            if command_nan and k == 900:
                command[1] = np.nan
            cmd = Multi(layout=Layout(dim=[], data_offset=0), data=command)
            w.write(commands, int(received[k]), serialize(cmd, Multi.__msgtype__))


def bag_file(defect: str, name: str = "run.bag", kind: str = "ros1") -> Callable[[Path], bytes]:
    """A setup ``blob``: the file ``name`` of the bag with ``defect`` (``"none"``: a valid one)."""
    return lambda _: _bag(defect, kind)[name]


def ros2_bag(defect: str, folder: str = "run") -> tuple[tuple[str, Callable[[Path], bytes]], ...]:
    """``(path, content)`` of every file of a ROS 2 (SQLite) bag folder with ``defect``."""
    return tuple((f"{folder}/{name}", bag_file(defect, name, "sqlite3")) for name in _bag(defect, "sqlite3"))


def log_file(defect: str, suffix: str) -> Callable[[Path], bytes]:
    """A run log (``.npz`` or ``.csv``) of the motion with ``defect`` (``time-jumps``: an hour
    after sample 1000; ``time-gap``: 20 ms after it)."""

    def make(_: Path) -> bytes:
        import io

        t, q, v, tau = _motion()
        if defect == "time-jumps":
            t[1000:] += 3600.0
        elif defect == "time-gap":
            t[1000:] += 0.02
        if suffix == ".npz":
            buffer = io.BytesIO()
            np.savez(buffer, t=t, q=q, tau=tau, v=v)
            return buffer.getvalue()
        rows = np.column_stack([t, q, tau])
        text = "t,q1,q2,tau1,tau2\n" + "\n".join(",".join(f"{x:.17g}" for x in row) for row in rows)
        return (text + "\n").encode()

    return make
