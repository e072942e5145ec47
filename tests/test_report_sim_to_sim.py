"""The report's section "Sim-to-sim" (:mod:`twolink_pin.report.sim_to_sim`, issue 44 part 4):
its rows are the ``compare`` runs they name (the same numbers from ``comparison.json``), its
"MuJoCo, no effect" row is the Pinocchio row, and the page shows it (a short report build)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from twolink_pin.cli import main
from twolink_pin.law_variant import parse_variant
from twolink_pin.model import load_robot
from twolink_pin.report import ReportOptions, build_report
from twolink_pin.report.sim_to_sim import alone_on, arm_effects, sim_to_sim_law
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig

DURATION = 4.0
"""One period of the twolink's reference (the section's runs, started on it)."""


def test_the_sections_rows_are_the_compare_runs_they_name(tmp_path: Path) -> None:
    """``pd``'s rows: each row's RMS ‖e‖ = (Σ_j RMS(e_j)²)^½ and max |e| from ``compare``'s
    comparison.json for the row's variant (the same runs; a row not rerun because its effect
    cannot act, its variant's run too: to 1e-12); the effects are the twolink's six; "MuJoCo,
    no effect" equals the Pinocchio row to 1e-12 rad; the soft limits are not rerun (the ±π
    ranges are never reached), the effects that act change the error."""
    options = ReportOptions(run=RunSpec(shared=True, simulation=SimulationConfig(duration=30.0)), workers=1)
    section = sim_to_sim_law("pd", parse_variant("pd"), options)
    assert section["duration_s"] == DURATION
    keys = [e["key"] for e in arm_effects(load_robot(), options)]
    assert keys == ["armature", "joint_damping", "frictionloss", "soft_limits", "saturate", "integrator"]
    rows = section["rows"]
    assert len(rows) == 3 + len(keys) and all(row["finished"] for row in rows)
    texts = [row["variant"] for row in rows]
    out = tmp_path / "compare"
    argv = [
        "compare",
        *texts,
        "--duration",
        str(DURATION),
        "--q0-offset",
        "0",
        "--no-plot",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    table = json.loads((out / "comparison.json").read_text())["controllers"]
    for row in rows:
        metrics = table[row["variant"]]
        assert row["rms_e"] == pytest.approx(
            math.sqrt(sum(x * x for x in metrics["rms"]["e"])), rel=1e-12, abs=1e-15
        )
        assert row["max_e"] == pytest.approx(max(metrics["max"]["e"]), rel=1e-12, abs=1e-15)
    derived = [row["short"] for row in rows if row.get("derived")]
    assert "+ soft limits" in derived
    assert abs(rows[1]["delta_rms_e"]) < 1e-12 and abs(rows[1]["delta_max_e"]) < 1e-12
    assert all(abs(row["delta_rms_e"]) > 1e-7 for row in rows[2:5])  # armature, damping, dry friction act
    # the report's laws after its first: the first and last rows, the same runs, the same numbers
    fewer = sim_to_sim_law("pd", parse_variant("pd"), options, alone=False)
    assert [row["short"] for row in fewer["rows"]] == ["Pinocchio", "+ every effect"]
    assert fewer["effects_alone"] is False and section["effects_alone"] is True
    for row in fewer["rows"]:
        same = next(r for r in rows if r["variant"] == row["variant"])
        assert {k: v for k, v in row.items() if k != "seconds"} == {
            k: v for k, v in same.items() if k != "seconds"
        }


def test_each_effect_alone_on_the_first_law_unless_every_law_is_asked_for() -> None:
    """:func:`alone_on`: the report's first law by default, every law with sim_to_sim_all."""
    names = ["pd", "computed-torque", "adaptive"]
    assert alone_on(ReportOptions(workers=1), names) == ["pd"]
    assert alone_on(ReportOptions(workers=1, sim_to_sim_all=True), names) == names
    assert alone_on(ReportOptions(workers=1), []) == []


