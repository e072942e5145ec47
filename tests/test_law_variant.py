"""One law twice (issue 38 §6): the variant grammar ``LAW@KEY=VALUE…`` (twolink_pin/law_variant.py)
read and written back, its errors, and a variant's row in ``compare`` equal, number for number,
to ``simulate`` with the same options."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.cli import main
from twolink_pin.errors import ControllerSpecError, InvalidParameterError
from twolink_pin.law_variant import file_stem, format_variant, parse_variant, parse_variants
from twolink_pin.run_rows import build_rows
from twolink_pin.run_spec import RunSpec
from twolink_pin.scenario import law_class

SLIDING = str(Path(__file__).resolve().parents[1] / "examples" / "sliding_mode.py") + ":SlidingMode"


def test_a_variant_names_its_law_its_gains_and_its_model() -> None:
    v = parse_variant("pd@kp=200,150@kd=40")
    assert (v.law, v.name, v.key) == ("pd", "pd", "pd@kp=200,150@kd=40")
    assert v.gains == (("kp", (200.0, 150.0)), ("kd", 40.0)) and v.parameters is None
    plain = parse_variant("pd")
    assert plain.key == "pd" and plain.settings == ()
    model = parse_variant("computed-torque@model=runs@2/id.urdf")  # '@' in a path: no 'NAME=' after it
    assert (model.parameters, model.parameters_use, model.gains) == ("runs@2/id.urdf", "model", ())
    assert parse_variant("adaptive@p0=C:/x.json@k=30").settings == (("k", 30.0), ("p0", "C:/x.json"))


def test_a_law_files_variant_is_keyed_by_the_laws_name() -> None:
    """``file.py:Class@k=3``: the ':' of the file reference and of the class are the law's; the
    row is named by the law's registered name and the settings as written."""
    v = parse_variant(f"{SLIDING}@k=3@phi=0.1")
    assert v.law == SLIDING and v.key == "sliding-mode@k=3@phi=0.1"
    assert v.law_class() is law_class(SLIDING)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("pd@zeta=1", ("zeta", "a gain of 'pd' (kp, kd), model, p0 or a plant key")),
        ("pd@kp=1@kp=2", ("kp is given twice: '1' and '2'",)),
        ("pd@kp=", ("kp = ''", "a value after 'kp='")),
        ("pd@", ("'@'", "nothing follows it")),
        ("pd@kp", ("'kp' is no KEY=VALUE",)),
        (f"{SLIDING}@", ("nothing follows it",)),
        ("@kp=1", ("a law before the first '@'",)),
        ("pd@kp=abc", ("kp = 'abc'", "a number, got 'abc'")),
        ("pd@kd=nan", ("a finite number, got 'nan'",)),
        ("pd@p0=x.json", ("'pd' estimates none",)),
        ("adaptive@model=a.json@p0=b.json", ("one parameter file per run",)),
    ],
)
def test_a_bad_variant_is_refused_naming_what_is_wrong(text: str, words: tuple[str, ...]) -> None:
    with pytest.raises(InvalidParameterError) as caught:
        parse_variant(text)
    message = str(caught.value)
    assert message.startswith("variant ") and repr(text) in message
    for word in words:
        assert word in message


def test_an_unknown_law_in_a_variant_is_the_unknown_law_error() -> None:
    with pytest.raises(ControllerSpecError, match="no law of that name"):
        parse_variant("nolaw@kp=1")


def test_the_same_variant_twice_is_refused_in_any_order() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"each variant once: it is the same run as 'pd@kp=1@kd=2'"
    ):
        parse_variants(["pd@kp=1@kd=2", "pd@kd=2.0@kp=1"])
    with pytest.raises(InvalidParameterError, match="same run as 'pd'"):
        parse_variants(["pd", "pd"])
    assert [v.key for v in parse_variants(["pd", "pd@kp=1", "pd@kp=2"])] == ["pd", "pd@kp=1", "pd@kp=2"]


