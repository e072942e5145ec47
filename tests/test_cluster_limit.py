"""``sweep --workers`` at the process limit (issue 30): when the LocalCluster's worker
processes cannot start, one line on stderr says why, the exit status is 2 (as every error of
a cluster that cannot run the work), no output folder is written, no process is left behind
and no worker traceback is printed.

The limit is the kernel's: the command runs in a pids cgroup of its own (root ignores
``RLIMIT_NPROC``, not a cgroup's ``pids.max``), and a hook lowers ``pids.max`` to 1 at a set
point of the start-up, not at a time: when the command starts its first worker process
(the fork fails with ``EAGAIN``), or when a worker process starts (it cannot create its first
thread). Where cgroups cannot be made (not root, no pids controller), the same outcome is
checked with a fault hook that fails the worker's start as fork does at the limit.

Before: twelve ``KeyError`` tracebacks of multiprocessing's resource tracker (killed by the
command's reaping, then restarted by the exit handlers), a traceback per worker process that
could not start a thread, and a cause of "Nanny failed to start.".

Also here: a successful run's LocalCluster whose worker is slow to exit closes quietly."""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import subprocess
import sys
import textwrap
import uuid
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest

pytest.importorskip("distributed")

PIDS = Path("/sys/fs/cgroup/pids")
"""The cgroup v1 pids hierarchy (this machine and CI); cgroup v2 would be /sys/fs/cgroup."""

HOOK = textwrap.dedent(
    """
    import errno, multiprocessing.process, os, sys
    CGROUP, WHEN = {cgroup!r}, {when!r}
    def limit():  # no new process or thread in the command's cgroup from here on
        with open(os.path.join(CGROUP, "pids.max"), "w") as f:
            f.write("1")
    if WHEN == "worker" and getattr(multiprocessing.process.current_process(), "_inheriting", False):
        limit()  # a spawned worker process, before its first thread
    if WHEN == "import" and getattr(multiprocessing.process.current_process(), "_inheriting", False):
        sys.modules["pinocchio"] = None  # the worker dies in its imports
    import twolink_pin_entry
    if __name__ == "__main__":
        if CGROUP:
            with open(os.path.join(CGROUP, "cgroup.procs"), "w") as f:
                f.write(str(os.getpid()))
        start = multiprocessing.process.BaseProcess.start
        def start_at_the_limit(self):
            if "Worker" in self.name:
                if WHEN == "fork":
                    limit()
                elif WHEN == "fault":  # as fork fails at the limit
                    raise OSError(errno.EAGAIN, os.strerror(errno.EAGAIN))
            start(self)
        multiprocessing.process.BaseProcess.start = start_at_the_limit
        sys.argv = ["twolink-pin", *sys.argv[1:]]
        twolink_pin_entry.main()
    """
)
"""The command behind a hook; a file, not ``-c``: a spawned worker imports it as its main."""


@contextlib.contextmanager
def _cgroup() -> Iterator[Path]:
    """A pids cgroup of its own, removed afterwards (its processes killed first if any)."""
    folder = PIDS / f"twolink-pin-test-{uuid.uuid4().hex[:12]}"
    try:
        folder.mkdir()
    except OSError as exc:
        pytest.skip(f"cannot make a pids cgroup ({exc.strerror}); the fault-hook case covers this")
    try:
        yield folder
    finally:
        left = [psutil.Process(int(pid)) for pid in (folder / "cgroup.procs").read_text().split()]
        for p in left:
            with contextlib.suppress(psutil.Error):
                p.kill()
        psutil.wait_procs(left, timeout=30)  # they leave the cgroup once they have ended
        (folder / "pids.max").write_text("max")
        folder.rmdir()


def _run(tmp_path: Path, cgroup: str, when: str) -> tuple[subprocess.CompletedProcess[str], list[str]]:
    script = tmp_path / "limit_hook.py"
    script.write_text(HOOK.format(cgroup=cgroup, when=when))
    work = tmp_path / "work"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "TWOLINK_PIN_READY_FILE"}
    argv = ["sweep", "pd", "--samples", "20", "--workers", "2", "--out", "s"]
    proc = subprocess.Popen(
        [sys.executable, str(script), *argv],
        cwd=work,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        out, err = proc.communicate(timeout=300)  # bounded only against a hang
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        pytest.fail(f"still running 300 s after the limit was reached; stderr ends {err[-300:]!r}")
    group = []
    for p in psutil.process_iter():
        with contextlib.suppress(ProcessLookupError, psutil.Error):
            if os.getpgid(p.pid) == proc.pid:
                group.append(p)
    # the resource tracker ends on its pipe's end, a moment later: bounded only against one left for good
    _, alive = psutil.wait_procs(group, timeout=30)
    left = [f"{p.pid} {' '.join(p.cmdline())[:200]}" for p in alive]
    for p in alive:
        with contextlib.suppress(psutil.Error):
            p.kill()
    assert sorted(p.name for p in work.iterdir()) == [], "an output or staging folder was written"
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err), left


