"""The command line: JSON outputs against the library and closed forms, exit codes, one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.twolink.closed_form import forward_kinematics


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_info_json_reads_p_from_the_urdf(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "info", "--json")
    data = json.loads(out)
    assert code == 0
    assert (data["nq"], data["nv"]) == (2, 2)
    np.testing.assert_allclose(data["link_lengths"], [0.38, 0.24], atol=1e-15)
    np.testing.assert_allclose(data["torque_limits"], [240, 40])
    np.testing.assert_allclose(data["p"], [3.4, 0.4, 0.3], atol=1e-12)


def test_info_payload_changes_p_by_the_closed_form(capsys: pytest.CaptureFixture[str]) -> None:
    m, l1, l2 = 2.0, 0.38, 0.24
    _, out, _ = run(capsys, "info", "--payload", str(m), "--json")
    expected = [3.4 + m * (l1**2 + l2**2), 0.4 + m * l2**2, 0.3 + m * l1 * l2]
    np.testing.assert_allclose(json.loads(out)["p"], expected, atol=1e-12)


@pytest.mark.parametrize("q", [(0.0, 0.0), (0.3, 0.5), (-2.0, 3.0), (0.1, -1e-3)])
def test_fk_json_equals_closed_form(capsys: pytest.CaptureFixture[str], q: tuple[float, float]) -> None:
    _, out, _ = run(capsys, "fk", *map(str, q), "--json")
    np.testing.assert_allclose(json.loads(out)["xy"], forward_kinematics(np.array(q), 0.38, 0.24), atol=1e-14)


def test_ik_json_branches_reach_the_target(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "ik", "0.48", "-0.1", "--json")
    sols = np.array(json.loads(out)["solutions"])
    assert sols[0, 1] > 0 > sols[1, 1]
    np.testing.assert_allclose(sols.round(4), [[-0.7044, 1.3587], [0.2936, -1.3587]])  # report Table 1 row 3
    for q in sols:
        np.testing.assert_allclose(forward_kinematics(q, 0.38, 0.24), [0.48, -0.1], atol=1e-12)


def test_trajectory_json_meets_the_via_points(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "trajectory", "--json")
    data = json.loads(out)
    coeffs = np.array(data["coefficients"])
    assert coeffs.shape == (2, 11)
    for t, q in zip(data["times"], data["via_q"]):
        np.testing.assert_allclose([np.polynomial.polynomial.polyval(t, c) for c in coeffs], q, atol=1e-9)
    assert data["within_limits"] is True
    assert np.all(np.array(data["peak_torque"]) < np.array(data["torque_limits"]))


def test_simulate_takes_a_law_from_a_users_file(capsys: pytest.CaptureFixture[str]) -> None:
    """``simulate examples/sliding_mode.py:SlidingMode`` runs the tutorial's law: it tracks."""
    code, out, _ = run(
        capsys, "simulate", "examples/sliding_mode.py:SlidingMode", "--duration", "8", "--json"
    )
    data = json.loads(out)
    assert code == 0 and data["controller"] == "sliding-mode"
    assert max(data["metrics"]["final_period_max_abs_e"]) < 1e-3


def test_simulate_gain_option_sets_one_value_or_one_per_joint(capsys: pytest.CaptureFixture[str]) -> None:
    """--gain kp=0 is refused (> 0); --gain kd=30,40 gives the first torque −Kp e(0) − Kd ė(0) = −(350, −300)·0.1."""
    code, out, _ = run(capsys, "simulate", "pd", "--duration", "0.01", "--gain", "kd=30,40", "--json")
    assert code == 0
    # At t = 0 the feedforward and ė vanish at the via point; −Kp e(0) = (−35, 30) N·m dominates.
    assert json.loads(out)["metrics"]["max"]["tau"][0] >= 35 - 1e-9