def test_format_variant_writes_the_changed_gains_in_order_and_reads_back() -> None:
    kp = np.array([[[150.0, 20.0, 0.0], [20.0, 150.0, 0.0], [0.0, 0.0, 80.0]]])  # as a law holds it
    text = format_variant("osc", {"kp": kp, "kd": 20.0}, defaults={"kd": np.eye(3)[None] * 20.0})
    assert text == "osc@kp=150,20,0,20,150,0,0,0,80"
    assert (
        format_variant("pd", {"kp": (350.0, 300.0), "kd": 40.0}, defaults={"kp": [[350, 300]]}) == "pd@kd=40"
    )
    assert format_variant("pd", {"kp": None, "kd": 40.0}) == "pd@kd=40"  # None: left to the robot
    assert format_variant("computed-torque", {"lam": 0.1 + 0.2}, model="id.urdf") == (
        "computed-torque@lam=0.30000000000000004@model=id.urdf"
    )
    with pytest.raises(InvalidParameterError, match="would start a setting"):
        format_variant("pd", model="x@kp=1.urdf")
    with pytest.raises(InvalidParameterError, match="one value set"):
        format_variant("pd", {"kp": np.ones((3, 2))})


@settings(max_examples=60, deadline=None)
@given(
    kp=st.lists(st.floats(1e-12, 1e12, allow_nan=False), min_size=1, max_size=2),
    lam=st.floats(1e-12, 1e12, allow_nan=False),
)
def test_format_then_parse_gives_back_the_same_numbers(kp: list[float], lam: float) -> None:
    text = format_variant("computed-torque", {"k": kp, "lam": lam})
    back = dict(parse_variant(text).gains)
    assert np.array_equal(np.atleast_1d(back["k"]), kp) and back["lam"] == lam


def test_file_stems_are_safe_and_distinct() -> None:
    keys = ["pd", "pd@kp=200,150", "pd@kp=200.150", "computed-torque@model=../a b/id.urdf"]
    stems = [file_stem(k) for k in keys]
    assert stems[0] == "pd" and len(set(stems)) == len(stems)
    assert all(
        set(s) <= set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") for s in stems
    )


def test_a_variants_settings_replace_the_shared_ones_in_the_one_builder() -> None:
    """``for_law(variant)``: its gains over ``--gain pd.kp``, its λ over ``--lambda``; the
    others' runs keep the shared values. A bad value names its row."""
    from twolink_pin.model import load_robot

    shared = RunSpec(
        shared=True, lam=3.0, law_gains=(("pd", (("kp", 100.0),)), ("computed-torque", (("k", 7.0),)))
    )
    robot = load_robot()
    rows = build_rows(
        shared, parse_variants(["pd", "pd@kd=9", "computed-torque", "computed-torque@lam=2"]), robot
    )
    gains = {key: row.scenario.controller.gains for key, row in rows.items()}
    assert float(np.max(gains["pd@kd=9"].kp)) == 100.0 and float(np.max(gains["pd@kd=9"].kd)) == 9.0
    assert float(np.max(gains["computed-torque"].lam)) == 3.0
    assert (
        float(np.max(gains["computed-torque@lam=2"].lam)) == 2.0
        and float(np.max(gains["computed-torque@lam=2"].k)) == 7.0
    )
    with pytest.raises(InvalidParameterError, match=r"^pd@kp=1,2,3: kp = \[1\.0, 2\.0, 3\.0\] is invalid"):
        build_rows(shared, parse_variants(["pd@kp=1,2,3"]), robot)


RUN = ["--duration", "0.3"]


