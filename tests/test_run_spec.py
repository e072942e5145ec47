"""Tests of twolink_pin.run_spec: one description of a run, built in one place.

The pattern for a new run option (README, layout): a test that the option, given on the
command line, reaches the built plant or law — parse the arguments as the CLI does, build
the spec with :func:`twolink_pin.cli.commands.common.run_spec`, build the scenario and look
at the object that the option must change (see ``test_an_option_reaches_the_plant``).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.cli.commands.common import run_spec
from twolink_pin.cli.parser import build_parser
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot
from twolink_pin.run_spec import PlantOptions, RunSpec, make_scenario
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.trajectory import default_trajectory

ROBOT = load_robot()


def _spec(*argv: str, law: str | None = "pd") -> RunSpec:
    args = build_parser().parse_args(list(argv))
    return run_spec(args, law if argv[0] != "compare" else None)


@pytest.mark.parametrize(
    ("option", "plant_has_friction", "saturates"),
    [
        ((), False, False),  # pd estimates no friction: the report's plant has none
        (("--plant-friction", "on"), True, False),
        (("--saturate",), False, True),
    ],
)
def test_an_option_reaches_the_plant(
    option: tuple[str, ...], plant_has_friction: bool, saturates: bool
) -> None:
    """The pattern: argv → run_spec → build → the plant the option changes."""
    plant = _spec("simulate", "pd", *option).build(ROBOT).plant
    assert (plant.friction is not None) is plant_has_friction
    assert plant.saturate is saturates
    if plant_has_friction:
        assert plant.friction is not None
        assert np.allclose(plant.friction.viscous, ROBOT.profile.friction[0])


def test_plant_friction_off_removes_it_for_a_law_that_estimates_it() -> None:
    """`adaptive-friction` runs on the profile's friction by default; `--plant-friction off`
    takes it out of the plant (the law's own belief is unchanged)."""
    default = _spec("simulate", "adaptive-friction", law="adaptive-friction").build(ROBOT)
    off = _spec("simulate", "adaptive-friction", "--plant-friction", "off", law="adaptive-friction").build(
        ROBOT
    )
    assert default.plant.friction is not None and off.plant.friction is None


def test_a_gain_and_lambda_reach_the_law() -> None:
    """--gain and --lambda on the command line are the law's gains after build."""
    law = _spec("simulate", "pd", "--gain", "kp=200", "--gain", "kd=30,40")
    controller = law.build(ROBOT).controller
    assert np.allclose(controller.gains.kp, 200.0 * np.eye(2))  # matrix gains: 200 I, diag(30, 40)
    assert np.allclose(controller.gains.kd, np.diag([30.0, 40.0]))
    adaptive = _spec("simulate", "adaptive", "--lambda", "3", law="adaptive").build(ROBOT).controller
    assert float(np.asarray(adaptive.gains.lam)) == 3.0


def test_the_spec_builds_what_make_scenario_builds_and_runs_the_same() -> None:
    """RunSpec.build with no option is make_scenario with the same settings: the same run,
    bit for bit (the report's numbers depend on it)."""
    config = SimulationConfig(duration=0.3)
    spec = RunSpec(law="adaptive", lam=4.0, simulation=config)
    a = simulate(*spec.build(ROBOT), default_trajectory(ROBOT), config)
    b = simulate(*make_scenario("adaptive", ROBOT, lam=4.0), default_trajectory(ROBOT), config)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.tau, b.tau)


def test_a_shared_spec_gives_lambda_and_gains_to_the_laws_they_belong_to() -> None:
    """compare: λ goes to the laws with one, pd.kp only to pd; a gain of a law not run is refused."""
    shared = _spec("compare", "--lambda", "3", "--gain", "pd.kp=123")
    assert shared.shared and shared.law is None
    pd = shared.for_law("pd")
    assert pd.lam is None and dict(pd.gains) == {"kp": 123.0}
    adaptive = shared.for_law("adaptive")
    assert adaptive.lam == 3.0 and adaptive.gains == ()
    assert np.allclose(pd.build(ROBOT).controller.gains.kp, 123.0 * np.eye(2))
    with pytest.raises(InvalidParameterError, match="a law that runs here"):
        shared.check_law_gains(["adaptive", "computed-torque"])


def test_a_gain_without_its_law_is_refused_in_compare(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["compare", "pd", "--gain", "kp=200", "--duration", "0.1", "--no-plot", "--out", "x"]) == 2
    assert "LAW.NAME=VALUE" in capsys.readouterr().err