def test_the_figure_centres_the_bars_a_row_has(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A law without the rows of each effect alone has no bar in their groups; each group's bars
    are centred on its label (one bar: on it), the every-effect group has a bar per law."""
    from matplotlib.figure import Figure

    import twolink_pin.plotting.sim_to_sim as plot

    def law(name: str, shorts: list[str]) -> dict[str, object]:
        rows = [{"short": s, "finished": True, "delta_rms_e": 1e-3, "delta_max_e": 2e-3} for s in shorts]
        return {"law": name, "rows": rows}

    full = ["Pinocchio", "MuJoCo, no effect", "+ armature", "+ every effect"]
    laws = [law("pd", full), law("adaptive", [full[0], full[3]])]
    drawn: list[Figure] = []
    original = plot.save_figure
    monkeypatch.setattr(plot, "save_figure", lambda fig, path: (drawn.append(fig), original(fig, path))[1])
    plot.save_sim_to_sim_figure(laws, tmp_path / "f.png", "t")
    ax = drawn[0].axes[0]
    centres = {}
    for container, name in zip(ax.containers, ("pd", "adaptive"), strict=True):
        centres[name] = sorted(round(bar.get_y() + bar.get_height() / 2, 9) for bar in container)
    # groups from the top: no effect (y = 2), armature (y = 1), every effect (y = 0); height 0.4
    assert centres["pd"] == [-0.2 + 0.4, 1.0, 2.0]
    assert centres["adaptive"] == [-0.2]


def test_eleven_laws_bars_are_told_apart(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The UR5 has eleven laws and matplotlib's cycle ten colours: no two laws' bars look the
    same (colour and hatch), so mpc's bars are not taken for pd's."""
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure

    import twolink_pin.plotting.sim_to_sim as plot

    rows = [{"short": s, "finished": True, "delta_rms_e": 1e-3, "delta_max_e": 2e-3} for s in ("P", "+ all")]
    laws = [{"law": f"law{k}", "rows": rows} for k in range(11)]
    drawn: list[Figure] = []
    original = plot.save_figure
    monkeypatch.setattr(plot, "save_figure", lambda fig, path: (drawn.append(fig), original(fig, path))[1])
    plot.save_sim_to_sim_figure(laws, tmp_path / "f.png", "t")
    looks = {(to_rgba(c[0].get_facecolor()), c[0].get_hatch()) for c in drawn[0].axes[0].containers}
    assert len(looks) == 11


@pytest.mark.report
def test_the_report_shows_the_section_and_its_figure(tmp_path: Path) -> None:
    """A one-law report: the section's table on the page (a row per plant), in report.md and in
    results.json, its figure written; --no-sim-to-sim leaves it out."""
    run = RunSpec(shared=True, simulation=SimulationConfig(duration=DURATION))
    short = {"workers": 1, "animation": False, "identification": False, "limits_section": False}
    results = build_report(
        tmp_path / "r", ReportOptions(run=run, controllers=("pd",), **short), command_line="pytest"
    )
    section = results["sim_to_sim"]
    assert [law["law"] for law in section["laws"]] == ["pd"]
    page = (tmp_path / "r" / "index.html").read_text()
    assert 'id="sim-to-sim"' in page and page.count("<tr><td>pd</td>") >= 9
    assert (tmp_path / "r" / "figures" / section["figure"]).stat().st_size > 10_000
    assert "## Sim-to-sim" in (tmp_path / "r" / "report.md").read_text()
    without = build_report(
        tmp_path / "w", ReportOptions(run=run, controllers=("pd",), sim_to_sim=False, **short)
    )
    assert without["sim_to_sim"] is None
    assert without["controllers"]["pd"]["metrics"] == results["controllers"]["pd"]["metrics"]


def test_no_sim_to_sim_and_sim_to_sim_all_are_the_options_fields(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``report --no-sim-to-sim`` sets ReportOptions.sim_to_sim to False (default True),
    ``--sim-to-sim-all`` ReportOptions.sim_to_sim_all to True (default False)."""
    import twolink_pin.report as report_package

    seen: list[ReportOptions] = []

    def capture(out: object, options: ReportOptions, **_: object) -> dict[str, float]:
        seen.append(options)
        return {"total_seconds": 0.0}

    monkeypatch.setattr(report_package, "build_report", capture)
    assert main(["report", "--out", str(tmp_path / "a")]) == 0
    assert main(["report", "--no-sim-to-sim", "--out", str(tmp_path / "b")]) == 0
    assert main(["report", "--sim-to-sim-all", "--out", str(tmp_path / "c")]) == 0
    assert [o.sim_to_sim for o in seen] == [True, False, True]
    assert [o.sim_to_sim_all for o in seen] == [False, False, True]
