"""The run options: the parser's run-option group and the run description agree, the plant is
one frozen value, and an option either acts or is refused (issue 28 §1, §4; issue 30).

Every option of the parser's ``run options`` group (``cli.common_options.run_group``) must
change the :class:`~twolink_pin.run_spec.RunSpec` the command builds, and every field of the
spec must be reachable from some option: a new option added to one side only fails here.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.cli.commands.common import run_spec
from twolink_pin.cli.common_options import run_option_strings
from twolink_pin.cli.parser import build_parser
from twolink_pin.disturbances import PayloadStep
from twolink_pin.model import example_robot_urdf, load_robot
from twolink_pin.plant import DEFAULT_FRICTION, Plant
from twolink_pin.simulation.events import payload_plant

SAMPLES = {
    "--duration": ["--duration", "2"],
    "--dt": ["--dt", "0.002"],
    "--lambda": ["--lambda", "7"],
    "--q0-offset": ["--q0-offset", "0.2"],
    "--saturate": ["--saturate"],
    "--joint-stops": ["--joint-stops"],
    "--method": ["--method", "adaptive"],
    "--control-period": ["--control-period", "0.01"],
    "--friction-smoothing": ["--friction-smoothing", "0.01"],
    "--plant-friction": ["--plant-friction", "on"],
    "--gain": ["--gain", "k=3"],
    "--p0": ["--p0", "p.json"],
    "--model": ["--model", "p.json"],
    "--wrench": ["--wrench", "1,0,0@0:1"],
    "--payload-step": ["--payload-step", "1@0.5"],
    "--sensor-noise": ["--sensor-noise", "0.001"],
    "--noise-seed": ["--sensor-noise", "0.001", "--noise-seed", "5"],
    "--delay": ["--delay", "2"],
    "--plant": ["--plant", "mujoco"],
    "--armature": ["--armature", "0.1"],
    "--joint-damping": ["--joint-damping", "0.5"],
    "--frictionloss": ["--plant", "mujoco", "--frictionloss", "0.2"],
    "--soft-limits": ["--plant", "mujoco", "--soft-limits", "off"],
    "--solref": ["--plant", "mujoco", "--solref", "0.01,1"],
    "--solimp": ["--plant", "mujoco", "--solimp", "0.8,0.9,0.01"],
    "--mujoco-integrator": ["--plant", "mujoco", "--mujoco-integrator", "euler"],
    "--believe-effects": ["--armature", "0.1", "--believe-effects"],
}
"""A non-default value of each run option (a new option needs one here)."""
NOT_FROM_OPTIONS = {"law", "law_gains", "shared", "parameters_use", "rtol", "atol", "v0_offset"}
"""Fields of the run description set by the command, not by one run option of ``simulate``
(the law is its argument; per-law gains and ``shared`` belong to ``compare``; the use of a
parameter file follows from ``--p0``/``--model``; tolerances of the adaptive integrator and the
initial velocity offset are library settings without an option)."""


def _simulate_parser() -> argparse.ArgumentParser:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices["simulate"]


def _fields(spec_dict: dict, prefix: str = "") -> dict[str, object]:
    flat: dict[str, object] = {}
    for key, value in spec_dict.items():
        if isinstance(value, dict) and key in ("plant", "simulation"):
            flat |= _fields(value, f"{key}.")
        else:
            flat[prefix + key] = value
    return flat


def test_every_run_option_changes_the_run_and_every_field_has_an_option() -> None:
    """The parser's run-option group and RunSpec agree both ways (fails when a parser line or a
    field is added without the other)."""
    options = run_option_strings(_simulate_parser())
    assert options, "simulate has no run-option group"
    missing = sorted(options - SAMPLES.keys())
    assert not missing, f"give a sample value in SAMPLES for the new run option(s) {missing}"
    default = _fields(
        run_spec(build_parser().parse_args(["simulate", "computed-torque"]), "computed-torque").as_dict()
    )
    reached: set[str] = set()
    for option in sorted(options):
        args = build_parser().parse_args(["simulate", "computed-torque", *SAMPLES[option]])
        changed = {
            k for k, v in _fields(run_spec(args, "computed-torque").as_dict()).items() if v != default.get(k)
        }
        assert changed, f"{option} does not reach the run description (RunSpec)"
        reached |= changed
    unreached = (
        {k.rpartition(".")[2] for k in default} - {k.rpartition(".")[2] for k in reached} - NOT_FROM_OPTIONS
    )
    assert not unreached, f"RunSpec fields no run option sets: {sorted(unreached)}"


def test_animate_from_refuses_exactly_the_run_options(tmp_path, capsys) -> None:
    """animate --from takes the refused options from the parser's group, not a hand-kept list."""
    args = build_parser().parse_args(["animate", "--from", "x.npz"])
    assert args.run_options == run_option_strings(_simulate_parser())
    assert main(["animate", "--from", str(tmp_path / "x.npz"), "--delay", "3"]) == 2
    assert "--delay" in capsys.readouterr().err


