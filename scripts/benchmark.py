"""Benchmark of the one engine against a pure-Python closed-form baseline, measured in one run.

For each law (the five built-in ones and the tutorial's ``examples/sliding_mode.py``):
seconds per 30-s simulation (RK4, dt = 1 ms; min and median of several runs) of the single
run with the law at every stage, the single run with the law sampled at 1 kHz (zero-order
hold), and the batch engine per simulation at N = 1000 on 2 threads; each also as a ratio
``Nx`` to the baseline — the report's PD job as a plain Python loop over floats with the
closed-form M and C (no Pinocchio, no numpy per stage), timed in the same run and
interleaved with the others. The targets are printed beside (:data:`SINGLE_TARGET`: pd and
robust at most 12× the baseline — MuJoCo 4.0 with a Python controller at every RK4 stage on
this job, as first measured: 1.35 s against 0.111 s —, computed-torque 12.8×, adaptive 18×,
adaptive-friction 26×); the batch at most 1.0× per simulation (``--batch-only`` runs just that). The UR5 (pd, computed-torque,
adaptive) beside it: a single run and the batch at N = 1000, against the same baseline
(``--ur5-only`` runs just that). Then the batch engine's
scaling from N = 1 to 10 000 runs with 1 and 2 threads, the peak memory of sweeps of 1 000
and 10 000 runs (each in a fresh process), and the wall time of ``twolink-pin report``.

Last, sweep throughput on Dask (``--sweep-only`` runs just this part; ``--quick`` alone
skips it): runs/s of the same pd sweep in-process, on a LocalCluster of 1 worker and of 2
workers, for the twolink and the UR5 at several horizons, the ratio 2 workers / 1 worker
and the shortest horizon from which it reaches 1.6×; and the client's peak memory at
100 000 runs of 0.05 s (against 10 000: bounded), in-process and with ``--workers 2``.

Batch and sweep timings use shorter simulations where N is large (noted in the output):
the cost per step is constant, so seconds per 30-s simulation = elapsed × 30 / duration / N.

Usage::

    .venv/bin/python scripts/benchmark.py            # full: 10-20 minutes
    .venv/bin/python scripts/benchmark.py --quick    # smoke test: seconds, numbers rough
    .venv/bin/python scripts/benchmark.py --json     # also a JSON line at the end
    .venv/bin/python scripts/benchmark.py --sweep-only [--quick]   # Dask throughput, client memory
    .venv/bin/python scripts/benchmark.py --ur5-only [--quick]     # the UR5 against the baseline
    .venv/bin/python scripts/benchmark.py --single-only [--quick]  # every law's single run, back to back; osc on the Panda
    .venv/bin/python scripts/benchmark.py --shared-only [--quick]  # two batches at once; 200-run sweep, 2 workers
    .venv/bin/python scripts/benchmark.py --big-arms-only [--quick]  # issue 31: Panda osc/impedance, batches, floor
    .venv/bin/python scripts/benchmark.py --tune-only [--quick]    # tune: from a change to updated results
    .venv/bin/python scripts/benchmark.py --qp-osc-only [--quick]  # issue 37: qp-osc against osc on the Panda
    .venv/bin/python scripts/benchmark.py --optimal-only [--quick] [--croc PYTHON] # issues 36, 45: retiming, optimize, the anchor
    .venv/bin/python scripts/benchmark.py --mpc-only [--quick]     # issue 37: mpc's 30-s runs, batch, demo (a);
                                                                   # issue 45: against crocoddyl's MPC (mpc_anchor.py)
    .venv/bin/python scripts/benchmark.py --contact-only [--quick] # issue 46: the contact lab, contact's cost
    .venv/bin/python scripts/benchmark.py --arms-only [--quick]    # issue 50: every arm × law at the defaults
    .venv/bin/python scripts/benchmark.py --mujoco-only [--quick]  # issue 44: the MuJoCo plant beside Pinocchio's
    .venv/bin/python scripts/benchmark.py --equations-only [--quick]  # issue 47: symbolic equations, scaling

``--arms-only`` (issue 50, ``scripts/arms.py``): every profile of ``examples/arms`` — every
fixed-base arm example-robot-data ships, each arm of its trees, a 5-link chain — with every
built-in law for 3 s at its defaults; goals: 100 % of (arm × law) run, ``computed-torque`` on the
exact model within 1e-3 rad at 3 s, the step check at most 5 ms per run (median). The single-run
guards above (ratios to the baseline) are the step check's cost on the whole run.

``tune`` (issue 29): the latency from a change of a gain to updated results (the run simulated,
measured, the scene, plots and metrics table updated, its JSON line reported) for one period
of the reference: pd on the twolink (4 s; goal 0.5 s), pd on the UR5, osc on the Panda; the
median and the largest of several changes, through the tuner's own server (no browser).
Then as a person meets it (issue 38): ``tune`` started as a command, its page in headless
Chromium (software WebGL), the arm playing; from one ArrowRight on the focused slider
``kp joint 1`` to the page showing the new run's first period (its status line "period 1 of
P shown", which the tuner sends after that period's plots and with its metrics table: the
goal applies to it) and to the page showing the complete run (key → page), beside key → the
JSON line and the simulation's own time: pd on the twolink (goal 0.5 s), osc on the Panda
(goal 2 s).

A shared machine: two copies of the pd batch (N = 1000, 0.2 s) started together in two
processes, at the default thread count, at 1 and at 2 threads, per simulation against the
baseline (the default must not be slower than one thread); and the 200-run twolink sweep
in-process against ``--workers 2`` (cluster start included).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin import (  # first, before pinocchio loads: OpenMP's passive wait policy (twolink_pin.openmp)
    Plant,
    SimulationConfig,
    default_trajectory,
    load_robot,
    make_scenario,
    simulate,
    simulate_batch,
)
from twolink_pin.openmp import available_cores
from twolink_pin.simulation import default_threads
from twolink_pin.trajectory import JointTrajectory, with_force

FULL = 30.0
"""The job's simulated time [s]."""
DT = 1.0e-3
"""RK4 step [s]."""
HERE = Path(__file__).resolve().parent
LAWS = (
    "pd",
    "computed-torque",
    "robust",
    "adaptive",
    "adaptive-friction",
    str(HERE.parent / "examples" / "sliding_mode.py") + ":SlidingMode",
)
"""The laws timed: the built-in five and the tutorial's."""
SINGLE_TARGET = {
    "pd": 12.0,
    "computed-torque": 12.8,
    "robust": 12.0,
    "adaptive": 18.0,
    "adaptive-friction": 26.0,
}
"""The single-run targets (× the baseline): issue 48's for pd (12×), computed-torque (12.8×:
MuJoCo's pace with the same law) and adaptive-friction (26×); the first issue's for robust
(MuJoCo's 12×) and adaptive (1.5× that)."""
BATCH_TARGET = 1.0
"""The issue's batch target per simulation (× the baseline), every law."""


def _label(spec: str) -> str:
    return "sliding-mode (example)" if spec.endswith(":SlidingMode") else spec


def baseline_pd(
    trajectory: JointTrajectory,
    p: np.ndarray,
    gains: Any,
    q0: np.ndarray,
    v0: np.ndarray,
    dt: float,
    n: int,
) -> tuple[list[float], list[float], list[float]]:
    """The PD job as a pure-Python loop on floats with the report's closed-form model.

    ``M = [[p1 + 2 p3 c2, p2 + p3 c2], [p2 + p3 c2, p2]]``, ``C = p3 s2 [[−q̇2, −(q̇1 + q̇2)], [q̇1, 0]]``;
    law ``τ = M q̈_d + C q̇_d − Kp e − Kd ė`` at every RK4 stage; ``q̈ = M⁻¹ (τ − C q̇)`` by the
    2×2 inverse. The reference is precomputed on the half-step grid (vectorised), as in
    the simulators. Returns the flat q, q̇, τ histories.
    """
    half = trajectory.sample(np.arange(2 * n + 1) * (dt / 2))
    rq1, rq2 = half.q[:, 0].tolist(), half.q[:, 1].tolist()
    rv1, rv2 = half.v[:, 0].tolist(), half.v[:, 1].tolist()
    ra1, ra2 = half.a[:, 0].tolist(), half.a[:, 1].tolist()
    p1, p2, p3 = (float(x) for x in p)
    kp1, kp2 = (float(x) for x in np.diag(np.asarray(gains.kp)[0]))  # the report's: diagonal matrices
    kd1, kd2 = (float(x) for x in np.diag(np.asarray(gains.kd)[0]))
    cos, sin = math.cos, math.sin

    def f(q1: float, q2: float, v1: float, v2: float, i: int) -> tuple[float, float, float, float]:
        c2, s2 = cos(q2), sin(q2)
        m11, m12, h = p1 + 2 * p3 * c2, p2 + p3 * c2, p3 * s2
        wd1, wd2, ad1, ad2 = rv1[i], rv2[i], ra1[i], ra2[i]
        t1 = m11 * ad1 + m12 * ad2 - h * (v2 * wd1 + (v1 + v2) * wd2) - kp1 * (q1 - rq1[i]) - kd1 * (v1 - wd1)
        t2 = m12 * ad1 + p2 * ad2 + h * v1 * wd1 - kp2 * (q2 - rq2[i]) - kd2 * (v2 - wd2)
        b1, b2 = t1 + h * (v2 * v1 + (v1 + v2) * v2), t2 - h * v1 * v1
        det = m11 * p2 - m12 * m12
        return (p2 * b1 - m12 * b2) / det, (m11 * b2 - m12 * b1) / det, t1, t2

    q1, q2 = float(q0[0]), float(q0[1])
    v1, v2 = float(v0[0]), float(v0[1])
    Q: list[float] = []
    V: list[float] = []
    T: list[float] = []
    h2, h6 = dt / 2, dt / 6
    for k in range(n):
        i = 2 * k
        a11, a12, t1, t2 = f(q1, q2, v1, v2, i)
        Q += (q1, q2)
        V += (v1, v2)
        T += (t1, t2)
        x1, x2, y1, y2 = q1 + h2 * v1, q2 + h2 * v2, v1 + h2 * a11, v2 + h2 * a12
        a21, a22, _, _ = f(x1, x2, y1, y2, i + 1)
        x1b, x2b, y1b, y2b = q1 + h2 * y1, q2 + h2 * y2, v1 + h2 * a21, v2 + h2 * a22
        a31, a32, _, _ = f(x1b, x2b, y1b, y2b, i + 1)
        x1c, x2c, y1c, y2c = q1 + dt * y1b, q2 + dt * y2b, v1 + dt * a31, v2 + dt * a32
        a41, a42, _, _ = f(x1c, x2c, y1c, y2c, i + 2)
        q1, q2 = q1 + h6 * (v1 + 2 * (y1 + y1b) + y1c), q2 + h6 * (v2 + 2 * (y2 + y2b) + y2c)
        v1, v2 = v1 + h6 * (a11 + 2 * (a21 + a31) + a41), v2 + h6 * (a12 + 2 * (a22 + a32) + a42)
    Q += (q1, q2)
    V += (v1, v2)
    return Q, V, T


def _timed(run: Callable[[], Any]) -> float:
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def _machine() -> dict[str, Any]:
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": available_cores(),
        "default_threads": default_threads(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pinocchio": version("pin"),
        "system": f"{platform.system()} {platform.release()}",
        "load_average": [round(x, 2) for x in os.getloadavg()],
    }