def test_simulate_last_period_line_says_when_the_run_is_shorter_than_a_period(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The twolink's reference repeats every 4 s: a 2-s run's "last period" is the whole run,
    its max |e| the 0.1-rad initial offset, and the line says so; an 8-s run's is the
    steady state, printed to 4 significant digits (not as 0.00000000)."""
    assert main(["simulate", "pd", "--duration", "2"]) == 0
    short = next(line for line in capsys.readouterr().out.splitlines() if "last period" in line)
    assert (
        short
        == "  last period max |e| (0.1, 0.1) rad (the run is shorter than one 4-s period: over the whole run)"
    )
    assert main(["simulate", "pd", "--duration", "8"]) == 0
    long = next(line for line in capsys.readouterr().out.splitlines() if "last period" in line)
    values = [float(x) for x in long.split("(")[1].split(")")[0].split(",")]
    assert "shorter" not in long and all(0 < v < 1e-6 for v in values), long


def test_simulate_json_short_pd_run(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "simulate", "pd", "--duration", "0.5", "--json")
    data = json.loads(out)
    assert code == 0 and data["controller"] == "pd"
    assert data["p_hat_final"] is None
    # At t = 0 the PD torque is Kp·e(0) with e(0) = (0.1, −0.1): max |tau| >= (35, 30) N·m.
    assert data["metrics"]["max"]["tau"][0] >= 35 - 1e-9 and data["metrics"]["max"]["tau"][1] >= 30 - 1e-9
    assert data["metrics"]["max"]["e"] == pytest.approx([0.1, 0.1], abs=1e-12)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["ik", "1", "1"], "outside the reachable annulus 0.14 <= r <= 0.62 m"),
        (["fk", "nan", "0"], "expected a finite number, got 'nan'"),
        (["simulate", "pd", "--duration", "0"], "expected a number in (0, 1e+06] s, got '0'"),
        (
            ["simulate", "lqr"],
            "controller 'lqr': no law of that name; registered laws are pd, computed-torque",
        ),
        (
            ["simulate", "pd", "--lambda", "3"],
            "lambda = 3.0 is invalid: expected a law with a λ gain; 'pd' has none",
        ),
        (
            ["simulate", "pd", "--gain", "kq=1"],
            "gain = 'kq' is invalid: expected one of the gains of 'pd': kp, kd",
        ),
        (["info", "--payload", "-1"], "expected a number in [0, 10000] kg, got '-1'"),
        (["info", "--urdf", "/nonexistent.urdf"], "file not found"),
        (["info", "--robot", "ur55"], "no robot of that name; named robots are twolink"),
        (["fk", "0.1"], "Q = [0.1] is invalid: expected 2 joint angles [rad] for twolink (nq = 2)"),
        (
            ["simulate", "pd", "--duration", "1", "--dt", "0.5", "--control-period", "0.7"],
            "control_period = 0.7 is invalid",
        ),
        (
            ["simulate", "pd", "--q0-offset", "0.1", "0.2", "0.3"],
            "q0_offset = (0.1, 0.2, 0.3) is invalid: expected one value, or 2 values",
        ),
    ],
)
def test_bad_input_exits_2_with_one_line(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    try:
        code = main(argv)  # library errors: main returns 2
    except SystemExit as exc:  # usage errors: argparse exits 2
        code = exc.code
    _, err = capsys.readouterr()
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1


def test_console_script_runs_as_a_process() -> None:
    """The installed entry point works outside pytest (exit status and stdout)."""
    proc = subprocess.run(
        [sys.executable, "-m", "twolink_pin.cli", "fk", "0", "0", "--json"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0
    np.testing.assert_allclose(json.loads(proc.stdout)["xy"], [0.62, 0.0], atol=1e-15)
    bad = subprocess.run(
        [sys.executable, "-m", "twolink_pin.cli", "ik", "5", "5"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


def test_animate_live_serves_on_loopback_and_stops_cleanly_on_ctrl_c(tmp_path) -> None:
    """The README's live command: prints a 127.0.0.1 URL that serves the viewer; SIGINT exits 0."""
    import signal
    import urllib.request

    saved = tmp_path / "run.npz"
    assert main(["simulate", "pd", "--duration", "0.2", "--save", str(saved)]) == 0
    proc = subprocess.Popen(
        [sys.executable, "-m", "twolink_pin.cli", "animate", "--from", str(saved), "--no-browser", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = proc.stdout.readline()  # type: ignore[union-attr]
        info = json.loads(line)
        assert info["host"] == "127.0.0.1" and info["url"].startswith(f"http://127.0.0.1:{info['port']}/")
        with urllib.request.urlopen(info["url"], timeout=10) as response:
            assert response.status == 200
            assert b"<html" in response.read().lower()
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_a_bug_is_one_line_and_exit_1_or_its_traceback_on_request(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An exception the library does not expect (here a RuntimeError in a command) is one line on
    stderr that says it is ours, exit status 1; TWOLINK_PIN_DEBUG=1 re-raises it."""
    from twolink_pin.cli import commands

    def broken(args: object) -> int:
        raise RuntimeError("boom")

    monkeypatch.setattr(commands, "cmd_robots", broken)
    monkeypatch.delenv("TWOLINK_PIN_DEBUG", raising=False)
    assert main(["robots"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: RuntimeError: boom" in err
    monkeypatch.setenv("TWOLINK_PIN_DEBUG", "1")
    with pytest.raises(RuntimeError, match="boom"):
        main(["robots"])
