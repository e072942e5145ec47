"""The report's worker count: by default the cores this process may use (its affinity)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.report import ReportOptions
from twolink_pin.report.build import WORKERS_SHARE

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


_SHARED = """
import json, sys
from twolink_pin.report.build import WORKERS_SHARE
from twolink_pin.report.pool import worker_pool

def imported(names):
    return [name in sys.modules for name in names]

assert not any(imported(WORKERS_SHARE)), "the test needs a process that has not imported them"
with worker_pool(2) as pool:
    alone = pool.submit(imported, WORKERS_SHARE).result()
with worker_pool(2, WORKERS_SHARE) as pool:
    shared = pool.submit(imported, WORKERS_SHARE).result()
print(json.dumps([alone, shared]))
"""


def test_the_workers_fork_with_the_shared_modules_already_imported() -> None:
    """matplotlib and SciPy imported once before the fork, not again in each worker: a worker
    of a pool without them has none of them; a worker of the report's pool has all."""
    out = subprocess.run([sys.executable, "-c", _SHARED], capture_output=True, text=True, check=True).stdout
    n = len(WORKERS_SHARE)
    assert json.loads(out) == [[False] * n, [True] * n]


_FROZEN = """
import gc, json, os
from twolink_pin.report.pool import worker_pool

def state():
    return os.getpid(), gc.get_freeze_count(), gc.isenabled()

gc.collect()
held = [[i] for i in range(50_000)]  # tracked objects this process holds when the workers fork
with worker_pool(2) as pool:
    first = pool.submit(state)
    after = gc.get_freeze_count()  # this process, right after the fork
    workers = [first.result(), *(pool.submit(state).result() for _ in range(3))]
print(json.dumps({"after": after, "workers": workers, "parent": os.getpid(), "enabled": gc.isenabled()}))
"""


def test_the_workers_fork_with_the_parents_objects_frozen_out_of_their_collector() -> None:
    """A worker's garbage collector never walks the objects it inherited (``gc.freeze`` before the
    fork): each worker holds at least the 50 000 lists its parent had, frozen; the parent's own
    are unfrozen right after the fork, and its collector stays on."""
    out = subprocess.run([sys.executable, "-c", _FROZEN], capture_output=True, text=True, check=True).stdout
    found = json.loads(out)
    assert found["after"] == 0 and found["enabled"]
    assert all(pid != found["parent"] and frozen >= 50_000 and on for pid, frozen, on in found["workers"])


_KEPT = """
import gc, json
from twolink_pin.report.pool import worker_pool

gc.freeze()  # this process's own choice
before = gc.get_freeze_count()
with worker_pool(2) as pool:
    pool.submit(int).result()
    after = gc.get_freeze_count()
print(json.dumps([before, after]))
"""


def test_a_process_that_froze_its_objects_itself_keeps_them_frozen() -> None:
    out = subprocess.run([sys.executable, "-c", _KEPT], capture_output=True, text=True, check=True).stdout
    before, after = json.loads(out)
    assert before > 0 and after == before  # not unfrozen by the pool