_SWEEP_CHILD = """
import sys, tracemalloc
from twolink_pin import default_trajectory, load_robot
from twolink_pin.simulation import SimulationConfig
from twolink_pin.run_spec import RunSpec
from twolink_pin.studies.sweep import SweepConfig, GainRange, run_sweep

def high_water_mib():  # VmHWM: this process's peak RSS (ru_maxrss would carry the parent's over exec)
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM")) / 1024

robot = load_robot(); trajectory = default_trajectory(robot)
samples, duration, out, trace = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3], sys.argv[4] == "trace"
config = SweepConfig(RunSpec(law="pd", simulation=SimulationConfig(duration=duration)), samples, seed=1,
                     q0_spread=0.1, param_error=0.2, gains=(GainRange("kp", 100.0, 400.0),))
before = high_water_mib()
if trace:
    tracemalloc.start()
output = run_sweep(config, robot, trajectory, out, plot=False)
traced = tracemalloc.get_traced_memory()[1] / 2**20 if trace else float("nan")
print(before, high_water_mib(), traced, output.seconds)
"""


def _child_memory(script: str, *args: object) -> dict[str, Any]:
    """Run a sweep ``script`` in a fresh process; its printed peak RSS before / after the sweep,
    Python allocations' peak [MiB] (None when not traced) and the sweep's seconds."""
    done = subprocess.run(
        [sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True, check=True
    )
    before, peak, traced, seconds = (float(x) for x in done.stdout.split())
    python_peak = None if math.isnan(traced) else traced
    return {
        "rss_before_mib": before,
        "rss_peak_mib": peak,
        "python_peak_mib": python_peak,
        "seconds": seconds,
    }


def _python_peak(memory: dict[str, Any]) -> str:
    """``Python allocations peak … MiB`` of a child's ``memory``, or that it was not traced."""
    if memory["python_peak_mib"] is None:
        return "Python allocations not traced (--quick)"
    return f"Python allocations peak {memory['python_peak_mib']:6.1f} MiB"


def _sweep_memory(samples: int, duration: float, out: str, trace: bool = True) -> dict[str, Any]:
    """Peak memory of a PD sweep in a fresh process: peak RSS before / after, Python allocations
    (traced unless ``trace`` is false: ``--quick``, tracemalloc makes the sweep ~2x slower)."""
    flag = "trace" if trace else "-"
    return {"samples": samples, **_child_memory(_SWEEP_CHILD, samples, duration, out, flag)}


# -- sweep throughput on Dask ---------------------------------------------------------------------

SWEEP_HORIZONS = {"twolink": (0.05, 0.2, 1.0, 3.0), "ur5": (0.05, 0.2, 1.0)}
"""Horizons [s] of the throughput sweeps, per robot."""
SWEEP_BUDGET = {"twolink": 1500.0, "ur5": 300.0}
"""Simulated run-seconds per measurement (samples = budget / horizon, at least 500)."""
TARGET_SPEEDUP = 1.6
"""The issue's 2-worker target: >= 1.6x the 1-worker throughput (2 cores)."""


def _throughput_study(samples: int, duration: float) -> Any:
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.studies.sweep import SweepConfig

    return SweepConfig(
        RunSpec(law="pd", simulation=SimulationConfig(duration=duration)), samples, seed=1, q0_spread=0.05
    )


_CLIENT_CHILD = """
import sys, tracemalloc
from twolink_pin import default_trajectory, load_robot
from twolink_pin.simulation import SimulationConfig
from twolink_pin.run_spec import RunSpec
from twolink_pin.studies.sweep import SweepConfig, run_sweep

def high_water_mib():  # VmHWM: this process's peak RSS (the client's; Dask workers are other processes)
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM")) / 1024

if __name__ == "__main__":
    samples, duration, out, workers = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3], int(sys.argv[4])
    trace = sys.argv[5] == "trace"
    scheduler = sys.argv[6] if len(sys.argv) > 6 else None  # a running cluster of `workers` workers
    robot = load_robot(); trajectory = default_trajectory(robot)
    config = SweepConfig(RunSpec(law="pd", simulation=SimulationConfig(duration=duration)), samples, seed=1, q0_spread=0.05)
    before = high_water_mib()
    if trace:
        tracemalloc.start()
    where = {"scheduler": scheduler} if scheduler else {"workers": workers or None}
    output = run_sweep(config, robot, trajectory, out, plot=True, **where)
    traced = tracemalloc.get_traced_memory()[1] / 2**20 if trace else float("nan")
    print(before, high_water_mib(), traced, output.seconds)
"""


def _client_memory(
    samples: int, duration: float, workers: int, out: str, scheduler: str | None = None, trace: bool = True
) -> dict[str, Any]:
    """Peak memory of the sweep's client (the whole sweep in-process when ``workers`` is 0;
    on the running cluster at ``scheduler`` of ``workers`` workers when given, else on a
    LocalCluster of its own); Python allocations traced unless ``trace`` is false (``--quick``:
    under tracemalloc the lazy imports of Dask, matplotlib and pyarrow and the figure cost
    ~10 s of CPU per child, the sweep itself ~1 s)."""
    where = () if scheduler is None else (scheduler,)
    flag = "trace" if trace else "-"
    return {
        "samples": samples,
        "workers": workers,
        **_child_memory(_CLIENT_CHILD, samples, duration, out, workers, flag, *where),
    }


def sweep_section(quick: bool) -> dict[str, Any]:
    """Sweep throughput in-process / 1 / 2 workers and the client's memory (see the docstring)."""
    import tempfile

    from twolink_pin.studies import cluster
    from twolink_pin.studies.sweep import run_sweep

    if not cluster.available():
        print(f"\nsweep throughput: skipped, Dask is not installed ({cluster.INSTALL_HINT})")
        return {}
    horizons = {"twolink": (0.05,), "ur5": (0.05,)} if quick else SWEEP_HORIZONS
    budget = {"twolink": 5.0, "ur5": 1.0} if quick else SWEEP_BUDGET
    least = 40 if quick else 500
    repeats = 1 if quick else 3
    rows: list[dict[str, Any]] = []
    starts: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp, contextlib.ExitStack() as stack:
        engines: dict[str, Any] = {}
        for count in (1, 2):
            started = time.perf_counter()
            engines[f"{count}w"] = stack.enter_context(cluster.open_cluster(workers=count))
            starts[f"{count}w"] = time.perf_counter() - started
        print(
            f"\nsweep throughput, pd, ±0.05 rad initial error (runs/s over the runs and the streaming of the rows, "
            f"best of {repeats} interleaved; chunks auto; LocalCluster start excluded: 1 worker {starts['1w']:.1f} s, 2 workers {starts['2w']:.1f} s; "
            f"load average {[round(x, 2) for x in os.getloadavg()]})"
        )
        print(
            f"  {'robot':8s} {'horizon':>8s} {'runs':>6s} {'chunk 1w/2w':>12s} {'in-process':>11s} {'1 worker':>9s} "
            f"{'2 workers':>10s} {'2w/1w':>6s}"
        )
        for name, chosen in horizons.items():
            robot = load_robot(name)
            trajectory = default_trajectory(robot)
            for engine in engines.values():  # warm-up: each worker loads the robot's code paths once
                run_sweep(
                    _throughput_study(4, 0.01),
                    robot,
                    trajectory,
                    f"{tmp}/warm",
                    plot=False,
                    client=engine.client,
                )
            for duration in chosen:
                samples = max(least, round(budget[name] / duration))
                study = _throughput_study(samples, duration)
                row: dict[str, Any] = {"robot": name, "duration": duration, "samples": samples}
                for _ in range(repeats):  # interleaved; the best of each: the least disturbed by other load
                    for mode, engine in (("in_process", None), *engines.items()):
                        client = None if engine is None else engine.client
                        output = run_sweep(
                            study, robot, trajectory, f"{tmp}/{mode}", plot=False, client=client
                        )
                        row[mode] = max(row.get(mode, 0.0), samples / output.seconds)
                        row[f"chunk_{mode}"] = output.chunk
                row["speedup"] = row["2w"] / row["1w"]
                rows.append(row)
                print(
                    f"  {name:8s} {duration:6.2f} s {samples:6d} {row['chunk_1w']:>5d}/{row['chunk_2w']:<6d} "
                    f"{row['in_process']:9.1f}/s {row['1w']:7.1f}/s {row['2w']:8.1f}/s {row['speedup']:5.2f}x"
                )
        reached = {}
        for name in horizons:
            good = [r["duration"] for r in rows if r["robot"] == name and r["speedup"] >= TARGET_SPEEDUP]
            reached[name] = min(good) if good else None
            where = f"from {reached[name]:g} s horizons on" if good else "at none of the horizons measured"
            print(f"  {name}: 2 workers reach {TARGET_SPEEDUP:g}x the 1-worker throughput {where}")
        memory = []
        sizes = (500,) if quick else (10_000, 100_000)
        print(
            "\nclient memory of a pd sweep of 0.05-s runs (fresh process, VmHWM; figure on; chunks auto; "
            "--workers 2: the client of the 2-worker cluster above, the workers being other processes)"
        )
        for samples in sizes:
            for workers in (0, 2):
                scheduler = engines["2w"].address if workers else None
                out = os.path.join(tmp, f"{samples}-{workers}")
                mem = _client_memory(samples, 0.05, workers, out, scheduler, trace=not quick)
                memory.append(mem)
                label = "in-process" if workers == 0 else "--workers 2 (client only)"
                print(
                    f"  {label:26s} {samples:6d} runs: peak RSS {mem['rss_peak_mib']:7.1f} MiB (after imports "
                    f"{mem['rss_before_mib']:6.1f} MiB), {_python_peak(mem)}, {mem['seconds']:.1f} s"
                )
    return {
        "sweep_throughput": rows,
        "sweep_speedup_from": reached,
        "cluster_start_seconds": starts,
        "client_memory": memory,
    }


# -- a shared machine: two batches at once; a 200-run sweep in-process against 2 workers -------------

_CONTENDER = """
import sys, time
import numpy as np
from twolink_pin import default_trajectory, load_robot, make_scenario, simulate_batch
from twolink_pin.simulation import SimulationConfig

threads = None if sys.argv[1] == "default" else int(sys.argv[1])
robot = load_robot(); trajectory = default_trajectory(robot)
controller, plant = make_scenario("pd", robot)
offsets = np.random.default_rng(0).uniform(-0.1, 0.1, (1000, robot.nv))
config = SimulationConfig(duration=float(sys.argv[2]))
simulate_batch(controller, plant, trajectory, SimulationConfig(duration=0.01), q0_offsets=offsets,
               threads=threads, progress=False)  # warm-up
print("ready", flush=True)
sys.stdin.readline()  # go: both copies start together
start = time.perf_counter()
batch = simulate_batch(controller, plant, trajectory, config, q0_offsets=offsets, threads=threads, progress=False)
print(time.perf_counter() - start, batch.threads, flush=True)
"""
CONTENTION_N, CONTENTION_DURATION = 1000, 0.2
"""The issue's contention case: pd, N = 1000, 0.2 s simulated."""
QUICK_CONTENTION_DURATION = 0.05
"""``--quick``: the same batch, 0.05 s simulated (the smoke test's eight processes)."""


def _two_at_once(
    threads: str, copies: int = 2, duration: float = CONTENTION_DURATION
) -> tuple[list[float], int]:
    """``copies`` copies of the pd batch of ``duration`` [s] started together (each in its own
    process, all ready first; one copy: the batch alone, the machine otherwise free); their
    seconds per 30-s simulation and the thread count they used."""
    children = [
        subprocess.Popen(
            [sys.executable, "-c", _CONTENDER, threads, str(duration)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        for _ in range(copies)
    ]
    try:
        for child in children:  # the readiness line of each, then go for both
            assert child.stdout is not None and child.stdout.readline().strip() == "ready"
        for child in children:
            assert child.stdin is not None
            child.stdin.write("go\n")
            child.stdin.flush()
        outputs = [child.communicate()[0].split() for child in children]
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()
    scale = FULL / duration / CONTENTION_N
    return [float(out[0]) * scale for out in outputs], int(outputs[0][1])


def contention_section(
    baseline: Callable[[], Any], scale: float, repeats: int, duration: float = CONTENTION_DURATION
) -> dict[str, Any]:
    """Two copies of the batch (``duration`` [s] simulated) at once, at the default thread
    count, 1 and 2 threads, per simulation against the baseline timed in between (the issue:
    default 6.2 s, 1 thread 0.85 s, 2 threads 3.7 s per copy, before the passive wait policy)."""
    rows: dict[str, list[float]] = {"default": [], "1": [], "2": []}
    alone: dict[str, list[float]] = {"default": [], "1": []}  # one copy: the machine free
    used = used_alone = 0
    base_times = []
    for _ in range(repeats):  # interleaved: load drift hits all alike
        base_times.append(_timed(baseline))
        for threads in rows:
            seconds, count = _two_at_once(threads, duration=duration)
            rows[threads].append(max(seconds))  # the slower copy: what the user waits for
            used = count if threads == "default" else used
        for threads in alone:
            seconds, count = _two_at_once(threads, copies=1, duration=duration)
            alone[threads].append(seconds[0])
            used_alone = count if threads == "default" else used_alone
    base = min(base_times) * scale
    print(
        f"\ncontention: two copies of the pd batch at once (N = {CONTENTION_N}, {duration:g} s simulated, "
        f"separate processes started together); seconds per 30-s simulation of the slower copy, min of {repeats} "
        f"(median), ratio to the baseline ({base:.3f} s) of this section; load average "
        f"{[round(x, 2) for x in os.getloadavg()]}"
    )
    for threads, times in rows.items():
        label = (
            f"default ({used} thread{'s' if used != 1 else ''})"
            if threads == "default"
            else f"{threads} thread(s)"
        )
        best = min(times)
        print(f"  {label:22s} {best:8.4f} s {best / base:7.3f}x   (median {statistics.median(times):.4f} s)")
    verdict = min(rows["default"]) <= min(rows["1"]) * 1.1
    print(f"  default not slower than 1 thread when shared (within 10 %): {'met' if verdict else 'NOT met'}")
    print("one copy alone (the same batch, nothing else started by the benchmark)")
    for threads, times in alone.items():
        label = (
            f"default ({used_alone} thread{'s' if used_alone != 1 else ''})"
            if threads == "default"
            else "1 thread(s)"
        )
        best = min(times)
        print(f"  {label:22s} {best:8.4f} s {best / base:7.3f}x   (median {statistics.median(times):.4f} s)")
    free = min(alone["default"]) < min(alone["1"]) and statistics.median(
        alone["default"]
    ) < statistics.median(alone["1"])
    print(f"  default faster than 1 thread when alone (min and median): {'met' if free else 'NOT met'}")
    return {
        "contention": {
            "baseline_seconds": base,
            "default_threads": used,
            "seconds_per_sim": {k: min(v) for k, v in rows.items()},
            "median_seconds_per_sim": {k: statistics.median(v) for k, v in rows.items()},
            "alone_default_threads": used_alone,
            "alone_seconds_per_sim": {k: min(v) for k, v in alone.items()},
            "alone_median_seconds_per_sim": {k: statistics.median(v) for k, v in alone.items()},
        }
    }


SWEEP_200 = 200
"""Runs of the issue's sweep (in-process 36.9 s against 46.7 s on ``--workers 2``: one chunk)."""


def sweep_200_section(duration: float = 30.0, repeats: int = 3) -> dict[str, Any]:
    """Sweep throughput, 200 runs, in-process vs ``--workers 2``: the twolink pd sweep of
    :data:`SWEEP_200` runs of ``duration`` [s] as the command line runs it (a fresh
    ``twolink-pin sweep`` process each time: imports, robot, LocalCluster start and its
    workers' imports included), the two modes alternated ``repeats`` times so that a change
    of load hits both; the medians and every pair are printed with the load average."""
    import statistics
    import subprocess
    import tempfile

    from twolink_pin.studies import cluster

    if not cluster.available():
        print(f"\nsweep of {SWEEP_200} runs: skipped, Dask is not installed ({cluster.INSTALL_HINT})")
        return {}
    command = [sys.executable, "-m", "twolink_pin.cli", "sweep", "pd", "--samples", str(SWEEP_200)]
    command += ["--duration", f"{duration:g}", "--no-plot", "--json"]
    seconds: dict[str, list[float]] = {"in_process": [], "workers_2": []}
    loads = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats):
            for label, extra in (("in_process", []), ("workers_2", ["--workers", "2"])):
                start = time.perf_counter()
                subprocess.run(
                    [*command, "--out", f"{tmp}/{label}-{k}", *extra], check=True, capture_output=True
                )
                seconds[label].append(time.perf_counter() - start)
            loads.append(round(os.getloadavg()[0], 2))
    median = {label: statistics.median(values) for label, values in seconds.items()}
    print(
        f"\nsweep throughput, {SWEEP_200} runs, in-process vs --workers 2 (twolink pd, {duration:g}-s runs, wall "
        f"of the whole command, {repeats} alternated pairs; 1-min load average after each pair {loads}):"
    )
    for label, values in seconds.items():
        shown = ", ".join(f"{x:.1f}" for x in values)
        print(
            f"  {label:10s} median {median[label]:6.1f} s ({SWEEP_200 / median[label]:5.1f} runs/s; each: {shown} s)"
        )
    ratio = median["in_process"] / median["workers_2"]
    print(f"  in-process / --workers 2 (medians): {ratio:.2f} (above 1: the 2 workers are faster)")
    return {"sweep_200": {"duration": duration, "seconds": seconds, "median": median, "load_average": loads}}


def _batch_case(spec: str, robot: Any, n: int) -> tuple[Any, Any, np.ndarray]:
    """One law object for N runs (per-run initial offsets ± 0.1 rad) and its plant."""
    controller, plant = make_scenario(spec, robot)
    offsets = np.random.default_rng(0).uniform(-0.1, 0.1, (n, robot.nv)) + np.array([0.1, -0.1])
    return controller, plant, offsets


def batch_rows(
    baseline: Callable[[], Any], base_times: list[float], robot: Any, trajectory: Any, quick: bool
) -> dict[str, float]:
    """Seconds per 30-s simulation of each law's batch at N = 1000 on 2 threads (min of 3 rounds,
    each round after one more baseline timing appended to ``base_times``: the load hits both)."""
    batch_n = 100 if quick else 1000
    batch_duration = 0.05 if quick else 1.0
    batch_rounds = 1 if quick else 3
    batch_times: dict[str, list[float]] = {spec: [] for spec in LAWS}
    batch_cases = {spec: _batch_case(spec, robot, batch_n) for spec in LAWS}
    config = SimulationConfig(duration=batch_duration, dt=DT)
    for _ in range(batch_rounds):
        base_times.append(_timed(baseline))
        for spec, (law, plant_b, offsets) in batch_cases.items():
            elapsed = _timed(
                lambda c=law, p=plant_b, o=offsets: simulate_batch(
                    c, p, trajectory, config, q0_offsets=o, threads=2, progress=False
                )
            )
            batch_times[spec].append(elapsed * FULL / batch_duration / batch_n)
    return {spec: min(times) for spec, times in batch_times.items()}


def batch_only_section(
    baseline: Callable[[], Any], scale: float, robot: Any, trajectory: Any, quick: bool
) -> dict[str, Any]:
    """``--batch-only``: each law's batch per simulation (:func:`batch_rows`) against the
    baseline's minimum over the rounds, with the batch target (:data:`BATCH_TARGET`)."""
    load_before = [round(x, 2) for x in os.getloadavg()]
    base_times: list[float] = []
    batch = batch_rows(baseline, base_times, robot, trajectory, quick)
    base = min(base_times) * scale
    load_after = [round(x, 2) for x in os.getloadavg()]
    print(
        f"\nbatch per simulation (N = {100 if quick else 1000}, 2 threads, min of the rounds) against the baseline "
        f"{base:.3f} s (min of {len(base_times)}, one before each round); load average {load_before} -> {load_after}"
    )
    for spec in LAWS:
        ratio = batch[spec] / base
        print(f"  {_label(spec):24s} {batch[spec]:8.3f} s {ratio:6.2f}x{_verdict(ratio, BATCH_TARGET)}")
    return {"batch_only": {"baseline_seconds": base, "seconds": {_label(k): v for k, v in batch.items()}}}


UR5_LAWS = ("pd", "computed-torque", "adaptive")
"""The laws timed on the UR5 (6 joints, 10 x 6 base parameters + friction for the adaptive law)."""


def ur5_section(baseline: Callable[[], Any], scale: float, quick: bool, repeats: int) -> dict[str, Any]:
    """The UR5 beside the twolink: seconds per 30-s simulation of a single run (law at every
    stage) and of the batch at N = 1000 per simulation, each timed interleaved with the
    twolink's pure-Python baseline (``baseline``, ``scale`` to 30 s) and given as a ratio to it."""
    ur5 = load_robot("ur5")
    reference = default_trajectory(ur5)
    single_duration = 0.2 if quick else 2.0
    batch_n = 100 if quick else 1000
    batch_duration = 0.02 if quick else 0.2
    rng = np.random.default_rng(0)
    offsets = rng.uniform(-0.05, 0.05, (batch_n, ur5.nv))
    single_config = SimulationConfig(duration=single_duration, dt=DT, q0_offset=0.05)
    batch_config = SimulationConfig(duration=batch_duration, dt=DT)
    base_times: list[float] = []
    single: dict[str, list[float]] = {spec: [] for spec in UR5_LAWS}
    batch: dict[str, list[float]] = {spec: [] for spec in UR5_LAWS}
    scenarios = {spec: make_scenario(spec, ur5) for spec in UR5_LAWS}
    for _ in range(repeats):
        base_times.append(_timed(baseline) * scale)
        for spec, (law, plant) in scenarios.items():
            single[spec].append(
                _timed(lambda c=law, p=plant: simulate(c, p, reference, single_config))
                * FULL
                / single_duration
            )
    for _ in range(1 if quick else 2):
        base_times.append(_timed(baseline) * scale)
        for spec, (law, plant) in scenarios.items():
            elapsed = _timed(
                lambda c=law, p=plant: simulate_batch(
                    c, p, reference, batch_config, q0_offsets=offsets, threads=2, progress=False
                )
            )
            batch[spec].append(elapsed * FULL / batch_duration / batch_n)
    base = min(base_times)
    print(
        f"\nthe UR5 (6 joints) beside the twolink: seconds per 30-s simulation and ratio to the twolink's "
        f"baseline ({base:.3f} s, min of {len(base_times)} interleaved; single: {single_duration:g} s simulated, "
        f"min of {repeats}; batch: N = {batch_n}, {batch_duration:g} s simulated, 2 threads, per simulation)"
    )
    print(f"  {'law':24s} {'single (per stage)':>20s} {'batch per sim':>20s}")
    rows = {}
    for spec in UR5_LAWS:
        cells = [min(single[spec]), min(batch[spec])]
        rows[spec] = {"single": cells[0], "batch_per_sim": cells[1]}
        print(f"  {spec:24s} " + " ".join(f"{x:10.3f} s {x / base:6.2f}x" for x in cells))
    return {"ur5": {"baseline_seconds": base, "batch_n": batch_n, "seconds": rows}}


SINGLE_RUN_ROBOTS = ("twolink", "ur5")
"""The single-run rows: every built-in law (the package's registry, not a table here) on these arms."""


def _built_in_laws() -> list[str]:
    """The names of the package's own laws that run in free space, in registry order (plugins and
    files left out; ``force`` and ``hybrid`` press on a surface: ``--contact-only``)."""
    from twolink_pin.controllers.loading import available_controllers

    return [
        n
        for n, cls in available_controllers().items()
        if cls.__module__.startswith("twolink_pin.controllers") and not cls.force_control
    ]


MUJOCO_RATIO = 12.8
"""Issue 22 item 4: MuJoCo 4.0 with a Python law at every RK4 stage, × the baseline of the same run."""


def single_runs_section(
    baseline: Callable[[], Any], scale: float, quick: bool, repeats: int
) -> dict[str, Any]:
    """Every built-in law's single run (N = 1, law at every RK4 stage) against the pure-Python
    baseline, timed **back to back** (baseline, law; baseline, law; ...) so that each pair sees
    the same load: per law the ratio of minima and the median of the pairs' ratios, against
    MuJoCo's 12.8x (:data:`MUJOCO_RATIO`); the load average before and after."""
    duration = 0.2 if quick else 2.0
    load_before = [round(x, 2) for x in os.getloadavg()]
    rows: dict[str, dict[str, Any]] = {}
    for robot_name in SINGLE_RUN_ROBOTS:
        laws = _built_in_laws()
        robot = load_robot(robot_name)
        reference = default_trajectory(robot)
        config = SimulationConfig(
            duration=duration, dt=DT, q0_offset=None if robot_name == "twolink" else 0.05
        )
        for spec in laws:
            law, plant = make_scenario(spec, robot)
            simulate(law, plant, reference, SimulationConfig(duration=0.01, dt=DT))  # warm: imports, caches
            base, run, pairs = [], [], []
            for _ in range(repeats):
                b = _timed(baseline) * scale
                r = (
                    _timed(lambda c=law, p=plant, t=reference, f=config: simulate(c, p, t, f))
                    * FULL
                    / duration
                )
                base.append(b)
                run.append(r)
                pairs.append(r / b)
            rows[f"{robot_name} {spec}"] = {
                "seconds": min(run),
                "baseline_seconds": min(base),
                "ratio_of_minima": min(run) / min(base),
                "median_pair_ratio": statistics.median(pairs),
            }
    load_after = [round(x, 2) for x in os.getloadavg()]
    print(
        f"\nsingle runs (N = 1, law at every RK4 stage, {duration:g} s simulated), each timed back to back with "
        f"the baseline {repeats} times; load average {load_before} -> {load_after}"
    )
    print(
        f"  {'law':28s} {'s per 30 s':>10s} {'min/min':>9s} {'median pair':>12s}  target <= {MUJOCO_RATIO:g}x"
    )
    for name, row in rows.items():
        verdict = "met" if row["median_pair_ratio"] <= MUJOCO_RATIO else "NOT met"
        print(
            f"  {name:28s} {row['seconds']:10.3f} {row['ratio_of_minima']:8.2f}x {row['median_pair_ratio']:11.2f}x  "
            f"{verdict}"
        )
    return {
        "single_runs": {
            "duration": duration,
            "repeats": repeats,
            "load_average": [load_before, load_after],
            "target": MUJOCO_RATIO,
            "rows": rows,
        }
    }


def osc_panda_section(baseline: Callable[[], Any], scale: float, quick: bool, repeats: int) -> dict[str, Any]:
    """``osc`` on the Panda (7 joints, a redundant arm: the posture task in the null space):
    seconds per 30-s simulation of a single run and of the batch at N = 1000 per simulation,
    beside the pure-Python baseline timed in the same run (issue 20)."""
    panda = load_robot("panda")
    reference = default_trajectory(panda)
    law, plant = make_scenario("osc", panda)
    single_duration = 0.05 if quick else 0.5
    batch_n = 100 if quick else 1000
    batch_duration = 0.01 if quick else 0.02
    offsets = np.random.default_rng(0).uniform(-0.05, 0.05, (batch_n, panda.nv))
    single_config = SimulationConfig(duration=single_duration, dt=DT, q0_offset=0.05)
    batch_config = SimulationConfig(duration=batch_duration, dt=DT)
    base: list[float] = []
    single: list[float] = []
    batch: list[float] = []
    for _ in range(repeats):
        base.append(_timed(baseline) * scale)
        single.append(_timed(lambda: simulate(law, plant, reference, single_config)) * FULL / single_duration)
    for _ in range(1 if quick else 2):
        base.append(_timed(baseline) * scale)
        elapsed = _timed(
            lambda: simulate_batch(
                law, plant, reference, batch_config, q0_offsets=offsets, threads=None, progress=False
            )
        )
        batch.append(elapsed * FULL / batch_duration / batch_n)
    b = min(base)
    print(
        f"\nosc on the Panda (7 joints): seconds per 30-s simulation and ratio to the baseline ({b:.3f} s, min of "
        f"{len(base)} interleaved; single: {single_duration:g} s simulated, min of {repeats}; batch: N = {batch_n}, "
        f"{batch_duration:g} s simulated, default threads, per simulation); load average "
        f"{[round(x, 2) for x in os.getloadavg()]}"
    )
    print(f"  {'single':10s} {min(single):10.3f} s {min(single) / b:7.2f}x")
    print(f"  {'batch':10s} {min(batch):10.3f} s {min(batch) / b:7.2f}x")
    return {
        "osc_panda": {
            "baseline_seconds": b,
            "single_seconds": min(single),
            "batch_per_sim_seconds": min(batch),
            "batch_n": batch_n,
            "single_duration": single_duration,
            "batch_duration": batch_duration,
        }
    }


QP_OSC_TARGET = 2.0
"""Issue 37's goal: ``qp-osc`` on the Panda at most this many times ``osc``'s time per run."""


def _qp_osc_profile(law: Any, plant: Any, reference: Any, config: SimulationConfig) -> dict[str, float]:
    """One run of ``law`` (qp-osc) with its two parts timed: building the QPs
    (``_problems``: the task, Λ, the costs and the bounds) and solving them (``solve_qp``: the
    closed form or ProxQP), and how many evaluations needed ProxQP; µs per evaluation."""
    import twolink_pin.controllers.qp_osc as module

    spent = {"build": 0.0, "solve": 0.0, "evaluations": 0, "prox": 0}
    build, solve = type(law)._problems, module.solve_qp

    def timed_build(self: Any, x: Any, terms: Any) -> Any:
        start = time.perf_counter()
        out = build(self, x, terms)
        spent["build"] += time.perf_counter() - start
        spent["evaluations"] += len(out[0])
        return out

    def timed_solve(qp: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        out = solve(qp, **kwargs)
        spent["solve"] += time.perf_counter() - start
        spent["prox"] += out.iterations > 0
        return out

    type(law)._problems, module.solve_qp = timed_build, timed_solve
    try:
        start = time.perf_counter()
        simulate(law, plant, reference, config)
        total = time.perf_counter() - start
    finally:
        type(law)._problems, module.solve_qp = build, solve
    n = max(1, int(spent["evaluations"]))
    return {
        "evaluations": n,
        "prox_share": spent["prox"] / n,
        "build_us": spent["build"] / n * 1e6,
        "solve_us": spent["solve"] / n * 1e6,
        "stage_us": total / n * 1e6,
    }


def qp_osc_section(quick: bool, repeats: int) -> dict[str, Any]:
    """Issue 37's goal: ``qp-osc`` against ``osc`` on the Panda, the same single run (its default
    reference, 0.05 rad off, law at every RK4 stage), timed back to back ``repeats`` times, per
    30-s run and as the ratio of minima (goal <= 2); then where qp-osc's time goes, per
    evaluation: building the QP, solving it, the whole stage — on that run (no limit binds)
    and on docs/limits.md's demo (the folded elbow, 3 kg, a 1.5-rad start: limits bind)."""
    from twolink_pin import read_trajectory_file

    panda = load_robot("panda")
    reference = default_trajectory(panda)
    duration = 0.1 if quick else 2.0
    config = SimulationConfig(duration=duration, dt=DT, q0_offset=0.05)
    laws = {name: make_scenario(name, panda) for name in ("osc", "qp-osc")}
    times: dict[str, list[float]] = {name: [] for name in laws}
    for _ in range(repeats):
        for name, (law, plant) in laws.items():
            times[name].append(_timed(lambda law=law, plant=plant: simulate(law, plant, reference, config)))
    seconds = {name: min(t) * FULL / duration for name, t in times.items()}
    ratio = seconds["qp-osc"] / seconds["osc"]
    loaded = load_robot("panda", payload=3.0)
    fold = read_trajectory_file(HERE.parent / "examples" / "panda_fold_pose.toml", loaded)
    law, plant = make_scenario("qp-osc", loaded)
    demo = SimulationConfig(duration=0.1 if quick else 2.5, dt=DT, q0_offset=(1.5, 0, 0, 0, 0, 0, 0))
    profiles = {  # the least disturbed of the repeats (the smallest stage time)
        "default reference": min(
            (_qp_osc_profile(*laws["qp-osc"], reference, config) for _ in range(repeats)),
            key=lambda r: r["stage_us"],
        ),
        "limits demo": min(
            (_qp_osc_profile(law, plant, fold, demo) for _ in range(repeats)), key=lambda r: r["stage_us"]
        ),
    }
    print(
        f"\nqp-osc against osc on the Panda (default reference, 0.05 rad off; {duration:g} s simulated, min of "
        f"{repeats} back to back): seconds per 30-s run; load average {[round(x, 2) for x in os.getloadavg()]}"
    )
    print(f"  {'osc':10s} {seconds['osc']:10.3f} s")
    print(f"  {'qp-osc':10s} {seconds['qp-osc']:10.3f} s {ratio:7.2f}x osc{_verdict(ratio, QP_OSC_TARGET)}")
    print(
        f"  qp-osc per evaluation (least disturbed of {repeats} runs): building the QP, solving it (closed form or "
        "ProxQP), the whole stage"
    )
    for label, row in profiles.items():
        print(
            f"  {label:18s} build {row['build_us']:7.1f} us  solve {row['solve_us']:7.1f} us  stage "
            f"{row['stage_us']:7.1f} us  ProxQP on {100 * row['prox_share']:5.1f} % of {row['evaluations']} evaluations"
        )
    return {
        "qp_osc_panda": {
            "duration": duration,
            "repeats": repeats,
            "osc_seconds": seconds["osc"],
            "qp_osc_seconds": seconds["qp-osc"],
            "ratio": ratio,
            "target": QP_OSC_TARGET,
            "profile": profiles,
        }
    }


MPC_TARGETS = {"twolink": 3.0, "ur5": 30.0}
"""Issue 37's goals for ``mpc``: seconds per 30-s run (the twolink 10× faster than real time)."""


def _mpc_split(law: Any, plant: Any, reference: Any, config: SimulationConfig) -> dict[str, float]:
    """One run of ``law`` with its replans timed apart: total (wall and this process's CPU),
    replans (building the QPs and solving them; the rest is the plant and the law between
    replans), in seconds, and the number of replans."""
    from mpc_anchor import replans_timed  # scripts/mpc_anchor.py, beside this file

    cpu = time.process_time()
    with replans_timed(law) as spent:
        total = _timed(lambda: simulate(law, plant, reference, config))
    return {
        "total": total,
        "cpu": time.process_time() - cpu,
        "update": spent["update"],
        "replans": spent["replans"],
    }


def mpc_section(quick: bool, repeats: int) -> dict[str, Any]:
    """Issue 37's goals for ``mpc``: a 30-s run on the twolink (<= 3 s) and on the UR5 (<= 30 s),
    the default reference 0.1 / 0.05 rad off, the law replanning every 10 ms (min of ``repeats``,
    the replans' share beside); a batch of N runs per run (one derivatives call for the N plans,
    the N QPs solved one after the other); and demo (a) of docs/control_within_limits.md — the
    retimed twolink, the model 20 % light — with its limit violations counted (goal: none)."""
    from twolink_pin.controllers import ModelPredictive
    from twolink_pin.limits import EFFORT, VELOCITY, joint_limits
    from twolink_pin.trajectory import time_optimal

    durations = {"twolink": 0.5 if quick else 30.0, "ur5": 0.2 if quick else 30.0}
    seconds, shares = {}, {}
    print(
        f"\nmpc (horizon 0.2 s, 8 knots, replans every 10 ms; min of {repeats}): seconds per 30-s run; "
        f"load average {[round(x, 2) for x in os.getloadavg()]}"
    )
    for name, duration in durations.items():
        robot = load_robot(name)
        law, plant = ModelPredictive(robot), Plant(robot)
        config = SimulationConfig(duration=duration, dt=DT)
        runs = [_mpc_split(law, plant, default_trajectory(robot), config) for _ in range(repeats)]
        best = min(runs, key=lambda r: r["total"])
        seconds[name] = best["total"] * FULL / duration
        cpu = best["cpu"] * FULL / duration
        shares[name] = best["update"] / best["total"]
        per_replan = 1e6 * best["update"] / max(best["replans"], 1)
        met = "met" if seconds[name] <= MPC_TARGETS[name] else "NOT met"
        print(
            f"  {name:8s} {seconds[name]:8.3f} s per 30-s run (CPU {cpu:.3f} s; {FULL / seconds[name]:.1f}x real time; "
            f"replans {100 * shares[name]:.0f} % of it, {per_replan:.0f} us each) (target <= {MPC_TARGETS[name]:g} s: {met})"
        )
    robot = load_robot()
    n, batch_duration = (4, 0.2) if quick else (50, 2.0)
    offsets = np.random.default_rng(0).uniform(-0.1, 0.1, (n, robot.nv))
    law = ModelPredictive(robot)
    elapsed = _timed(
        lambda: simulate_batch(
            law, Plant(robot), default_trajectory(robot), SimulationConfig(duration=batch_duration, dt=DT),
            q0_offsets=offsets,
        )
    )  # fmt: skip
    batch = elapsed * FULL / batch_duration / n
    print(
        f"  batch    {batch:8.3f} s per 30-s run, N = {n} ({batch_duration:g} s each; one derivatives call per replan)"
    )
    retimed = time_optimal(robot, default_trajectory(robot)).trajectory
    light = ModelPredictive(robot, model_parameters=np.asarray(robot.p) * 0.8)
    run = simulate(light, Plant(robot), retimed, SimulationConfig(duration=0.2 if quick else 2.112, dt=DT))
    limits = joint_limits(robot)
    violations = int(
        (limits.excess(EFFORT, run.tau_command) > 0).sum() + (limits.excess(VELOCITY, run.v) > 0).sum()
    )
    rms = np.sqrt(np.mean(run.e**2, axis=0))
    print(
        f"  demo (a) retimed twolink, model 20 % light: {violations} limit violations over {run.t.size} samples "
        f"(goal 0: {'met' if violations == 0 else 'NOT met'}), RMS e {np.round(rms, 4).tolist()} rad"
    )
    return {
        "mpc": {
            "seconds_per_30s": seconds,
            "replan_share": shares,
            "targets": MPC_TARGETS,
            "batch_seconds_per_30s": batch,
            "batch_n": n,
            "demo_a_violations": violations,
        }
    }


BIG_ARM_TARGETS = {"osc batch": 8.0, "adaptive batch": 5.0}
"""Issue 31's batch targets per run (× the baseline): osc on the Panda, adaptive on the UR5."""


def _floor_stage(robot: Any, law: str, n: int) -> Callable[[], None]:
    """One RK4 stage of a batch of ``n`` runs reduced to its bare Pinocchio calls in a plain
    loop over the runs (the floor of issue 31): what the Terms call per run for ``law``
    (``osc``: one computeAllTerms + the frame's placement, Jacobian and J̇q̇; ``adaptive``:
    one joint-torque regressor on the polarisation pair) and the plant's one abaInParallel."""
    import pinocchio as pin

    from twolink_pin.dynamics import polarisation_pair

    rng = np.random.default_rng(0)
    model = robot.model
    Q = robot.home + rng.uniform(-0.05, 0.05, (n, robot.nv))
    V = rng.uniform(-0.5, 0.5, (n, robot.nv))
    pool = pin.ModelPool(model, 1)
    out = np.empty((robot.nv, n))
    Qt, Vt = np.ascontiguousarray(Q.T), np.ascontiguousarray(V.T)
    if law == "osc":
        data, fid, frame = model.createData(), robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

        def stage() -> None:
            for q, v in zip(Q, V, strict=True):
                pin.computeAllTerms(model, data, q, v)
                pin.updateFramePlacement(model, data, fid)
                pin.getFrameJacobian(model, data, fid, frame)
                pin.getFrameClassicalAcceleration(model, data, fid, frame)
            pin.abaInParallel(1, pool, Qt, Vt, Vt, out)

        return stage
    pair = polarisation_pair(model)
    pdata = pair.createData()
    Q2, V2 = np.concatenate((Q, Q), axis=1), np.concatenate((V, V), axis=1)
    A2 = np.zeros_like(V2)

    def stage_regressor() -> None:
        for q, v, a in zip(Q2, V2, A2, strict=True):
            pin.computeJointTorqueRegressor(pair, pdata, q, v, a)
        pin.abaInParallel(1, pool, Qt, Vt, Vt, out)

    return stage_regressor


def big_arms_section(baseline: Callable[[], Any], scale: float, quick: bool, repeats: int) -> dict[str, Any]:
    """Issue 31: ``osc`` and ``impedance`` on the Panda (single run, law at every stage and held
    over the step), the ``osc`` batch on the Panda (N = 100 and 1000) and the UR5's ``adaptive``
    batch (N = 1000), per run against the baseline timed back to back; and the floor — the bare
    per-run Pinocchio calls of a batch stage in a plain loop (:func:`_floor_stage`) — with the
    batch's distance to it. Batches and floor on one thread."""
    panda, ur5 = load_robot("panda"), load_robot("ur5")
    single_duration = 0.05 if quick else 0.5
    rows: dict[str, dict[str, float]] = {}

    def pair(label: str, run: Callable[[], Any], per_run_scale: float) -> None:
        base, times = [], []
        for _ in range(repeats):
            base.append(_timed(baseline) * scale)
            times.append(_timed(run) * per_run_scale)
        rows[label] = {"seconds": min(times), "baseline": min(base), "ratio": min(times) / min(base)}

    for law in ("osc", "impedance"):
        reference = default_trajectory(panda)
        for tag, period in (("per stage", None), ("held", DT)):
            config = SimulationConfig(duration=single_duration, dt=DT, q0_offset=0.05, control_period=period)

            def one(law: str = law, config: SimulationConfig = config, reference: Any = reference) -> None:
                c, p = make_scenario(law, panda)
                simulate(c, p, reference, config)

            pair(f"panda {law} single, {tag}", one, FULL / single_duration)
    floors: dict[str, float] = {}
    cases = [("panda", panda, "osc", 100), ("panda", panda, "osc", 1000), ("ur5", ur5, "adaptive", 1000)]
    for name, robot, law, n in cases[:1] + cases[2:] if quick else cases:
        n = min(n, 100) if quick else n
        duration = 0.005 if quick else (0.02 if n >= 1000 else 0.1)
        reference = default_trajectory(robot)
        offsets = np.random.default_rng(0).uniform(-0.05, 0.05, (n, robot.nv))
        config = SimulationConfig(duration=duration, dt=DT)

        def batch(
            robot: Any = robot,
            law: str = law,
            offsets: np.ndarray = offsets,
            config: Any = config,
            ref: Any = reference,
        ) -> None:
            c, p = make_scenario(law, robot)
            simulate_batch(c, p, ref, config, q0_offsets=offsets, threads=1, progress=False)

        label = f"{name} {law} batch N={n}, per run"
        pair(label, batch, FULL / duration / n)
        stage = _floor_stage(robot, law, n)
        stage()
        floor = min(_timed(stage) for _ in range(max(3, repeats))) * 4 * round(FULL / DT) / n
        floors[label] = floor
        rows[label]["floor"] = floor
    print(
        f"\nissue 31, the big arms: seconds per 30-s run, each timed back to back with the baseline {repeats} times "
        f"(ratio of minima); single runs {single_duration:g} s simulated; batches 1 thread, per run; floor: the bare "
        f"per-run Pinocchio calls of a batch stage in a plain loop; load average {[round(x, 2) for x in os.getloadavg()]}"
    )
    print(f"  {'case':44s} {'s per 30 s':>10s} {'ratio':>8s} {'floor s':>9s} {'x floor':>8s}")
    for label, row in rows.items():
        target = next((t for k, t in BIG_ARM_TARGETS.items() if label.split(" ", 1)[1].startswith(k)), None)
        floor_cells = f" {row['floor']:9.3f} {row['seconds'] / row['floor']:7.2f}x" if "floor" in row else ""
        print(
            f"  {label:44s} {row['seconds']:10.3f} {row['ratio']:7.2f}x{floor_cells}{_verdict(row['ratio'], target)}"
        )
    return {"big_arms": rows}


TUNE_GOAL = 0.5
"""From a change to updated results for the twolink's one-period pd run [s] (issue 29)."""


def _tune_latency(robot_name: str, law: str, changes: int) -> list[float]:
    """Seconds from each of ``changes`` gain changes to the tuner's report of the new run."""
    import threading

    from twolink_pin.cli.simulate_line import command_line, simulate_argv
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.tuning import Tuner

    robot = load_robot(robot_name)
    reference = default_trajectory(robot)
    base = RunSpec(law=law, simulation=SimulationConfig(duration=float(reference.period), dt=DT))
    finished = threading.Semaphore(0)
    tuner = Tuner(
        base,
        0.0,
        lambda payload: (robot, reference),
        lambda spec, payload: command_line(simulate_argv(spec, robot_name, payload)),
        lambda spec, payload: {},
        lambda line: finished.release(),
        port=0,
    )
    try:
        assert finished.acquire(timeout=600)  # the first run
        seconds = []
        for k in range(changes):
            slider = tuner.panel.sliders[-1]  # the last gain's scale: × 1.01, 1.02, …
            slider.value = 1.0 + 0.01 * (k + 1)
            start = time.perf_counter()
            tuner.changed()
            assert finished.acquire(timeout=600)
            seconds.append(time.perf_counter() - start)
        return seconds
    finally:
        tuner.close()


PAGE_GOALS = {("twolink", "pd"): 0.5, ("panda", "osc"): 2.0}
"""Key press → updated page [s] (issue 38), headless Chromium, the arm playing."""
SHOWN_JS = """
window.twolinkFirst = {};
window.twolinkShown = {};
window.twolinkKeys = [];
window.addEventListener('keydown', function () { window.twolinkKeys.push(Date.now()); }, true);
new MutationObserver(function () {
  var m = /run (\\d+): (period \\d+ of|[\\d.]+ s simulated)/.exec(document.body.textContent);
  if (!m) return;
  if (!(m[1] in window.twolinkFirst)) window.twolinkFirst[m[1]] = Date.now();
  if (m[2].indexOf('period') < 0 && !(m[1] in window.twolinkShown)) window.twolinkShown[m[1]] = Date.now();
}).observe(document.body, {subtree: true, childList: true, characterData: true});
"""
"""Times (ms since the epoch) the page saw: each key press; each run's first view (its
status line "run N: period 1 of P shown", sent with the first period's metrics after its
plots, or the complete run's for a run of one period) and its complete view ("run N: 12 s
simulated in …")."""


def _tune_page_latency(
    robot_name: str, law: str, changes: int, playing: bool = True, duration: float | None = None
) -> dict[str, list[float]]:
    """Key → the page's first view of the new run (its first period), key → the page showing
    the complete run, key → the page's keydown, key → JSON line, and the run's own time [s]
    for ``changes`` ArrowRight presses on ``kp joint 1`` (or the first gain's first
    slider), the arm playing (or paused from the page's play box first); the tuner's
    default duration (three periods) or ``duration`` [s]."""
    import json
    import queue
    import subprocess
    import threading

    root = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root / "tests"))
    from browser import start_chromium  # the tests' headless Chromium (software WebGL)
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    from twolink_pin.tuning.scene import RESUME_AFTER

    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "twolink_pin_entry",
            "tune",
            law,
            f"--robot={robot_name}",
            "--json",
            "--no-browser",
            *([] if duration is None else [f"--duration={duration:g}"]),
        ],
        cwd=root,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    lines: queue.Queue[tuple[float, dict[str, Any]]] = queue.Queue()

    def read() -> None:
        assert proc.stdout is not None
        for text in proc.stdout:
            lines.put((time.time(), json.loads(text)))

    threading.Thread(target=read, daemon=True).start()

    def next_line(wanted: Any) -> tuple[float, dict[str, Any]]:
        while True:
            at, line = lines.get(timeout=600)
            if wanted(line):
                return at, line

    out: dict[str, list[float]] = {"first": [], "page": [], "json": [], "run": [], "key": []}
    try:
        url = next_line(lambda line: "url" in line)[1]["url"]
        next_line(lambda line: "metrics" in line)
        with start_chromium(1400, 1000) as driver:
            driver.get(url)
            driver.execute_script(SHOWN_JS)
            thumb = WebDriverWait(driver, 600).until(
                lambda d: d.execute_script(
                    "var l = Array.from(document.querySelectorAll('label')).find("
                    "function (e) { return / joint 1 | axis x /.test(e.textContent + ' '); });"
                    "return l ? document.getElementById(l.htmlFor).querySelector('[role=slider]') : null;"
                )
            )
            WebDriverWait(driver, 600).until(
                lambda d: d.execute_script("return Object.keys(window.twolinkShown).length")
            )
            if not playing:
                driver.find_element("xpath", "//*[text()='playback']").click()  # its folder starts closed
                WebDriverWait(driver, 600).until(
                    lambda d: d.execute_script(
                        "return Array.from(document.querySelectorAll('label')).some(e => e.textContent === 'play')"
                    )
                )
                driver.execute_script(
                    "var l = Array.from(document.querySelectorAll('label')).find(e => e.textContent === 'play');"
                    "var n = l; for (var i = 0; i < 12; i++) { n = n.parentElement;"
                    " var c = n.querySelector('input[type=checkbox]'); if (c) { c.click(); return; } }"
                )
            time.sleep(2.0)  # the playback running (or paused) as a person finds it
            for _ in range(changes):
                driver.execute_script("arguments[0].focus()", thumb)
                pressed = time.time()
                ActionChains(driver).send_keys(Keys.ARROW_RIGHT).perform()
                at, line = next_line(lambda line: "metrics" in line or "error" in line)
                run = str(line["run"])
                shown = WebDriverWait(driver, 600).until(
                    lambda d, run=run: d.execute_script("return window.twolinkShown[arguments[0]]", run)
                )
                out["page"].append(shown / 1e3 - pressed)
                first = driver.execute_script("return window.twolinkFirst[arguments[0]]", run)
                out["first"].append(first / 1e3 - pressed)
                keys = driver.execute_script("return window.twolinkKeys")
                out["key"].append(keys[-1] / 1e3 - pressed if keys else float("nan"))
                out["json"].append(at - pressed)
                out["run"].append(float(line.get("seconds", float("nan"))))
                time.sleep(RESUME_AFTER + 1.0)  # the arm plays again before the next press
    finally:
        proc.terminate()
        proc.wait(timeout=60)
    return out


