"""Via poses on every arm of the catalog that can set a pose, the Panda's 7 joints included
(trajectory/pose_ik.py's posture objective, trajectory/se3.py).

Independent checks: the answer of :func:`solve_pose` with a posture is a constrained minimum
(the null-space projection of ``q_posture − q`` vanishes, computed here from Pinocchio's
Jacobian and numpy's pseudo-inverse) and does not depend on the seed; the joint path of a
closed pose path closes and is continuous; its forward kinematics (Pinocchio) is the pose
path; and osc tracks the Panda's example square as it tracks the UR5's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.controllers import load_controller
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.trajectory import read_trajectory_file, solve_pose
from twolink_pin.trajectory.se3 import PoseTrajectory, pose_trajectory

ROOT = Path(__file__).resolve().parents[1]
PANDA = load_robot("panda")
PANDA_SQUARE = ROOT / "examples" / "panda_square_pose.toml"


def _home_pose(robot_name: str) -> tuple[RobotModel, np.ndarray, np.ndarray]:
    robot = load_robot(robot_name)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.home)
    frame = data.oMf[robot.ee_frame_id]
    return robot, frame.translation.copy(), frame.rotation.copy()


def _assert_closed_and_continuous(trajectory: PoseTrajectory) -> None:
    start, end = trajectory.sample(np.array([0.0])), trajectory.sample(np.array([trajectory.period]))
    np.testing.assert_allclose(end.q, start.q, rtol=0, atol=1e-9)  # the joint path repeats
    np.testing.assert_allclose(trajectory.via_q[-1], trajectory.via_q[0], rtol=0, atol=1e-12)
    eps = 1e-9
    for t in trajectory.times[1:-1]:
        left, right = trajectory.sample(np.array([t - eps])), trajectory.sample(np.array([t + eps]))
        np.testing.assert_allclose(left.q, right.q, rtol=0, atol=1e-7)
        np.testing.assert_allclose(left.v, right.v, rtol=0, atol=1e-6)
    t = np.linspace(0.0, trajectory.period, 2001)  # no jump: each step is what q̇ accounts for
    path = trajectory.sample(t)
    step = np.diff(path.q, axis=0)
    by_velocity = 0.5 * (path.v[1:] + path.v[:-1]) * np.diff(t)[:, None]
    assert np.abs(step - by_velocity).max() < 1e-3 * max(float(np.abs(step).max()), 1e-9)


def test_a_redundant_arms_pose_solution_is_nearest_its_posture_whatever_the_seed() -> None:
    _, p, R = _home_pose("panda")
    goal_p, goal_R = p + np.array([0.1, -0.1, -0.1]), R @ pin.exp3(np.array([0.0, 0.2, 0.3]))
    answers = []
    for seed in (PANDA.home, PANDA.home + 0.2, PANDA.home - np.linspace(0.0, 0.3, 7)):
        q = solve_pose(PANDA, goal_p, goal_R, seed, posture=PANDA.home)
        data = PANDA.model.createData()
        pin.framesForwardKinematics(PANDA.model, data, q)
        assert np.linalg.norm(data.oMf[PANDA.ee_frame_id].translation - goal_p) < 1e-9
        J = pin.computeFrameJacobian(PANDA.model, data, q, PANDA.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
        null = (np.eye(7) - np.linalg.pinv(J) @ J) @ (PANDA.home - q)
        assert np.linalg.norm(null) < 1e-8  # stationary: no self-motion brings it closer to home
        answers.append(q)
    for q in answers[1:]:
        np.testing.assert_allclose(q, answers[0], rtol=0, atol=1e-8)


def test_the_panda_example_square_closes_in_joint_space() -> None:
    square = read_trajectory_file(PANDA_SQUARE, PANDA)
    assert isinstance(square, PoseTrajectory)
    _assert_closed_and_continuous(square)
    assert square.ik_error[0] < 1e-9 and square.ik_error[1] < 1e-9
    model, data, fid = PANDA.model, PANDA.model.createData(), PANDA.ee_frame_id
    t = np.linspace(0.0, square.period, 161)
    joint, pose = square.sample(t), square.pose(t)
    for i in range(t.size):  # the joint reference's forward kinematics is the pose path
        pin.framesForwardKinematics(model, data, joint.q[i])
        assert np.linalg.norm(data.oMf[fid].translation - pose.position[i]) < 1e-9
        assert np.linalg.norm(pin.log3(data.oMf[fid].rotation.T @ pose.rotation[i])) < 1e-9


@pytest.mark.parametrize("robot_name", ["ur5", "panda", "kinova", "z1"])
def test_a_square_and_a_back_and_forth_about_home_close_on_every_arm(robot_name: str) -> None:
    """Every catalog arm with 6 or more joints: a 10 cm square about its home pose whose tool
    turns at the corners, and a straight 10 cm back-and-forth, both close in joint space."""
    robot, p, R = _home_pose(robot_name)
    corners = np.array([[0, 1, 1], [0, -1, 1], [0, -1, -1], [0, 1, -1], [0, 1, 1]]) * 0.05
    turns = [
        np.zeros(3),
        np.array([0, 0.2, 0]),
        np.array([0, 0.2, 0.3]),
        np.array([-0.2, 0, 0.3]),
        np.zeros(3),
    ]
    square = pose_trajectory(robot, [0, 2, 4, 6, 8], p + corners, np.array([R @ pin.exp3(w) for w in turns]))
    _assert_closed_and_continuous(square)
    line = pose_trajectory(robot, [0, 2, 4], np.array([p, p + np.array([0, 0.1, 0]), p]), np.array([R, R, R]))
    _assert_closed_and_continuous(line)


@pytest.mark.parametrize(
    ("robot_name", "file"), [("ur5", "ur5_square_pose.toml"), ("panda", "panda_square_pose.toml")]
)
def test_osc_tracks_the_example_squares_alike_on_the_ur5_and_the_panda(robot_name: str, file: str) -> None:
    """From the reference's first configuration with the exact model, osc's task error obeys
    ë + D ė + K e = 0 from e(0) = 0 on both arms: it stays at the integrator's error."""
    robot = load_robot(robot_name)
    square = read_trajectory_file(ROOT / "examples" / file, robot)
    osc = load_controller("osc")(robot)
    config = SimulationConfig(duration=8.0, q0_offset=(0.0,) * robot.nv)
    result = simulate(osc, Plant(robot), square, config)
    model, data, fid = robot.model, robot.model.createData(), robot.ee_frame_id
    assert isinstance(square, PoseTrajectory)
    pose = square.pose(np.asarray(result.t))
    worst_p = worst_r = 0.0
    for i, q in enumerate(np.asarray(result.q)[::10]):
        pin.framesForwardKinematics(model, data, q)
        frame = data.oMf[fid]
        worst_p = max(worst_p, float(np.linalg.norm(frame.translation - pose.position[10 * i])))
        worst_r = max(worst_r, float(np.linalg.norm(pin.log3(frame.rotation.T @ pose.rotation[10 * i]))))
    assert worst_p < 1e-6 and worst_r < 1e-6
