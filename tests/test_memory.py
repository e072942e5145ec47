"""The memory a command may still use (``twolink_pin.memory``) and what ``mpc``'s horizon takes
(``optimal.horizon.horizon_bytes``), measured in child processes: under ``ulimit -v`` what is
left is the limit less what the process already holds (it was the whole limit: a horizon
passed the check and ProxQP aborted the process), and the estimate bounds the peak address
space one replan really takes."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")


def _child(code: str) -> dict:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_under_an_address_space_limit_what_is_left_is_available() -> None:
    """With ``RLIMIT_AS`` = what the process holds + 300 MB, 300 MB (less what it takes
    meanwhile) are available, not the limit."""
    found = _child(
        "import json, resource\n"
        "import twolink_pin.memory as m\n"
        "used = m.address_space_used()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (used + 300 * 10**6, resource.RLIM_INFINITY))\n"
        "print(json.dumps({'used': used, 'available': m.available_memory()}))\n"
    )
    assert found["used"] > 10**7
    assert 250 * 10**6 < found["available"] <= 300 * 10**6


MEASURE = """
import json, sys
import twolink_pin.controllers.mpc as mpc
from twolink_pin.memory import address_space_used
from twolink_pin.optimal.horizon import horizon_bytes
seen = {}
check = mpc.check_memory
def measured(knots, interval, limits, runs, what="horizon"):
    seen.update(before=address_space_used(), need=horizon_bytes(knots, limits, runs))
    return check(knots, interval, limits, runs, what)
mpc.check_memory = measured
from twolink_pin.cli import main
status = main(sys.argv[1:])
peak = int(open("/proc/self/status").read().split("VmPeak:")[1].split()[0]) * 1024
print(json.dumps({**seen, "peak": peak, "status": status}))
"""


@pytest.mark.parametrize(
    "argv",
    [
        ["--gain", "horizon=0.3", "--gain", "knot_interval=0.001"],  # twolink: 300 knots, n = 600, m = 1800
        [
            "--robot",
            "panda",
            "--gain",
            "horizon=0.3",
            "--gain",
            "knot_interval=0.01",
        ],  # 30 knots, n = 210, m = 840
    ],
    ids=["twolink-300-knots", "panda-30-knots"],
)
def test_the_horizons_estimate_bounds_the_peak_address_space_of_a_replan(argv: list[str]) -> None:
    """One replan (a 2-ms run) in a child: its peak address space over what it held when
    the horizon was checked is within the estimate, and the estimate is not absurd (< 5×)."""
    found = _child(MEASURE.replace("sys.argv[1:]", repr(["simulate", "mpc", "--duration", "0.002", *argv])))
    grew = found["peak"] - found["before"]
    assert found["status"] in (0, 1)  # a replan that fails says so; the memory was taken either way
    assert grew <= found["need"] < 5 * grew, found
