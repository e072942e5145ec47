"""``mpc`` against the anchor, crocoddyl's BoxFDDP MPC, on the same twolink references (issue 45,
item 6): the course's polynomial and its path retimed at 90 % of the limits; the same horizon,
knots, replanning period, weights, limit scale, plant step and start. Imported by
``scripts/benchmark.py --mpc-only``; the anchor's side is ``scripts/anchors/croc_mpc.py``, run
in a scratch venv named by ``CROCODDYL_PYTHON`` (default ``/tmp/croc/bin/python``; the column is
skipped, saying so, when there is none): ``pin==4.0.0 crocoddyl==3.2.1``, never a dependency.

Per reference and side: time per replan [µs], real-time factor (simulated / wall seconds of the
whole run, replans included), RMS and last-period max joint error [rad], the largest excess over
the effort (commanded), velocity and position limits; then the anchor's error over ``mpc``'s
(the lead; the goal is 10–25× on both references) and ``mpc``'s real-time factor (goal ≥ 10×).
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin import Plant, SimulationConfig, default_trajectory, load_robot, simulate
from twolink_pin.controllers import ModelPredictive
from twolink_pin.limits import EFFORT, POSITION, VELOCITY, joint_limits
from twolink_pin.run_spec import gains_used
from twolink_pin.trajectory import time_optimal

PEER = Path(__file__).resolve().parent / "anchors" / "croc_mpc.py"
DEFAULT_PYTHON = "/tmp/croc/bin/python"
LEAD_GOAL = (10.0, 25.0)
REAL_TIME_GOAL = 10.0


def _finite(values: Any) -> list[float | None]:
    return [float(x) if np.isfinite(x) else None for x in np.asarray(values, dtype=float)]


def peer_python() -> str | None:
    """The scratch venv's python that has crocoddyl, or None."""
    path = os.environ.get("CROCODDYL_PYTHON", DEFAULT_PYTHON)
    return path if Path(path).exists() else None


@contextlib.contextmanager
def replans_timed(law: Any) -> Iterator[dict[str, float]]:
    """Within the block, ``law.update`` (its replans) timed: the yielded dict's ``update`` [s]
    and ``replans`` (a count) grow with each call; the law's own method is back afterwards."""
    spent = {"update": 0.0, "replans": 0}
    update = law.update

    def timed(x: Any, terms: Any) -> Any:
        start = time.perf_counter()
        try:
            return update(x, terms)
        finally:
            spent["update"] += time.perf_counter() - start
            spent["replans"] += 1

    law.update = timed
    try:
        yield spent
    finally:
        del law.update


def _project(robot: Any, reference: Any, duration: float) -> dict[str, Any]:
    """``mpc``'s run on ``reference``: the same figures the peer prints."""
    law = ModelPredictive(robot)
    with replans_timed(law) as spent:
        start = time.perf_counter()
        run = simulate(law, Plant(robot), reference, SimulationConfig(duration=duration))
        wall = time.perf_counter() - start
    limits = joint_limits(robot)
    last = run.t >= run.t[-1] - reference.period - 1e-12
    return {
        "wall_s": wall,
        "real_time_factor": duration / wall,
        "replan_us": 1e6 * spent["update"] / max(spent["replans"], 1),
        "rms_e": np.sqrt(np.mean(run.e**2, axis=0)).tolist(),
        "last_period_max_e": np.abs(run.e[last]).max(axis=0).tolist(),
        "excess": {
            "effort": float(limits.excess(EFFORT, run.tau_command).max()),
            "velocity": float(limits.excess(VELOCITY, run.v).max()),
            "position": float(limits.excess(POSITION, run.q).max()),
        },
        "gains": law,
    }


