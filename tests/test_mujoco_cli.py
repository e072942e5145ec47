"""``--plant mujoco`` on the command line (issue 44 parts 1 and 6): every command that runs a plant
takes it; a URDF MuJoCo cannot compile, an option the chosen plant lacks and MuJoCo missing are
one line and exit 2 before any run; a MuJoCo run that goes unstable is a failed run at its time
with MuJoCo's cause (exit 1), and nothing else is printed or written."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main

MASSLESS = """<?xml version="1.0"?>
<robot name="massless">
  <link name="base_link"/>
  <link name="link1"/>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="10"/>
  </joint>
  <link name="link2">
    <inertial><origin xyz="0.2 0 0" rpy="0 0 0"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="joint2" type="revolute">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0" rpy="1.5707963 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="10"/>
  </joint>
</robot>
"""
"""A massless first link whose joint moves the second: Pinocchio's M(q) is positive definite,
MuJoCo refuses a moving body without mass."""


def _one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    return lines[0]


def test_a_urdf_mujoco_cannot_compile_is_one_line_naming_the_file_and_mujocos_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("massless.urdf").write_text(MASSLESS)
    assert (
        main(["simulate", "pd", "--robot", "massless.urdf", "--duration", "0.01"]) == 0
    )  # Pinocchio runs it
    capsys.readouterr()
    assert (
        main(["simulate", "pd", "--robot", "massless.urdf", "--plant", "mujoco", "--duration", "0.01"]) == 2
    )
    line = _one_line(capsys.readouterr().err)
    assert "massless.urdf" in line and "MuJoCo" in line and "mass and inertia of moving bodies" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["massless.urdf"]  # no MUJOCO_LOG.TXT


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--frictionloss", "0.2"], ("--frictionloss", "--plant mujoco")),
        (["--soft-limits", "on"], ("--soft-limits", "--plant mujoco")),
        (["--mujoco-integrator", "euler"], ("--mujoco-integrator", "--plant mujoco")),
        (["--plant", "mujoco", "--joint-stops"], ("--joint-stops", "soft limits")),
        (["--plant", "mujoco", "--armature", "0"], ("--armature", "0 everywhere")),
        (["--plant", "mujoco", "--mujoco-integrator", "euler", "--method", "adaptive"], ("--method rk4",)),
        (["--believe-effects"], ("--believe-effects", "armature")),
    ],
)
def test_an_option_the_plant_lacks_or_that_does_nothing_is_refused(
    argv: list[str], words: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["simulate", "pd", "--duration", "0.01", *argv]) == 2
    line = _one_line(capsys.readouterr().err)
    assert all(word in line for word in words), line


def test_mujoco_missing_says_how_to_install_it(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)  # import mujoco raises ImportError
    assert main(["simulate", "pd", "--plant", "mujoco", "--duration", "0.01"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "pip install 'mujoco-core" in line


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_an_unstable_mujoco_run_fails_at_its_time_with_mujocos_cause(
    integrator: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A stiffness MuJoCo's Euler (and RK4) cannot hold at 1 ms: exit 1, the time, MuJoCo's
    warning or its non-finite q̈; no reset (the state never comes back), nothing on stdout, no file."""
    monkeypatch.chdir(tmp_path)
    argv = ["simulate", "pd", "--plant", "mujoco", "--mujoco-integrator", integrator, "--gain", "kp=1e9"]
    assert main([*argv, "--duration", "1"]) == 1
    out, err = capsys.readouterr()
    line = _one_line(err)
    assert "diverged at t = 0.00" in line and "MuJoCo" in line and not out
    if integrator == "euler":
        assert "mjWARN_BADQACC" in line
    assert not list(tmp_path.iterdir())


def test_simulate_compare_and_sweep_take_the_mujoco_plant(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """simulate's record names the plant; compare's rows pd and pd@plant=mujoco are the same run
    (their metrics to 1e-12); a sweep on MuJoCo gives the run a single simulate gives."""
    assert main(["simulate", "pd", "--plant", "mujoco", "--duration", "0.5", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["run"]["plant"]["engine"] == "mujoco" and record["plant"].startswith("MuJoCo")
    out = tmp_path / "compare"
    assert (
        main(["compare", "pd", "pd@plant=mujoco", "--duration", "0.5", "--no-plot", "--out", str(out)]) == 0
    )
    table = json.loads((out / "comparison.json").read_text())
    assert "MuJoCo" in table["plants"]["pd@plant=mujoco"] and "MuJoCo" not in table["plants"]["pd"]
    rows = table["controllers"]
    np.testing.assert_allclose(rows["pd@plant=mujoco"]["rms"]["e"], rows["pd"]["rms"]["e"], rtol=1e-12)
    sweep = tmp_path / "sweep"
    argv = [
        "sweep",
        "pd",
        "--samples",
        "3",
        "--plant",
        "mujoco",
        "--duration",
        "0.5",
        "--no-plot",
        "--out",
        str(sweep),
    ]
    assert main(argv) == 0
    first = json.loads((sweep / "runs.json").read_text())[0]
    capsys.readouterr()
    offsets = [str(first["q0_offset1"]), str(first["q0_offset2"])]
    assert (
        main(["simulate", "pd", "--plant", "mujoco", "--duration", "0.5", "--json", "--q0-offset", *offsets])
        == 0
    )
    single = json.loads(capsys.readouterr().out)
    assert first["rms_e1"] == pytest.approx(single["metrics"]["rms"]["e"][0], rel=1e-12)
