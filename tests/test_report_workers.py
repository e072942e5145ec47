"""The report's worker count: by default the cores this process may use (its affinity)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.report import ReportOptions

_CHILD = """
import os, sys
os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # as taskset -c would
from twolink_pin.report import ReportOptions
print(ReportOptions().workers, ReportOptions(workers=3).workers)
"""


def test_default_workers_are_the_cores_this_process_may_use() -> None:
    assert ReportOptions().workers == min(len(os.sched_getaffinity(0)), 64)


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="needs Linux CPU affinity")
def test_a_process_pinned_to_one_core_runs_the_report_in_one_process() -> None:
    out = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["1", "3"]  # the default follows the affinity; an explicit count wins


@pytest.mark.parametrize("bad", [0, 65, 2.5, True, "2"])
def test_a_bad_worker_count_is_refused_naming_it(bad: object) -> None:
    with pytest.raises(InvalidParameterError, match="workers"):
        ReportOptions(workers=bad)  # type: ignore[arg-type]