def tune_page_section(quick: bool) -> dict[str, Any]:
    """``tune`` in Chromium: key press → updated page (see the module docstring)."""
    import shutil

    changes = 2 if quick else 5
    if not (shutil.which("chromium") or Path("/usr/bin/chromium").exists()):
        print("\ntune in Chromium: skipped (no /usr/bin/chromium: scripts/install_browser.sh)")
        return {}
    print(
        f"\ntune in headless Chromium (software WebGL), the arm playing: one ArrowRight on the first gain's "
        f"first slider → the page shows the new run's first period (status line, its metrics, plots; the goal "
        f"applies to it) and then the complete run; median and max of {changes}"
    )
    out: dict[str, Any] = {}
    cases = [(name, law, goal, None) for (name, law), goal in PAGE_GOALS.items()]
    # the Panda once more with one period (the periods control at 1): tune runs three by default
    cases.insert(2, ("panda", "osc", PAGE_GOALS[("panda", "osc")], 4.0))
    for robot_name, law, goal, duration in cases[:1] if quick else cases:
        for playing in (True, False):
            got = _tune_page_latency(robot_name, law, changes, playing, duration)
            first, page = statistics.median(got["first"]), statistics.median(got["page"])
            how = "playing" if playing else "paused"
            length = "3 periods" if duration is None else f"{duration:g} s"
            print(
                f"  {law + ' on the ' + robot_name + ', ' + length + ', ' + how:40s} key → first period shown "
                f"{first:6.3f} s (max {max(got['first']):6.3f} s)"
                + (f" (goal {goal:g} s: {'met' if first <= goal else 'NOT met'})" if playing else "")
                + f"; key → complete run shown {page:6.3f} s (max {max(got['page']):6.3f} s); "
                f"key → keydown in the page {statistics.median(got['key']):6.3f} s, "
                f"key → JSON {statistics.median(got['json']):6.3f} s, run {statistics.median(got['run']):6.3f} s"
            )
            out[f"{law}_{robot_name}_{length.replace(' ', '_')}_{how}"] = {
                "first_period_median_seconds": first,
                "first_period_max_seconds": max(got["first"]),
                "page_median_seconds": page,
                "page_max_seconds": max(got["page"]),
                "keydown_median_seconds": statistics.median(got["key"]),
                "json_median_seconds": statistics.median(got["json"]),
                "run_median_seconds": statistics.median(got["run"]),
            }
    return {"tune_page_latency": out}


