"""ROS bags as identification logs: bags written by rosbags' own writers (ROS 2 SQLite and MCAP,
ROS 1), from a simulated run with stamp jitter, shuffled joint order, dropped messages and
arrival out of order, give the estimates of the equivalent NPZ log.

What makes the comparison honest: both logs sample **one continuous motion** — the arm on its
excitation, with the torque inverse dynamics plus friction give at any instant (what the
noise-free closed loop of :func:`simulate_log` produces, exactly). The NPZ holds it on the exact
uniform grid; the bag holds it at jittered acquisition times (``header.stamp`` = grid time +
up to ±5 % of a step; the bag's receive time later still, by a random transport delay, so the
messages are stored out of stamp order), in a different joint order per message, with ~1 %
of the messages and a burst of 6 dropped. Nothing of the NPZ's grid is given to the reader:
it recovers the grid from the stamps and interpolates (cubic spline for q, linear for τ), so
the estimates agree only as far as the resampling rule is accurate.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.errors import InputFileError, InvalidParameterError
from twolink_pin.identification import IdentificationOptions, RunLog, identify, read_log, write_log
from twolink_pin.identification.bags import read_bag
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.identification.simulated import plant_friction
from twolink_pin.trajectory import read_trajectory_file
from twolink_pin.twolink import excitation as twolink_excitation

FIXTURES = Path(__file__).parent / "fixtures"
JITTER = 0.05
"""Stamp jitter, as a fraction of the step (uniform in ±)."""


def motion(robot, trajectory, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q̇ and τ = RNEA(q, q̇, q̈) + friction(q̇) of the arm exactly on ``trajectory`` at times ``t``."""
    s = trajectory.sample(t)
    data = robot.model.createData()
    friction = plant_friction(robot)
    tau = np.array([pin.rnea(robot.model, data, q, v, a) for q, v, a in zip(s.q, s.v, s.a)])
    return s.q, s.v, tau + friction.torque(s.v)


def true_parameters(robot) -> np.ndarray:
    return ParameterSet.of(robot).true_values(robot.model, plant_friction(robot))


def grid_log(robot, trajectory, duration: float, dt: float) -> RunLog:
    t = dt * np.arange(round(duration / dt) + 1)
    q, v, tau = motion(robot, trajectory, t)
    return RunLog(t=t, q=q, tau=tau, v=v, source="grid", true_parameters=true_parameters(robot))


def joint_names(robot) -> list[str]:
    return [str(n) for n in robot.model.names[1:]]


