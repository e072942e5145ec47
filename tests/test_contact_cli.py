"""The contact on the command line: ``--scene``, ``--wall``, a trajectory's ``force`` column, the
force sensor's noise; the lab's files in ``examples/``; every refusal one line (exit 2), a
contact too stiff for the step a failed run (exit 1)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest_sim import ROBOT

from twolink_pin.cli import main
from twolink_pin.contact import read_scene
from twolink_pin.contact_metrics import contact_metrics
from twolink_pin.run_spec import PlantOptions, RunSpec
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.storage import load_result
from twolink_pin.trajectory import read_trajectory_file

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCENE = str(EXAMPLES / "wall.toml")
SLIDE = str(EXAMPLES / "wall_slide.toml")
LAB = ["--scene", SCENE, "--trajectory", SLIDE, "--q0-offset", "0"]


def _error(capsys: pytest.CaptureFixture[str], argv: list[str], code: int = 2) -> str:
    try:
        assert main(argv) == code
    except SystemExit as exit_:
        assert exit_.code == code
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_simulate_against_the_wall_gives_the_librarys_run_and_saves_the_contact(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    saved = tmp_path / "run.npz"
    argv = ["simulate", "hybrid", "--duration", "2", *LAB, "--save", str(saved), "--json"]
    assert main(argv) == 0
    payload = json.loads(capsys.readouterr().out)
    spec = RunSpec(
        law="hybrid",
        plant=PlantOptions(scene=read_scene(SCENE)),
        simulation=SimulationConfig(2.0, q0_offset=0.0),
    )
    expected = contact_metrics(
        simulate(*spec.build(ROBOT), read_trajectory_file(SLIDE, ROBOT), spec.simulation), ROBOT
    )
    assert expected is not None
    for key, value in expected.as_dict().items():
        assert payload["contact_metrics"][key] == pytest.approx(value, rel=1e-12), key
    result = load_result(saved)  # the saved run keeps the contact, as recorded
    assert result.wrench is not None and result.penetration is not None and result.force_des is not None
    assert contact_metrics(result, ROBOT) == pytest.approx(expected)


def test_the_force_sensors_noise_is_recorded_and_has_its_deviation(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    saved = tmp_path / "noisy.npz"
    argv = ["simulate", "force", "--duration", "2", *LAB, "--sensor-noise", "0,0,0.5", "--save", str(saved)]
    assert main(argv) == 0
    capsys.readouterr()
    result = load_result(saved)
    assert result.wrench_measured is not None and result.wrench is not None
    noise = result.wrench_measured - result.wrench
    assert np.std(noise[:, :3]) == pytest.approx(0.5, rel=0.05)
    assert np.all(noise[:, 3:] == 0)


def test_compare_runs_the_lab_side_by_side(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "lab"
    argv = ["compare", "hybrid", "impedance", "--duration", "2", *LAB, "--out", str(out), "--json"]
    assert main([*argv, "--gain", "impedance.k=1000"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert set(payload["contact_metrics"]) == {"hybrid", "impedance"}
    assert (out / "figures" / "contact.png").is_file()
    assert "contact: the force held" in (out / "comparison.md").read_text()


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--wall", "0.5,0,0:0,0,0"], "non-zero direction"),
        (["--wall", "0.5,0,0:nan,0,0"], "finite"),
        (["--wall", "0.5,0,0:inf,0,0"], "finite"),
        (["--wall", "0.5,0,0:-1,0,0:-10"], "stiffness"),
        (["--wall", "0.5,0,0:-1,0,0:1000:-1"], "damping"),
        (["--wall", "0.5,0,0:-1,0,0:1000:10:-0.3"], "Coulomb"),
        (["--wall", "0.5,0,0"], "X,Y,Z:NX,NY,NZ"),
        (["--scene", SCENE, "--wall", "0.9,0,0:-1,0,0"], "one of --scene FILE and --wall"),
        (["--wall", "0.49,0,0:-1,0,0", "--q0-offset", "0"], "mm inside surface 'wall'"),
        (["--sensor-noise", "0,0,1"], "a force sensor"),
        (["--trajectory", SLIDE], "a surface to press on"),
    ],
)
def test_bad_contact_input_is_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], argv: list[str], said: str
) -> None:
    assert said in _error(capsys, ["simulate", "pd", "--duration", "0.05", *argv])


def test_a_force_law_or_reference_where_it_means_nothing_is_refused(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert "controls a contact force" in _error(capsys, ["simulate", "hybrid", "--duration", "0.05"])
    err = _error(capsys, ["simulate", "force", "--duration", "0.05", "--wall", "0.6,0,0:-1,0,0"])
    assert "'force' column" in err
    err = _error(capsys, ["simulate", "impedance", "--duration", "0.05", *LAB])
    assert "a law that controls a force (force, hybrid)" in err


def test_a_contact_too_stiff_for_the_step_fails_the_run_naming_the_limit(
    capsys: pytest.CaptureFixture[str],
) -> None:
    err = _error(
        capsys,
        ["simulate", "hybrid", "--duration", "2", "--trajectory", SLIDE, "--q0-offset", "0", "--wall",
         "0.55,0,0:-1,0,0:1e9:0"],
        code=1,
    )  # fmt: skip
    assert "contact with surface 'wall' at t = " in err and "largest stable stiffness at --dt 0.001 s" in err