def tune_section(quick: bool) -> dict[str, Any]:
    """``tune``: the latency from a change to updated results (see the module docstring)."""
    changes = 2 if quick else 5
    cases = [("twolink", "pd"), ("ur5", "pd"), ("panda", "osc")]
    print(
        f"\ntune: from a change of a gain to updated results, one period of the reference, median and max of "
        f"{changes} changes (goal for pd on the twolink {TUNE_GOAL:g} s); load average "
        f"{[round(x, 2) for x in os.getloadavg()]}"
    )
    out: dict[str, Any] = {}
    for robot_name, law in cases[:1] if quick else cases:
        seconds = _tune_latency(robot_name, law, changes)
        period = float(default_trajectory(load_robot(robot_name)).period)
        median = statistics.median(seconds)
        goal = (
            f"  (goal {TUNE_GOAL:g} s: {'met' if median <= TUNE_GOAL else 'NOT met'})"
            if robot_name == "twolink"
            else ""
        )
        print(
            f"  {law + ' on the ' + robot_name:22s} {period:5.1f} s run   {median:6.3f} s   max {max(seconds):6.3f} s{goal}"
        )
        out[f"{law}_{robot_name}"] = {"period": period, "median_seconds": median, "max_seconds": max(seconds)}
    return {"tune_latency": out}


