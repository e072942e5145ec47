"""The ``twolink-pin`` console script: signal handlers first, the package second.

Importing :mod:`twolink_pin` (Pinocchio, NumPy, SciPy) takes seconds on a busy machine;
an interrupt during that import used to end in a ``KeyboardInterrupt`` traceback (or, inside
NumPy's import, an ``ImportError`` that hides it). This module imports nothing heavy. Its
first statements install SIGINT and SIGTERM handlers that, until the command starts, end
the process at once with one line (``twolink-pin: interrupted`` / ``twolink-pin:
terminated``) and exit status 130 / 143: while the package loads and the arguments are
parsed there is nothing to clean up (no output, no worker). From the command's start
:func:`twolink_pin.cli.main` raises ``KeyboardInterrupt`` where the program is, so that
staging files are removed and workers stopped, and reports the interrupt whatever exception
it turned into. When the command has finished, a late signal cannot change its outcome: the
process runs the exit handlers and ends with the command's status (the interpreter's own
finalisation, during which Python restores the default handlers, is skipped).

``python -m twolink_pin_entry`` runs the same code as the console script;
``twolink_pin.cli.main`` stays the library-level entry (``python -m twolink_pin.cli``, covered
only once the package is imported). A signal that arrives before the interpreter reaches this
module's first line ends the process as the operating system does (exit −2 / −15).
"""

from __future__ import annotations

import errno
import os
import signal
import sys

INTERRUPTED, TERMINATED = 130, 143
"""Exit statuses for SIGINT and SIGTERM (128 + the signal number, as shells report)."""


def _flush() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):
            pass


def _say(line: str) -> None:
    if sys.stderr is None:  # fd 2 closed at start-up: never print on stdout instead
        return
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _leave_at_once(signum: int, frame: object) -> None:
    """Before the command starts: nothing to clean up, so say it and go."""
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_IGN)
    _say("twolink-pin: terminated" if signum == signal.SIGTERM else "twolink-pin: interrupted")
    _flush()
    os._exit(TERMINATED if signum == signal.SIGTERM else INTERRUPTED)


def _ready(stage: str) -> None:
    """As :func:`twolink_pin.readiness.ready`, without importing the package."""
    path = os.environ.get("TWOLINK_PIN_READY_FILE")
    if path:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
            try:
                os.write(fd, f"{stage}\n".encode())
            finally:
                os.close(fd)
        except OSError:
            pass


def _adopt_orphans() -> None:
    """Become the reaper of this command's orphaned descendants (Linux ``PR_SET_CHILD_SUBREAPER``):
    a process a law started and detached (``sleep 600 &`` in a shell it ran) is re-parented to
    this process instead of init, so that :func:`_end_children` finds it."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER = 36
    except (OSError, AttributeError):  # not Linux: children are still ended, orphans are not found
        pass


def _children() -> list[int]:
    """This process's living children (from /proc; empty where there is none)."""
    me = os.getpid()
    found = []
    try:
        entries = os.listdir("/proc")
    except OSError:
        return []
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as f:
                fields = f.read().rpartition(b")")[2].split()
        except OSError:
            continue
        if len(fields) > 1 and int(fields[1]) == me and fields[0] != b"Z":
            found.append(int(entry))
    return found


def _end_children() -> None:
    """Kill every process this command started that is still running (a law's subprocess or
    ``multiprocessing`` child; the command's own workers are stopped by then), and their
    children as they are re-parented here, so that none keeps the command alive (Python's
    exit waits for ``multiprocessing`` children) or outlives it."""
    tracker = sys.modules.get("multiprocessing.resource_tracker")
    # multiprocessing's resource tracker ends by itself when this process's end of its pipe
    # closes; killed here, the exit handlers' unregistering (a LocalCluster that did not
    # start leaves semaphores) starts a new one that prints a KeyError traceback per name.
    spared = getattr(getattr(tracker, "_resource_tracker", None), "_pid", None)
    for _ in range(100):  # each round ends one generation (their orphans come back to us)
        children = [pid for pid in _children() if pid != spared]
        if not children:
            break
        for pid in children:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        for pid in children:
            try:
                os.waitpid(pid, 0)
            except OSError:  # not our child after all (a race), or reaped by its owner
                pass
    try:  # zombies of processes reaped by nobody
        while os.waitpid(-1, os.WNOHANG)[0] > 0:
            pass
    except OSError:
        pass


