"""The report of a task-space law (issue 28 §3): its task table and figure beside the joint
ones, the numbers ``simulate`` gives for the same run, the gains in the comparison, and a
wrench's window shaded where it acts. Nothing in the report names the law: its class
declares ``task_space``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from twolink_pin.cli import main

RUN = ["--duration", "0.3", "--wrench", "5,0,0@0.1:0.2"]


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("report") / "r"
    argv = ["report", "--controller", "osc", "--controller", "pd", "--no-animation", "--no-identification"]
    assert main([*argv, *RUN, "--workers", "1", "--out", str(out)]) == 0
    return out


def test_the_report_has_the_task_laws_task_errors_as_simulate_gives_them(
    report: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    results: dict[str, Any] = json.loads((report / "results.json").read_text())
    assert main(["simulate", "osc", *RUN, "--json"]) == 0
    expected = json.loads(capsys.readouterr().out)["task_metrics"]
    osc, pd = results["controllers"]["osc"], results["controllers"]["pd"]
    assert osc["task_metrics"] == pytest.approx(expected, rel=1e-12)
    assert pd["task_metrics"] is None and results["comparison"]["task_metrics"].keys() == {"osc"}
    assert "osc_task_error.png" in osc["figures"] and not any("task" in f for f in pd["figures"])
    html = (report / "index.html").read_text()
    assert '<table id="table2-task">' in html and "figures/osc_task_error.png" in html
    row = f"<tr><td>osc</td><td>{expected['position_rms_mm']:.4g}</td>"
    assert row in html


def test_the_reports_comparison_lists_the_gains(report: Path) -> None:
    markdown = (report / "report.md").read_text()
    assert "| pd | kp = (350, 300), kd = (40, 50) | no friction, wrench | finished |" in markdown
    assert "| osc | kp = [[100, 0, 0], [0, 100, 0], [0, 0, 100]], kd = [[20, 0, 0]," in markdown