def _verdict(ratio: float, target: float | None) -> str:
    if target is None:
        return ""
    return f" (target <= {target:g}x: {'met' if ratio <= target else 'NOT met'})"


def identification_section(quick: bool) -> dict[str, Any]:
    """``identify`` on the UR5 (48 parameters) from a noisy log along its stored excitation
    (tests/fixtures/ur5_excitation.json), and the ``--physical`` fit on top; the simulated run
    that makes the log is not timed."""
    from pathlib import Path

    from twolink_pin.identification import IdentificationOptions, add_noise, identify, simulate_log
    from twolink_pin.identification.physical import compare_physical
    from twolink_pin.trajectory import read_trajectory_file

    ur5 = load_robot("ur5")
    fixture = Path(__file__).resolve().parents[1] / "tests" / "fixtures" / "ur5_excitation.json"
    duration = 3.0 if quick else 20.0
    log = add_noise(simulate_log(ur5, read_trajectory_file(fixture, ur5), duration=duration), 1e-5, 0.05, 0)
    options = IdentificationOptions()
    start = time.perf_counter()
    result = identify(log, ur5, options)
    seconds_identify = time.perf_counter() - start
    start = time.perf_counter()
    compare_physical(log, ur5, options, result)
    seconds_physical = time.perf_counter() - start
    print(
        f"\nidentify on the UR5 ({result.size} parameters, {duration:g}-s log at 2 kHz along its stored excitation, "
        f"{result.fit_samples} samples fitted): {seconds_identify:.2f} s; --physical fit on top "
        f"(consistency SDPs, the constrained fit, the validation period): {seconds_physical:.2f} s"
    )
    return {
        "identify_ur5": {
            "duration": duration,
            "parameters": result.size,
            "seconds": seconds_identify,
            "physical_seconds": seconds_physical,
        },
        **ur5_commands_section(quick),
    }


