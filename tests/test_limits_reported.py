"""Limits read and reported everywhere (issue 36, part 1), each against an independent reading:

* ``info --json``'s ``limits`` are the URDF's own ``<limit>`` attributes, read by ElementTree;
* ``trajectory --json``'s ``limits_check`` on the Kinova's swing compressed in time (period 4 → 3 s)
  says the velocity limits do not hold, with each peak that of the polynomial's own derivative
  (numpy's ``polyder`` of the printed coefficients) on a grid 10× finer;
* a run's recorded crossings (``simulate --json``) equal a recomputation in plain numpy from the
  saved result's ``t``, ``q``, ``q̇`` arrays and the URDF's XML;
* a sweep's ``summary.json`` counts equal its rows', and a row's crossing equals that of the same
  run simulated alone;
* the torque check of the report, the figures and ``trajectory`` is the limits check's effort kind.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from numpy.polynomial import polynomial as P

from twolink_pin.cli import main
from twolink_pin.feasibility import check_torques
from twolink_pin.limits import check_limits
from twolink_pin.model import load_robot
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig
from twolink_pin.studies.sweep import SweepConfig, run_sweep
from twolink_pin.trajectory import default_trajectory


def _json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    code = main([*argv, "--json"])
    out = capsys.readouterr().out
    assert code == 0
    return json.loads(out)


def _xml_limits(urdf: str | Path) -> dict[str, dict[str, float]]:
    """Each moving joint's ``<limit>`` as ElementTree reads it ({} for none); a continuous joint,
    or a range with lower == upper (the URDF's default 0, 0), has no range."""
    out = {}
    for joint in ET.parse(urdf).getroot().iter("joint"):
        if joint.get("type") not in ("revolute", "continuous", "prismatic"):
            continue
        limit = joint.find("limit")
        attrs = {} if limit is None else {k: float(v) for k, v in limit.attrib.items()}
        if joint.get("type") == "continuous" or attrs.get("lower", 0.0) == attrs.get("upper", 0.0):
            attrs.pop("lower", None), attrs.pop("upper", None)
        out[str(joint.get("name"))] = attrs
    return out


@pytest.mark.parametrize("name", ["twolink", "kinova", "panda"])
def test_info_json_limits_are_the_urdf_s_own(capsys: pytest.CaptureFixture[str], name: str) -> None:
    """Per joint: the range, velocity and effort of ``info --json`` are the URDF's attributes (0 or
    absent: null); acceleration only where the profile gives it (the Panda: Franka's data sheet)."""
    info = _json(capsys, "info", "--robot", name)
    limits, joints = info["limits"], info["joint_names"]
    xml = _xml_limits(load_robot(name).urdf_path)
    assert set(limits) >= {"position_lower", "position_upper", "velocity", "effort"}
    for j, joint in enumerate(joints):
        attrs = xml[joint]
        for key in ("velocity", "effort"):
            assert limits[key][j] == (attrs[key] if attrs.get(key, 0.0) > 0 else None), (joint, key)
        for key in ("lower", "upper"):
            expected = attrs.get(key)
            got = limits[f"position_{key}"][j]
            assert (got is None) if expected is None else got == pytest.approx(expected, abs=1e-12)
    if name == "panda":
        assert limits["acceleration"] == [15, 7.5, 10, 12.5, 15, 20, 20]
    else:
        assert "acceleration" not in limits


def test_trajectory_json_says_the_kinova_s_fast_swing_breaks_its_velocity_limits(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The Kinova's default swing through the same via points in 3 s instead of 4: the velocity
    check fails (peak above 0.63 rad/s), and so does the verdict at the top; each peak is the
    largest |q̇| of numpy's derivative of the printed coefficients on a 10× finer grid, the margin
    limit − peak, the limit the URDF's."""
    base = default_trajectory(load_robot("kinova"))
    fast = tmp_path / "fast.json"
    fast.write_text(
        json.dumps({"times": (np.asarray(base.times) * 0.75).tolist(), "joints": base.via_q.tolist()})
    )
    out = _json(capsys, "trajectory", "--robot", "kinova", "--trajectory", str(fast))
    check = out["limits_check"]
    assert set(check) == {"position", "velocity", "acceleration", "effort", "within_limits"}
    assert check["within_limits"] is False and check["velocity"]["within_limits"] is False
    assert check["position"]["within_limits"] and check["effort"]["within_limits"]
    grid = out["limits_check_grid"]
    assert grid["instants"] == 4001 and grid["step"] == pytest.approx(3.0 / 4000, rel=1e-12)
    t = np.linspace(0.0, 3.0, 40001)
    speed = np.stack([np.abs(P.polyval(t, P.polyder(c))) for c in out["coefficients"]], axis=1)
    velocity = check["velocity"]
    np.testing.assert_allclose(velocity["peak"], speed.max(axis=0), rtol=1e-5)
    xml = _xml_limits(load_robot("kinova").urdf_path)
    limits = [a["velocity"] for a in xml.values()]
    np.testing.assert_allclose(velocity["limit"], limits, rtol=0, atol=0)
    np.testing.assert_allclose(velocity["margin"], np.array(limits) - velocity["peak"], rtol=0, atol=1e-12)
    assert all(m < 0 for m in velocity["margin"][:3])  # the arm's joints (0.63 rad/s) are too slow
    worst = speed.argmax(axis=0) * (t[1] - t[0])
    np.testing.assert_allclose(velocity["time"], worst, rtol=0, atol=1e-3)


def test_a_run_s_crossings_are_those_of_its_saved_arrays(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """``simulate`` from 3.5 rad off the reference on joint 1: it starts past its ±π range and
    swings faster than 10 rad/s. The JSON's crossings (joint, first time, largest excess) equal plain
    numpy on the ``t``, ``q``, ``q̇`` arrays of the saved ``.npz`` with the URDF's XML limits."""
    saved = tmp_path / "run.npz"
    argv = ("simulate", "pd", "--duration", "0.4", "--q0-offset", "3.5", "0", "--save", str(saved))
    out = _json(capsys, *argv)
    with np.load(saved) as data:
        t, q, v = data["t"], data["q"], data["v"]
    xml = _xml_limits(load_robot().urdf_path)
    lower = np.array([a["lower"] for a in xml.values()])
    upper = np.array([a["upper"] for a in xml.values()])
    speed = np.array([a["velocity"] for a in xml.values()])
    for kind, excess in (
        ("position", np.maximum(q - upper, lower - q)),
        ("velocity", np.abs(v) - speed),
    ):
        crossed = (excess > 0).any(axis=0)
        recorded = out["crossings"][kind]
        assert recorded["crossed"] == crossed.tolist(), kind
        for j in range(2):
            if crossed[j]:
                assert recorded["first_time"][j] == t[np.argmax(excess[:, j] > 0)], (kind, j)
                assert recorded["excess"][j] == excess[:, j].max(), (kind, j)
            else:
                assert recorded["first_time"][j] is None and recorded["excess"][j] is None
    assert out["crossings"]["position"]["crossed"] == [True, False]
    assert out["crossings"]["velocity"]["crossed"][0] is True
    assert out["limits"]["velocity"] == [10.0, 10.0]


def test_the_sweep_s_crossing_counts_are_its_rows(tmp_path: Path) -> None:
    """Six runs from up to ±4 rad off the reference: ``summary.json``'s ``position_crossed`` and
    ``velocity_crossed`` count the rows whose flags are set, ``crossed_joints`` the non-null
    first times per joint; the flags agree with the per-joint columns; and a row that crossed
    has the crossing of the same run simulated alone (its q0 offset, computed-torque's gains)."""
    robot = load_robot()
    config = SweepConfig(
        RunSpec(law="computed-torque", simulation=SimulationConfig(duration=0.3, q0_offset=0.0)),
        samples=6,
        seed=3,
        q0_spread=4.0,
    )
    run_sweep(config, robot, default_trajectory(robot), tmp_path, plot=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    rows = json.loads((tmp_path / "runs.json").read_text())
    for kind in ("position", "velocity"):
        flags = [r[f"{kind}_crossed"] for r in rows]
        per_joint = [[r[f"{kind}_crossed_at{j + 1}"] is not None for r in rows] for j in range(2)]
        assert summary[f"{kind}_crossed"] == sum(flags)
        assert summary["crossed_joints"][kind] == [sum(c) for c in per_joint]
        assert flags == [a or b for a, b in zip(*per_joint)]
    assert 0 < summary["position_crossed"] < 6 and summary["velocity_crossed"] > 0
    crossed = next(r for r in rows if r["position_crossed"])
    from twolink_pin.simulation import simulate

    spec = RunSpec(
        law="computed-torque",
        simulation=SimulationConfig(duration=0.3, q0_offset=(crossed["q0_offset1"], crossed["q0_offset2"])),
    )
    result = simulate(*spec.build(robot), default_trajectory(robot), spec.simulation)
    alone = result.crossings.position
    for j in range(2):
        first = crossed[f"position_crossed_at{j + 1}"]
        assert (first is None) if not alone.crossed[j] else first == alone.first_time[j]
        assert crossed[f"position_excess{j + 1}"] == alone.excess[j]


def test_the_torque_check_is_the_limits_check_s_effort_kind() -> None:
    """One definition: ``check_torques`` shows the effort kind of ``check_limits`` on the same grid
    (the report's numbers: peaks, times, margins, verdict)."""
    robot = load_robot()
    trajectory = default_trajectory(robot)
    torque, limits = check_torques(robot, trajectory), check_limits(robot, trajectory)
    effort = limits.of("effort")
    np.testing.assert_array_equal(torque.t, limits.motion.t)
    np.testing.assert_array_equal(torque.tau, limits.motion.tau)
    for a, b in ((torque.peak, effort.peak), (torque.peak_time, effort.time), (torque.margin, effort.margin)):
        np.testing.assert_array_equal(a, b)
    assert torque.within_limits is effort.within_limits is True
    assert math.isclose(float(torque.peak[1]), 1.1245, abs_tol=1e-4)
