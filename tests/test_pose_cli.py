"""`fk` and `info` print the end effector's pose as a via-pose file writes it (cli/commands/model.py).

Independent checks: the printed rotation against Pinocchio's frame placement, the printed
``rpy`` against that rotation through ``pin.rpy.rpyToMatrix``, and a via-pose file written
from the printed text alone read back by the via-pose reader to the same pose.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.cli import main
from twolink_pin.model import load_robot
from twolink_pin.trajectory import read_trajectory_file
from twolink_pin.trajectory.se3 import PoseTrajectory

NUMBERS = r"\[([-0-9., ]+)\]"


def _frame(robot_name: str, q: np.ndarray) -> pin.SE3:
    robot = load_robot(robot_name)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.ee_frame_id]


def _printed(text: str, key: str) -> list[float]:
    match = re.search(rf"^\s*{key}\s+{NUMBERS}", text, re.M)
    assert match, f"no {key} line in:\n{text}"
    return [float(x) for x in match.group(1).split(",")]


def _round_trip(robot_name: str, text: str, tmp_path: Path) -> PoseTrajectory:
    """A via-pose file holding the printed position and rpy twice, read back."""
    p, rpy = _printed(text, "position"), _printed(text, "rpy")
    path = tmp_path / "from_the_cli.toml"
    path.write_text(f"times = [0.0, 1.0]\npositions = [{p}, {p}]\nrpy = [{rpy}, {rpy}]\n")
    trajectory = read_trajectory_file(path, load_robot(robot_name))
    assert isinstance(trajectory, PoseTrajectory)
    return trajectory


@pytest.mark.parametrize("robot_name", ["twolink", "ur5", "panda", "kinova"])
def test_fk_json_gives_the_frames_rotation_and_its_rpy(
    robot_name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = load_robot(robot_name)
    q = robot.home + 0.1 * np.cos(np.arange(robot.nq))
    assert main(["fk", "--robot", robot_name, *map(str, q), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    frame = _frame(robot_name, q)
    np.testing.assert_allclose(out["rotation"], frame.rotation, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pin.rpy.rpyToMatrix(*out["rpy"]), frame.rotation, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["position"], frame.translation, rtol=0, atol=1e-12)


@pytest.mark.parametrize("robot_name", ["ur5", "panda"])
def test_a_via_pose_file_written_from_fks_text_reproduces_the_pose(
    robot_name: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robot = load_robot(robot_name)
    q = robot.home + 0.1 * np.cos(np.arange(robot.nq))
    assert main(["fk", "--robot", robot_name, *(repr(float(x)) for x in q)]) == 0
    trajectory = _round_trip(robot_name, capsys.readouterr().out, tmp_path)
    frame = _frame(robot_name, q)
    np.testing.assert_allclose(trajectory.positions[0], frame.translation, rtol=0, atol=1e-8)
    assert np.linalg.norm(pin.log3(trajectory.rotations[0].T @ frame.rotation)) < 1e-8
    reached = _frame(robot_name, trajectory.via_q[0])  # the reader's IK reaches the same pose
    assert np.linalg.norm(reached.translation - frame.translation) < 1e-8


@pytest.mark.parametrize("robot_name", ["ur5", "panda"])
def test_info_shows_home_and_its_pose_as_a_via_pose_file_writes_it(
    robot_name: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robot = load_robot(robot_name)
    assert main(["info", "--robot", robot_name, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    frame = _frame(robot_name, robot.home)
    np.testing.assert_allclose(out["home"], robot.home, rtol=0, atol=0)
    np.testing.assert_allclose(out["home_pose"]["rotation"], frame.rotation, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["home_pose"]["position"], frame.translation, rtol=0, atol=1e-12)
    assert main(["info", "--robot", robot_name]) == 0
    text = capsys.readouterr().out
    np.testing.assert_allclose(_printed(text, r"home\s+q ="), robot.home, rtol=0, atol=1e-9)
    trajectory = _round_trip(robot_name, text, tmp_path)
    assert np.linalg.norm(pin.log3(trajectory.rotations[0].T @ frame.rotation)) < 1e-8
    np.testing.assert_allclose(trajectory.via_q[0], robot.home, rtol=0, atol=1e-6)  # IK from home stays home
