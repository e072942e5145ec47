"""Per-stage profile of a single run (N = 1): microseconds per RK4 stage in the law, in
Pinocchio (the ``Terms`` the law asks for and the plant's ABA) and in the engine.

An instrumented run: the engine's three doors (``law_call`` — the law behind its
containment —, ``terms_for`` and ``dynamics_for``) are wrapped with
``time.perf_counter_ns`` accumulators, then one timed single run per law is made with the
wrappers and one without (the plain wall time). Split per stage (4 stages per step):

* **law** — inside the law's ``compute`` less the ``Terms`` calls it makes, plus the
  containment around it;
* **Pinocchio** — the ``Terms`` calls (``pin.rnea``, the regressor, CRBA, ...) and the
  plant's ``pin.aba``, with their small numpy glue;
* **engine** — the rest of the instrumented run's wall time: RK4 arithmetic, LawInput,
  recording, block checks, and the timers' own cost (about 0.1 µs a pair, 2–3 pairs a
  stage); ``total`` is the plain run's time per stage, without timers.

The least disturbed of ``--repeats`` runs is kept (on a shared machine the spread is other
processes).

``--instructions`` counts instead of timing, which does not depend on the machine's load:
the script runs itself under valgrind's callgrind (instrumentation switched on after the
imports and a warm-up run per law), each law for 0.05 s and 0.15 s simulated with a
callgrind dump around each run, and prints the difference of the two runs' instruction
counts per RK4 stage (0.1 s = 400 stages: setup and first-call costs cancel).

Usage::

    .venv/bin/python scripts/profile_stages.py [--duration 2] [--robot twolink|ur5|panda] [--laws pd,...]
    .venv/bin/python scripts/profile_stages.py --instructions [--robot ur5] [--laws pd,...]
"""

from __future__ import annotations

import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import time
from typing import Any

from twolink_pin import SimulationConfig, default_trajectory, load_robot, make_scenario, simulate
from twolink_pin.simulation import engine

DEFAULT_LAWS = {
    "twolink": ("pd", "computed-torque", "adaptive", "adaptive-friction"),
    "ur5": ("pd", "computed-torque", "adaptive"),
    "panda": ("osc",),
}


class _Clock:
    def __init__(self) -> None:
        self.ns = {"law": 0, "terms": 0, "aba": 0}
        self.calls = 0


def _instrument(clock: _Clock) -> tuple[Any, Any, Any]:
    originals = (engine.law_call, engine.terms_for, engine.dynamics_for)
    law_call, terms_for, dynamics_for = originals
    ns = clock.ns
    now = time.perf_counter_ns

    def timed_law_call(controller: Any, noise: Any, method: str = "compute") -> Any:
        call = law_call(controller, noise, method)

        def law(x: Any, terms: Any) -> Any:
            start = now()
            try:
                return call(x, terms)
            finally:
                ns["law"] += now() - start
                clock.calls += 1

        return law

    class TimedTerms:
        def __init__(self, inner: Any) -> None:
            self._inner = inner

        def __getattr__(self, name: str) -> Any:
            method = getattr(self._inner, name)
            if not callable(method):
                return method

            def timed(*args: Any, **kwargs: Any) -> Any:
                start = now()
                try:
                    return method(*args, **kwargs)
                finally:
                    ns["terms"] += now() - start

            setattr(self, name, timed)  # made once: later calls do not pay for the wrapper in "law"
            return timed

    def timed_terms_for(*args: Any, **kwargs: Any) -> Any:
        return TimedTerms(terms_for(*args, **kwargs))

    def timed_dynamics_for(*args: Any, **kwargs: Any) -> Any:
        accel = dynamics_for(*args, **kwargs)

        def timed(*a: Any) -> Any:
            start = now()
            try:
                return accel(*a)
            finally:
                ns["aba"] += now() - start

        return timed

    engine.law_call, engine.terms_for, engine.dynamics_for = (  # type: ignore[assignment]
        timed_law_call,
        timed_terms_for,
        timed_dynamics_for,
    )
    return originals