def test_the_plant_is_frozen_and_its_variants_are_replacements() -> None:
    robot = load_robot()
    plant = Plant(robot, payload_step=PayloadStep(1.0, 0.5))
    with pytest.raises(dataclasses.FrozenInstanceError):
        plant.saturate = True  # type: ignore[misc]
    heavier = payload_plant(plant)
    assert heavier.model is not plant.model and plant.model is robot.model
    # the payload's mass is carried by the model after the step: 1 kg more in total
    total = sum(inertia.mass for inertia in heavier.model.inertias) - sum(
        i.mass for i in plant.model.inertias
    )
    assert total == pytest.approx(1.0, abs=1e-12)


def test_load_robot_reads_the_urdf_damping_and_friction() -> None:
    """RobotModel.urdf_friction equals the URDF's <dynamics> read as XML (a second reader)."""
    path = example_robot_urdf("panda_description/urdf/panda.urdf")
    root = ET.parse(path).getroot()
    damping = {
        j.get("name"): float(
            (j.find("dynamics").get("damping") or 0.0) if j.find("dynamics") is not None else 0.0
        )
        for j in root.iter("joint")
    }
    robot = load_robot("panda")
    names = [robot.model.names[j] for j in range(1, robot.model.njoints)]
    friction = robot.urdf_friction
    assert friction is not None
    np.testing.assert_allclose(friction[0], [damping[n] for n in names], rtol=0, atol=0)
    assert load_robot("ur5").urdf_friction is None


