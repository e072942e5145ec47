"""``trajectory --time-optimal`` and ``optimize`` on the command line: their JSON against the
library and the files they write, their refusals (exit 2) and failures (exit 1, nothing
written)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.model import load_robot
from twolink_pin.trajectory import SampledTrajectory, default_trajectory, read_trajectory_file


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_time_optimal_json_and_the_saved_file_that_trajectory_reads(capsys, tmp_path: Path) -> None:
    """The JSON's duration is the saved file's period; `trajectory --trajectory FILE` reads it
    back (samples, via times) and checks its torque; the active limits name kind and joint."""
    saved = tmp_path / "fast.json"
    code, out, err = run(capsys, "trajectory", "--time-optimal", "--save", str(saved), "--json")
    data = json.loads(out)
    assert code == 0 and "saved to" in err
    assert data["duration"] < data["original_period"] == 4.0
    assert {a["kind"] for a in data["active"]} >= {"effort"} and data["limits_check"]["within_limits"]
    back = read_trajectory_file(saved, load_robot("twolink"))
    assert isinstance(back, SampledTrajectory) and back.period == pytest.approx(data["duration"], rel=1e-12)
    code, out, _ = run(capsys, "trajectory", "--trajectory", str(saved), "--json")
    assert code == 0 and json.loads(out)["samples"] == back.times.size


def test_limit_scale_lengthens_and_bad_scales_are_refused(capsys) -> None:
    _, out, _ = run(capsys, "trajectory", "--time-optimal", "--limit-scale", "0.5", "--json")
    half = json.loads(out)["duration"]
    _, out, _ = run(capsys, "trajectory", "--time-optimal", "--json")
    assert half > json.loads(out)["duration"]
    for bad in ("0", "1.5", "nan", "-1"):
        with pytest.raises(SystemExit) as exit_info:
            main(["trajectory", "--time-optimal", "--limit-scale", bad])
        assert exit_info.value.code == 2
    code, _, err = run(capsys, "trajectory", "--limit-scale", "0.5")
    assert code == 2 and "--limit-scale" in err and "--time-optimal" in err


def test_a_urdf_without_velocity_limits_is_refused_naming_the_joint(capsys) -> None:
    code, _, err = run(capsys, "trajectory", "--time-optimal", "--robot", "double_pendulum")
    assert code == 2 and "velocity limit of joint 'joint1'" in err and len(err.strip().splitlines()) == 1


def test_optimize_json_against_the_library_and_its_file(capsys, tmp_path: Path) -> None:
    """The keys the issue names; the via error measured from the saved file (read back)."""
    saved = tmp_path / "least.toml"
    code, out, _ = run(capsys, "optimize", "--cost", "effort", "--save", str(saved), "--json")
    data = json.loads(out)
    assert code == 0
    for key in ("duration", "iterations", "seconds", "via_error", "max_violation"):
        assert key in data
    assert data["effort"] <= data["reference_effort"] and data["max_violation"] <= 0
    reference = default_trajectory(load_robot("twolink"))
    back = read_trajectory_file(saved, load_robot("twolink"))
    assert np.abs(back.sample(reference.times).q - reference.via_q).max() <= 1e-6


def test_a_failed_optimisation_exits_1_and_replaces_nothing(capsys, tmp_path: Path) -> None:
    """One SQP iteration does not converge: exit 1 saying what did not (the cost), by how much
    and what to try; the file already at --save is left as it was."""
    saved = tmp_path / "mine.json"
    saved.write_text('{"mine": true}\n')
    code, out, err = run(capsys, "optimize", "--max-iterations", "1", "--save", str(saved))
    assert code == 1 and "the cost did not settle in 1 SQP iterations" in err and "--max-iterations" in err
    assert saved.read_text() == '{"mine": true}\n' and out == ""


def test_optimize_refuses_a_reference_without_via_points(capsys, tmp_path: Path) -> None:
    fourier = tmp_path / "f.toml"
    fourier.write_text(
        "[fourier]\nperiod = 4.0\nharmonics = 1\na = [[0.1], [0.1]]\nb = [[0.0], [0.0]]\noffset = [0.0, 0.5]\n"
    )
    code, _, err = run(capsys, "optimize", "--trajectory", str(fourier))
    assert code == 2 and "via points" in err