def profile(robot_name: str, spec: str, duration: float, repeats: int) -> dict[str, float]:
    """µs per RK4 stage: law, Pinocchio, engine, total (plain run, min of ``repeats``)."""
    robot = load_robot(robot_name)
    reference = default_trajectory(robot)
    config = SimulationConfig(duration=duration, dt=1e-3, q0_offset=0.05 if robot_name != "twolink" else None)
    stages = 4 * config.steps
    plain = []
    for _ in range(repeats):
        controller, plant = make_scenario(spec, robot)
        start = time.perf_counter_ns()
        simulate(controller, plant, reference, config)
        plain.append(time.perf_counter_ns() - start)
    best: dict[str, float] | None = None
    for _ in range(repeats):
        clock = _Clock()
        originals = _instrument(clock)
        try:
            controller, plant = make_scenario(spec, robot)
            start = time.perf_counter_ns()
            simulate(controller, plant, reference, config)
            elapsed = time.perf_counter_ns() - start
        finally:
            engine.law_call, engine.terms_for, engine.dynamics_for = originals  # type: ignore[assignment]
        law = (clock.ns["law"] - clock.ns["terms"]) / stages / 1e3
        pinocchio = (clock.ns["terms"] + clock.ns["aba"]) / stages / 1e3
        rest = elapsed / stages / 1e3 - law - pinocchio
        if best is None or elapsed < best["instrumented"]:
            best = {"law": law, "pinocchio": pinocchio, "engine": rest, "instrumented": elapsed}
    assert best is not None
    best["total"] = min(plain) / stages / 1e3
    return best


SHORT, LONG = 0.05, 0.15
"""Simulated seconds of the two counted runs per law (``--instructions``)."""


def _counted_runs(robot_name: str, laws: list[str]) -> None:
    """Under callgrind (``--instr-atstart=no --dump-before=getppid``): warm up, switch the
    instrumentation on, then each law for SHORT and LONG seconds between ``os.getppid()``
    calls (each call ends a dump)."""
    robot = load_robot(robot_name)
    reference = default_trajectory(robot)
    offset = 0.05 if robot_name != "twolink" else None
    for spec in laws:
        controller, plant = make_scenario(spec, robot)
        simulate(controller, plant, reference, SimulationConfig(duration=0.01, dt=1e-3, q0_offset=offset))
    subprocess.run(["callgrind_control", "-i", "on", str(os.getpid())], check=True, capture_output=True)
    for spec in laws:
        for duration in (SHORT, LONG):
            controller, plant = make_scenario(spec, robot)
            config = SimulationConfig(duration=duration, dt=1e-3, q0_offset=offset)
            os.getppid()
            simulate(controller, plant, reference, config)
            os.getppid()


def instructions(robot_name: str, laws: list[str]) -> dict[str, float]:
    """Instructions per RK4 stage of each law's single run (callgrind, see module doc)."""
    if shutil.which("valgrind") is None or shutil.which("callgrind_control") is None:
        raise SystemExit("--instructions needs valgrind (apt-get install valgrind)")
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "cg.out")
        command = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--dump-before=getppid"]
        command += [f"--callgrind-out-file={out}", sys.executable, __file__, "--robot", robot_name]
        command += ["--laws", ",".join(laws), "--counted-child"]
        subprocess.run(command, check=True, capture_output=True)
        totals = []
        for path in sorted(glob.glob(out + ".*"), key=lambda f: int(f.rsplit(".", 1)[1])):
            with open(path) as dump:
                totals.append(next(int(line.split()[1]) for line in dump if line.startswith("totals:")))
    runs = totals[1::2]  # dump 0 ends at the first marker; then run, gap, run, gap, ...
    stages = 4 * round((LONG - SHORT) / 1e-3)
    return {spec: (runs[2 * i + 1] - runs[2 * i]) / stages for i, spec in enumerate(laws)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=2.0, help="simulated seconds per run (default 2)")
    parser.add_argument("--robot", default="twolink", help="twolink, ur5 or panda (default twolink)")
    parser.add_argument("--laws", default=None, help="comma-separated laws (default: the robot's set)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per law, the least disturbed kept")
    parser.add_argument(
        "--instructions", action="store_true", help="instructions per stage under callgrind instead of µs"
    )
    parser.add_argument("--counted-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    laws = args.laws.split(",") if args.laws else list(DEFAULT_LAWS[args.robot])
    if args.counted_child:
        _counted_runs(args.robot, laws)
        return 0
    if args.instructions:
        print(f"{args.robot}: instructions per RK4 stage (callgrind, {LONG:g} s run less {SHORT:g} s run)")
        for spec, count in instructions(args.robot, laws).items():
            print(f"  {spec:20s} {count / 1e3:8.1f} k")
        return 0
    print(
        f"{args.robot}, {args.duration:g} s simulated, dt = 1 ms, min of {args.repeats}; "
        f"load average {[round(x, 2) for x in os.getloadavg()]}"
    )
    print(f"  {'law':20s} {'law µs':>8s} {'Pinocchio µs':>13s} {'engine µs':>10s} {'total µs/stage':>15s}")
    for spec in laws:
        row = profile(args.robot, spec, args.duration, args.repeats)
        print(
            f"  {spec:20s} {row['law']:8.2f} {row['pinocchio']:13.2f} {row['engine']:10.2f} {row['total']:15.2f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
