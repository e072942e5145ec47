"""A signal while worker processes start, made to coincide with the start by a hook, not by
timing.

The report: Ctrl-C while it forks its workers (CI, stop 26: the report ran on for 30 s after
SIGINT). A Python signal handler that raises inside ``os.fork``'s at-fork hooks (logging
registers some) has its exception printed as "Exception ignored" and dropped, so the
interrupt was lost; a hook registered before the command sends the signal from inside the fork.

``sweep --workers``: Ctrl-C to the process group while a LocalCluster's worker process is
starting. The worker died in its imports with a traceback, and Dask's exit hook failed on the
half-started cluster with another; a hook sends SIGINT to the group right after the first
worker process is spawned."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import psutil
import pytest

HOOK = textwrap.dedent(
    """
    import os, signal, sys
    fired = []
    def _during_fork():  # the first fork in this process: the report's first worker
        if not fired:
            fired.append(1)
            os.kill(os.getpid(), signal.{signal})
    os.register_at_fork(after_in_parent=_during_fork)
    sys.argv = ["twolink-pin", *sys.argv[1:]]
    import twolink_pin_entry
    twolink_pin_entry.main()
    """
)


AFTER_SPAWN = textwrap.dedent(
    """
    import multiprocessing.process, os, signal, sys, time
    start = multiprocessing.process.BaseProcess.start
    def importing(pid):  # its memory map holds asyncio's extension: Dask's imports have begun
        try:
            with open(f"/proc/{{pid}}/maps") as maps:
                return "_asyncio" in maps.read()
        except OSError:
            return True  # it has ended
    def start_then_ctrl_c(self):  # Dask's first worker process, in the middle of its imports
        start(self)
        if "Worker" in self.name and not getattr(start_then_ctrl_c, "fired", False):
            start_then_ctrl_c.fired = True
            end = time.monotonic() + 60
            while not importing(self.pid) and time.monotonic() < end:
                time.sleep(0.001)  # polling a condition, not a delay before the signal
            os.killpg(0, signal.SIGINT)  # as a terminal does: the whole process group
    multiprocessing.process.BaseProcess.start = start_then_ctrl_c
    sys.argv = ["twolink-pin", *sys.argv[1:]]
    import twolink_pin_entry
    twolink_pin_entry.main()
    """
)


def _run(
    tmp_path: Path, signame: str, script: str = HOOK, argv: tuple[str, ...] = ()
) -> tuple[subprocess.CompletedProcess[str], list[str]]:
    env = {k: v for k, v in os.environ.items() if k != "TWOLINK_PIN_READY_FILE"}
    argv = argv or ("report", "--workers", "2", "--duration", "30", "--no-animation", "--out", "r")
    proc = subprocess.Popen(
        [sys.executable, "-c", script.format(signal=signame), *argv],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    children: list[str] = []
    try:
        # Bounded only against a hang (the bug: the report went on to its end, minutes later).
        out, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        pytest.fail(f"still running 120 s after {signame} during the fork; stderr ends {err[-300:]!r}")
    group = []
    for p in psutil.process_iter():
        with contextlib.suppress(ProcessLookupError, psutil.Error):
            if os.getpgid(p.pid) == proc.pid:
                group.append(p)
    # What the command started goes with it (the resource tracker, on its pipe's end, a moment
    # later): bounded only against a process left behind for good.
    _, alive = psutil.wait_procs(group, timeout=30)
    children = [f"{p.pid} {' '.join(p.cmdline())[:200]}" for p in alive]
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err), children


@pytest.mark.parametrize(
    ("signame", "code", "word"), [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated")]
)
def test_a_signal_during_the_workers_fork_stops_the_report(
    tmp_path: Path, signame: str, code: int, word: str
) -> None:
    done, left = _run(tmp_path, signame)
    assert left == []
    assert done.returncode == code, done.stderr[-500:]
    assert done.stderr.rstrip().endswith(f"twolink-pin: {word}"), done.stderr[-500:]
    assert "Exception ignored" not in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert not (tmp_path / "r").exists()
    assert [p.name for p in tmp_path.iterdir()] == []  # no staging folder left either


def test_a_signal_some_library_swallowed_stops_the_report_at_its_next_step(tmp_path: Path) -> None:
    """The handlers record every signal (interrupts.received) before raising; if the exception
    is dropped on its way (an at-fork hook, a finaliser), the report's next step raises it: no
    report, no staging folder. A signal recorded before this build (an earlier, finished call
    in the same process) does not stop the next one."""
    from twolink_pin import interrupts
    from twolink_pin.report import ReportOptions, build_report
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationConfig

    small = ReportOptions(
        run=RunSpec(simulation=SimulationConfig(duration=0.5)),
        workers=2,
        animation=False,
        identification=False,
        limits_section=False,
        sim_to_sim=False,
        controllers=("pd", "computed-torque"),
    )
    seen: list[str] = []

    def progress(what: str, done: int, total: int) -> None:
        seen.append(what)
        if what == "model and trajectory":
            interrupts.note(signal.SIGINT)  # as the handler does; its exception "was dropped"

    mark = len(interrupts.received)
    try:
        with pytest.raises(KeyboardInterrupt):
            build_report(tmp_path / "out", small, progress=progress)
        assert seen == ["model and trajectory"]  # stopped at the very next step
        assert list(tmp_path.iterdir()) == []
        results = build_report(tmp_path / "again", small)  # the old entry is not this build's
        assert set(results["controllers"]) == {"pd", "computed-torque"}
    finally:
        del interrupts.received[mark:]


def test_ctrl_c_while_a_local_clusters_worker_starts_is_one_line_and_leaves_nothing(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    argv = ("sweep", "pd", "--samples", "400", "--duration", "2", "--workers", "2", "--out", "s")
    done, left = _run(tmp_path, "SIGINT", AFTER_SPAWN, argv)
    assert done.returncode == 130, done.stderr[-800:]
    assert done.stderr.rstrip().endswith("twolink-pin: interrupted"), done.stderr[-800:]
    for noise in ("Traceback", "Exception ignored", "Error"):
        assert noise not in done.stderr, done.stderr
    assert [p.name for p in tmp_path.iterdir()] == []
    assert left == []  # the scheduler's and the workers' processes went with it


def test_a_wait_for_a_run_ends_at_a_signal_whose_exception_was_dropped() -> None:
    """A SIGINT whose KeyboardInterrupt Python dropped (raised in a gc callback or a finaliser:
    only interrupts.received has it) ends the report's wait for a run at its next poll, not when
    the run ends (the report ran on for 30 s after Ctrl-C in a loaded fresh-clone make test). A
    signal recorded before the wait began does not; without a signal the result comes back."""
    import threading
    from concurrent.futures import Future

    from twolink_pin import interrupts

    mark = len(interrupts.received)
    try:
        interrupts.note(signal.SIGINT)  # an earlier, finished call's signal
        done: Future[str] = Future()
        threading.Thread(target=done.set_result, args=("run",)).start()
        assert interrupts.result_of(done, since=len(interrupts.received)) == "run"
        never: Future[str] = Future()  # a run that does not end while we wait
        since = len(interrupts.received)
        interrupts.note(signal.SIGINT)  # as the handler does; its exception "was dropped"
        with pytest.raises(KeyboardInterrupt):
            interrupts.result_of(never, since=since)
        interrupts.note(signal.SIGTERM)
        with pytest.raises(interrupts.Terminated):
            interrupts.result_of(never, since=since)
    finally:
        del interrupts.received[mark:]
