"""The report's section "The reference within the limits" (issue 36 part 4): its numbers
recomputed from the reference files it saves (Pinocchio's RNEA on a finer grid), the
time-optimal reference at its limits, one tracking row per law and reference that
``simulate --trajectory`` reproduces, and the report's other numbers unchanged by it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import SimulationConfig
from twolink_pin.limits import joint_limits
from twolink_pin.model import load_robot
from twolink_pin.report import ReportOptions, build_report
from twolink_pin.run_spec import RunSpec
from twolink_pin.trajectory import read_trajectory_file

LAWS = ("pd", "computed-torque")
OPTIONS = {
    "run": RunSpec(simulation=SimulationConfig(duration=1.0)),
    "workers": 1,
    "animation": False,
    "identification": False,
    "controllers": LAWS,
    "sim_to_sim": False,
}
FINE = 12001
"""Instants of the finer grid the tests recompute a reference on (the section's: 4001)."""


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("limits") / "r"
    build_report(out, ReportOptions(**OPTIONS), command_line="pytest")
    return out


def _section(report: Path) -> dict[str, Any]:
    section: dict[str, Any] = json.loads((report / "results.json").read_text())["within_limits"]
    return section


def _rnea(robot: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    data = robot.model.createData()
    return np.array([pin.rnea(robot.model, data, *x) for x in zip(q, v, a, strict=True)])


def _fine(robot: Any, path: Path, speed: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A saved reference read back and played ``speed`` times as fast over one period: time
    [s], q̇ [rad/s], τ [N·m] by RNEA, on :data:`FINE` instants."""
    trajectory = read_trajectory_file(path, robot)
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, FINE)
    ref = trajectory.sample(t)
    v, a = ref.v * speed, ref.a * speed**2
    return t / speed, v, _rnea(robot, ref.q, v, a)


def test_peak_ratios_and_effort_are_rnea_of_the_saved_files_on_a_finer_grid(report: Path) -> None:
    """Each reference's peak |q̇|/limit and |τ|/limit per joint and its ∫τᵀτ dt, recomputed
    from its file with pin.rnea on 3× the section's grid; the two designed references hold
    every limit there, the minimum effort's ∫τᵀτ is at most the polynomial's and the
    retiming is shorter than the polynomial's 4 s."""
    robot = load_robot(None)
    limits = joint_limits(robot)
    refs = _section(report)["references"]
    assert list(refs) == ["reference", "time_optimal", "minimum_effort"]
    effort = {}
    for key, row in refs.items():
        t, v, tau = _fine(robot, report / row["file"])
        velocity = np.abs(v).max(axis=0) / limits.velocity
        torque = np.abs(tau).max(axis=0) / limits.effort
        np.testing.assert_allclose(row["peak_ratio"]["velocity"], velocity, rtol=2e-3)
        np.testing.assert_allclose(row["peak_ratio"]["effort"], torque, rtol=2e-3)
        effort[key] = float(np.trapezoid((tau**2).sum(axis=1), t))
        assert row["effort_integral"] == pytest.approx(effort[key], rel=1e-3)
        assert row["duration_s"] == pytest.approx(t[-1] - t[0], rel=1e-12)
        if key != "reference":
            assert max(velocity.max(), torque.max()) <= 1.0 + 1e-6, key
    assert effort["minimum_effort"] <= effort["reference"]
    assert refs["time_optimal"]["duration_s"] < refs["reference"]["duration_s"] == 4.0


def test_the_time_optimal_reference_played_1_percent_faster_crosses_a_limit(report: Path) -> None:
    """At 1/0.99 of its speed (q̇/0.99, q̈/0.99²) the retimed path exceeds a velocity or an
    effort limit: it was as fast as the limits allow."""
    robot = load_robot(None)
    limits = joint_limits(robot)
    _, v, tau = _fine(robot, report / "references" / "time_optimal.json", speed=1 / 0.99)
    worst = max(
        (np.abs(v).max(axis=0) / limits.velocity).max(), (np.abs(tau).max(axis=0) / limits.effort).max()
    )
    assert worst > 1.0


def test_one_row_per_law_and_reference_as_simulate_runs_it(
    report: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """laws × references rows, in the page's table too; pd's row on the retimed reference is
    what ``simulate pd --trajectory references/time_optimal.json`` gives for one period (its
    crossings of the velocity and effort limits among them)."""
    from twolink_pin.cli import main

    section = _section(report)
    rows = section["tracking"]
    assert [(r["law"], r["reference"]) for r in rows] == [
        (law, ref) for ref in ("reference", "time_optimal", "minimum_effort") for law in (*LAWS, "mpc")
    ]
    html = (report / "index.html").read_text()
    body = html[html.index('<table id="limits-tracking">') :]
    assert body[: body.index("</table>")].count("<tr>") == 1 + len(rows)
    assert "last period max |e1| [rad]" in body[: body.index("</table>")]
    row = next(r for r in rows if r["law"] == "pd" and r["reference"] == "time_optimal")
    duration = row["duration_s"]
    assert duration == pytest.approx(2 * section["references"]["time_optimal"]["duration_s"], rel=1e-12)
    path = report / "references" / "time_optimal.json"
    assert main(["simulate", "pd", "--trajectory", str(path), "--duration", repr(duration), "--json"]) == 0
    ran = json.loads(capsys.readouterr().out)
    for signal in ("e", "edot", "tau"):
        assert row["metrics"]["rms"][signal] == pytest.approx(ran["metrics"]["rms"][signal], rel=1e-9)
    assert row["crossings"] == ran["crossings"]
    assert row["crossings"]["effort"]["crossed"][0] and row["crossings"]["velocity"]["crossed"][1]
    assert row["metrics"]["final_period_max_abs_e"] == ran["metrics"]["final_period_max_abs_e"]


def test_the_last_period_is_the_tracking_not_the_offset(report: Path) -> None:
    """Every row's max |e| is the 0.1-rad initial offset (the transient); its last period's, a
    period after a settling second, is far below it on the two references at rest-to-rest
    pace: the table tells the laws apart by it. mpc runs every reference beside the report's
    laws and finishes each."""
    rows = _section(report)["tracking"]
    for row in rows:
        assert row["finished"], row
        assert max(row["metrics"]["max"]["e"]) >= 0.1 - 1e-12
        if row["reference"] != "time_optimal":
            assert max(row["metrics"]["final_period_max_abs_e"]) < 0.01, row["law"]
    assert {r["reference"] for r in rows if r["law"] == "mpc"} == {
        "reference",
        "time_optimal",
        "minimum_effort",
    }


def test_the_reports_other_numbers_are_the_same_without_the_section(report: Path, tmp_path: Path) -> None:
    """--no-limits-section: no section on the page nor in results.json; every other number of
    results.json equal (to 1e-12) with and without it."""
    results = build_report(tmp_path / "without", ReportOptions(limits_section=False, **OPTIONS))
    assert results["within_limits"] is None
    assert 'id="limits"' not in (tmp_path / "without" / "index.html").read_text()
    with_section = json.loads((report / "results.json").read_text())
    without = json.loads((tmp_path / "without" / "results.json").read_text())
    # how the run went, not what it found: the wall-clock figures, and whether the equations were
    # derived or read from the cache (the first build derives them unless another test did)
    wall = {"seconds", "total_seconds", "command_line", "within_limits", "from_cache"}
    compared = _compare(with_section, without, wall)
    assert compared > 300  # the model, trajectory, metrics, crossings, errata of both laws


def _compare(a: Any, b: Any, skip: set[str], where: str = "") -> int:
    """Assert ``a`` and ``b`` hold the same keys and numbers (to 1e-12) apart from ``skip``;
    returns how many numbers were compared."""
    if isinstance(a, dict):
        assert set(a) - skip == set(b) - skip, where
        return sum(_compare(a[k], b[k], skip, f"{where}.{k}") for k in a if k not in skip)
    if isinstance(a, list):
        assert len(a) == len(b), where
        return sum(_compare(x, y, skip, f"{where}[{i}]") for i, (x, y) in enumerate(zip(a, b)))
    if isinstance(a, float):
        assert a == pytest.approx(b, rel=1e-12, abs=1e-12), where
        return 1
    assert a == b, where
    return 0


def test_no_limits_section_is_the_options_field(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """``report --no-limits-section`` sets ReportOptions.limits_section to False (default True)."""
    import twolink_pin.report as report_package
    from twolink_pin.cli import main

    seen: list[ReportOptions] = []

    def capture(out: Any, options: ReportOptions, **_: Any) -> dict[str, Any]:
        seen.append(options)
        return {"total_seconds": 0.0}

    monkeypatch.setattr(report_package, "build_report", capture)
    assert main(["report", "--out", str(tmp_path / "a")]) == 0
    assert main(["report", "--no-limits-section", "--out", str(tmp_path / "b")]) == 0
    assert [o.limits_section for o in seen] == [True, False]


@pytest.mark.browser
def test_the_section_in_chromium(report: Path) -> None:
    """The section's figures decode, its tables have a row per reference and per (law,
    reference), the navigation links to it."""
    from browser import require_chromium, start_chromium

    require_chromium()
    with start_chromium(1280, 900) as driver:
        driver.get((report / "index.html").as_uri())
        images = driver.execute_script(
            "return Array.from(document.querySelectorAll('#limits ~ figure img'))"
            ".map(i => [i.getAttribute('src'), i.complete, i.naturalWidth]);"
        )
        section = [src for src, *_ in images if "limits_references_" in src]
        assert len(section) == 2  # velocity and torque: the twolink gives no acceleration limit
        assert all(complete and width > 0 for src, complete, width in images if src in section)
        rows = driver.execute_script(
            "const n = id => document.querySelectorAll('#' + id + ' tbody tr').length;"
            "return [n('limits-references'), n('limits-tracking'),"
            " document.querySelectorAll('nav a[href=\"#limits\"]').length];"
        )
        assert rows == [3, 3 * (len(LAWS) + 1), 1]  # the report's laws and mpc


def test_a_robot_without_velocity_limits_gets_a_note_instead_of_a_retiming(tmp_path: Path) -> None:
    """The double pendulum's URDF gives no velocity limit: no time-optimal retiming (a note
    naming the missing limit), the reference and the minimum-effort trajectory with their
    rows, no ratio columns and no figure (no joint has a limit to draw)."""
    from twolink_pin.law_variant import parse_variants
    from twolink_pin.model import example_robot_urdf
    from twolink_pin.report.within_limits import limits_section

    urdf = str(example_robot_urdf("double_pendulum_description/urdf/double_pendulum.urdf"))
    (tmp_path / "figures").mkdir()
    options = ReportOptions(robot=urdf, **{k: v for k, v in OPTIONS.items() if k != "controllers"})
    section = limits_section([("pd", parse_variants(("pd",))[0])], options, str(tmp_path))
    assert list(section["references"]) == ["reference", "minimum_effort"]
    assert len(section["notes"]) == 1 and "no time-optimal retiming" in section["notes"][0]
    assert "velocity limit" in section["notes"][0]
    assert all(ref["peak_ratio"] == {} for ref in section["references"].values())
    assert section["figures"] == [] and [(r["law"], r["reference"]) for r in section["tracking"]] == [
        ("pd", "reference"),
        ("mpc", "reference"),
        ("pd", "minimum_effort"),
        ("mpc", "minimum_effort"),
    ]
    assert (
        read_trajectory_file(tmp_path / "references" / "minimum_effort.json", load_robot(urdf)).period == 4.0
    )


@pytest.mark.parametrize("law", ["pd", "adaptive"])
def test_a_row_on_the_reference_read_from_the_reports_run_is_the_row_run_again(law: str) -> None:
    """With runs at least as long as a tracking row's (the default 30 s), the report reads each
    law's row on its own reference from its run (:func:`report_run_row`: the first 5 s of a
    6-s run here) instead of running it again: every number is the row run on its own
    (:func:`_track`, a second run), bit for bit — adaptive's estimates included; runs shorter
    than the row's are not read."""
    from dataclasses import replace

    from twolink_pin.law_variant import parse_variants
    from twolink_pin.report.runs import reference_trajectory
    from twolink_pin.report.within_limits import _track, report_run_row, reuses_report_runs
    from twolink_pin.simulation import simulate

    options = ReportOptions(run=RunSpec(shared=True, simulation=SimulationConfig(duration=6.0)), workers=1)
    robot = load_robot(None)
    reference = reference_trajectory(robot, options)
    assert reuses_report_runs(options, reference)
    short = replace(options, run=replace(options.run, simulation=SimulationConfig(duration=4.0)))
    assert not reuses_report_runs(short, reference)  # a 4-s run is shorter than the 5-s row
    variant = parse_variants((law,))[0]
    controller, plant = options.run.for_law(variant).build(robot)
    run = simulate(controller, plant, reference, options.run.simulation)
    read = report_run_row(options, reference, run)
    again = _track(robot, variant, options, reference)
    assert read.pop("from_report_run") is True
    read.pop("seconds"), again.pop("seconds")
    assert read == again and read["duration_s"] == 5.0


def test_a_row_whose_report_run_failed_is_run_again(tmp_path: Path) -> None:
    """:func:`fill_report_runs`: a pending row whose law has no report run (it failed) is run
    on its own, as the section would have; the other rows are kept as they are."""
    from twolink_pin.law_variant import parse_variants
    from twolink_pin.report.within_limits import fill_report_runs

    options = ReportOptions(run=RunSpec(shared=True, simulation=SimulationConfig(duration=6.0)), workers=1)
    rows = [("pd", parse_variants(("pd",))[0])]
    kept = {"law": "mpc", "reference": "reference", "finished": False, "failed": "kept"}
    section = {"tracking": [{"law": "pd", "reference": "reference", "pending": True}, kept]}
    filled = fill_report_runs(section, rows, options, load_robot(None), {})
    first = filled["tracking"][0]
    assert first["finished"] and "from_report_run" not in first and "pending" not in first
    assert first["duration_s"] == 5.0 and filled["tracking"][1] == kept