def _peer(
    python: str, robot: Any, reference: Any, law: ModelPredictive, duration: float, folder: Path
) -> dict[str, Any]:
    """The anchor's run on the same reference, in the scratch venv (one JSON line back)."""
    dt = 1e-3
    g = law.gains
    span = duration + float(g.horizon) + float(g.replan_period) + dt
    times = dt * np.arange(int(np.ceil(span / dt)) + 1)
    sample = reference.sample(times)
    arrays = folder / "reference.npz"
    np.savez(arrays, t=times, q=sample.q, v=sample.v, a=sample.a)
    limits = joint_limits(robot)
    used = gains_used(law)
    job = {
        "urdf": str(robot.urdf_path),
        "arrays": str(arrays),
        "grid": dt,
        "dt": dt,
        "duration": duration,
        "period": reference.period,
        "q0_offset": list(robot.profile.q0_offset or (0.0,) * robot.nv),
        "limits": {
            k: _finite(getattr(limits, k)) for k in ("position_lower", "position_upper", "velocity", "effort")
        },
        "gains": {
            k: np.asarray(used[k], dtype=float).tolist()
            for k in (
                "horizon",
                "knot_interval",
                "replan_period",
                "weight_q",
                "weight_v",
                "weight_tau",
                "limit_scale",
            )
        },
    }
    path = folder / "job.json"
    path.write_text(json.dumps(job))
    done = subprocess.run(
        [python, str(PEER), str(path)],
        capture_output=True,
        text=True,
        timeout=1800,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
        check=False,
    )
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["no output"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def _row(side: str, r: dict[str, Any]) -> str:
    if "error" in r:
        return f"    {side:10s} failed: {r['error']}"
    e, last, ex = r["rms_e"], r["last_period_max_e"], r["excess"]
    return (
        f"    {side:10s} {r['replan_us']:8.0f} us/replan {r['real_time_factor']:6.1f}x real time   "
        f"RMS e ({e[0]:.3g}, {e[1]:.3g}) rad   last-period max e ({last[0]:.3g}, {last[1]:.3g}) rad   "
        f"largest excess: effort {max(ex['effort'], 0):.3g} N·m, velocity {max(ex['velocity'], 0):.3g} rad/s, "
        f"position {max(ex['position'], 0):.3g} rad"
    )


def anchor_section(quick: bool) -> dict[str, Any]:
    """Both references, both sides; the anchor's column skipped (said so) without its venv."""
    robot = load_robot()
    duration = 2.0 if quick else 30.0
    polynomial = default_trajectory(robot)
    references = {
        "polynomial": polynomial,
        "retimed 90 %": time_optimal(robot, polynomial, limit_scale=0.9).trajectory,
    }
    python = peer_python()
    print(
        f"\nmpc against crocoddyl's BoxFDDP MPC (same horizon 0.2 s, 8 knots, replans every 10 ms, RK4 at 1 ms; "
        f"{duration:g} s each; load average {[round(x, 2) for x in os.getloadavg()]})"
    )
    if python is None:
        print(
            f"  crocoddyl column skipped: no scratch venv at {os.environ.get('CROCODDYL_PYTHON', DEFAULT_PYTHON)} "
            "(python3 -m venv /tmp/croc && /tmp/croc/bin/pip install pin==4.0.0 crocoddyl==3.2.1, or set CROCODDYL_PYTHON)"
        )
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="twolink-pin-anchor-") as tmp:
        for name, reference in references.items():
            ours = _project(robot, reference, duration)
            law = ours.pop("gains")
            theirs = _peer(python, robot, reference, law, duration, Path(tmp)) if python else None
            print(f"  {name} (period {reference.period:.4g} s):")
            print(_row("mpc", ours))
            entry: dict[str, Any] = {"mpc": ours}
            if theirs is not None:
                print(_row("crocoddyl", theirs))
                entry["crocoddyl"] = theirs
                if "error" not in theirs:
                    lead = {
                        key: float(np.max(theirs[key]) / max(np.max(ours[key]), 1e-300))
                        for key in ("rms_e", "last_period_max_e")
                    }
                    entry["lead"] = lead
                    print(
                        f"    lead: crocoddyl's error / mpc's: RMS {lead['rms_e']:.1f}x, last-period max "
                        f"{lead['last_period_max_e']:.1f}x (goal {LEAD_GOAL[0]:g}-{LEAD_GOAL[1]:g}x); mpc "
                        f"{ours['real_time_factor']:.1f}x real time (goal >= {REAL_TIME_GOAL:g}x)"
                    )
            results[name] = entry
    return {"mpc_anchor": results}