def write_ros1_without_velocities(path: Path, log: RunLog, skip: range = range(0)) -> Path:
    """A ROS 1 bag of ``log``'s joints ``joint1``, ``joint2`` whose messages log positions and
    efforts but no velocities (an empty field), written by rosbags' writer; the samples in
    ``skip`` are left out."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    JointState, Header, Time = (
        store.types[n]
        for n in ("sensor_msgs/msg/JointState", "std_msgs/msg/Header", "builtin_interfaces/msg/Time")
    )
    with Writer(path) as w:
        c = w.add_connection("/joint_states", JointState.__msgtype__, typestore=store)
        for k, t in enumerate(log.t):
            if k in skip:
                continue
            ns = 10**9 + round(t * 1e9)
            msg = JointState(
                header=Header(seq=k, stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                name=["joint1", "joint2"],
                position=log.q[k],
                velocity=np.zeros(0),
                effort=log.tau[k],
            )
            w.write(c, ns, store.serialize_ros1(msg, JointState.__msgtype__))
    return path


def write_bag(
    path: Path,
    robot,
    trajectory,
    duration: float,
    dt: float,
    kind: str,
    seed: int = 0,
    extra_joint: bool = True,
    torque_topic: str | None = None,
) -> Path:
    """A joint-state bag of the motion (module docstring) written by rosbags' writer of ``kind``
    (``"sqlite3"``, ``"mcap"`` or ``"ros1"``)."""
    rng = np.random.default_rng(seed)
    grid = dt * np.arange(round(duration / dt) + 1)
    keep = rng.random(grid.size) > 0.01
    keep[grid.size // 3 : grid.size // 3 + 6] = False  # a burst of 6
    keep[[0, -1]] = True
    t = grid[keep] + rng.uniform(-JITTER, JITTER, keep.sum()) * dt
    t[0], t[-1] = grid[0], grid[-1]
    q, v, tau = motion(robot, trajectory, t)
    names = joint_names(robot) + (["gripper_finger"] if extra_joint else [])
    start_ns = 1_700_000_000 * 10**9
    stamps = start_ns + np.round(t * 1e9).astype(np.int64)
    received = stamps + rng.integers(100_000, 3_000_000, stamps.size)  # 0.1–3 ms transport delay
    order = np.argsort(received, kind="stable")
    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1
        from rosbags.typesys import Stores, get_typestore

        store = get_typestore(Stores.ROS1_NOETIC)
        writer: object = Writer1(path)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore

        store = get_typestore(Stores.ROS2_HUMBLE)
        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        writer = Writer(path, version=8, storage_plugin=plugin)
    JointState = store.types["sensor_msgs/msg/JointState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    serialize = store.serialize_ros1 if kind == "ros1" else store.serialize_cdr
    with writer as w:  # type: ignore[attr-defined]
        connection = w.add_connection("/joint_states", JointState.__msgtype__, typestore=store)
        if torque_topic:
            command = w.add_connection(torque_topic, "std_msgs/msg/Float64MultiArray", typestore=store)
            Multi = store.types["std_msgs/msg/Float64MultiArray"]
            Layout = store.types["std_msgs/msg/MultiArrayLayout"]
        for k in order:
            perm = rng.permutation(len(names))
            ordered = [names[i] for i in perm]
            position = np.append(q[k], 0.01)[perm]
            velocity = np.append(v[k], 0.0)[perm]
            effort = np.append(np.zeros(robot.nv) if torque_topic else tau[k], 0.0)[perm]
            if not extra_joint:
                keep_j = np.array([n != "gripper_finger" for n in ordered])
                ordered = [n for n in ordered if n != "gripper_finger"]
                position, velocity, effort = position[keep_j], velocity[keep_j], effort[keep_j]
            sec, nanosec = divmod(int(stamps[k]), 10**9)
            header = (
                Header(seq=int(k), stamp=Time(sec=sec, nanosec=nanosec), frame_id="")
                if kind == "ros1"
                else Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id="")
            )
            msg = JointState(header=header, name=ordered, position=position, velocity=velocity, effort=effort)
            w.write(connection, int(received[k]), serialize(msg, JointState.__msgtype__))
            if torque_topic:
                cmd = Multi(layout=Layout(dim=[], data_offset=0), data=np.asarray(tau[k], dtype=float))
                w.write(command, int(stamps[k]), serialize(cmd, Multi.__msgtype__))
    return path


def relative(a: np.ndarray, b: np.ndarray) -> float:
    """max |a − b| / |b|, absolute (in the parameter's unit) where |b| < 1e-9 (the twolink's
    link2.mcy is 0: its estimates are rounding, ~1e-11)."""
    return float(np.max(np.abs(a - b) / np.where(np.abs(b) > 1e-9, np.abs(b), 1.0)))


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


@pytest.fixture(scope="module")
def twolink_npz(twolink, tmp_path_factory) -> tuple[Path, np.ndarray]:
    log = grid_log(twolink, twolink_excitation.identification_excitation(), 30.0, 1e-3)
    path = write_log(tmp_path_factory.mktemp("npz") / "twolink.npz", log)
    result = identify(read_log(path, twolink.nv), twolink)
    return path, result.estimate


def test_the_equivalent_npz_recovers_the_truth(twolink, twolink_npz) -> None:
    """The yardstick itself: the grid log of the exact motion gives the true parameters to 1e-6."""
    _, estimate = twolink_npz
    truth = true_parameters(twolink)
    assert relative(estimate, truth) < 1e-6


@pytest.mark.parametrize("kind", ["sqlite3", "ros1"])
def test_twolink_bag_gives_the_npz_estimates(twolink, twolink_npz, tmp_path: Path, kind: str) -> None:
    """Jittered, shuffled, with drops and an extra joint: the same estimates as the NPZ to 1e-6
    (measured 1.5e-7). The SQLite bag is given by its .db3 file, not its folder."""
    name = {"sqlite3": "run", "ros1": "run.bag"}[kind]
    bag = write_bag(
        tmp_path / name, twolink, twolink_excitation.identification_excitation(), 30.0, 1e-3, kind
    )
    if kind == "sqlite3":
        bag = next(bag.glob("*.db3"))
    log, summary = read_bag(bag, joint_names(twolink))
    assert summary.stamps == "header.stamp"
    assert summary.ignored_joints == ("gripper_finger",)
    assert summary.period == pytest.approx(1e-3, rel=1e-3)
    assert summary.dropped >= 6 and any(length > 6e-3 for _, length in summary.gaps)
    estimate = identify(log, twolink).estimate
    assert relative(estimate, twolink_npz[1]) < 1e-6


def test_cli_reads_a_twolink_mcap_bag_with_commanded_torques(
    twolink, twolink_npz, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``identify --data BAG --torque-topic`` (MCAP, torques as ros2_control's Float64MultiArray
    commands, zero efforts in the joint states): the NPZ's estimates to 1e-6, and the summary
    says where the torques came from and what was dropped."""
    bag = write_bag(
        tmp_path / "run",
        twolink,
        twolink_excitation.identification_excitation(),
        30.0,
        1e-3,
        "mcap",
        seed=2,
        torque_topic="/effort_controller/commands",
    )
    assert (
        main(["identify", "--data", str(bag), "--torque-topic", "/effort_controller/commands", "--json"]) == 0
    )
    document = json.loads(capsys.readouterr().out)
    estimate = np.array([row["estimate"] for row in document["parameters"]])
    assert relative(estimate, twolink_npz[1]) < 1e-6
    assert main(["identify", "--data", str(bag), "--torque-topic", "/effort_controller/commands"]) == 0
    text = capsys.readouterr().out
    assert "torques: commanded, /effort_controller/commands" in text and "messages dropped" in text


