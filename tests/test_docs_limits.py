"""docs/control_within_limits.md, run: every command on the page is run here and every output
line the page quotes must be in what it prints (stdout, or stderr for the runs the page shows
failing); the page's path is the example file; demo (b) is checked from the runs its
``compare`` made: qp-osc keeps every joint inside its range, every velocity, acceleration and
commanded torque within its limit, where osc takes joint 4 past its range and asks joint 6 for
more than its effort limit; the pushed Panda from its compare's runs (qp-osc's torques within
the limits, its joint-limit excess below osc's); demo (a) from its compare's runs (mpc's
torques within the limits, its velocity excess below half computed-torque's, the lower RMS
error) and from the run file its ``simulate --save`` wrote (every commanded torque within).

Slow-ish: two 2.5-s Panda runs (one with its limits binding for 0.7 s) and one that fails at
0.12 s. ``compare`` runs with ``--no-plot``: what is checked here is what it prints and its runs
(the figures are scripts/docs_images.py's, their code tests/test_plotting_limits.py's).
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from docs_pages import blocks, commands, quoted_in

from twolink_pin.cli import main
from twolink_pin.documents import load_toml
from twolink_pin.limits import ACCELERATION, EFFORT, POSITION, VELOCITY, joint_limits
from twolink_pin.model import load_robot

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "control_within_limits.md").read_text()
COMMANDS = commands(PAGE)


def test_the_page_compares_osc_and_qp_osc_on_its_example_path() -> None:
    verbs = [shlex.split(c)[1:3] for c, _ in COMMANDS]
    assert ["compare", "osc"] in verbs and ["simulate", "qp-osc"] in verbs
    panda = [c for c, _ in COMMANDS if "--robot panda" in c and "--wrench" not in c]  # not the push
    assert len(panda) == 3 and all("examples/panda_fold_pose.toml" in c for c in panda)
    page = load_toml(next(text for kind, text in blocks(PAGE) if kind == "toml"), "page")
    assert page == load_toml((ROOT / "examples" / "panda_fold_pose.toml").read_text(), "file")


def test_demo_a_compares_mpc_and_computed_torque_on_the_retimed_twolink() -> None:
    """Demo (a)'s commands: the retimed reference saved, then read by a compare and a saved run
    of mpc, both with the light model; that model is the twolink's with every link × 0.8
    (CRBA on both URDFs)."""
    verbs = [shlex.split(c)[1:3] for c, _ in COMMANDS]
    assert ["trajectory", "--time-optimal"] in verbs and ["compare", "mpc"] in verbs
    retimed = [c for c, _ in COMMANDS if "out/twolink_time_optimal.toml" in c]
    assert len(retimed) == 3 and all("--model examples/twolink_light.urdf" in c for c in retimed[1:])
    import pinocchio as pin

    light, twolink = load_robot(str(ROOT / "examples" / "twolink_light.urdf")), load_robot()
    for q in np.random.default_rng(0).uniform(-3, 3, (5, 2)):  # to the file's 12 digits
        m_light = pin.crba(light.model, light.model.createData(), q)
        np.testing.assert_allclose(
            m_light, 0.8 * pin.crba(twolink.model, twolink.model.createData(), q), rtol=1e-10
        )


RETIMED = "out/twolink_time_optimal.toml"
"""Demo (a)'s retimed reference, which its later commands read."""