def _finish(code: int) -> None:
    """End the process with ``code``, the command's outcome: exit handlers run (with a
    signal then ending the process at once with ``code``), streams flushed, and no
    interpreter finalisation left for a signal to land in."""

    def done(signum: int, frame: object) -> None:
        _flush()
        os._exit(code)

    for s in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(s) is not signal.SIG_IGN:
            signal.signal(s, done)
    try:
        _end_children()  # before the exit handlers: multiprocessing's would wait for a law's child
        import atexit

        atexit._run_exitfuncs()
    finally:
        _flush()
        os._exit(code)


def _quiet_worker_start() -> None:
    """In a process that ``multiprocessing`` spawned from this command (a Dask worker, which
    imports this module as its ``__main__``): if it cannot create a thread or process (the
    limit on processes reached), it ends with status ``EX_TEMPFAIL`` instead of printing a
    traceback, and a worker that fails while it starts (its imports) does not log its
    traceback: the command names the cause in one line (:mod:`twolink_pin.studies.cluster_startup`)."""
    process = sys.modules.get("multiprocessing.process")
    if process is None or not getattr(process.current_process(), "_inheriting", False):
        return
    run = process.BaseProcess.run

    def run_or_leave(self: object) -> None:
        try:
            run(self)
        except (OSError, RuntimeError) as exc:
            if isinstance(exc, OSError) and exc.errno in (errno.EAGAIN, errno.ENOMEM):
                raise SystemExit(os.EX_TEMPFAIL) from None
            if isinstance(exc, RuntimeError) and "can't start new thread" in str(exc):
                raise SystemExit(os.EX_TEMPFAIL) from None
            raise

    process.BaseProcess.run = run_or_leave
    import logging  # the worker's failed start (an import that fails) is the command's one line

    logging.getLogger("distributed.nanny").addFilter(
        lambda record: record.getMessage() != "Failed to initialize worker"
    )


_quiet_worker_start()

# pyarrow (the sweeps' Parquet files) allocates through the system's malloc. libarrow also
# carries jemalloc, and at the limit on processes and threads "<jemalloc>: background thread
# creation failed (11)" was written to fd 2 dozens of times beside the command's one line
# (tests/test_cluster_limit.py's fork case, twice on 6 Dec 2026 under load; 16 runs with the
# pool chosen passed, and 10 of 11 without). Set before pyarrow is imported, here or in a worker
# this command spawns (they inherit it); a user's own value stays.
os.environ.setdefault("ARROW_DEFAULT_MEMORY_POOL", "system")
# That was not enough (the fork case failed so again, 1 run in 6 under load on 7 Dec): libarrow's
# jemalloc starts its background thread when pyarrow is imported, whichever pool is chosen (a
# process has 3 threads after `import pyarrow`, 2 with this), and its compiled-in conf asks for
# that thread; jemalloc's own environment variable turns it off.
os.environ.setdefault("JE_ARROW_MALLOC_CONF", "background_thread:false")


def main() -> int:
    """Run ``twolink-pin`` with the process's arguments. Ends the process (it never returns)."""
    signal.signal(signal.SIGTERM, _leave_at_once)
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # a background job ignores Ctrl-C
        signal.signal(signal.SIGINT, _leave_at_once)
    code = 1
    _adopt_orphans()
    try:
        _ready("started")
        from twolink_pin.cli import main as cli_main

        code = cli_main()
    except SystemExit as exc:  # argparse's --help and usage errors (already printed)
        if isinstance(exc.code, int) or exc.code is None:
            code = exc.code or 0
        else:
            _say(str(exc.code))
    except KeyboardInterrupt:  # raised by a handler of the command that outlived it
        code = INTERRUPTED
        _say("twolink-pin: interrupted")
    _finish(code)
    return code  # not reached


if __name__ == "__main__":
    sys.exit(main())