EXCITE_UR5_DOCUMENTED = 64.0
"""docs/identification.md: ``excite --robot ur5 --starts 1 --max-iterations 100`` took 64 s [s]."""
COMMAND_TARGET = 1.5
"""Issue 28 §8: a command within this many times its documented time."""


def ur5_commands_section(quick: bool) -> dict[str, Any]:
    """The two UR5 commands issue 28 §8 timed, end to end as a user runs them (CLI ``main``,
    output discarded): ``excite --robot ur5 --starts 1 --max-iterations 100`` against the 64 s
    docs/identification.md quotes, and ``identify --robot ur5`` (its simulated default: the
    stored excitation, the simulated log, the fit). Wall and CPU time: a CPU time well above
    the wall time is BLAS threads spinning (what made both slow before)."""
    import contextlib
    import io
    import tempfile

    from twolink_pin.cli import main

    iterations = 3 if quick else 100
    rows: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, argv, documented in (
            (
                "excite_ur5",
                [
                    "excite",
                    "--robot",
                    "ur5",
                    "--starts",
                    "1",
                    "--max-iterations",
                    str(iterations),
                    "--out",
                    f"{folder}/ex.json",
                ],
                EXCITE_UR5_DOCUMENTED * iterations / 100,
            ),
            (
                "identify_ur5_cli",
                ["identify", "--robot", "ur5", *(["--duration", "3"] if quick else [])],
                None,
            ),
        ):
            wall, cpu = time.perf_counter(), time.process_time()
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                code = main(argv)
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            verdict = "" if documented is None else _verdict(wall / documented, COMMAND_TARGET)
            print(
                f"twolink-pin {' '.join(argv[:3])}: exit {code}, {wall:.1f} s wall, {cpu:.1f} s CPU{verdict}"
            )
            rows[name] = {
                "argv": argv,
                "exit": code,
                "seconds": wall,
                "cpu_seconds": cpu,
                "documented": documented,
            }
    return rows


