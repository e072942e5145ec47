"""A sweep of a task-space law carries its task errors (issue 28 §3): the columns of
``runs.csv`` / Parquet, ``summary.json`` and ``distributions.png`` are what ``simulate``
reports for the same run (one definition, :mod:`twolink_pin.task_metrics`)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.studies.parquet import read_columns
from twolink_pin.task_metrics import TASK_UNITS

TASK = [f"task_{name}" for name in TASK_UNITS]


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_sweep_of_osc_has_the_task_errors_simulate_reports(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sweep"
    argv = ["sweep", "osc", "--samples", "3", "--duration", "0.2", "--q0-spread", "0.1"]
    assert main([*argv, "--gain", "kp=50:200", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "task_position_rms_mm" in text and "task_orientation_last_period_max_deg" in text
    rows = _rows(out / "runs.csv")
    assert all(name in rows[0] for name in TASK)
    parquet = read_columns(out / "runs", TASK)
    row = rows[1]
    offsets = [row["q0_offset1"], row["q0_offset2"]]
    single = [
        "simulate",
        "osc",
        "--duration",
        "0.2",
        "--q0-offset",
        *offsets,
        "--gain",
        f"kp={row['gain_kp']}",
    ]
    assert main([*single, "--json"]) == 0
    expected = json.loads(capsys.readouterr().out)["task_metrics"]
    for name, value in expected.items():
        assert float(row[f"task_{name}"]) == pytest.approx(value, rel=1e-9, abs=1e-12), name
        assert parquet[f"task_{name}"][1] == float(row[f"task_{name}"])
    summary = json.loads((out / "summary.json").read_text())
    for name in TASK:
        column = np.array([float(r[name]) for r in rows])
        assert summary["metrics"][name]["median"] == pytest.approx(np.median(column), rel=1e-12)


def test_a_sweep_of_a_joint_law_has_the_task_errors_fk_of_its_runs_gives(tmp_path: Path) -> None:
    """Issue 38 §8: a joint-space law moves the same end effector: a sweep of ``pd`` carries the
    task columns, each row's equal to Pinocchio's FK of that run's q against q_des (the run
    simulated again with the row's initial offset)."""
    from test_task_metrics import reference_task_metrics

    from twolink_pin import load_robot, make_scenario, simulate
    from twolink_pin.simulation import SimulationConfig
    from twolink_pin.trajectory import default_trajectory

    out = tmp_path / "sweep"
    argv = ["sweep", "pd", "--samples", "2", "--duration", "0.05", "--q0-spread", "0.1"]
    assert main([*argv, "--out", str(out), "--no-plot"]) == 0
    rows = _rows(out / "runs.csv")
    assert all(name in rows[0] for name in TASK)
    robot = load_robot()
    for row in rows:
        offset = (float(row["q0_offset1"]), float(row["q0_offset2"]))
        result = simulate(
            *make_scenario("pd", robot),
            default_trajectory(robot),
            SimulationConfig(duration=0.05, q0_offset=offset),
        )
        expected = reference_task_metrics(robot, result)
        for name, value in expected.items():
            assert float(row[f"task_{name}"]) == pytest.approx(value, rel=1e-9, abs=1e-12), name
