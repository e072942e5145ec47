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


def test_a_sweep_against_a_wall_has_the_contact_columns(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Each row carries the contact metrics; a run never in contact has none (null), and the
    summary's statistics are over the runs that have them."""
    out = tmp_path / "sweep"
    argv = [
        "sweep",
        "pd",
        "--samples",
        "3",
        "--duration",
        "0.3",
        "--wall",
        "0.9,0,0:-1,0,0",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    capsys.readouterr()
    rows = json.loads((out / "runs.json").read_text())
    assert all(row["contact_time_in_contact"] == 0 and row["contact_force_rms_error"] is None for row in rows)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["metrics"]["contact_force_rms_error"] == {"median": None, "p5": None, "p95": None}
    assert summary["metrics"]["contact_max_penetration_mm"]["median"] == 0


def test_the_animation_draws_the_surfaces_and_the_contact_force() -> None:
    from twolink_pin.visualization.motion import prepare_motion
    from twolink_pin.visualization.overlays import run_overlays
    from twolink_pin.visualization.scene import scene_commands

    scene = read_scene(SCENE)
    t = np.linspace(0.0, 1.0, 11)
    q = np.tile(ROBOT.home + np.array([0.0, 0.6]), (11, 1))
    contact = np.zeros((11, 6))
    contact[5:, 0] = 10.0  # pressing the wall with 10 N from t = 0.5 s
    overlays = run_overlays(None, t, scene, contact)
    np.testing.assert_array_equal(overlays["wrench"][6], [-10.0, 0.0, 0.0])  # the wall's push on the arm
    motion = prepare_motion(ROBOT, t, q, q, None, 10.0, **overlays)
    drawn = scene_commands(ROBOT, motion)
    paths = {str(c.get("path", "")) for c in drawn.commands}
    assert any("surfaces/wall" in p for p in paths) and any("wrench" in p for p in paths)
    assert drawn.wrench_scale is not None


def test_tunes_simulate_line_names_the_scene() -> None:
    from twolink_pin.cli.simulate_line import simulate_argv

    spec = RunSpec(law="hybrid", plant=PlantOptions(scene=read_scene(SCENE)))
    assert simulate_argv(spec, scene=SCENE)[-1] == f"--scene={SCENE}"
    from twolink_pin.cli.contact_options import wall

    plane = RunSpec(law="pd", plant=PlantOptions(scene=wall("0.9,0,0:-1,0,0:2000:30:0.1")))
    token = simulate_argv(plane)[-1]
    assert token.startswith("--wall=") and wall(token.removeprefix("--wall=")) == plane.plant.scene


def test_the_lab_script_prints_its_table_and_draws_its_figure(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "contact_lab", EXAMPLES.parent / "scripts" / "contact_lab.py"
    )
    assert spec is not None and spec.loader is not None
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    script.main(["--robots", "twolink", "--duration", "1.5", "--out", str(tmp_path)])
    table = capsys.readouterr().out.strip().splitlines()
    rows = [(row.split("|")[1].strip(), row.split("|")[2].strip()) for row in table[2:]]
    laws = ["hybrid", "force", "impedance"]
    assert rows == [(law, plant) for plant in ("pinocchio", "mujoco") for law in laws]
    assert (tmp_path / "contact_twolink.png").is_file()
    assert (tmp_path / "contact_twolink_mujoco.png").is_file()


def test_the_reports_contact_table_reads_results_json_and_a_line_reference_has_no_coefficients() -> None:
    """The report's contact table is results.json's contact metrics (— where a metric is
    undefined); a straight-line reference (a PoseTrajectory) has no polynomial coefficients to show
    (the report failed on one before)."""
    from twolink_pin.contact_metrics import CONTACT_UNITS
    from twolink_pin.report.build import _trajectory_facts  # the function under test
    from twolink_pin.report.pages import _contact_table

    metrics = dict.fromkeys(CONTACT_UNITS, 1.5) | {"force_rms_error": None}
    table = _contact_table(
        {"controllers": {"hybrid": {"contact_metrics": metrics}, "pd": {"contact_metrics": None}}}
    )
    assert table is not None and [row[0] for row in table["rows"]] == ["hybrid"]
    assert table["rows"][0][1] == "—" and table["headers"][1] == "RMS force error [N]"
    facts = _trajectory_facts(read_trajectory_file(SLIDE, ROBOT), None, [])
    assert facts["coefficients"] is None and len(facts["times"]) == 7


def test_tunes_view_draws_the_surfaces_and_the_contact_force() -> None:
    """The tuner in-process (no browser) on hybrid against the wall: its first run reports the
    contact's line, and its Viser scene holds the wall and the contact force's arrows."""
    import queue

    from twolink_pin.cli.simulate_line import command_line, simulate_argv
    from twolink_pin.tuning import Tuner

    reference = read_trajectory_file(SLIDE, ROBOT)
    lines: queue.Queue[dict[str, object]] = queue.Queue()
    spec = RunSpec(
        law="hybrid",
        plant=PlantOptions(scene=read_scene(SCENE)),
        simulation=SimulationConfig(duration=1.5, q0_offset=0.0),
    )
    tuner = Tuner(
        spec,
        0.0,
        lambda payload: (ROBOT, reference),
        lambda spec, payload: command_line(simulate_argv(spec, None, payload, SLIDE, SCENE)),
        lambda spec, payload: {},
        lines.put,
    )
    try:
        first = lines.get(timeout=120)
        scene = tuner.scene
        assert [h.name for h in scene._surface_handles] == ["/surfaces/wall"]
        assert scene._arrows is not None and np.ptp(scene._arrows[:, 1] - scene._arrows[:, 0]) > 0
    finally:
        tuner.close()
    assert f"--scene={SCENE}" in str(first["command"])