CONTACT_GOALS = {"hybrid_force_rms_error_N": 0.5, "contact_cost_ratio": 1.5}
"""Issue 46's goals: the twolink's contact lab, force RMS error of ``hybrid`` after 0.5 s in
contact [N]; a run against the wall over the same run without it (time ratio)."""


CONTACT_PLANTS = ("pinocchio", "mujoco")
"""The plants the contact lab and its cost run on (``PlantOptions.engine``)."""
CONTACT_LAWS = (("hybrid", {}), ("force", {}), ("impedance", {"k": 1000.0, "d": 300.0}))
"""The lab's laws and their gains (impedance's stiffness: with the wall in series, about 10 N)."""


def contact_section(quick: bool, repeats: int) -> dict[str, Any]:
    """Issue 46: the contact lab on the twolink (examples/wall.toml, examples/wall_slide.toml;
    scripts/contact_lab.py) on each plant — each law's contact metrics, ``hybrid``'s force RMS
    error against its goal; then the cost of the contact on each plant: the lab's run with the
    wall and the same run without it on the same plant (the law, reference and step alike; the
    wall's scene left out), interleaved, the fastest of ``repeats`` each, as a ratio (impedance:
    the lab's law that runs either way; pd: the cheapest law, the contact's share largest)."""
    from twolink_pin.contact import read_scene
    from twolink_pin.trajectory import read_trajectory_file

    robot = load_robot()
    examples = Path(__file__).resolve().parents[1] / "examples"
    scene = read_scene(examples / "wall.toml")
    lab = read_trajectory_file(examples / "wall_slide.toml", robot)
    config = SimulationConfig(duration=2.0 if quick else 6.0, q0_offset=0.0)
    metrics = {engine: _contact_lab(robot, scene, lab, config, engine) for engine in CONTACT_PLANTS}
    reference = with_force(lab, None)  # the force column means nothing to the laws of the cost's runs
    cost = {
        engine: _contact_cost(robot, scene, reference, config, engine, repeats) for engine in CONTACT_PLANTS
    }
    return {"contact": {"lab": metrics, "cost": cost, "goals": CONTACT_GOALS}}


def _contact_lab(robot: Any, scene: Any, lab: Any, config: SimulationConfig, engine: str) -> dict[str, Any]:
    """The lab's laws against the wall on the plant ``engine``: their contact metrics (printed)."""
    from twolink_pin.contact_metrics import contact_metrics
    from twolink_pin.plant_options import PlantOptions
    from twolink_pin.run_spec import RunSpec

    print(
        f"\ncontact lab on the twolink, {engine} plant ({config.duration:g} s; goal: hybrid's force RMS "
        "error <= 0.5 N)"
    )
    metrics: dict[str, Any] = {}
    for law, gains in CONTACT_LAWS:
        plant = PlantOptions(scene=scene, engine=engine)
        spec = RunSpec(law=law, gains=tuple(gains.items()), plant=plant, simulation=config)
        m = contact_metrics(simulate(*spec.build(robot), lab, config), robot)
        assert m is not None
        metrics[law] = m.as_dict()
        print(
            f"  {law:10s} force RMS error {m.force_rms_error:.3g} N, max {m.force_max_error:.3g} N, peak impact "
            f"{m.peak_impact_force:.3g} N, along the wall RMS {m.tangent_rms_mm:.3g} mm, max penetration "
            f"{m.max_penetration_mm:.3g} mm"
        )
    rms = metrics["hybrid"]["force_rms_error"]
    verdict = "met" if rms is not None and rms <= CONTACT_GOALS["hybrid_force_rms_error_N"] else "NOT met"
    print(f"  hybrid's force RMS error {rms:.3g} N (goal <= 0.5 N: {verdict})")
    return metrics