def test_missing_joint_extra_joint_and_a_long_gap_are_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A model joint absent from the messages is named with what the bag has; a gap longer than
    10 steps is refused with where it is; both as one line on stderr, exit 2."""
    twolink = load_robot("twolink")
    bag = write_bag(
        tmp_path / "short", twolink, twolink_excitation.identification_excitation(), 0.3, 1e-3, "sqlite3"
    )
    with pytest.raises(
        InputFileError,
        match=r"no joints 'shoulder_pan_joint', .* of the model \(the messages name .*; not in the model: .*'gripper_finger'",
    ):
        read_bag(bag, joint_names(load_robot("ur5")))
    assert main(["identify", "--data", str(bag), "--robot", "ur5"]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        len(err.splitlines()) == 1
        and "shoulder_pan_joint" in err
        and "not in the model: " in err
        and "'gripper_finger'" in err
    )
    assert main(["identify", "--data", str(bag), "--topic", "/joint_state"]) == 2
    assert (
        "no topic '/joint_state'; its topics are /joint_states (sensor_msgs/msg/JointState)"
        in capsys.readouterr().err
    )
    gap = tmp_path / "gap.bag"
    rng_log = grid_log(twolink, twolink_excitation.identification_excitation(), 0.3, 1e-3)
    write_ros1_without_velocities(
        gap, rng_log, skip=range(100, 120)
    )  # 20 missing: a 21-ms gap after t = 0.099 s
    with pytest.raises(InputFileError, match=r"gap of 21 ms \(21.0 steps of 1 ms\) after t = 0.099 s"):
        read_bag(gap, ["joint1", "joint2"])


def test_a_bag_without_velocities_is_read_whatever_memory_held(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Velocities are optional: a bag whose messages log none is read, and what its unused
    velocity rows would have held is never checked (they were uninitialised memory: a NaN
    there refused a valid bag now and then). The rows are made NaN here to show it."""
    import twolink_pin.identification.bags as bags

    real = np.empty

    def poisoned(shape, dtype=float, *args, **kwargs):  # np.empty that returns NaN floats
        out = real(shape, dtype, *args, **kwargs)
        if np.dtype(dtype).kind == "f":
            out.fill(np.nan)
        return out

    twolink = load_robot("twolink")
    log = grid_log(twolink, twolink_excitation.identification_excitation(), 0.3, 1e-3)
    path = write_ros1_without_velocities(tmp_path / "no_velocity.bag", log)
    monkeypatch.setattr(bags.np, "empty", poisoned)
    read, _ = read_bag(path, ["joint1", "joint2"])
    np.testing.assert_allclose(read.q, log.q, atol=1e-9)


