"""The MuJoCo plant beside the Pinocchio plant (issue 44), measured in one run (``scripts/benchmark.py
--mujoco-only`` runs it; it runs alone too).

Speed: seconds per 30-s run of the same law with the same integrator (RK4 at 1 ms, the law at every
stage) on each plant, timed back to back ``repeats`` times (minima of wall-clock time, and of the
process's CPU time, the steadier on a loaded machine; ratios MuJoCo / Pinocchio): the
twolink's ``pd`` (goal ≤ 1.0×) and ``adaptive``, the Panda's ``osc`` (goal ≤ 1.0×); then a batch of
N = 1000 twolink ``pd`` runs per run (MuJoCo: one ``mujoco.batch`` of N simulations; Pinocchio:
``abaInParallel``), both on one thread. Equality: every extra effect off, the largest
``|q_mujoco − q_pinocchio|`` [rad] over the run for the twolink, the UR5 and the Panda × ``pd``,
``computed-torque``, ``adaptive``, ``osc`` (goal ≤ 1e-8 over 30 s).

Usage::

    .venv/bin/python scripts/benchmark_mujoco.py [--quick] [--repeats N] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from twolink_pin import PlantOptions, RunSpec, SimulationConfig, default_trajectory, load_robot, simulate
from twolink_pin.studies.batch import simulate_batch

FULL = 30.0
"""The job's simulated time [s]: every time is per 30-s run."""
SPEED_CASES = (("twolink", "pd", 1.0), ("twolink", "adaptive", None), ("panda", "osc", 1.0))
"""(robot, law, goal ratio or None) of the single-run timings."""
EQUALITY_CASES = tuple(
    (r, law) for r in ("twolink", "ur5", "panda") for law in ("pd", "computed-torque", "adaptive", "osc")
)
"""The arms × laws of the equality goal."""
EQUALITY_GOAL = 1e-8
"""Largest joint difference allowed between the plants [rad]."""


def _built(robot: Any, law: str, engine: str, duration: float) -> tuple[Any, Any, SimulationConfig]:
    spec = RunSpec(law=law, plant=PlantOptions(engine=engine), simulation=SimulationConfig(duration=duration))
    controller, plant = spec.build(robot)
    return controller, plant, spec.simulation


def _timed(run: Callable[[], Any]) -> tuple[float, float]:
    """Wall-clock and CPU seconds of ``run()`` (this process's CPU: on a loaded machine the steadier)."""
    start, cpu = time.perf_counter(), time.process_time()
    run()
    return time.perf_counter() - start, time.process_time() - cpu


def speed(quick: bool, repeats: int) -> dict[str, Any]:
    """Seconds per 30-s run on each plant and their ratio (module docstring)."""
    rows: dict[str, Any] = {}
    for name, law, goal in SPEED_CASES:
        robot = load_robot(name)
        reference = default_trajectory(robot)
        duration = (0.1 if quick else 2.0) if name == "panda" else (0.5 if quick else 10.0)
        runs = {e: _built(robot, law, e, duration) for e in ("pinocchio", "mujoco")}
        times: dict[str, list[tuple[float, float]]] = {e: [] for e in runs}
        for _ in range(repeats):
            for engine, (controller, plant, config) in runs.items():
                times[engine].append(
                    _timed(lambda c=controller, p=plant, g=config, r=reference: simulate(c, p, r, g))
                )
        rows[f"{name} {law} single"] = _row(times, FULL / duration, goal)
    robot = load_robot()
    reference = default_trajectory(robot)
    n, duration = (50, 0.01) if quick else (1000, 0.2)
    offsets = np.random.default_rng(0).uniform(-0.1, 0.1, (n, robot.nv))
    batch: dict[str, list[tuple[float, float]]] = {}
    for engine in ("pinocchio", "mujoco"):
        controller, plant, config = _built(robot, "pd", engine, duration)
        run = lambda c=controller, p=plant, g=config: simulate_batch(  # noqa: E731
            c, p, reference, g, q0_offsets=offsets, threads=1, progress=False
        )
        batch[engine] = [_timed(run) for _ in range(repeats)]
    rows[f"twolink pd batch N={n}, per run"] = _row(batch, FULL / duration / n, None)
    return rows


def _row(times: dict[str, list[tuple[float, float]]], scale: float, goal: float | None) -> dict[str, Any]:
    """Minimum wall and CPU seconds per 30-s run of each plant and the ratios MuJoCo / Pinocchio."""
    wall = {e: min(t[0] for t in ts) * scale for e, ts in times.items()}
    cpu = {e: min(t[1] for t in ts) * scale for e, ts in times.items()}
    return wall | {
        "cpu": cpu,
        "ratio": wall["mujoco"] / wall["pinocchio"],
        "cpu_ratio": cpu["mujoco"] / cpu["pinocchio"],
        "goal": goal,
    }


def equality(quick: bool) -> dict[str, float]:
    """The largest joint difference [rad] between the plants per arm and law (module docstring)."""
    duration = 1.0 if quick else FULL
    out = {}
    for name, law in EQUALITY_CASES:
        robot = load_robot(name)
        reference = default_trajectory(robot)
        q = []
        for engine in ("pinocchio", "mujoco"):
            controller, plant, config = _built(robot, law, engine, duration)
            q.append(simulate(controller, plant, reference, config).q)
        out[f"{name} {law}"] = float(np.abs(q[0] - q[1]).max())
    return out


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="short runs, one repeat (smoke test)")
    parser.add_argument("--repeats", type=int, default=None, help="timings per case (default 5; quick 1)")
    parser.add_argument("--json", action="store_true", help="also print the results as one JSON line")
    parser.add_argument("--speed-only", action="store_true", help="the timings only (no equality runs)")
    args = parser.parse_args(argv)
    repeats = args.repeats or (1 if args.quick else 5)
    load = [round(x, 2) for x in os.getloadavg()]
    rows = speed(args.quick, repeats)
    print(
        f"\nissue 44, the MuJoCo plant: seconds per 30-s run, back to back {repeats} times (minima); load average {load}"
    )
    print(f"  {'case':36s} {'Pinocchio s':>11s} {'MuJoCo s':>9s} {'ratio':>7s} {'CPU ratio':>10s}")
    for label, row in rows.items():
        verdict = ""
        if row["goal"] is not None:
            met = max(row["ratio"], row["cpu_ratio"]) <= row["goal"]
            verdict = f"  goal ≤ {row['goal']:g}x: {'met' if met else 'NOT met'}"
        print(
            f"  {label:36s} {row['pinocchio']:11.3f} {row['mujoco']:9.3f} {row['ratio']:6.2f}x "
            f"{row['cpu_ratio']:9.2f}x{verdict}"
        )
    same = {} if args.speed_only else equality(args.quick)
    print(
        f"\n  equality, every effect off: max |q_mujoco − q_pinocchio| [rad] over {1.0 if args.quick else FULL:g} s"
    )
    for label, worst in same.items():
        print(
            f"  {label:36s} {worst:11.2e}  {'met' if worst <= EQUALITY_GOAL else 'NOT met'} (≤ {EQUALITY_GOAL:g})"
        )
    results = {
        "mujoco": {
            "speed": rows,
            "equality": same,
            "load_average": load,
            "load_average_end": list(os.getloadavg()),
        }
    }
    if args.json:
        print(json.dumps(results))
    return results


if __name__ == "__main__":
    main()