def test_the_spec_survives_json_and_refuses_bad_values() -> None:
    spec = RunSpec(
        law="pd",
        gains=(("kd", (30.0, 40.0)),),
        lam=None,
        plant=PlantOptions(friction="on", saturate=True, friction_smoothing=0.01),
        simulation=SimulationConfig(duration=2.0, q0_offset=(0.1, -0.2)),
    )
    assert RunSpec.from_dict(json.loads(json.dumps(spec.as_dict()))) == spec
    with pytest.raises(InvalidParameterError, match="plant friction"):
        PlantOptions(friction="sometimes")
    with pytest.raises(InvalidParameterError, match="parameters_use"):
        RunSpec(law="pd", parameters="p.json")
    assert replace(spec, plant=PlantOptions()).friction_smoothing == 0.0
    assert RunSpec(simulation=SimulationConfig(method="adaptive")).friction_smoothing == 1e-3


def test_animate_from_a_saved_ur5_run_needs_nothing_else(tmp_path: Path) -> None:
    """simulate --save records the robot; animate --from replays it without --robot."""
    saved = tmp_path / "run.npz"
    assert main(["simulate", "pd", "--robot", "ur5", "--duration", "0.05", "--save", str(saved)]) == 0
    html = tmp_path / "a.html"
    assert main(["animate", "--from", str(saved), "--html", str(html)]) == 0
    assert "ur5" in html.read_text(errors="replace").lower()


def test_a_urdf_of_yours_starts_off_its_reference_and_the_twolink_keeps_the_reports(tmp_path: Path) -> None:
    """docs/any_robot.md: ±0.05 rad alternating for a robot with no preset; the twolink keeps
    the course report's 0.1 and −0.1 rad (its report scenarios do not change)."""
    from twolink_pin.model.profile import DEFAULT_Q0_OFFSET

    arm = tmp_path / "arm.urdf"
    arm.write_text(Path(str(ROBOT.urdf_path)).read_text())
    mine = load_robot(str(arm))
    assert mine.name == "arm" and DEFAULT_Q0_OFFSET == 0.05
    assert mine.profile.q0_offset == (0.05, -0.05)
    assert ROBOT.profile.q0_offset == (0.1, -0.1)  # the report's, Section 5
    result = simulate(*make_scenario("pd", mine), default_trajectory(mine), SimulationConfig(duration=0.01))
    assert np.allclose(result.q[0] - result.q_des[0], (0.05, -0.05))