def _contact_cost(
    robot: Any, scene: Any, reference: Any, config: SimulationConfig, engine: str, repeats: int
) -> dict[str, Any]:
    """The lab's run with the wall over the same run without it, both on the plant ``engine``."""
    from twolink_pin.plant_options import PlantOptions
    from twolink_pin.run_spec import RunSpec

    cost: dict[str, Any] = {}
    print(
        f"contact's cost on the {engine} plant: the lab's run with the wall / without it (fastest of {repeats}, interleaved)"
    )
    for law, gains in (("impedance", {"k": 1000.0, "d": 300.0}), ("pd", {})):
        walled = PlantOptions(scene=scene, engine=engine)
        free = PlantOptions(engine=engine)
        specs = {
            key: RunSpec(law=law, gains=tuple(gains.items()), plant=plant, simulation=config)
            for key, plant in (("wall", walled), ("free", free))
        }
        times: dict[str, list[float]] = {"wall": [], "free": []}
        for _ in range(repeats):
            for key, spec in specs.items():
                scenario = spec.build(robot)
                times[key].append(_timed(lambda s=scenario: simulate(*s, reference, config)))
        ratio = min(times["wall"]) / min(times["free"])
        cost[law] = {"wall_seconds": min(times["wall"]), "free_seconds": min(times["free"]), "ratio": ratio}
        goal = f"goal <= {CONTACT_GOALS['contact_cost_ratio']:g}x: {'met' if ratio <= 1.5 else 'NOT met'}"
        print(
            f"  {law:10s} {min(times['wall']):.3f} s / {min(times['free']):.3f} s = {ratio:.2f}x"
            + (
                f" ({goal})"
                if law == "impedance"
                else " (the cheapest law: the contact's share at its largest)"
            )
        )
    return cost


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="short runs and few repeats (smoke test)")
    parser.add_argument(
        "--repeats", type=int, default=None, help="repeats per single-run timing (default 5; quick 1)"
    )
    parser.add_argument("--json", action="store_true", help="also print the results as one JSON line")
    parser.add_argument(
        "--sweep-only", action="store_true", help="only the sweep throughput on Dask and the client's memory"
    )
    parser.add_argument(
        "--ur5-only", action="store_true", help="only the UR5's single run and batch against the baseline"
    )
    parser.add_argument(
        "--identify-only", action="store_true", help="only identify on the UR5 and its --physical fit"
    )
    parser.add_argument(
        "--batch-only",
        action="store_true",
        help="only each twolink law's batch per simulation (N = 1000, 2 threads) against the baseline",
    )
    parser.add_argument(
        "--single-only",
        action="store_true",
        help="only every law's single run (twolink, UR5) back to back with the baseline, and osc on the Panda",
    )
    parser.add_argument(
        "--big-arms-only",
        action="store_true",
        help="only issue 31's rows: osc/impedance on the Panda, osc and UR5 adaptive batches, their floor",
    )
    parser.add_argument(
        "--shared-only",
        action="store_true",
        help="only the contention row (two batches at once) and the 200-run sweep in-process against 2 workers",
    )
    parser.add_argument(
        "--tune-only", action="store_true", help="only tune's latency from a change to updated results"
    )
    parser.add_argument(
        "--qp-osc-only", action="store_true", help="only qp-osc against osc on the Panda (issue 37's goal)"
    )
    parser.add_argument(
        "--mpc-only",
        action="store_true",
        help="only mpc's goals: 30-s runs on the twolink and the UR5, demo (a), and against crocoddyl's MPC "
        "(CROCODDYL_PYTHON: a scratch venv's python with pin 4.0 and crocoddyl 3.2.1; skipped without)",
    )
    parser.add_argument(
        "--croc",
        metavar="PYTHON",
        default=None,
        help="with --optimal-only: a python with pin 4.0 and crocoddyl 3.2.1 (a scratch venv) to run the anchor beside",
    )
    parser.add_argument(
        "--mujoco-only",
        action="store_true",
        help="only issue 44's goals: the MuJoCo plant's time per run and its equality with Pinocchio's "
        "(scripts/benchmark_mujoco.py)",
    )
    parser.add_argument(
        "--optimal-only",
        action="store_true",
        help="only issue 36's goals: the time-optimal retiming, the minimum-effort twolink, the UR5 through via poses",
    )
    parser.add_argument(
        "--contact-only",
        action="store_true",
        help="only issue 46's goals: the twolink's contact lab, a run with the wall against one without",
    )
    parser.add_argument(
        "--arms-only",
        action="store_true",
        help="only issue 50's goals: every arm of examples/arms with every law at its defaults, the step check's cost",
    )
    parser.add_argument(
        "--equations-only",
        action="store_true",
        help="only issue 47's goals: the symbolic equations' time, the module's M(q) against pin.crba, the "
        "scaling table (scripts/equations_benchmark.py)",
    )
    parser.add_argument(
        "--contention-only",
        action="store_true",
        help="only the contention row: two batches at once, and one alone (default threads against 1)",
    )
    parser.add_argument(
        "--sweep-200",
        type=float,
        default=None,
        metavar="S",
        help="only the row 'sweep throughput, 200 runs, in-process vs --workers 2', with runs of S seconds",
    )
    args = parser.parse_args(argv)
    if args.sweep_200 is not None:
        results = sweep_200_section(args.sweep_200, args.repeats or 3)
        if args.json:
            print(json.dumps(results))
        return 0
    quick = args.quick
    repeats = args.repeats or (1 if quick else 5)
    single_duration = 0.5 if quick else 10.0
    robot = load_robot()
    trajectory = default_trajectory(robot)
    results: dict[str, Any] = {"machine": _machine(), "quick": quick}
    m = results["machine"]
    print(
        f"machine: {m['cpu']}, {m['cores']} cores, {m['system']}; Python {m['python']}, numpy {m['numpy']}, "
        f"pinocchio {m['pinocchio']}; load average {m['load_average']}"
    )
    if args.arms_only:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from arms import arms_section  # scripts/arms.py

        results.update(arms_section(quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.qp_osc_only:
        results.update(qp_osc_section(quick, args.repeats or (1 if quick else 5)))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.mpc_only:
        results.update(mpc_section(quick, args.repeats or (1 if quick else 3)))
        from mpc_anchor import anchor_section  # scripts/mpc_anchor.py, beside this file

        results.update(anchor_section(quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.contact_only:
        results.update(contact_section(quick, args.repeats or (1 if quick else 5)))
        results["machine"]["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
        print(f"load average at the end {results['machine']['load_average_end']}")
        if args.json:
            print(json.dumps(results))
        return 0
    if args.mujoco_only:
        sys.path.insert(0, str(HERE))
        from benchmark_mujoco import main as mujoco_main

        results.update(
            mujoco_main(
                [*(["--quick"] if quick else []), "--repeats", str(args.repeats or (1 if quick else 5))]
            )
        )
        if args.json:
            print(json.dumps(results))
        return 0
    if args.equations_only:
        from equations_benchmark import equations_section  # scripts/: the script's own folder

        results.update(equations_section(quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.optimal_only:  # scripts/bench_optimal.py, beside the baseline of this run
        from bench_optimal import optimal_section

        robot0 = load_robot()
        reference0 = default_trajectory(robot0)
        gains0 = make_scenario("pd", robot0).controller.gains
        start0 = reference0.sample(0.0)
        steps = round(2.0 / DT)

        def baseline_30s() -> float:
            q0 = start0.q + np.array([0.1, -0.1])
            return (
                _timed(lambda: baseline_pd(reference0, robot0.p, gains0, q0, start0.v, DT, steps))
                * FULL
                / 2.0
            )

        results.update(optimal_section(quick, baseline_30s, args.croc))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.tune_only:
        results.update(tune_section(quick))
        results.update(tune_page_section(quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.identify_only:
        results.update(identification_section(quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.sweep_only:
        results.update(sweep_section(quick))
        results["machine"]["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
        print(f"\nload average at the end {results['machine']['load_average_end']}")
        if args.json:
            print(json.dumps(results))
        return 0

    # -- the baseline ----------------------------------------------------------------------
    n = round(single_duration / DT)
    ref0 = trajectory.sample(0.0)
    q0, v0 = ref0.q + np.array([0.1, -0.1]), ref0.v
    pd_gains = make_scenario("pd", robot).controller.gains

    def baseline() -> Any:
        return baseline_pd(trajectory, robot.p, pd_gains, q0, v0, DT, n)

    scale = FULL / single_duration
    if args.shared_only or args.contention_only:
        contention_duration = QUICK_CONTENTION_DURATION if quick else CONTENTION_DURATION
        results.update(contention_section(baseline, scale, repeats, contention_duration))
        if not quick and not args.contention_only:
            results.update(sweep_200_section())
        if args.json:
            print(json.dumps(results))
        return 0
    if args.big_arms_only:
        results.update(big_arms_section(baseline, scale, quick, repeats))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.single_only:
        results.update(single_runs_section(baseline, scale, quick, repeats))
        results.update(osc_panda_section(baseline, scale, quick, repeats))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.batch_only:
        results.update(batch_only_section(baseline, scale, robot, trajectory, quick))
        if args.json:
            print(json.dumps(results))
        return 0
    if args.ur5_only:
        results.update(ur5_section(baseline, scale, quick, repeats))
        if args.json:
            print(json.dumps(results))
        return 0
    Q, _, _ = baseline()
    controller, plant = make_scenario("pd", robot)
    check = simulate(controller, plant, trajectory, SimulationConfig(duration=single_duration, dt=DT))
    agreement = float(np.abs(np.array(Q).reshape(-1, 2) - check.q).max())
    print(
        f"\nbaseline: pure-Python floats, closed-form PD job ({single_duration:g} s simulated, x{scale:g}); "
        f"agrees with simulate('pd') to {agreement:.1e} rad"
    )

    # -- single runs, round-robin with the baseline so that load drift hits all alike ------------
    cases: dict[tuple[str, str], Callable[[], None]] = {}
    for spec in LAWS:
        for label, period in (("per_stage", None), ("sampled_1khz", DT)):
            config = SimulationConfig(duration=single_duration, dt=DT, control_period=period)

            def run(spec: str = spec, config: SimulationConfig = config) -> None:
                c, p = make_scenario(spec, robot)
                simulate(c, p, trajectory, config)

            cases[spec, label] = run
    timings: dict[Any, list[float]] = {key: [] for key in cases}
    base_times = []
    for _ in range(repeats):
        base_times.append(_timed(baseline))
        for key, run in cases.items():
            timings[key].append(_timed(run))
    batch = batch_rows(baseline, base_times, robot, trajectory, quick)
    batch_n = 100 if quick else 1000
    batch_duration = 0.05 if quick else 1.0
    batch_rounds = 1 if quick else 3

    # Ratios of minima: on a shared VM the spread is other processes, and the least
    # disturbed of the interleaved runs is the reproducible figure (timeit's convention).
    single: dict[str, dict[str, float]] = {spec: {} for spec in LAWS}
    single_median: dict[str, dict[str, float]] = {spec: {} for spec in LAWS}
    for (spec, label), times in timings.items():
        single[spec][label] = min(times) * scale
        single_median[spec][label] = statistics.median(times) * scale
    base = min(base_times) * scale
    base_median = statistics.median(base_times) * scale
    results["baseline_seconds"] = base
    results["baseline_median_seconds"] = base_median
    print(
        f"baseline {base:.3f} s per 30-s simulation (min of {len(base_times)} interleaved with the others; "
        f"median {base_median:.3f} s, max {max(base_times) * scale:.3f} s)"
    )
    threads = max(1, min(2, default_threads(), batch_n // 256))
    print(
        f"\nseconds per 30-s simulation and ratio to the baseline (single: min of {repeats}, {single_duration:g} s "
        f"simulated, interleaved with the baseline, ratio of minima; batch: N = {batch_n}, {batch_duration:g} s "
        f"simulated, {threads} thread(s), per simulation, min of {batch_rounds})"
    )
    print(f"  {'law':24s} {'per-stage law':>20s} {'sampled 1 kHz':>20s} {'batch per sim':>20s}")
    for spec in LAWS:
        cells = [single[spec]["per_stage"], single[spec]["sampled_1khz"], batch[spec]]
        print(f"  {_label(spec):24s} " + " ".join(f"{x:10.3f} s {x / base:6.2f}x" for x in cells))
    print(f"\nthe same, medians of {repeats} (ratio to the baseline's median)")
    print(f"  {'law':24s} {'per-stage law':>20s} {'sampled 1 kHz':>20s}")
    for spec in LAWS:
        cells = [single_median[spec]["per_stage"], single_median[spec]["sampled_1khz"]]
        print(f"  {_label(spec):24s} " + " ".join(f"{x:10.3f} s {x / base_median:6.2f}x" for x in cells))
    print("\ntargets (ratio of minima)")
    for spec in LAWS:
        ratio = single[spec]["per_stage"] / base
        line = f"  {_label(spec):24s} single {ratio:6.2f}x{_verdict(ratio, SINGLE_TARGET.get(spec))}"
        ratio_b = batch[spec] / base
        print(line + f"; batch {ratio_b:5.2f}x{_verdict(ratio_b, BATCH_TARGET)}")
    results["single"] = {_label(k): v for k, v in single.items()}
    results["single_median"] = {_label(k): v for k, v in single_median.items()}
    results["batch_per_sim"] = {
        "n": batch_n,
        "duration": batch_duration,
        "seconds": {_label(k): v for k, v in batch.items()},
    }
    results.update(ur5_section(baseline, scale, quick, repeats))
    results.update(single_runs_section(baseline, scale, quick, repeats))
    results.update(osc_panda_section(baseline, scale, quick, repeats))
    results.update(qp_osc_section(quick, repeats))
    results.update(mpc_section(quick, 1 if quick else 3))
    if not quick:  # the smoke test runs --big-arms-only --quick on its own
        results.update(big_arms_section(baseline, scale, quick, repeats))
    results.update(identification_section(quick))
    from bench_optimal import optimal_section

    results.update(optimal_section(quick, lambda: _timed(baseline) * scale))

    # -- batch scaling ------------------------------------------------------------------------------
    sizes = (1, 10, 100) if quick else (1, 10, 100, 1000, 10000)
    budget = 1.0 if quick else 1000.0  # simulated run-seconds per measurement
    print("\nbatch scaling, pd: seconds per 30-s simulation (ratio to the baseline)")
    print(f"  {'N':>6s} {'simulated':>10s} {'1 thread':>20s} {'2 threads':>20s}")
    scaling = []
    for size in sizes:
        duration = min(FULL, max(0.02 if quick else 0.2, budget / size))
        law, plant_s, offsets = _batch_case("pd", robot, size)
        config = SimulationConfig(duration=duration, dt=DT)
        row: dict[str, float] = {"n": size, "duration": duration}
        for count in (1, 2):
            start = time.perf_counter()
            simulate_batch(
                law, plant_s, trajectory, config, q0_offsets=offsets, threads=count, progress=False
            )
            row[f"threads_{count}"] = (time.perf_counter() - start) * FULL / duration / size
        scaling.append(row)
        used = max(1, min(2, size // 256))
        note = "" if used == 2 else "  (2 requested, 1 used: N < 512)"
        print(
            f"  {size:6d} {duration:8.2f} s "
            + " ".join(f"{row[f'threads_{c}']:10.4f} s {row[f'threads_{c}'] / base:6.3f}x" for c in (1, 2))
            + note
        )
    results["batch_scaling"] = scaling
    contention_duration = QUICK_CONTENTION_DURATION if quick else CONTENTION_DURATION
    results.update(contention_section(baseline, scale, 1 if quick else 3, contention_duration))

    # -- sweep memory ---------------------------------------------------------------------------------
    sweep_sizes = (100, 1000) if quick else (1000, 10000)
    sweep_duration = 0.02 if quick else 0.5
    print(
        f"\npeak memory of a pd sweep (±0.1 rad, ±20 % parameters, kp range; {sweep_duration:g} s simulated "
        "per run; chunks of 1000; fresh process; plot off)"
    )
    import tempfile

    memory = []
    with tempfile.TemporaryDirectory() as tmp:
        for samples in sweep_sizes:
            mem = _sweep_memory(samples, sweep_duration, os.path.join(tmp, str(samples)), trace=not quick)
            memory.append(mem)
            print(
                f"  {samples:6d} runs: peak RSS {mem['rss_peak_mib']:7.1f} MiB (after imports and setup "
                f"{mem['rss_before_mib']:6.1f} MiB), {_python_peak(mem)}, {mem['seconds']:.1f} s"
            )
    results["sweep_memory"] = memory

    # -- the one-command report (target: <= 10 s on a 2-core machine) ---------------------------
    if quick:
        print("\nreport: skipped with --quick")
    else:
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            subprocess.run(
                [
                    sys.executable,
                    "-m",
                    "twolink_pin.cli",
                    "report",
                    "--out",
                    os.path.join(tmp, "out"),
                    "--json",
                ],
                check=True,
                capture_output=True,
            )
            seconds = time.perf_counter() - start
        results["report_seconds"] = seconds
        print(f"\nreport: `twolink-pin report` in a fresh process {seconds:.1f} s (target 10 s)")
    if quick:
        print("\nsweep throughput on Dask: skipped with --quick (--sweep-only --quick runs it small)")
    else:
        results.update(sweep_200_section())
        results.update(sweep_section(quick))
        results.update(tune_section(quick))
    results["machine"]["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
    print(f"\nload average at the end {results['machine']['load_average_end']}")
    if args.json:
        print(json.dumps(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
