"""``scripts/benchmark.py --equations-only``: the symbolic equations' goals and how far they scale.

Issue 47's goals, measured in one run: the twolink's M, C, g and Y derived and made readable
(no cache) in at most 2 s — in this process after a first derivation that pays SymPy's
import, and cold in a fresh process (the import included); the UR5's first three joints in
at most 30 s; the ``--python`` module's ``M(q)`` faster than ``pin.crba`` from Python on the
twolink (one state into a new array, one state into ``out``, and per state in a batch of
1000; beside ``pin.crba`` alone and with the symmetrisation a full M needs).

Then the scaling table for ``docs/equations.md``: the UR5's first n joints, n = 1..6 (1..3
with ``--quick``), the seconds of each step (the exact derivation, the readable expressions,
the numpy module) and the size of what comes out (SymPy's ``count_ops`` of M, C, g and Y, the
module's lines), and a derivation read back from the cache.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin import load_robot

TWOLINK_GOAL = 2.0
"""Issue 47: the twolink's four terms derived and simplified [s]."""
UR5_3_GOAL = 30.0
"""Issue 47: a 3-joint spatial arm (the UR5's first three joints) [s]."""

_COLD = """
import json, os, time
os.environ["TWOLINK_PIN_CACHE"] = "off"
from twolink_pin.model import load_robot
robot = load_robot()
start = time.perf_counter()
from twolink_pin.symbolic import derive_equations
derive_equations(robot, use_cache=False)
print(json.dumps({"cold": time.perf_counter() - start}))
"""


def _steps(name: str, joints: int | None) -> dict[str, Any]:
    """Seconds of each step and the sizes, for the first ``joints`` of ``name`` (no cache)."""
    import sympy as sp

    from twolink_pin.symbolic.derivation import derive
    from twolink_pin.symbolic.equations import equations_from
    from twolink_pin.symbolic.numpy_module import numpy_module
    from twolink_pin.symbolic.skeleton import skeleton_of
    from twolink_pin.symbolic.support import first_joints

    robot = load_robot(name)
    model = robot.model if joints is None else first_joints(robot.model, joints)
    start = time.perf_counter()
    derivation = derive(skeleton_of(model))
    derived = time.perf_counter()
    eq = equations_from(derivation, skeleton_of(model), model, robot.name, from_cache=False)
    readable = time.perf_counter()
    source = numpy_module(eq)
    written = time.perf_counter()
    return {
        "joints": model.nv,
        "base_parameters": len(eq.beta),
        "derive_s": derived - start,
        "readable_s": readable - derived,
        "module_s": written - readable,
        "total_s": written - start,
        "ops": {key: int(sp.count_ops(getattr(eq, key))) for key in ("M", "C", "g", "Y")},
        "module_lines": source.count("\n"),
    }


