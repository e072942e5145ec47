"""What a command loads before it starts: every ``twolink-pin`` process (the CLI, each Dask
worker, the tuner's reruns in the tests) imports the package first, so a heavy import that
only one feature needs is paid by all of them. ``scipy.interpolate`` (pose paths, with
``scipy.optimize``: ~0.8 s), ``scipy.integrate`` (the adaptive-step method, ~0.3 s),
``scipy.linalg`` (the pivoted QR of the base parameters of an arm without a closed-form map,
``expm`` of the adaptation's averaged modes: ~0.3 s of CPU, a third of a twolink command's),
matplotlib (figures), Dask, TOPP-RA (~1.1 s: it loads matplotlib), ProxQP and SymPy (the equations,
~0.5 s) are imported where they are used, not at start-up.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

DEFERRED = (
    "scipy.linalg",
    "scipy.interpolate",
    "scipy.integrate",
    "scipy.optimize",
    "scipy.signal",
    "matplotlib",
    "dask",
    "distributed",
    "viser",
    "cvxpy",
    "rosbags",
    "toppra",
    "proxsuite",
    "sympy",
)
"""Modules that importing the package and its CLI must not import."""
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _loaded_after(statement: str) -> set[str]:
    code = f"{statement}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300
    )
    return set(json.loads(done.stdout.splitlines()[-1]))


def test_importing_the_cli_leaves_the_heavy_optional_modules_unloaded() -> None:
    loaded = _loaded_after("import twolink_pin, twolink_pin.cli, twolink_pin_entry")
    assert "pinocchio" in loaded  # the check sees what was imported
    assert sorted(m for m in DEFERRED if m in loaded) == []


def test_a_pose_path_and_the_adaptive_method_still_load_what_they_need() -> None:
    """The deferred imports happen where they are used (a pose trajectory builds its spline
    with scipy.interpolate; the adaptive method integrates with scipy.integrate)."""
    loaded = _loaded_after(
        "from pathlib import Path\n"
        "from twolink_pin.model import load_robot\n"
        "from twolink_pin.trajectory.file import read_trajectory_file\n"
        "from twolink_pin.run_spec import make_scenario\n"
        "from twolink_pin.simulation import SimulationConfig, simulate\n"
        "robot = load_robot('ur5')\n"
        f"read_trajectory_file(Path({str(EXAMPLES)!r}) / 'ur5_square_pose.toml', robot)\n"
        "twolink = load_robot('twolink')\n"
        "c, p = make_scenario('pd', twolink)\n"
        "from twolink_pin.trajectory import default_trajectory\n"
        "simulate(c, p, default_trajectory(twolink), SimulationConfig(duration=0.01, method='adaptive'))"
    )
    assert {"scipy.interpolate", "scipy.integrate", "scipy.linalg"} <= loaded
