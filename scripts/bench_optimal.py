"""scripts/benchmark.py --optimal-only: the references designed within the limits (issues 36 and 45).

Each timing is the wall time of one call in this process after a first call that paid the
imports (the minimum-effort twolink also in a fresh process: "cold"), beside the pure-Python
baseline of benchmark.py timed in the same run, so that a goal set on another machine reads as
``seconds × GOALS_BASELINE / baseline`` ("normalised"). Rows:

- the time-optimal retiming of the report's path (goal 20 ms);
- the minimum-effort twolink (goal 100 ms cold) and the UR5 through the via poses of
  examples/ur5_square_pose.toml (goal 2 s), with the default regulariser;
- ``optimize --cost time`` on the twolink, from the retiming (issue 45: 8-9 s; goal 0.5 s);
- the anchor (issue 45): the UR5's least effort alone, from and to rest (crocoddyl's problem):
  ∫τᵀτ dt, its largest excess over a limit on a 10 kHz grid (pin.rnea), seconds, iterations;
  with ``--croc PYTHON`` (a venv with pin 4.0 and crocoddyl 3.2.1, never a dependency:
  ``python3 -m venv /tmp/croc && /tmp/croc/bin/pip install pin==4.0.0 crocoddyl==3.2.1``) beside
  crocoddyl's BoxFDDP on the same problem (../shared/bench/optctl: tk_export.py, croc_effort.py,
  recompute.py), at its default weights and at via weight 1e8, barrier 1e5 (its limits nearly held);
- the Panda's fold (examples/panda_fold_pose.toml) by default and with the effort alone (issue 45:
  60 iterations ended in "no convergence"; 192 and 14 s with --max-iterations 300).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

RETIME_GOAL = 0.020
"""Issue 36: the time-optimal retiming of the report's via points within 20 ms [s]."""
EFFORT_GOAL = 0.100
"""Issue 36: the minimum-effort twolink through the report's via points within 100 ms, cold [s]."""
POSES_GOAL = 2.0
"""Issue 36: the UR5 through the four via poses of examples/ur5_square_pose.toml within 2 s [s]."""
TIME_GOAL = 0.5
"""Issue 45: optimize --cost time on the twolink within 0.5 s (it took 8-9 s) [s]."""
ANCHOR_GOAL = 1.05
"""Issue 45: the UR5's least effort within 5 % of crocoddyl's at equal end conditions."""
GOALS_BASELINE = 0.110
"""The baseline's 30-s time on the machine the goals were set on [s] (benchmark.py's)."""
ROOT = Path(__file__).resolve().parents[1]
OPTCTL = next(
    (p / "shared" / "bench" / "optctl" for p in (ROOT.parent, ROOT.parent.parent) if (p / "shared").is_dir()),
    ROOT.parent / "shared" / "bench" / "optctl",
)
"""The anchor's scripts: ``../shared/bench/optctl`` of the repository (or of the folder of its
worktrees)."""

_COLD = """
import json, time
from twolink_pin import load_robot, default_trajectory
from twolink_pin.trajectory import optimize
robot = load_robot("twolink"); reference = default_trajectory(robot)
start = time.perf_counter(); first = optimize(robot, reference, "effort"); cold = time.perf_counter() - start
start = time.perf_counter(); optimize(robot, reference, "effort"); warm = time.perf_counter() - start
print(json.dumps({"cold": cold, "warm": warm, "iterations": first.iterations}))
"""
"""A fresh process: the package and the robot loaded (not timed), then the first optimisation
(its lazy imports included) and a second one."""


def _best(run: Callable[[], Any], repeats: int) -> tuple[float, float, Any]:
    """The fastest and the median wall time of ``repeats`` calls [s], and the last result."""
    times, out = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        out = run()
        times.append(time.perf_counter() - start)
    return min(times), float(np.median(times)), out


def _goal(seconds: float, goal: float, norm: float) -> str:
    """``seconds`` normalised by ``norm`` against ``goal``."""
    return f"normalised {seconds * norm:.3g} s (goal <= {goal:g} s: {'met' if seconds * norm <= goal else 'NOT met'})"