def _load_module(source: str) -> Any:
    folder = Path(tempfile.mkdtemp())
    path = folder / "twolink_equations.py"
    path.write_text(source, encoding="utf-8")
    spec = importlib.util.spec_from_file_location("twolink_equations", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _per_call(call: Any, number: int, repeats: int) -> float:
    return min(timeit.repeat(call, number=number, repeat=repeats)) / number


def _symmetrised(upper: np.ndarray) -> np.ndarray:
    """The full M from CRBA's upper triangle, as a Python user writes it."""
    return np.triu(upper) + np.triu(upper, 1).T


def _mass_matrix_speed(quick: bool) -> dict[str, float]:
    """Seconds per M(q) of the module and of Pinocchio, interleaved (best of the repeats)."""
    from twolink_pin.symbolic import derive_equations
    from twolink_pin.symbolic.numpy_module import numpy_module

    robot = load_robot()
    module = _load_module(numpy_module(derive_equations(robot, use_cache=False)))
    model, data = robot.model, robot.create_data()
    q = np.array([0.3, 1.1])
    out = np.empty((2, 2))
    batch = np.random.default_rng(0).uniform(-3, 3, (1000, 2))
    number, repeats = (2000, 3) if quick else (20000, 7)
    cases = {
        "module_new": lambda: module.M(q),
        "module_out": lambda: module.M(q, out=out),
        "crba": lambda: pin.crba(model, data, q),
        "crba_symmetrised": lambda: _symmetrised(pin.crba(model, data, q)),
    }
    best = {key: float("inf") for key in cases}
    for _ in range(repeats):  # interleaved, so that load drift hits all alike
        for key, call in cases.items():
            best[key] = min(best[key], _per_call(call, number, 1))
    best["module_batch_per_state"] = _per_call(lambda: module.M(batch), 20 if quick else 200, repeats) / len(
        batch
    )
    return best


def equations_section(quick: bool) -> dict[str, Any]:
    """The goals and the scaling table (module docstring)."""
    from twolink_pin.symbolic import derive_equations

    robot = load_robot()
    derive_equations(robot, use_cache=False)  # pays SymPy's import once
    repeats = 1 if quick else 5
    twolink = min(_steps("twolink", None)["total_s"] for _ in range(repeats))
    done = subprocess.run([sys.executable, "-c", _COLD], capture_output=True, text=True, check=True)
    cold = json.loads(done.stdout.splitlines()[-1])["cold"]
    rows = [_steps("ur5", n) for n in range(1, 4 if quick else 7)]
    ur5_3 = rows[2]["total_s"]
    speed = _mass_matrix_speed(quick)
    with tempfile.TemporaryDirectory() as folder:
        import os

        os.environ["TWOLINK_PIN_CACHE"] = folder
        derive_equations(load_robot("ur5"), joints=3)
        start = time.perf_counter()
        assert derive_equations(load_robot("ur5"), joints=3).from_cache
        cached = time.perf_counter() - start
        del os.environ["TWOLINK_PIN_CACHE"]
    print("\nequations in closed form (issue 47): derived, made readable and written as a module, no cache")
    print(
        f"  twolink, M C g Y: {twolink:.3f} s warm, {cold:.2f} s cold (SymPy's import included) "
        f"(goal <= {TWOLINK_GOAL:g} s: {'met' if max(twolink, cold) <= TWOLINK_GOAL else 'NOT met'})"
    )
    print(
        f"  UR5's first 3 joints: {ur5_3:.2f} s (goal <= {UR5_3_GOAL:g} s: "
        f"{'met' if ur5_3 <= UR5_3_GOAL else 'NOT met'}); read back from the cache: {cached:.2f} s"
    )
    crba = speed["crba"]
    print(
        f"  twolink M(q), module vs pin.crba from Python ({crba * 1e6:.2f} µs; with the symmetrisation "
        f"{speed['crba_symmetrised'] * 1e6:.2f} µs): new array {speed['module_new'] * 1e6:.2f} µs "
        f"({speed['module_new'] / crba:.2f}x), into out {speed['module_out'] * 1e6:.2f} µs "
        f"({speed['module_out'] / crba:.2f}x), per state in a batch of 1000 "
        f"{speed['module_batch_per_state'] * 1e6:.3f} µs ({speed['module_batch_per_state'] / crba:.3f}x)"
    )
    print(
        "  UR5, first n joints: seconds (derive + readable + module = total), count_ops of M C g Y, module lines"
    )
    for row in rows:
        ops = row["ops"]
        print(
            f"    n = {row['joints']}  β {row['base_parameters']:>2}  {row['derive_s']:6.2f} + {row['readable_s']:6.2f} "
            f"+ {row['module_s']:6.2f} = {row['total_s']:6.2f} s   ops {ops['M']:>6} {ops['C']:>6} {ops['g']:>5} "
            f"{ops['Y']:>6}   {row['module_lines']:>6} lines"
        )
    return {
        "equations": {
            "twolink_seconds": twolink,
            "twolink_cold_seconds": cold,
            "ur5_3_seconds": ur5_3,
            "ur5_3_cached_seconds": cached,
            "mass_matrix_seconds": speed,
            "scaling": rows,
            "goals": {"twolink": TWOLINK_GOAL, "ur5_3": UR5_3_GOAL},
        }
    }
