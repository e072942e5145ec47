"""The SE(3) reference (trajectory/se3.py, via poses in trajectory files) and the task reference
the engine passes to task-space laws (simulation/task_reference.py).

Independent checks: the twist and acceleration against finite differences of the pose path
(``pin.log3`` of relative rotations), left and right limits at the via poses and across the
period, the via poses hit exactly, the joint path's forward kinematics (Pinocchio) against
the pose path, and what a law receives in a real simulation against the path itself.
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput, Terms, load_controller
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, law_input, simulate, terms_for
from twolink_pin.trajectory import default_trajectory, read_trajectory_file, write_trajectory_file
from twolink_pin.trajectory.se3 import PoseTrajectory

ROOT = Path(__file__).resolve().parents[1]
UR5 = load_robot("ur5")
SQUARE = read_trajectory_file(ROOT / "examples" / "ur5_square_pose.toml", UR5)
assert isinstance(SQUARE, PoseTrajectory)
# times off the via poses (the derivatives there are zero: no information)
TIMES = np.array([0.3, 0.9, 1.41, 2.6, 3.3, 4.77, 5.5, 6.2, 7.05, 7.9])


def test_the_path_passes_through_every_via_pose_exactly() -> None:
    pose = SQUARE.pose(SQUARE.times)
    np.testing.assert_allclose(pose.position, SQUARE.positions, rtol=0, atol=1e-15)
    for R, R_via in zip(pose.rotation, SQUARE.rotations, strict=True):
        assert np.linalg.norm(pin.log3(R.T @ R_via)) < 1e-12
    file_rpy = [[np.pi, 0.2, -np.pi / 2 + 0.3]]  # the third via pose of the file, by hand
    np.testing.assert_allclose(SQUARE.rotations[2], pin.rpy.rpyToMatrix(*file_rpy[0]), atol=1e-15)


def test_twist_and_acceleration_are_the_derivatives_of_the_pose_path() -> None:
    h = 1e-4
    now, ahead, behind = SQUARE.pose(TIMES), SQUARE.pose(TIMES + h), SQUARE.pose(TIMES - h)
    linear_v = (ahead.position - behind.position) / (2 * h)
    linear_a = (ahead.position - 2 * now.position + behind.position) / h**2
    np.testing.assert_allclose(now.twist[:, :3], linear_v, rtol=0, atol=1e-7)
    np.testing.assert_allclose(now.accel[:, :3], linear_a, rtol=0, atol=1e-5)
    # ω (world) from R(t + h) R(t − h)ᵀ = exp(2h [ω]×), ω̇ from ω at t ± h/2
    omega = np.array([pin.log3(a @ b.T) for a, b in zip(ahead.rotation, behind.rotation, strict=True)]) / (
        2 * h
    )
    forward = np.array([pin.log3(a @ b.T) for a, b in zip(ahead.rotation, now.rotation, strict=True)]) / h
    backward = np.array([pin.log3(a @ b.T) for a, b in zip(now.rotation, behind.rotation, strict=True)]) / h
    np.testing.assert_allclose(now.twist[:, 3:], omega, rtol=0, atol=1e-7)
    np.testing.assert_allclose(now.accel[:, 3:], (forward - backward) / h, rtol=0, atol=1e-5)
    assert np.abs(now.twist).max() > 0.05 and np.abs(now.accel).max() > 0.1  # a moving path


def test_velocity_and_acceleration_are_continuous_at_the_vias_and_across_the_period() -> None:
    eps = 1e-9
    for t in [*SQUARE.times[1:-1], SQUARE.period]:
        left, right = SQUARE.pose(np.array([t - eps])), SQUARE.pose(np.array([t + eps]))
        np.testing.assert_allclose(left.twist, right.twist, rtol=0, atol=1e-12)
        np.testing.assert_allclose(left.accel, right.accel, rtol=0, atol=1e-6)
        np.testing.assert_allclose(left.position, right.position, rtol=0, atol=1e-12)
        joint_left, joint_right = SQUARE.sample(np.array([t - eps])), SQUARE.sample(np.array([t + eps]))
        for a, b in zip(joint_left, joint_right, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-5)


def test_the_joint_paths_forward_kinematics_is_the_pose_path() -> None:
    """FK (Pinocchio) of the IK'd joint path against the pose path at 801 times: within 1e-9 m
    and 1e-9 rad (measured: ~1e-11); J(q) q̇ is the twist and J q̈ + J̇ q̇ the acceleration."""
    model, data, fid = UR5.model, UR5.model.createData(), UR5.ee_frame_id
    t = np.linspace(0.0, SQUARE.period, 801)
    joint, pose = SQUARE.sample(t), SQUARE.pose(t)
    for i in range(t.size):
        pin.forwardKinematics(model, data, joint.q[i], joint.v[i], joint.a[i])
        frame = pin.updateFramePlacement(model, data, fid)
        assert np.linalg.norm(frame.translation - pose.position[i]) < 1e-9
        assert np.linalg.norm(pin.log3(frame.rotation.T @ pose.rotation[i])) < 1e-9
        twist = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
        accel = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
        np.testing.assert_allclose(twist, pose.twist[i], rtol=0, atol=1e-7)
        np.testing.assert_allclose(accel, pose.accel[i], rtol=0, atol=1e-5)
    assert SQUARE.ik_error[0] < 1e-9 and SQUARE.ik_error[1] < 1e-9


def test_the_joint_paths_derivatives_are_its_finite_differences() -> None:
    h = 1e-5
    now, ahead, behind = SQUARE.sample(TIMES), SQUARE.sample(TIMES + h), SQUARE.sample(TIMES - h)
    np.testing.assert_allclose(now.v, (ahead.q - behind.q) / (2 * h), rtol=0, atol=1e-6)
    np.testing.assert_allclose(now.a, (ahead.v - behind.v) / (2 * h), rtol=0, atol=1e-5)
    np.testing.assert_allclose(now.jerk, (ahead.a - behind.a) / (2 * h), rtol=0, atol=1e-3)


def test_a_written_file_reads_back_as_the_same_reference(tmp_path: Path) -> None:
    for name in ("square.toml", "square.json"):
        again = read_trajectory_file(write_trajectory_file(tmp_path / name, SQUARE), UR5)
        assert isinstance(again, PoseTrajectory)
        t = np.linspace(0.0, 8.0, 97)
        np.testing.assert_allclose(again.pose(t).position, SQUARE.pose(t).position, rtol=0, atol=1e-15)
        np.testing.assert_allclose(again.pose(t).rotation, SQUARE.pose(t).rotation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(again.sample(t).q, SQUARE.sample(t).q, rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("robot", "text", "match"),
    [
        ("ur5", "times = [0.0, 1.0]\nrpy = [[0, 0, 0], [0, 0, 0]]\n", "rpy.*beside 'positions'"),
        (
            "ur5",
            "times = [0.0, 1.0]\npositions = [[0.45, 0.1, 0.4], [0.45, 0.1, 0.4]]\nrpy = [[3.14159, 0, 0]]\n",
            r"rpy.*one row \(roll, pitch, yaw\) \[rad\] per time \(2\)",
        ),
        (
            "twolink",
            "times = [0.0, 1.0]\npositions = [[0.5, 0.1, 0.0], [0.5, 0.1, 0.0]]\nrpy = [[0, 0, 0], [0, 0, 0]]\n",
            "no orientations for twolink: its 2 joints cannot set a full pose",
        ),
        (
            "ur5",
            "times = [0.0, 1.0, 2.0]\npositions = [[0.45, 0.1, 0.4], [0.45, 0, 0.4], [0.45, 0.1, 0.4]]\n"
            "rpy = [[3.14159, 0, -1.5708], [3.14159, 0, -1.5708], [3.14159, 0.1, -1.5708]]\n",
            r"via poses\[2\].*the first via pose again",
        ),
    ],
)
def test_bad_via_poses_are_named(tmp_path: Path, robot: str, text: str, match: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InvalidParameterError, match=match):
        read_trajectory_file(path, load_robot(robot))


@pytest.mark.parametrize("robot", ["twolink", "ur5"])
def test_law_input_of_a_joint_reference_is_its_forward_kinematics(robot: str) -> None:
    """For a joint-space reference the task fields are FK of it: against terms.frame (a second
    Pinocchio path: computeJointJacobians, J q̇_d and J q̈_d + J̇ q̇_d)."""
    arm = load_robot(robot)
    law = load_controller("osc")(arm)
    rng = np.random.default_rng(5)
    qd, vd, ad = (rng.uniform(-1, 1, (1, arm.nv)) for _ in range(3))
    x = law_input(law, 0.0, qd, vd, np.zeros((1, 0)), qd, vd, ad)
    frame = terms_for(law).frame(qd, vd)
    np.testing.assert_allclose(x.x_des, frame.position, atol=1e-14)
    np.testing.assert_allclose(x.R_des, frame.rotation, atol=1e-14)
    np.testing.assert_allclose(x.twist_des, np.matvec(frame.jacobian, vd), atol=1e-12)
    np.testing.assert_allclose(x.accel_des, np.matvec(frame.jacobian, ad) + frame.drift, atol=1e-12)
    plain = load_controller("pd")(arm)
    assert law_input(plain, 0.0, qd, vd, np.zeros((1, 0)), qd, vd, ad).x_des is None


class Recorder(Controller, register=False):
    """A task-space law that records the task reference it is given and holds gravity."""

    name = "recorder"
    title = "records x_des"
    Gains = Gains
    task_space = True
    seen: ClassVar[list[tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]] = []

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        assert x.x_des is not None and x.R_des is not None and x.twist_des is not None
        assert x.accel_des is not None
        assert x.x_des.shape == (1, 3) and x.R_des.shape == (1, 3, 3) and x.accel_des.shape == (1, 6)
        for array in (x.x_des, x.R_des, x.twist_des, x.accel_des):
            with pytest.raises(ValueError, match="read-only"):
                array[...] = 0.0
        Recorder.seen.append((x.t, x.x_des.copy(), x.R_des.copy(), x.twist_des.copy(), x.accel_des.copy()))
        return LawOutput(terms.gravity(x.q))


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_the_engine_passes_the_pose_paths_own_reference(method: str) -> None:
    Recorder.seen = []
    simulate(Recorder(UR5), Plant(UR5), SQUARE, SimulationConfig(duration=0.05, method=method))
    t = np.array([s[0] for s in Recorder.seen])
    assert t.size > 10 and np.ptp(t) > 0.04
    pose = SQUARE.pose(t)
    for i, (_, x, R, w, a) in enumerate(Recorder.seen):
        # (the law's t and the engine's half-step grid differ in the last bit)
        np.testing.assert_allclose(x[0], pose.position[i], rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(R[0], pose.rotation[i], rtol=0, atol=1e-14)
        np.testing.assert_allclose(w[0], pose.twist[i], rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(a[0], pose.accel[i], rtol=1e-12, atol=1e-15)


def test_a_joint_reference_still_gives_the_same_osc_torque_as_before() -> None:
    """osc on the twolink's default (joint) reference: the torque equals the law written with the
    desired frame from terms.frame of the joint reference (the path the law took before)."""
    arm = load_robot("twolink")
    law = load_controller("osc")(arm)
    ref = default_trajectory(arm).sample(np.array([0.7]))
    q, v = ref.q + 0.01, ref.v - 0.02
    x = law_input(law, 0.7, q, v, np.zeros((1, 0)), ref.q, ref.v, ref.a)
    terms = terms_for(law)
    d = terms.frame(ref.q, ref.v)
    np.testing.assert_allclose(x.twist_des, np.matvec(d.jacobian, ref.v), atol=1e-13)
    tau = law.compute(x, terms).tau
    assert np.all(np.isfinite(tau)) and tau.shape == (1, 2)


def test_the_trajectory_command_shows_the_via_poses_and_their_configurations(
    capsys: pytest.CaptureFixture[str],
) -> None:
    import json

    from twolink_pin.cli import main

    path = str(ROOT / "examples" / "ur5_square_pose.toml")
    assert main(["trajectory", "--robot", "ur5", "--trajectory", path, "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    model, data, fid = UR5.model, UR5.model.createData(), UR5.ee_frame_id
    for q, p, rpy in zip(payload["via_q"], payload["positions"], payload["rpy"], strict=True):
        pin.framesForwardKinematics(model, data, np.array(q))
        np.testing.assert_allclose(data.oMf[fid].translation, p, atol=1e-9)  # the IK'd configuration's FK
        angle = np.linalg.norm(pin.log3(data.oMf[fid].rotation.T @ pin.rpy.rpyToMatrix(*rpy)))
        assert angle < 1e-9
    assert payload["ik_error"]["position_m"] < 1e-9 and payload["within_limits"]
