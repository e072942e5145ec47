"""Every arm a user brings, at the defaults (issue 50): each profile of ``examples/arms`` — every
fixed-base arm example-robot-data ships, as its URDF has it, each arm of its trees (Baxter, PR2,
TIAGo) through a profile, and a 5-link chain about parallel axes — with every built-in law for
3 s at default settings. Prints the (arm × law) table: ``ok``, or what failed; for
``computed-torque`` (the exact model) its largest |e| at the end [rad]; and the step check's cost
per run [ms].

Usage::

    .venv/bin/python scripts/arms.py            # every arm and law, 3 s each: minutes
    .venv/bin/python scripts/arms.py --quick    # 0.05 s runs on three arms (smoke test)
    .venv/bin/python scripts/arms.py --json     # also a JSON line at the end

``scripts/benchmark.py --arms-only`` runs it among the benchmark's goals; ``tests/test_arms.py``
(slow) asserts the same outcomes.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin import load_robot  # first, before pinocchio loads (twolink_pin.openmp)
from twolink_pin.errors import TwolinkPinError
from twolink_pin.run_spec import RunSpec
from twolink_pin.scenario import builtin_laws
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.step_check import check_step
from twolink_pin.trajectory import default_trajectory

ARMS = Path(__file__).resolve().parents[1] / "examples" / "arms"
"""The profiles of the arms (``*.toml``)."""
DURATION = 3.0
"""Simulated time of each run [s]."""
EXACT_GOAL = 1e-3
"""``computed-torque`` on the exact model ends within this [rad]."""
CHECK_GOAL_MS = 5.0
"""The step check's cost per run [ms] (the goal)."""


def arm_profiles() -> list[Path]:
    """The profiles of ``examples/arms``, by name."""
    return sorted(ARMS.glob("*.toml"))


def run_arm(profile: Path, duration: float = DURATION, laws: list[str] | None = None) -> dict[str, Any]:
    """Every law at its defaults on the arm of ``profile`` for ``duration`` [s]: per law
    ``{"ok", "error" (the end's largest |e| [rad]), "seconds", "check_ms", "failure"}``."""
    robot = load_robot(profile)
    reference = default_trajectory(robot)
    config = SimulationConfig(duration=duration)
    rows: dict[str, Any] = {"nv": robot.nv}
    for law in laws or list(builtin_laws()):
        row: dict[str, Any] = {"ok": False, "error": None, "failure": None}
        started = time.perf_counter()
        try:
            scenario = RunSpec(law=law, simulation=config).build(robot)
            times = []
            for _ in range(3):
                t = time.perf_counter()
                check_step(*scenario, reference, config)  # what simulate runs first
                times.append(time.perf_counter() - t)
            row["check_ms"] = 1e3 * min(times)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # a singularity warning is the law's note, not a failure
                result = simulate(*scenario, reference, config)
            e = np.abs(np.asarray(result.q)[-1] - np.asarray(result.q_des)[-1])
            row.update(ok=bool(np.isfinite(result.q).all()), error=float(e.max()))
        except TwolinkPinError as exc:
            row["failure"] = str(exc)
        row["seconds"] = time.perf_counter() - started
        rows[law] = row
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="0.05-s runs on three arms")
    parser.add_argument("--json", action="store_true", help="also print the results as one JSON line")
    args = parser.parse_args(argv)
    results = arms_section(args.quick)
    if args.json:
        print(json.dumps(results))
    return 0


def arms_section(quick: bool) -> dict[str, Any]:
    """The table and the goals (what ``scripts/benchmark.py --arms-only`` prints)."""
    profiles = arm_profiles()
    if quick:
        profiles = [p for p in profiles if p.stem in ("xarm7", "five_link_chain", "baxter_right")]
    duration = 0.05 if quick else DURATION
    laws = list(builtin_laws())
    print(
        f"\nevery arm at the defaults (issue 50): {len(profiles)} arms × {len(laws)} laws, {duration:g} s each; "
        f"load average {[round(x, 2) for x in os.getloadavg()]}"
    )
    width = max(len(p.stem) for p in profiles)
    print(f"{'arm':{width}s} nv  " + " ".join(f"{law[:10]:>10s}" for law in laws))
    table: dict[str, Any] = {}
    for profile in profiles:
        rows = run_arm(profile, duration, laws)
        table[profile.stem] = rows
        cells = []
        for law in laws:
            row = rows[law]
            cells.append(
                f"{('ok' if row['ok'] else 'FAILED'):>10s}"
                if law != "computed-torque" or not row["ok"]
                else f"{row['error']:>10.1e}"
            )
        print(f"{profile.stem:{width}s} {rows['nv']:2d}  " + " ".join(cells), flush=True)
    runs = [table[a][law] for a in table for law in laws]
    ran = sum(r["ok"] for r in runs)
    exact = [table[a]["computed-torque"]["error"] for a in table if table[a]["computed-torque"]["ok"]]
    checks = [r["check_ms"] for r in runs if r.get("check_ms") is not None]
    failures = {
        f"{a} × {law}": table[a][law]["failure"] for a in table for law in laws if not table[a][law]["ok"]
    }
    for where, why in failures.items():
        print(f"  {where}: {why}")
    summary = {
        "runs": len(runs),
        "ran": ran,
        "fraction_ran": ran / len(runs),
        "computed_torque_worst_error_rad": max(exact) if exact else None,
        "check_ms_median": statistics.median(checks),
        "check_ms_worst": max(checks),
        "failures": failures,
    }
    print(
        f"goals: {ran}/{len(runs)} (arm × law) run ({100 * ran / len(runs):.0f} %; goal 100 %); "
        f"computed-torque ends within {summary['computed_torque_worst_error_rad']:.2g} rad (goal {EXACT_GOAL:g}); "
        f"step check {summary['check_ms_median']:.2f} ms per run (median; worst {summary['check_ms_worst']:.2f}; "
        f"goal {CHECK_GOAL_MS:g} ms)"
    )
    return {"arms": {"table": table, **summary, "duration": duration}}


if __name__ == "__main__":
    raise SystemExit(main())