def _run(command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[int, dict[str, Any]]:
    """The page's command through ``main``, every ``out/`` path in ``tmp_path`` (the retimed
    reference made there first when the command reads it), ``compare`` without figures; and
    the runs ``compare`` made (each law's result as it was tabulated) or the run ``--save``d."""
    import twolink_pin.studies.comparison as comparison

    argv = shlex.split(command)[1:]
    if RETIMED in argv and argv[0] != "trajectory":
        assert main(["trajectory", "--time-optimal", "--save", str(tmp_path / Path(RETIMED).name)]) == 0
    argv = [str(tmp_path / Path(a).name) if a.startswith("out/") else a for a in argv]
    if argv[0] == "compare":
        argv.append("--no-plot")
    runs: dict[str, Any] = {}
    tabulate = comparison.run_comparison

    def keeping(runner: Any, names: Any, progress: Any = None, on_result: Any = None) -> Any:
        def kept(name: str, result: Any) -> None:
            runs[name] = result
            if on_result is not None:
                on_result(name, result)

        return tabulate(runner, names, progress, kept)

    monkeypatch.setattr(comparison, "run_comparison", keeping)
    monkeypatch.chdir(ROOT)
    status = main(argv)
    if "--save" in argv and argv[argv.index("--save") + 1].endswith(".npz") and status == 0:
        from twolink_pin.simulation.storage import load_result

        runs["saved"] = load_result(argv[argv.index("--save") + 1])
    return status, runs


@pytest.mark.slow
@pytest.mark.parametrize(("command", "quoted"), COMMANDS, ids=[shlex.split(c)[1] for c, _ in COMMANDS])
def test_every_command_prints_what_the_page_says(
    command: str,
    quoted: list[str],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    fails = any("failed at t =" in line for line in quoted)
    status, runs = _run(command, tmp_path, monkeypatch)
    out, err = capsys.readouterr()
    assert status == (1 if fails else 0), err
    printed = (err if fails else out).splitlines()
    for line in quoted:
        assert quoted_in(line, printed, whole=not fails), (
            f"{line!r} is not in the output of {command!r}:\n" + "\n".join(printed)
        )
    if "qp-osc" in runs and "--wrench" in command:
        _check_push(runs)
    elif "qp-osc" in runs:
        _check_demo(runs)
    elif "mpc" in runs:
        _check_demo_a(runs)
    elif "saved" in runs:
        _check_saved_mpc_run(runs["saved"])


def _check_demo_a(runs: dict[str, Any]) -> None:
    """Demo (a) from compare's runs: mpc keeps every commanded torque within its limit, crosses
    joint 2's velocity limit by less than half of computed-torque's excess (its model 20 % light)
    and has the lower RMS error on both joints; computed-torque takes joint 2 past 10.1 rad/s."""
    limits = joint_limits(load_robot())
    mpc, ct = runs["mpc"], runs["computed-torque"]
    assert limits.excess(EFFORT, mpc.tau_command).max() <= 0
    assert limits.excess(VELOCITY, ct.v)[:, 1].max() > 0.1
    assert limits.excess(VELOCITY, mpc.v).max() < 0.5 * limits.excess(VELOCITY, ct.v).max()
    rms = {name: np.sqrt(np.mean(run.e**2, axis=0)) for name, run in runs.items()}
    assert (rms["mpc"] < rms["computed-torque"]).all(), rms


def _check_saved_mpc_run(run: Any) -> None:
    """The saved file of demo (a)'s mpc run, every step of it: no commanded torque beyond its
    effort limit, joint 1's velocity within its limit (joint 2 crosses at the path's switches,
    its model 20 % light: the page says by how much); and it is the mpc run (its plan and its
    observer are its state)."""
    limits = joint_limits(load_robot())
    assert run.controller == "mpc" and run.t.size == 2113  # every 1-ms step of 2.112 s
    assert limits.excess(EFFORT, run.tau_command).max() <= 0
    assert limits.excess(VELOCITY, run.v)[:, 0].max() < 0
    # t_plan, replans, the deviation's q0, q̇0, its a_k at 8 knots, the observer's d̂ and ê
    assert run.state.shape[1] == 2 + 2 * 2 + 8 * 2 + 2 * 2


def _check_push(runs: dict[str, Any]) -> None:
    """The pushed Panda (150 N down on the hand, 0.5-1.5 s): qp-osc finishes with every
    commanded torque within its limit on every step, and its largest joint-limit excess
    (position [rad], velocity [rad/s]) is smaller than osc's, which also asks for more torque
    than the motors have."""
    limits = joint_limits(load_robot("panda"))
    qp, osc = runs["qp-osc"], runs["osc"]
    assert qp.t[-1] == osc.t[-1] == 4.0
    assert limits.excess(EFFORT, qp.tau_command).max() <= 0
    assert limits.excess(EFFORT, osc.tau_command).max() > 0
    for kind, of in ((POSITION, "q"), (VELOCITY, "v")):
        worst = {
            name: limits.excess(kind, getattr(run, of)).max() for name, run in (("qp", qp), ("osc", osc))
        }
        assert worst["qp"] < worst["osc"], (kind, worst)


def _check_demo(runs: dict[str, Any]) -> None:
    """Demo (b) from compare's own runs: qp-osc inside every limit (positions and commanded
    torques exactly, velocities and accelerations to RK4's rounding: 1e-6 rad/s, and a central
    difference of the recorded velocity to 1e-6 rad/s²); osc past joint 4's range by more than
    0.1 rad and above joint 6's effort limit."""
    limits = joint_limits(load_robot("panda", payload=3.0))
    qp, osc = runs["qp-osc"], runs["osc"]
    assert limits.excess(POSITION, qp.q).max() < 0
    assert limits.excess(EFFORT, qp.tau_command).max() < 0
    assert limits.excess(VELOCITY, qp.v).max() < 1e-6
    accel = (qp.v[2:] - qp.v[:-2]) / (qp.t[2:] - qp.t[:-2])[:, None]
    assert limits.excess(ACCELERATION, accel).max() < 1e-6
    assert limits.excess(POSITION, osc.q)[:, 3].max() > 0.1  # the elbow past its range
    assert limits.excess(EFFORT, osc.tau_command)[:, 5].max() > 5.0  # joint 6 above its 12 N·m
    assert np.abs(osc.v).max(axis=0)[0] > 2 * limits.velocity[0]  # and the base twice its speed


def test_the_quoted_numbers_are_compared_to_a_stated_tolerance_not_digit_by_digit() -> None:
    """What an AMD EPYC printed for the page's mpc run (0.03248 for 0.03249, 134.557 for
    134.556 N·m) matches the page; a difference the page's claims would notice (1 %), other
    words, or another integer (a joint, a count of iterations) does not."""
    quoted = "| mpc | 0.03249 | 0.03423 | 0.2991 | 0.6225 | 134.6 | 30.54 |"
    saved = "  RMS  e (0.03249, 0.03423) rad   edot (0.29906, 0.62248) rad/s   tau (134.556, 30.540) N·m"
    assert quoted_in(quoted, ["| mpc | 0.03248 | 0.03423 | 0.2991 | 0.6225 | 134.6 | 30.54 |"])
    assert quoted_in(saved, [saved.replace("134.556", "134.557")])
    assert not quoted_in(quoted, ["| mpc | 0.03281 | 0.03423 | 0.2991 | 0.6225 | 134.6 | 30.54 |"])
    assert not quoted_in(quoted, ["| pd | 0.03249 | 0.03423 | 0.2991 | 0.6225 | 134.6 | 30.54 |"])
    assert not quoted_in("failed after 15 iterations", ["x: failed after 16 iterations"], whole=False)
    assert quoted_in("failed after 15 iterations", ["x: failed after 15 iterations: y"], whole=False)