def test_ur5_mcap_bag_gives_the_npz_estimates(tmp_path: Path) -> None:
    """The UR5 (48 parameters) along its stored excitation at 2 kHz (the toolkit's log rate):
    bag and NPZ agree to 1e-6 (measured 6.7e-7; at 1 kHz the linear torque interpolation's
    (ωh)² error gives 3e-6 on wrist_1_link's smallest inertia combination)."""
    ur5 = load_robot("ur5")
    trajectory = read_trajectory_file(FIXTURES / "ur5_excitation.json", ur5)
    options = IdentificationOptions(validation=0.0)
    npz = write_log(tmp_path / "ur5.npz", grid_log(ur5, trajectory, 20.0, 5e-4))
    reference = identify(read_log(npz, ur5.nv), ur5, options).estimate
    assert relative(reference, true_parameters(ur5)) < 1e-6
    bag = write_bag(tmp_path / "ur5", ur5, trajectory, 20.0, 5e-4, "mcap", seed=1)
    log, _ = read_bag(bag, joint_names(ur5))
    assert relative(identify(log, ur5, options).estimate, reference) < 1e-6


def test_broken_bags_and_pipes_are_refused_before_reading(tmp_path: Path) -> None:
    """Bytes that are not a bag, a FIFO named like one (which would block the reader), a folder
    without metadata.yaml: each one error naming the path and what was expected."""
    import os

    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"not a bag at all")
    with pytest.raises(InputFileError, match=r"garbage.mcap: is not a readable ROS bag"):
        read_bag(garbage, ["joint1"])
    pipe = tmp_path / "pipe.bag"
    os.mkfifo(pipe)
    with pytest.raises(InputFileError, match=r"pipe.bag: is not a regular file .*expected a ROS bag"):
        read_bag(pipe, ["joint1"])
    with pytest.raises(InputFileError, match=r"folder without metadata.yaml"):
        read_bag(tmp_path, ["joint1"])


def test_reading_a_bag_takes_at_most_three_times_its_size(twolink, tmp_path: Path) -> None:
    """Messages are streamed into preallocated arrays: the peak of the memory Python and NumPy
    allocate while reading (tracemalloc: deterministic, not timed) stays under
    READ_MEMORY_FACTOR = 3 × the bag's size on disk (measured 1.7; the reader that kept every
    message as an object took 8.8 ×)."""
    import tracemalloc

    from twolink_pin.identification.bag_checks import READ_MEMORY_FACTOR

    bag = write_bag(
        tmp_path / "run", twolink, twolink_excitation.identification_excitation(), 10.0, 1e-3, "sqlite3"
    )
    disk = sum(p.stat().st_size for p in bag.glob("*.db3"))
    read_bag(bag, joint_names(twolink))  # imports and the type store, outside the measurement
    tracemalloc.start()
    try:
        log, _ = read_bag(bag, joint_names(twolink))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert log.samples > 9_000
    assert READ_MEMORY_FACTOR == 3.0
    assert peak < READ_MEMORY_FACTOR * disk, f"peak {peak / disk:.2f} × the bag's {disk} bytes"


def test_a_bag_too_large_for_the_memory_available_is_refused_by_its_size(
    twolink, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With TWOLINK_PIN_MEMORY below 3 × the bag's size the bag is refused before it is opened
    (a bag whose content is garbage is refused for its size, not its bytes); at 3 × it is read."""
    bag = write_bag(
        tmp_path / "run.bag", twolink, twolink_excitation.identification_excitation(), 0.3, 1e-3, "ros1"
    )
    disk = bag.stat().st_size
    monkeypatch.setenv("TWOLINK_PIN_MEMORY", str(3 * disk - 1))
    with pytest.raises(
        InputFileError, match=r"MiB on disk; reading it needs up to 3 × that .* MiB of memory are available"
    ):
        read_bag(bag, joint_names(twolink))
    garbage = tmp_path / "garbage.bag"
    garbage.write_bytes(b"x" * disk)
    with pytest.raises(InputFileError, match="MiB of memory are available"):
        read_bag(garbage, joint_names(twolink))
    monkeypatch.setenv("TWOLINK_PIN_MEMORY", str(3 * disk))
    assert read_bag(bag, joint_names(twolink))[0].samples > 250
    monkeypatch.setenv("TWOLINK_PIN_MEMORY", "lots")
    with pytest.raises(
        InvalidParameterError, match=r"TWOLINK_PIN_MEMORY.*'lots'.*positive whole number of bytes"
    ):
        read_bag(bag, joint_names(twolink))
