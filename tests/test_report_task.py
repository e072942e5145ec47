"""The report of a task-space law (issue 28 §3): its task table and figure beside the joint
ones, the numbers ``simulate`` gives for the same run, the gains in the comparison, and a
wrench's window shaded where it acts. Nothing in the report names the law: its class
declares ``task_space``. Issue 38: the joint-space pd has its task errors too (§8), and
``pd@kp=200,150`` is a row of its own beside pd, its runs overlaid with pd's (§6)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from twolink_pin.cli import main

RUN = ["--duration", "0.3", "--wrench", "5,0,0@0.1:0.2"]
VARIANT = "pd@kp=200,150"


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("report") / "r"
    argv = ["report", "--controller", "osc", "--controller", "pd", "--controller", VARIANT]
    argv += ["--no-animation", "--no-identification", "--no-limits-section", "--no-sim-to-sim"]
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
    assert results["comparison"]["task_metrics"].keys() == {"osc", "pd", VARIANT}
    assert "osc_task_error.png" in osc["figures"] and not any("task" in f for f in pd["figures"])
    html = (report / "index.html").read_text()
    assert '<table id="table2-task">' in html and "figures/osc_task_error.png" in html
    row = f"<tr><td>osc</td><td>{expected['position_rms_mm']:.4g}</td>"
    assert row in html


def test_the_reports_comparison_lists_the_gains(report: Path) -> None:
    markdown = (report / "report.md").read_text()
    assert "| pd | kp = (350, 300), kd = (40, 50) | no friction, wrench | finished |" in markdown
    assert "| osc | kp = [[100, 0, 0], [0, 100, 0], [0, 0, 100]], kd = [[20, 0, 0]," in markdown


def test_a_joint_space_laws_task_errors_are_fk_of_its_run(report: Path, tmp_path: Path) -> None:
    """Issue 38 §8: pd's row of the task table is Pinocchio's FK of pd's own run (simulated
    again with the same options and saved) against its reference."""
    from test_task_metrics import reference_task_metrics

    from twolink_pin.model import load_robot
    from twolink_pin.simulation.storage import load_result

    results: dict[str, Any] = json.loads((report / "results.json").read_text())
    saved = tmp_path / "pd.npz"
    assert main(["simulate", "pd", *RUN, "--save", str(saved)]) == 0
    expected = reference_task_metrics(load_robot(), load_result(saved))
    assert results["controllers"]["pd"]["task_metrics"] == pytest.approx(expected, rel=1e-9, abs=1e-12)
    html = (report / "index.html").read_text()
    assert f"<tr><td>pd</td><td>{expected['position_rms_mm']:.4g}</td>" in html


def test_a_variant_is_a_row_of_its_own_as_simulate_runs_it(
    report: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 38 §6: ``--controller pd@kp=200,150`` is its own section, table row and CSV row,
    with simulate's numbers for ``--gain kp=200,150``; its runs overlaid with pd's."""
    from twolink_pin.law_variant import file_stem

    results: dict[str, Any] = json.loads((report / "results.json").read_text())
    assert list(results["controllers"]) == ["osc", "pd", VARIANT]
    capsys.readouterr()
    assert main(["simulate", "pd", *RUN, "--gain", "kp=200,150", "--json"]) == 0
    single = json.loads(capsys.readouterr().out)
    entry = results["controllers"][VARIANT]
    assert entry["metrics"] == single["metrics"] and entry["task_metrics"] == single["task_metrics"]
    assert entry["gains"].startswith("kp = (200, 150) N·m/rad") and entry["variant"] == {"kp": [200.0, 150.0]}
    assert all(f.startswith(file_stem(VARIANT) + "_") for f in entry["figures"])
    assert (
        results["overlays"] == {"pd": "pd_variants.png"}
        and (report / "figures" / "pd_variants.png").is_file()
    )
    html = (report / "index.html").read_text()
    assert f'id="ctrl-{VARIANT}"' in html and "figures/pd_variants.png" in html
    assert f"<tr><td>{VARIANT}</td><td>no friction, wrench</td>" in html
    assert f'\n"{VARIANT}",rms,' in (report / "comparison.csv").read_text()