def test_simulate_echoes_the_gains_it_used(capsys: pytest.CaptureFixture[str]) -> None:
    """The twolink's pd runs with the report's Kp = (350, 300), Kd = (40, 50): --json says so."""
    assert main(["simulate", "pd", "--duration", "0.01", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["gains"] == {"kp": [350.0, 300.0], "kd": [40.0, 50.0]}
    assert payload["q0_offset"] == [0.1, -0.1] and payload["plant"] == "no friction"


def test_sweep_and_animate_echo_the_gains_they_used(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """sweep and animate say the gains as simulate does: the report's Kp = (350, 300),
    Kd = (40, 50) for the twolink's pd, a --gain where given (text and --json); the sweep's
    drawn ranges stay its "gains"; animate --from rebuilds them from the run the file records."""
    argv = ["sweep", "pd", "--samples", "2", "--duration", "0.02", "--gain", "kd=30:60"]
    assert main([*argv, "--out", str(tmp_path / "s"), "--no-plot", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["gains_used"] == {"kp": [350.0, 300.0], "kd": [40.0, 50.0]}
    assert payload["gains"] == {"kd": [30.0, 60.0]}
    assert main([*argv, "--out", str(tmp_path / "t"), "--no-plot"]) == 0
    text = capsys.readouterr().out
    assert "gains kp = (350, 300)" in text and "kd drawn per run from U(30, 60)" in text
    html, saved = tmp_path / "a.html", tmp_path / "run.npz"
    assert (
        main(["animate", "pd", "--gain", "kp=200", "--duration", "0.02", "--html", str(html), "--json"]) == 0
    )
    # kp=200 on a matrix gain is 200 I: shown by its diagonal, as --gain takes it back
    assert json.loads(capsys.readouterr().out)["gains"] == {"kp": [200.0, 200.0], "kd": [40.0, 50.0]}
    assert main(["simulate", "pd", "--gain", "kp=210", "--duration", "0.02", "--save", str(saved)]) == 0
    capsys.readouterr()
    assert main(["animate", "--from", str(saved), "--html", str(html)]) == 0
    assert "pd gains kp = (210, 210) " in capsys.readouterr().out  # 210 I: by its diagonal


BLOWUP = """
from dataclasses import dataclass

from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput


@dataclass(frozen=True, eq=False)
class BlowupGains(Gains):
    pass


class Blowup(Controller[BlowupGains]):
    name = "blowup"
    title = "blows up"
    Gains = BlowupGains

    def compute(self, x: LawInput, terms: object) -> LawOutput:
        return LawOutput(1e9 * (x.q - x.q_des))
"""


def test_compare_keeps_the_laws_that_finished(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A law that diverges is a row saying when; the others' rows are written; exit status 1."""
    (tmp_path / "blowup.py").write_text(BLOWUP)
    out = tmp_path / "cmp"
    argv = ["compare", "pd", "computed-torque", f"{tmp_path}/blowup.py:Blowup", "--duration", "0.2"]
    argv += ["--no-step-check"]  # the step check would refuse blowup before any run (exit 2)
    assert main([*argv, "--no-plot", "--out", str(out), "--json"]) == 1
    captured = capsys.readouterr()
    said = [line for line in captured.err.split("\n") if "twolink-pin:" in line]
    assert captured.out == "" and len(said) == 1  # a failed run: one line (besides the progress bar)
    assert "blowup: simulation with controller 'blowup' diverged at t = " in captured.err
    payload = json.loads((out / "comparison.json").read_text())
    assert sorted(payload["controllers"]) == ["computed-torque", "pd"]
    assert "diverged at t = " in payload["failed"]["blowup"]
    table = (out / "comparison.csv").read_text()
    assert "pd,rms," in table and "blowup,failed," in table
    # the finished laws' numbers are those of a comparison without the failing law
    assert (
        main(
            [
                "compare",
                "pd",
                "computed-torque",
                "--duration",
                "0.2",
                "--no-plot",
                "--out",
                str(tmp_path / "b"),
                "--json",
            ]
        )
        == 0
    )
    alone = json.loads(capsys.readouterr().out)
    assert alone["controllers"] == payload["controllers"]
    assert set(payload["plants"].values()) == {"no friction"} and len(payload["plants"]) == 3


RAISER = """
from dataclasses import dataclass

from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput


@dataclass(frozen=True, eq=False)
class RaiserGains(Gains):
    pass


class Raiser(Controller[RaiserGains]):
    name = "raiser"
    title = "raises"
    Gains = RaiserGains

    def compute(self, x: LawInput, terms: object) -> LawOutput:
        if x.t > 0.01:
            raise ZeroDivisionError("my bug")
        return LawOutput(0 * x.q)
"""

NOT_A_DATACLASS = """
from typing import Any

from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput
from twolink_pin.controllers.gains import gain


class PlainGains(Gains):
    kp: Any = gain(1.0, per="joint", unit="N·m/rad", doc="kp")


class Plain(Controller[PlainGains]):
    name = "plain-gains"
    title = "gains without @dataclass"
    Gains = PlainGains

    def compute(self, x: LawInput, terms: object) -> LawOutput:
        return LawOutput(-self.gains.kp * (x.q - x.q_des))
"""


def test_a_law_that_raises_is_named_with_its_file_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """One line with the law's file and the line that raised; --debug adds its traceback."""
    monkeypatch.delenv("TWOLINK_PIN_DEBUG", raising=False)
    law = tmp_path / "raiser.py"
    law.write_text(RAISER)
    line = RAISER.splitlines().index('            raise ZeroDivisionError("my bug")') + 1
    assert main(["simulate", f"{law}:Raiser", "--duration", "0.05"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"raised at {law}:{line} in compute" in err
    assert main(["--debug", "simulate", f"{law}:Raiser", "--duration", "0.05"]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and f'File "{law}", line {line}' in err


def test_a_gains_class_that_is_not_a_dataclass_is_refused_by_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    law = tmp_path / "plain.py"
    law.write_text(NOT_A_DATACLASS)
    assert main(["simulate", f"{law}:Plain", "--duration", "0.05"]) == 2
    err = capsys.readouterr().err
    assert "PlainGains" in err and "must be a dataclass" in err and "Traceback" not in err