def _excess_10khz(robot: Any, trajectory: Any) -> float:
    """The largest excess over a velocity, effort or position limit on a 10 kHz grid (a fraction
    of the limit; of the range for a position), the torque by RNEA."""
    from twolink_pin.dynamics.rigid_body import inverse_dynamics_rows
    from twolink_pin.limits import joint_limits

    limits = joint_limits(robot)
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, int(trajectory.period * 10_000) + 1)
    s = trajectory.sample(t)
    tau = inverse_dynamics_rows(robot.model, s.q, s.v, s.a)
    span = limits.position_upper - limits.position_lower
    with np.errstate(invalid="ignore"):
        parts = [
            np.abs(s.v) / limits.velocity - 1,
            np.abs(tau) / limits.effort - 1,
            (s.q - limits.position_upper) / span,
            (limits.position_lower - s.q) / span,
        ]
    return float(max(np.nanmax(np.where(np.isfinite(p), p, -np.inf)) for p in parts))


def _crocoddyl(python: str, ur5_file: Path) -> dict[str, Any]:
    """crocoddyl's BoxFDDP on the UR5 problem (module docstring), each run recomputed by
    recompute.py from its node states: ∫τᵀτ dt, the largest excess, the via error, its time."""
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as folder:
        subprocess.run(
            [sys.executable, str(OPTCTL / "tk_export.py"), "--out", folder, "--checkout", str(ROOT),
             "--ur5-poses", str(ur5_file)],
            check=True, capture_output=True, text=True,
        )  # fmt: skip
        vias = str(Path(folder) / "ur5.json")
        for label, extra in (
            ("default", []),
            ("via 1e8, barrier 1e5", ["--weight", "1e8", "--barrier", "1e5"]),
        ):
            npz = str(Path(folder) / f"croc_{len(out)}.npz")
            done = subprocess.run(
                [python, str(OPTCTL / "croc_effort.py"), vias, "--problem", "joint", "--repeats", "0",
                 "--maxiter", "3000", "--save", npz, *extra],
                check=True, capture_output=True, text=True,
            )  # fmt: skip
            run = json.loads(done.stdout.splitlines()[-1])
            again = subprocess.run(
                [sys.executable, str(OPTCTL / "recompute.py"), "npz", npz, "--robot", "ur5", "--vias", vias],
                check=True, capture_output=True, text=True,
            )  # fmt: skip
            measured = json.loads(again.stdout.splitlines()[-1])["from_xs"]
            out[label] = {
                "effort": measured["effort_integral"],
                "max_excess": measured["max_excess"],
                "via_error": measured["via_error_joint"],
                "seconds": run["cold"]["total"],
                "iterations": run["iterations"],
            }
    return out


def optimal_section(quick: bool, baseline: Callable[[], float], croc: str | None = None) -> dict[str, Any]:
    """The rows of the module docstring; ``baseline()`` gives the baseline's 30-s time [s]."""
    from twolink_pin import default_trajectory, load_robot
    from twolink_pin.trajectory import optimize, read_trajectory_file, time_optimal

    if croc and not (OPTCTL / "croc_effort.py").is_file():
        raise SystemExit(f"--croc: the anchor's scripts are not in {OPTCTL}")
    repeats = 1 if quick else 5
    base = min(baseline() for _ in range(1 if quick else 3))
    norm = GOALS_BASELINE / base
    twolink, ur5, panda = load_robot("twolink"), load_robot("ur5"), load_robot("panda")
    reference = default_trajectory(twolink)
    poses = read_trajectory_file(ROOT / "examples" / "ur5_square_pose.toml", ur5)
    fold = read_trajectory_file(ROOT / "examples" / "panda_fold_pose.toml", panda)
    time_optimal(twolink, reference)  # imports toppra, once
    retime, retime_median, retimed = _best(lambda: time_optimal(twolink, reference), repeats)
    done = subprocess.run([sys.executable, "-c", _COLD], capture_output=True, text=True, check=True)
    cold = json.loads(done.stdout.splitlines()[-1])
    effort, _, least = _best(lambda: optimize(twolink, reference, "effort"), repeats)
    ur5_poses, _, square = _best(lambda: optimize(ur5, poses, "effort"), 1 if quick else 3)
    fast, fast_median, fastest = _best(lambda: optimize(twolink, reference, "time"), repeats)
    anchor = optimize(ur5, poses, "effort", ends="rest", regulariser="none", max_iterations=200)
    folded = optimize(panda, fold, "effort")
    alone = None if quick else optimize(panda, fold, "effort", regulariser="none", max_iterations=300)
    rows = {
        "baseline_seconds": base,
        "normalisation": norm,
        "retime_seconds": retime,
        "retime_median_seconds": retime_median,
        "retimed_duration": retimed.duration,
        "effort_cold_seconds": cold["cold"],
        "effort_warm_seconds": effort,
        "effort_iterations": least.iterations,
        "ur5_poses_seconds": ur5_poses,
        "ur5_poses_iterations": square.iterations,
        "time_seconds": fast,
        "time_median_seconds": fast_median,
        "time_duration": fastest.duration,
        "time_iterations": fastest.iterations,
        "anchor": {
            "effort": anchor.effort,
            "seconds": anchor.seconds,
            "iterations": anchor.iterations,
            "max_excess_10khz": _excess_10khz(ur5, anchor.trajectory),
        },
        "panda_fold": {"seconds": folded.seconds, "iterations": folded.iterations, "effort": folded.effort},
        "panda_fold_alone": None
        if alone is None
        else {"seconds": alone.seconds, "iterations": alone.iterations},
        "goals": {
            "retime": RETIME_GOAL,
            "effort_cold": EFFORT_GOAL,
            "ur5_poses": POSES_GOAL,
            "time": TIME_GOAL,
        },
        "load_average": [round(x, 2) for x in os.getloadavg()],
    }
    if croc:
        rows["crocoddyl"] = _crocoddyl(croc, ROOT / "examples" / "ur5_square_pose.toml")
    _print(rows, retimed, least, square, fastest)
    return {"optimal": rows}


