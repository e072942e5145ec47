"""Smoke test of scripts/benchmark.py: ``--quick`` runs and prints positive ratios.

No timing is asserted (the benchmark is how the targets are judged, on a quiet machine);
this only checks that every section runs and its ratios parse as positive numbers.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "benchmark.py"
RATIO = re.compile(r"(\S+)x\b")


def test_quick_benchmark_prints_positive_ratios_for_every_section() -> None:
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    lines = done.stdout.splitlines()
    table = lines[lines.index(next(x for x in lines if x.lstrip().startswith("law"))) + 1 :][:6]
    assert [row.split()[0] for row in table] == [
        "pd",
        "computed-torque",
        "robust",
        "adaptive",
        "adaptive-friction",
        "sliding-mode",
    ]
    for row in table:
        ratios = [float(x) for x in RATIO.findall(row)]
        assert len(ratios) == 3 and all(r > 0 for r in ratios), row
    scaling = [x for x in lines if re.match(r"\s+\d+\s+[\d.]+ s ", x)]
    assert len(scaling) == 3
    assert all(float(r) > 0 for row in scaling for r in RATIO.findall(row))
    assert any("peak RSS" in x for x in lines)
    results = json.loads(lines[-1])
    assert results["baseline_seconds"] > 0 and results["quick"] is True
    assert set(results["single"]) == {
        "pd",
        "computed-torque",
        "robust",
        "adaptive",
        "adaptive-friction",
        "sliding-mode (example)",
    }
    assert any("targets" in x for x in lines)
    contention = results["contention"]  # two batches at once: default, 1 and 2 threads
    assert set(contention["seconds_per_sim"]) == {"default", "1", "2"}
    assert all(x > 0 for x in contention["seconds_per_sim"].values()) and contention["default_threads"] >= 1
    assert set(contention["alone_seconds_per_sim"]) == {"default", "1"}  # one copy alone: default vs 1
    assert all(x > 0 for x in contention["alone_seconds_per_sim"].values())
    assert contention["alone_default_threads"] >= 1
    qp_osc = results["qp_osc_panda"]  # issue 37: qp-osc against osc on the Panda, and where its time goes
    assert qp_osc["ratio"] > 0 and qp_osc["osc_seconds"] > 0 and qp_osc["target"] == 2.0
    demo = qp_osc["profile"]["limits demo"]
    assert demo["build_us"] > 0 and demo["solve_us"] > 0 and 0 < demo["prox_share"] <= 1
    assert any("qp-osc" in x and "x osc" in x for x in lines)


def test_big_arms_rows_give_ratios_and_the_floor() -> None:
    """``--big-arms-only --quick`` (issue 31): the Panda's single runs and the batches, each with a
    positive ratio to the baseline, and each batch with its floor below it (the bare Pinocchio
    calls cannot cost more than the batch that makes them)."""
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "--big-arms-only", "--quick", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    rows = json.loads(done.stdout.splitlines()[-1])["big_arms"]
    assert {label.rsplit(",", 1)[0] for label in rows if "single" in label} == {
        "panda osc single",
        "panda impedance single",
    }
    batches = [label for label in rows if "batch" in label]
    assert [label.split(" batch")[0] for label in batches] == ["panda osc", "ur5 adaptive"]
    for label, row in rows.items():
        assert row["seconds"] > 0 and row["ratio"] > 0, label
    for label in batches:
        assert 0 < rows[label]["floor"] < rows[label]["seconds"], label


def test_the_mujoco_benchmark_prints_both_plants_and_the_equality() -> None:
    """``benchmark.py --mujoco-only --quick``: a row per case with positive seconds and ratios, and
    an equality line per arm and law under the goal."""
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "--mujoco-only", "--quick", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )
    results = json.loads(done.stdout.splitlines()[-1])["mujoco"]
    assert set(results["speed"]) >= {"twolink pd single", "panda osc single"}
    assert all(row["ratio"] > 0 and row["cpu_ratio"] > 0 for row in results["speed"].values())
    assert len(results["equality"]) == 12 and max(results["equality"].values()) <= 1e-8


def test_quick_equations_section_prints_its_goals() -> None:
    """``--equations-only --quick``: the goals' lines and the scaling table's rows (no timing asserted)."""
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "--equations-only", "--quick", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )
    lines = done.stdout.splitlines()
    assert any(line.startswith("  twolink, M C g Y:") for line in lines)
    assert any(line.startswith("  UR5's first 3 joints:") for line in lines)
    assert len([line for line in lines if line.startswith("    n = ")]) == 3
    results = json.loads(lines[-1])["equations"]
    assert results["twolink_seconds"] > 0 and results["mass_matrix_seconds"]["crba"] > 0
    assert [row["joints"] for row in results["scaling"]] == [1, 2, 3]