@pytest.fixture(scope="module")
def compared(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    """``compare pd pd@kp=200,150`` with its figures (the overlay among them)."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("variants") / "cmp"
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["compare", "pd", "pd@kp=200,150", *RUN, "--out", str(out), "--json"]) == 0
    return out, json.loads(buffer.getvalue())


def _simulated(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, object]:
    capsys.readouterr()
    assert main(["simulate", *argv, *RUN, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_variants_row_is_simulate_with_the_same_options(
    compared: tuple[Path, dict[str, object]], capsys: pytest.CaptureFixture[str]
) -> None:
    """Each row, keyed by its text in --json's controllers and in comparison.csv, holds the
    numbers simulate gives with the same options (--gain kp=200,150 for the variant)."""
    out, payload = compared
    controllers = payload["controllers"]
    assert isinstance(controllers, dict) and list(controllers) == ["pd", "pd@kp=200,150"]
    for key, argv in (("pd", ["pd"]), ("pd@kp=200,150", ["pd", "--gain", "kp=200,150"])):
        single = _simulated(capsys, *argv)
        assert controllers[key] == single["metrics"]
        assert payload["task_metrics"][key] == single["task_metrics"]  # type: ignore[index]
        assert payload["gains"][key] == single["gains"]  # type: ignore[index]
    assert controllers["pd"] != controllers["pd@kp=200,150"]
    with open(out / "comparison.csv", newline="") as f:
        rows = [r for r in csv.reader(f) if len(r) > 2 and r[1] == "rms"]
    assert [r[0] for r in rows] == ["pd", "pd@kp=200,150"]
    assert float(rows[1][2]) == pytest.approx(controllers["pd@kp=200,150"]["rms"]["e"][0], rel=1e-5)  # type: ignore[index]


def test_the_variants_of_a_law_are_overlaid(compared: tuple[Path, dict[str, object]]) -> None:
    """``pd_variants.png`` beside each row's own figures (a safe file name for the variant's)."""
    out, _ = compared
    names = {p.name for p in (out / "figures").iterdir()}
    stem = file_stem("pd@kp=200,150")
    assert {"pd_variants.png", "pd_torque.png", f"{stem}_torque.png", f"{stem}_theta1.png"} <= names


def test_the_overlay_draws_each_run_as_its_envelope_and_torque() -> None:
    """The overlay's curves are each run's own max|e| envelope and torque (second method:
    the runs' arrays), one line per run and panel, labelled by the row's name."""
    from twolink_pin.model import load_robot
    from twolink_pin.plotting._panels import envelope
    from twolink_pin.plotting.overlay import _overlay_figure
    from twolink_pin.simulation import SimulationConfig, simulate
    from twolink_pin.trajectory import default_trajectory

    robot = load_robot()
    shared = RunSpec(shared=True, simulation=SimulationConfig(duration=0.2))
    runs = {}
    for key, row in build_rows(shared, parse_variants(["pd", "pd@kp=50"]), robot).items():
        runs[key] = simulate(*row.scenario, default_trajectory(robot), row.spec.simulation)
    fig = _overlay_figure(runs, "pd")
    axes = {ax.get_label(): ax for ax in fig.axes}
    for j in range(robot.nv):
        lines = axes[f"e{j + 1}"].get_lines()
        assert [line.get_label() for line in lines] == ["pd", "pd@kp=50"]
        for line, result in zip(lines, runs.values(), strict=True):
            np.testing.assert_array_equal(line.get_ydata(), envelope(result.t, result.e[:, j])[1])
        torques = axes[f"tau{j + 1}-last"].get_lines()
        for line, result in zip(torques, runs.values(), strict=True):
            np.testing.assert_array_equal(line.get_ydata(), result.tau[:, j])  # a run shorter than a period


def test_a_model_variant_is_simulate_with_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``computed-torque@model=heavier.urdf`` believes the file's inertias as ``--model`` does;
    the plain row keeps the robot's own model."""
    urdf = tmp_path / "heavier.urdf"
    assert main(["info", "--payload", "0.5", "--write-urdf", str(urdf)]) == 0
    variant = f"computed-torque@model={urdf}"
    argv = ["compare", "computed-torque", variant, *RUN, "--no-plot", "--out", str(tmp_path / "c")]
    capsys.readouterr()
    assert main([*argv, "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert (
        payload["controllers"][variant]
        == _simulated(capsys, "computed-torque", "--model", str(urdf))["metrics"]
    )
    assert payload["controllers"]["computed-torque"] == _simulated(capsys, "computed-torque")["metrics"]
    assert payload["controllers"][variant] != payload["controllers"]["computed-torque"]


def test_compare_refuses_a_bad_variant_or_gain_naming_the_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exit 2, one line, nothing written: the same variant twice, an unknown key naming pd's
    gains, and a bad --gain of one law named with that law (not a bare ``kp``)."""
    cases = [
        (["pd", "pd@kd=50@kp=1", "pd@kp=1@kd=50"], "each variant once"),
        (["pd", "pd@zeta=1"], "a gain of 'pd' (kp, kd), model, p0 or a plant key"),
        (
            ["pd", "computed-torque", "--gain", "computed-torque.k=1,2,3"],
            "computed-torque: k = [1.0, 2.0, 3.0] is invalid",
        ),
    ]
    for argv, words in cases:
        out = tmp_path / "c"
        capsys.readouterr()
        assert main(["compare", *argv, *RUN, "--no-plot", "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], err
        assert not out.exists()
