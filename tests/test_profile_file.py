"""A user's own profile (issue 50 §6, §7): a TOML file gives any URDF what a catalog profile
gives, on every command; the catalog's own profiles are such files; bad input is one line
naming the key and the file, exit 2. And the home of a URDF without one (§4)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import tomllib

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.model.catalog import example_robot_urdf, names, package_folder
from twolink_pin.model.home import choose_home
from twolink_pin.twolink import reference

ROOT = Path(__file__).resolve().parents[1]
BAXTER = ROOT / "examples" / "baxter_right_arm.toml"


def test_baxters_right_arm_is_an_arm_of_seven_joints_the_rest_locked() -> None:
    robot = load_robot(BAXTER)
    assert robot.nv == 7 and robot.ee_frame == "right_gripper"
    assert [str(n) for n in robot.model.names[1:]] == [
        f"right_{j}" for j in ("s0", "s1", "e0", "e1", "w0", "w1", "w2")
    ]
    np.testing.assert_array_equal(robot.home, [0.0, -0.55, 0.0, 0.75, 0.0, 1.26, 0.0])
    # the locked links ride on the torso: the right arm's M is the full tree's right-arm block
    full = pin.buildModelFromUrdf(str(example_robot_urdf("baxter_description/urdf/baxter.urdf")))
    q = pin.neutral(full)
    table = tomllib.loads(BAXTER.read_text())["locked"]
    for name, value in table.items():
        q[full.idx_qs[full.getJointId(name)]] = value
    rows = [full.idx_vs[full.getJointId(f"right_{j}")] for j in ("s0", "s1", "e0", "e1", "w0", "w1", "w2")]
    for j in range(len(rows)):
        q[full.idx_qs[full.getJointId(str(robot.model.names[j + 1]))]] = robot.home[j]
    M_full = pin.crba(full, full.createData(), q)
    M_full = np.triu(M_full) + np.triu(M_full, 1).T
    M = pin.crba(robot.model, robot.model.createData(), robot.home)
    np.testing.assert_allclose(
        np.triu(M) + np.triu(M, 1).T, M_full[np.ix_(rows, rows)], rtol=1e-10, atol=1e-12
    )


def test_a_profile_runs_on_every_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    run = ["--robot", str(BAXTER), "--duration", "0.05"]
    assert main(["info", "--robot", str(BAXTER), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["profile"] == str(BAXTER)
    assert main(["simulate", "computed-torque", *run]) == 0
    assert main(["compare", "pd", "computed-torque", *run, "--no-plot", "--out", str(tmp_path / "c")]) == 0


CAMPAIGN = """
urdf = "example-robot-data:ur_description/urdf/ur5_robot.urdf"
end_effector = "tool0"
home = [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]
"""


@pytest.mark.parametrize(
    ("extra", "key", "expected"),
    [
        ('locked = ["elbow"]\n', "locked", "no such joint, joints are"),
        ("", "end_effector", "no such frame"),
        (
            'locked = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", '
            '"wrist_2_joint", "wrist_3_joint"]\n',
            "locked",
            "at least one joint of ur5_robot.urdf left free",
        ),
        ("", "home", "outside"),
        ("[gains.pdd]\nkp = 100\n", "gains.pdd", "a table of a registered law"),
        ("[gains.pd]\nkq = 100\n", "gains.pd.kq", "a gain of pd: kp, kd"),
        ("colour = 3\n", "colour", "one of the profile keys"),
        ("amplitude = -1\n", "amplitude", "a finite number > 0"),
    ],
)
def test_bad_profile_input_is_one_line_naming_the_key_and_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str, key: str, expected: str
) -> None:
    text = CAMPAIGN
    if key == "end_effector":
        text = text.replace('"tool0"', '"gripper"')
    if key == "home":
        text = text.replace("[0.0, -1.5708,", "[0.0, -7.0,")
    if extra.startswith("["):
        text = text + extra
    else:
        text = extra + text
    if key == "locked" and "shoulder_pan_joint" in extra:
        text = text.replace("home = [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]\n", "")
    if key == "locked" and '"elbow"' in extra:
        pass
    path = tmp_path / "mine.toml"
    path.write_text(text)
    assert main(["info", "--robot", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"{path}: {key}" in err[0] and expected in err[0], err[0]


def test_the_catalogs_own_profiles_are_files_and_the_twolinks_are_the_reports_numbers() -> None:
    files = sorted(p.stem for p in package_folder().glob("*.toml"))
    assert files == sorted(names())
    twolink = tomllib.loads((package_folder() / "twolink.toml").read_text())
    for law, gains in reference.REPORT_GAINS.items():
        assert {k: tuple(v) for k, v in twolink["gains"][law].items()} == gains, law
    assert tuple(twolink["q0_offset"]) == reference.Q0_OFFSET
    assert tuple(map(tuple, twolink["trajectory"]["cartesian_points"])) == reference.REPORT_VIA_XY
    assert tuple(twolink["trajectory"]["times"]) == reference.REPORT_TIMES
    friction = twolink["friction"]
    assert (tuple(friction["viscous"]), tuple(friction["coulomb"])) == reference.REPORT_FRICTION
    effects = twolink["effects"]
    assert tuple(effects["armature"]) == reference.ARMATURE
    assert (tuple(effects["damping"]), tuple(effects["frictionloss"])) == reference.REPORT_FRICTION


def test_robots_lists_the_profiles_of_the_users_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "baxter-right.toml").write_text(
        BAXTER.read_text().replace('urdf = "example-robot-data:', 'urdf = "example-robot-data:')
    )
    monkeypatch.setenv("TWOLINK_PIN_ROBOTS", str(tmp_path))
    assert main(["robots", "--json"]) == 0
    rows = {row["name"]: row for row in json.loads(capsys.readouterr().out)["robots"]}
    assert rows["baxter-right"]["nv"] == 7 and rows["baxter-right"]["profile"] == str(
        tmp_path / "baxter-right.toml"
    )
    assert main(["info", "--robot", "baxter-right", "--json"]) == 0  # by name, as a catalog robot
    assert json.loads(capsys.readouterr().out)["nv"] == 7


def test_a_urdf_without_a_home_gets_a_dexterous_one_near_the_middle_and_info_says_how(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The UR3's middle of the ranges is its stretched, singular zero pose; the chosen home is not
    singular, keeps a quarter of each range from every limit, and is the same every time."""
    urdf = example_robot_urdf("ur_description/urdf/ur3_robot.urdf")
    robot = load_robot(urdf)
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    assert np.all(robot.home >= lower + 0.25 * (upper - lower) - 1e-12)
    assert np.all(robot.home <= upper - 0.25 * (upper - lower) + 1e-12)
    J = pin.computeFrameJacobian(
        robot.model, robot.model.createData(), robot.home, robot.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
    )
    s = np.linalg.svd(J, compute_uv=False)
    assert s[-1] > 1e-2 * s[0]  # 6 rows move: not singular
    middle = 0.5 * (lower + upper)
    J0 = pin.computeFrameJacobian(
        robot.model, robot.model.createData(), middle, robot.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
    )
    assert np.linalg.svd(J0, compute_uv=False)[-1] < 1e-9  # the middle is
    np.testing.assert_array_equal(choose_home(robot.model, robot.ee_frame_id).q, robot.home)
    assert main(["info", "--robot", str(urdf)]) == 0
    assert "how      chosen: the most dexterous of 257 configurations" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "key", "expected"),
    [
        ("locked = {shoulder_pan_joint = 99.0}\n", "locked.shoulder_pan_joint", "range [-6.28319, 6.28319]"),
        ('free = ["elbow_joint"]\nlocked = ["elbow_joint"]\n', "locked", "not also listed in free"),
        ('free = ["elbow_joint"]\nlocked = ["elbow"]\n', "locked", "no such joint"),
        ("q0_offset = [0.1, 0.2]\n", "q0_offset", "one value [rad], or 6"),
        ("acceleration_limits = [10.0, 10.0]\n", "acceleration_limits", "6 values > 0"),
        ("friction = {viscous = [0.1], coulomb = [0.0]}\n", "friction.viscous", "6 values >= 0"),
        (
            "trajectory = {times = [0, 1], joint_points = [[0, 0], [1, 1]]}\n",
            "trajectory.joint_points",
            "6 joint",
        ),
        ("[gains.pd]\nkp = [100, 100]\n", "gains.pd.kp", "2 numbers are neither 1, 6"),
        ("effects = {armature = [0.1, 0.1]}\n", "effects.armature", "6 values"),
        ("effects = {armature = [-0.1]}\n", "effects.armature", ">= 0"),
    ],
)
def test_a_profile_value_the_arm_cannot_take_is_one_line_naming_the_key_and_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str, key: str, expected: str
) -> None:
    """A per-joint value of the wrong count, a lock outside the range or contradicting ``free``:
    refused when the arm is loaded, not when a run meets it (or never)."""
    head, _, tail = CAMPAIGN.partition("home =")
    text = head + extra + "home =" + tail if not extra.startswith("[") else CAMPAIGN + extra
    if "free" in extra:
        text = text.replace("home = [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]\n", "")
    path = tmp_path / "mine.toml"
    path.write_text(text)
    assert main(["info", "--robot", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"{path}: {key} = " in err[0] and expected in err[0], err[0]


def test_one_q0_offset_in_a_profile_is_every_joints(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(CAMPAIGN + "q0_offset = [0.1]\n")
    robot = load_robot(path)
    from twolink_pin.simulation.config import joint_offsets

    np.testing.assert_array_equal(joint_offsets("q0_offset", robot.profile.q0_offset, None, 6), [0.1] * 6)
