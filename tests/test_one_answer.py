"""One answer to "is it within its limits?" (issue 45 items 4 and 8): the JSON's ``within_limits``
of ``trajectory``, ``trajectory --time-optimal``, ``optimize`` and a run means every kind of
limit, the text's first verdict says the same, and the retiming's peaks are the same numbers on
the CLI, in the report's section and when its saved file is checked again — on one grid that
takes both sides of each of its acceleration jumps.

Independent readings: the peak velocity from numpy's derivative of the printed polynomial
coefficients on a grid 10× finer, the URDF's limits by ElementTree, the retimed samples' torque
by pin.rnea at the sample times themselves."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.polynomial import polynomial as P

from twolink_pin.cli import main
from twolink_pin.model import load_robot
from twolink_pin.trajectory import default_trajectory, read_trajectory_file

FAST = {
    "times": [0.0, 1.0, 2.0, 3.0, 4.0],
    "joints": [
        [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0],
        [1.446, -1.9708, 1.9708, -1.9708, -1.1708, -0.4],
        [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0],
        [-1.446, -1.1708, 1.1708, -1.1708, -1.9708, 0.4],
        [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0],
    ],
}
"""The UR5's default swing with joint 1 swung ±1.446 rad instead of ±0.4: its torque within
every effort limit (a third of the shoulder's), its velocity 4.57 rad/s against 3.15."""


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[str, dict]:
    """The command's text, then its JSON."""
    assert main(list(argv)) == 0
    text = capsys.readouterr().out
    assert main([*argv, "--json"]) == 0
    return text, json.loads(capsys.readouterr().out)


def _verdict(text: str) -> str:
    """The first line that gives a verdict."""
    words = ("FEASIBLE", "within every limit", "BEYOND A LIMIT")
    return next(line for line in text.splitlines() if any(w in line for w in words))


def _velocity_limits(urdf: str | Path) -> dict[str, float]:
    return {
        str(j.get("name")): float(j.find("limit").attrib["velocity"])  # type: ignore[union-attr]
        for j in ET.parse(urdf).getroot().iter("joint")
        if j.find("limit") is not None and "velocity" in j.find("limit").attrib  # type: ignore[union-attr]
    }


def test_a_path_beyond_a_velocity_limit_is_not_feasible_in_text_and_json(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The fast UR5 swing: its torque is within its limits, its velocity is not (4.57 rad/s
    against the URDF's 3.15, from the coefficients' derivative): the JSON's within_limits is
    false (within_effort_limits true), and the first verdict of the text says NOT FEASIBLE and
    names the velocity limit of joint 1 (it said "FEASIBLE: …" above "BEYOND A LIMIT")."""
    path = tmp_path / "fast.json"
    path.write_text(json.dumps(FAST))
    text, data = _run(capsys, "trajectory", "--robot", "ur5", "--trajectory", str(path))
    t = np.linspace(0.0, 4.0, 40001)
    speed = np.abs(P.polyval(t, P.polyder(data["coefficients"][0])))
    limit = _velocity_limits(load_robot("ur5").urdf_path)["shoulder_pan_joint"]
    assert speed.max() == pytest.approx(4.57, abs=0.005) and speed.max() > limit == 3.15
    assert data["within_limits"] is False and data["limits_check"]["within_limits"] is False
    assert data["within_effort_limits"] is True
    verdict = _verdict(text)
    assert verdict.startswith("NOT FEASIBLE") and "velocity limit of joint 1 (shoulder_pan_joint)" in verdict
    assert text.index(verdict) < text.index("BEYOND A LIMIT")


@pytest.mark.parametrize(
    "argv",
    [
        ("trajectory",),
        ("trajectory", "--time-optimal"),
        ("optimize",),
        ("simulate", "pd", "--duration", "0.5"),
    ],
)
def test_every_command_gives_one_answer(capsys: pytest.CaptureFixture[str], argv: tuple[str, ...]) -> None:
    """Within every limit: the JSON's within_limits is the conjunction of every kind's (of the
    limits check, or of the run's crossings), and the text's first verdict agrees."""
    text, data = _run(capsys, *argv)
    if argv[0] == "simulate":
        crossed = [any(kind["crossed"]) for kind in data["crossings"].values()]
        assert data["within_limits"] is (not any(crossed))
        return
    kinds = [v["within_limits"] for k, v in data["limits_check"].items() if k != "within_limits"]
    assert data["within_limits"] is all(kinds) is data["limits_check"]["within_limits"] is True
    verdict = _verdict(text)
    assert verdict.startswith("FEASIBLE") or verdict.strip().startswith("within every limit")


def test_the_retimings_peaks_are_the_same_numbers_everywhere(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """trajectory --time-optimal, a check of the file it saves (trajectory --trajectory) and the
    report's row (reference_row) give the same peak |τ|/limit, to the last digit, within 1e-4
    of the peak pin.rnea finds on 200 instants per sample interval (0.99829, 0.99982), where an
    even grid of the period's 4001 instants gave 0.9969, 0.9984."""
    from twolink_pin.report.within_limits import reference_row

    saved = tmp_path / "retimed.json"
    _, retimed = _run(capsys, "trajectory", "--time-optimal", "--save", str(saved))
    _, again = _run(capsys, "trajectory", "--trajectory", str(saved))
    robot = load_robot("twolink")
    samples = read_trajectory_file(saved, robot)
    row, _ = reference_row(robot, samples)
    limit = np.array(retimed["limits_check"]["effort"]["limit"])
    cli = np.array(retimed["limits_check"]["effort"]["peak"]) / limit
    assert list(cli) == list(np.array(again["limits_check"]["effort"]["peak"]) / limit)
    assert list(cli) == row["peak_ratio"]["effort"]
    _, fine = samples.dense(200)
    data = robot.model.createData()
    tau = np.array([pin.rnea(robot.model, data, *x) for x in zip(fine.q, fine.v, fine.a, strict=True)])
    truth = np.abs(tau).max(axis=0) / limit
    assert np.all(cli <= truth + 1e-12) and np.all(cli >= truth - 1e-4)
    assert np.all(truth <= 1.0)


def test_a_scaled_limit_is_reported_against_the_urdfs_too(capsys: pytest.CaptureFixture[str]) -> None:
    """--limit-scale 0.8: each peak line gives the fraction of the URDF's limit (ElementTree's),
    then that of the 80 % used (1.25 times it)."""
    text, data = _run(capsys, "trajectory", "--time-optimal", "--limit-scale", "0.8")
    urdf = _velocity_limits(load_robot("twolink").urdf_path)
    peaks = np.array(data["limits_check"]["velocity"]["peak"])
    true = peaks / np.array([urdf["joint1"], urdf["joint2"]])
    line = next(li for li in text.splitlines() if "peak |q̇| / limit" in li)
    printed = [float(x) for x in line.split(":")[1].split("(")[0].split(",")]
    used = [float(x) for x in line.split("of the 80 % used:")[1].rstrip(")").split(",")]
    np.testing.assert_allclose(printed, true, atol=6e-4)
    np.testing.assert_allclose(used, true / 0.8, atol=6e-4)
    assert max(used) > 0.99 and max(printed) < 0.81


def test_the_sampled_references_grid_takes_both_sides_of_each_jump() -> None:
    """The check grid of a retimed reference holds each repeated sample time twice, with the
    acceleration before and after the jump, and no two instants more than 1 ms apart."""
    from twolink_pin.limits import reference_motion
    from twolink_pin.trajectory import time_optimal

    robot = load_robot("twolink")
    retimed = time_optimal(robot, default_trajectory(robot)).trajectory
    motion = reference_motion(robot, retimed)
    jumps = np.flatnonzero(np.diff(retimed.times) == 0)
    assert jumps.size > 10
    for i in jumps[:20]:
        at = np.flatnonzero(motion.t == retimed.times[i])
        assert at.size == 2
        np.testing.assert_allclose(motion.a[at], retimed.a[[i, i + 1]], rtol=1e-9, atol=1e-9)
    assert np.diff(motion.t).max() <= 1e-3 + 1e-12


def test_a_run_past_its_range_and_speed_says_so_in_text_and_json(capsys: pytest.CaptureFixture[str]) -> None:
    """``simulate pd`` from 3.5 rad off on joint 1 (past its ±π range, then faster than 10
    rad/s): the JSON's within_limits is false, the conjunction of the crossings, not the effort
    alone; the text names the position range and the velocity limit crossed (on main a run's
    JSON had no within_limits)."""
    argv = ("simulate", "pd", "--duration", "0.4", "--q0-offset", "3.5", "0", "--saturate")
    text, data = _run(capsys, *argv)
    crossed = {kind: any(v["crossed"]) for kind, v in data["crossings"].items()}
    assert crossed["position"] and crossed["velocity"]
    assert data["within_limits"] is False
    assert "joint 1 (joint1) passed its position range" in text
    assert "joint 1 (joint1) exceeded its 10 rad/s velocity limit" in text