def _simulate(capsys, *argv: str) -> dict:
    assert main(["simulate", "pd", "--duration", "0.3", "--json", *argv]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("robot", ["ur5", "twolink"])
def test_plant_friction_on_applies_friction_on_every_robot(capsys, robot: str) -> None:
    """--plant-friction on is never a silent no-op: the plant has friction (the UR5: the stated
    default, no friction in its URDF; the twolink: its profile's), the JSON says which, and the
    run differs from the frictionless one."""
    on = _simulate(capsys, "--robot", robot, "--plant-friction", "on")
    plain = _simulate(capsys, "--robot", robot)
    nv = len(on["torque_limits"])
    expected = (
        ([DEFAULT_FRICTION[0]] * nv, [DEFAULT_FRICTION[1]] * nv)
        if robot == "ur5"
        else ([0.4, 0.2], [0.2, 0.1])
    )
    assert on["plant_friction"]["viscous"] == expected[0]
    assert on["plant_friction"]["coulomb"] == expected[1]
    assert plain["plant_friction"] is None and on["plant"] == "friction" and plain["plant"] == "no friction"
    assert not np.allclose(on["metrics"]["rms"]["e"], plain["metrics"]["rms"]["e"], rtol=1e-6, atol=0)


def test_the_text_summary_names_the_friction_values(capsys) -> None:
    assert main(["simulate", "pd", "--robot", "ur5", "--duration", "0.05", "--plant-friction", "on"]) == 0
    out = capsys.readouterr().out
    assert (
        "plant friction V = (0.4, 0.4, 0.4, 0.4, 0.4, 0.4) N·m·s/rad, C = (0.2, 0.2, 0.2, 0.2, 0.2, 0.2) N·m"
        in out
    )
    assert "the default (no friction in the URDF)" in out


def test_a_saved_noisy_run_records_what_the_law_measured_and_identify_uses_it(tmp_path, capsys) -> None:
    """simulate --save --sensor-noise keeps q_measured, v_measured: q, v plus the noise drawn from
    the run's own generator (SensorNoise.generators, the engine's stream); identify --data on it
    fits what was measured and says so: its residual is the noise's, not the ~0 of the true state."""
    from twolink_pin.disturbances import SensorNoise
    from twolink_pin.simulation.storage import load_result

    sigma_q, sigma_v = 1e-3, 1e-2
    noisy, clean = tmp_path / "noisy.npz", tmp_path / "clean.npz"
    common = ["simulate", "adaptive-friction", "--duration", "4"]
    assert (
        main([*common, "--sensor-noise", f"{sigma_q},{sigma_v}", "--noise-seed", "3", "--save", str(noisy)])
        == 0
    )
    assert main([*common, "--save", str(clean)]) == 0
    capsys.readouterr()
    result = load_result(noisy)
    assert result.q_measured is not None and result.v_measured is not None
    draws = SensorNoise(sigma_q, sigma_v, seed=3).generators(1)[0].standard_normal((result.t.size, 4))
    np.testing.assert_allclose(result.q_measured - result.q, sigma_q * draws[:, :2], rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.v_measured - result.v, sigma_v * draws[:, 2:], rtol=0, atol=1e-14)
    assert load_result(clean).q_measured is None

    def identified(path) -> dict:
        assert main(["identify", "--data", str(path), "--json"]) == 0
        return json.loads(capsys.readouterr().out)

    measured, true = identified(noisy), identified(clean)
    assert "q_measured, v_measured: what the law measured" in measured["source"]
    assert min(measured["residual_rms"]) > 100 * max(true["residual_rms"])


def test_model_accepts_a_urdf_the_law_believes_while_the_plant_stays_the_robot(tmp_path, capsys) -> None:
    """--model FILE.urdf: the law believes the URDF's inertias (here the twolink with 2 kg at the
    tool: its p is load_robot(payload=2).p), the plant stays the twolink, and every output names
    the believed model; a URDF of another arm is refused."""
    heavy = tmp_path / "heavy.urdf"
    assert main(["info", "--payload", "2", "--write-urdf", str(heavy)]) == 0
    capsys.readouterr()
    spec = run_spec(
        build_parser().parse_args(["simulate", "computed-torque", "--model", str(heavy)]), "computed-torque"
    )
    robot = load_robot()
    controller, plant = spec.build(robot)
    np.testing.assert_allclose(controller.believed_parameters(), load_robot(payload=2.0).p, rtol=1e-12)
    assert plant.model is robot.model
    saved = tmp_path / "run.npz"
    argv = ["simulate", "computed-torque", "--duration", "0.5", "--model", str(heavy)]
    assert main([*argv, "--save", str(saved)]) == 0
    assert f"law's model believes the inertias of the URDF {heavy} (--model); the plant is twolink's own" in (
        capsys.readouterr().out
    )
    assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["believed"] == {"file": str(heavy), "use": "model"}
    from twolink_pin.simulation.storage import load_record

    assert load_record(saved)["run"]["parameters"] == str(heavy)
    other = Path(__file__).parent / "corpus" / "urdf" / "arm3.urdf"
    assert main(["simulate", "computed-torque", "--duration", "0.1", "--model", str(other)]) == 2
    assert "expected twolink's" in capsys.readouterr().err