def _assert_one_line(done: subprocess.CompletedProcess[str], left: list[str], cause: str) -> None:
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr[-3000:]
    assert lines[0].startswith("twolink-pin: error: Dask cluster 127.0.0.1 (LocalCluster): "), lines[0]
    assert "the 2 Dask worker processes could not start: " + cause in lines[0], lines[0]
    assert lines[0].endswith("try fewer workers, or run in-process (without --workers)"), lines[0]
    assert done.returncode == 2, done.stderr
    assert left == []


@pytest.mark.skipif(sys.platform != "linux", reason="pids cgroups are Linux's")
@pytest.mark.parametrize(
    "when",
    [
        "fork",  # the first worker's fork
        "worker",  # the fork of the second worker or a worker's first thread, whichever comes first
    ],
)
def test_at_the_process_limit_a_sweep_says_why_in_one_line_and_leaves_nothing(
    tmp_path: Path, when: str
) -> None:
    with _cgroup() as cgroup:
        done, left = _run(tmp_path, str(cgroup), when)
        assert (cgroup / "cgroup.procs").read_text().split() == []  # nothing of the command left
    _assert_one_line(done, left, "")
    # the first refusal seen: the fork (EAGAIN), a thread of this process or of a worker
    reasons = ("Resource temporarily unavailable", "can't start new thread", "could not start its threads")
    assert any(r in done.stderr for r in reasons), done.stderr


def test_a_worker_start_failing_as_fork_does_at_the_limit_is_one_line(tmp_path: Path) -> None:
    """Without cgroups: the start of each worker process raises EAGAIN as fork does."""
    done, left = _run(tmp_path, "", "fault")
    _assert_one_line(done, left, "Resource temporarily unavailable")


def test_closing_a_local_cluster_whose_worker_is_slow_to_exit_prints_no_warning(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """After the work, a worker process that does not exit within 4 s (here: a teardown that
    never returns, as a loaded machine makes it slow) is killed by its nanny, which warned
    "Worker process still alive after 4.0 seconds, killing" on stderr after a successful
    sweep. The worker is still killed (the nanny's report of it, at INFO, stays)."""
    import threading

    from distributed import WorkerPlugin

    from twolink_pin.studies.cluster import open_cluster

    class Stuck(WorkerPlugin):  # type: ignore[misc]
        def teardown(self, worker: object) -> None:
            threading.Event().wait()

    with caplog.at_level(logging.INFO, logger="distributed"):
        with open_cluster(workers=1) as engine:
            engine.client.register_plugin(Stuck())
    said = [(r.levelno, r.getMessage()) for r in caplog.records if r.name == "distributed.nanny"]
    assert any(m.endswith("was killed by signal 9") for _, m in said), said
    assert [m for level, m in said if level >= logging.WARNING] == []


def test_a_worker_that_dies_in_its_imports_is_one_line_naming_the_error(tmp_path: Path) -> None:
    """Before: each worker logged "Failed to initialize worker" with its traceback."""
    done, left = _run(tmp_path, "", "import")
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr[-3000:]
    assert lines[0].startswith(
        "twolink-pin: error: Dask cluster 127.0.0.1 (LocalCluster): the LocalCluster did not start "
        "(ModuleNotFoundError: import of pinocchio halted"
    ), lines[0]
    assert done.returncode == 2 and left == []


def test_the_command_allocates_parquet_memory_without_jemalloc() -> None:
    """pyarrow's bundled jemalloc printed "<jemalloc>: background thread creation failed"
    dozens of times beside the one line at the process limit (the fork case above, now and then):
    the command makes pyarrow use the system allocator, in its own process and in the workers
    it spawns (they inherit the environment)."""
    code = (
        "import twolink_pin_entry, os, pyarrow;"
        "print(pyarrow.default_memory_pool().backend_name, os.environ['ARROW_DEFAULT_MEMORY_POOL'])"
    )
    env = {k: v for k, v in os.environ.items() if k != "ARROW_DEFAULT_MEMORY_POOL"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert done.stdout.split() == ["system", "system"], done.stderr


def test_the_command_starts_no_jemalloc_thread_when_pyarrow_is_imported() -> None:
    """The fork case above still printed jemalloc's line after the pool was chosen: importing
    pyarrow starts jemalloc's background thread (its compiled-in conf asks for one), whichever
    pool allocates. Behind the command's entry, importing pyarrow starts one thread fewer than the
    same import without it (pyarrow starts threads of its own besides: the count is compared, not
    fixed)."""
    code = (
        "import os, sys;"
        "sys.argv[1] == 'entry' and __import__('twolink_pin_entry');"
        "a = len(os.listdir('/proc/self/task')); import pyarrow;"
        "print(len(os.listdir('/proc/self/task')) - a)"
    )
    env = {
        k: v for k, v in os.environ.items() if k not in ("JE_ARROW_MALLOC_CONF", "ARROW_DEFAULT_MEMORY_POOL")
    }
    added = {
        how: subprocess.run(
            [sys.executable, "-c", code, how], env=env, capture_output=True, text=True, timeout=300
        ).stdout.strip()
        for how in ("entry", "bare")
    }
    assert int(added["entry"]) == int(added["bare"]) - 1, added
