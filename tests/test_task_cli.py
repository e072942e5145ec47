"""Task-space metrics in the commands (simulate's summary and --json, compare's table) and the
task-error figure, for laws whose class declares task_space = True — checked against the
errors recomputed here with Pinocchio's forward kinematics and log3 from the saved run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.cli import main
from twolink_pin.model import load_robot
from twolink_pin.plotting.task import _task_error_figure
from twolink_pin.simulation.storage import load_result

ROOT = Path(__file__).resolve().parents[1]
SQUARE = str(ROOT / "examples" / "ur5_square_pose.toml")
UR5 = load_robot("ur5")


def _errors(q: np.ndarray, q_des: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|p − p_d| [mm] and the angle of R R_dᵀ [deg] per sample, by Pinocchio directly."""
    model, data, fid = UR5.model, UR5.model.createData(), UR5.ee_frame_id
    mm, deg = np.empty(len(q)), np.empty(len(q))
    for k in range(len(q)):
        pin.framesForwardKinematics(model, data, q[k])
        p, R = data.oMf[fid].translation.copy(), data.oMf[fid].rotation.copy()
        pin.framesForwardKinematics(model, data, q_des[k])
        mm[k] = 1e3 * np.linalg.norm(p - data.oMf[fid].translation)
        deg[k] = np.degrees(np.linalg.norm(pin.log3(R @ data.oMf[fid].rotation.T)))
    return mm, deg


def test_simulate_shows_a_task_space_laws_errors_in_mm_and_deg(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    saved = tmp_path / "run.npz"
    argv = ["simulate", "osc", "--robot", "ur5", "--trajectory", SQUARE, "--duration", "0.3"]
    # no --plot: drawing a 6-joint run's figures was 3/4 of this test; that simulate --plot saves
    # osc_task_error.png is tests/test_plotting_spans.py's, the figure's content is checked below
    assert main([*argv, "--json", "--save", str(saved)]) == 0
    payload = json.loads(capsys.readouterr().out)
    result = load_result(saved)
    mm, deg = _errors(np.asarray(result.q), np.asarray(result.q_des))
    task = payload["task_metrics"]
    assert task["position_rms_mm"] == pytest.approx(np.sqrt(np.mean(mm**2)), rel=1e-9)
    assert task["position_max_mm"] == pytest.approx(mm.max(), rel=1e-9)
    assert task["orientation_max_deg"] == pytest.approx(deg.max(), rel=1e-9)
    assert task["orientation_last_period_max_deg"] == pytest.approx(deg.max(), rel=1e-9)  # < a period
    assert mm.max() > 10.0 and mm[-1] < 0.5 * mm.max()  # it starts off and converges
    # the figure draws those errors
    fig = _task_error_figure(UR5, result)
    lines = {ax.get_label(): ax.get_lines()[0].get_ydata() for ax in fig.axes}
    np.testing.assert_allclose(lines["mm"], mm, rtol=1e-9)
    np.testing.assert_allclose(lines["deg"], deg, rtol=1e-9, atol=1e-12)
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert f"task |p − p_d| RMS {task['position_rms_mm']:.4g} mm" in text
    assert f"max {task['orientation_max_deg']:.4g} deg" in text


def test_compare_tabulates_every_laws_task_errors(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """osc and, since issue 38 §8, the joint-space pd: each row of the task table is FK of
    that law's own saved run against its reference."""
    out = tmp_path / "cmp"
    argv = ["compare", "osc", "pd", "--robot", "ur5", "--trajectory", SQUARE, "--duration", "0.2"]
    # --no-plot: the 27 figures of two 6-joint runs took 5/6 of this test; tests/test_plotting.py
    # draws them
    assert main([*argv, "--out", str(out), "--json", "--no-plot"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert set(payload["task_metrics"]) == {"osc", "pd"}
    markdown = (out / "comparison.md").read_text()
    section = markdown.split("### task space")[1].split("###")[0]
    for law in ("osc", "pd"):
        saved = tmp_path / f"{law}.npz"
        run = ["simulate", law, "--robot", "ur5", "--trajectory", SQUARE, "--duration", "0.2"]
        assert main([*run, "--save", str(saved)]) == 0
        result = load_result(saved)
        mm, _ = _errors(np.asarray(result.q), np.asarray(result.q_des))
        assert payload["task_metrics"][law]["position_max_mm"] == pytest.approx(mm.max(), rel=1e-9)
        assert f"| {law} | {np.sqrt(np.mean(mm**2)):.4g} | {mm.max():.4g} |" in section