def _print(rows: dict[str, Any], retimed: Any, least: Any, square: Any, fastest: Any) -> None:
    norm = rows["normalisation"]
    print(
        f"\ntrajectories within limits (issues 36, 45): wall time of one call (best / median); the baseline "
        f"{rows['baseline_seconds']:.3f} s (goals' machine {GOALS_BASELINE:g} s); load {rows['load_average']}"
    )
    print(
        f"  time-optimal retiming, report's path: {rows['retime_seconds'] * 1e3:.1f} / "
        f"{rows['retime_median_seconds'] * 1e3:.1f} ms, {_goal(rows['retime_seconds'], RETIME_GOAL, norm)}; "
        f"{retimed.duration:.4f} s against the reference's {retimed.original_duration:g} s"
    )
    print(
        f"  minimum effort, twolink: cold {rows['effort_cold_seconds'] * 1e3:.0f} ms, "
        f"{_goal(rows['effort_cold_seconds'], EFFORT_GOAL, norm)}, then {rows['effort_warm_seconds'] * 1e3:.1f} ms; "
        f"{least.iterations} SQP iterations; ∫τᵀτ {least.effort:.4g} against the polynomial's "
        f"{least.reference_effort:.4g} N²·m²·s"
    )
    print(
        f"  minimum effort, UR5 through four via poses: {rows['ur5_poses_seconds']:.2f} s, "
        f"{_goal(rows['ur5_poses_seconds'], POSES_GOAL, norm)}; {square.iterations} iterations; the tool within "
        f"{square.hull.distance * 1e3:.0f} mm of the square"
    )
    print(
        f"  minimum time, twolink: {rows['time_seconds']:.3f} / {rows['time_median_seconds']:.3f} s, "
        f"{_goal(rows['time_seconds'], TIME_GOAL, norm)}; {fastest.duration:.4f} s against the retiming's "
        f"{fastest.retimed_duration:.4f} s, {fastest.iterations} SQP iterations"
    )
    a = rows["anchor"]
    print(
        f"  the anchor, UR5 least effort alone from and to rest: ∫τᵀτ {a['effort']:.5g} N²·m²·s, largest excess "
        f"on a 10 kHz grid {a['max_excess_10khz']:.2g}, {a['seconds']:.2f} s, {a['iterations']} iterations"
    )
    for label, c in rows.get("crocoddyl", {}).items():
        excess = max(c["max_excess"].values())
        print(
            f"    crocoddyl ({label}): ∫τᵀτ {c['effort']:.5g} (toolkit / crocoddyl {a['effort'] / c['effort']:.3f}, "
            f"goal <= {ANCHOR_GOAL:g}), largest excess {excess:.2g}, via error {c['via_error']:.2g} rad, "
            f"{c['seconds']:.2f} s, {c['iterations']} iterations"
        )
    fold, alone = rows["panda_fold"], rows["panda_fold_alone"]
    print(
        f"  Panda fold: {fold['iterations']} iterations, {fold['seconds']:.2f} s"
        + (
            ""
            if alone is None
            else f"; the effort alone {alone['iterations']} iterations, {alone['seconds']:.2f} s"
        )
    )


__all__ = ["optimal_section"]
