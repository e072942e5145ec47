"""The report's worker processes: a pool that never outlives the report, or the runs in
this process (``workers = 1``).

Ctrl-C and SIGTERM are the report's to handle: the workers ignore SIGINT (a terminal sends it
to the whole process group) and die on SIGTERM, and the report, on either, cancels what is
pending and kills them. Workers are started (forked) inside :func:`interrupts.deferred`, so a
signal that arrives during the fork is raised after it, not dropped by an at-fork hook.
"""

from __future__ import annotations

import gc
import importlib
import signal
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any

from twolink_pin import interrupts


class _InProcess:
    """A stand-in for ProcessPoolExecutor that runs each task at submit (workers = 1)."""

    def __enter__(self) -> _InProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        future: Future[Any] = Future()
        try:
            future.set_result(fn(*args))
        except Exception as exc:
            future.set_exception(exc)
        return future

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        return None


def _worker_start() -> None:
    """In each worker before its first task: the report, not the worker, acts on Ctrl-C."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _contained(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` in a worker with ``os._exit`` contained (:func:`~twolink_pin.user_code.exits_contained`):
    a law that calls it fails its run, named, instead of killing the worker and breaking the pool."""
    from twolink_pin.user_code import exits_contained

    with exits_contained():
        return fn(*args)


class _Workers:
    """The process pool, with each ``submit`` (which may fork workers) run deferred, and each
    task's user code unable to end its worker (:func:`_contained`).

    The workers fork in the first ``submit`` (a pool that forks starts them all at once), with
    every object of this process frozen out of the cyclic garbage collector (``gc.freeze``,
    undone here right after): a worker's collections then walk only the objects it made, not the
    ~240 000 it inherits (the modules of matplotlib, SciPy, SymPy, Pinocchio), each full one
    ~0.1 s of CPU — the pre-fork use the ``gc`` documentation describes. A process that has
    frozen objects itself is left as it is (unfreezing would undo its own freeze)."""

    def __init__(self, pool: ProcessPoolExecutor) -> None:
        self._pool = pool
        self._forked = False

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        with interrupts.deferred():
            if self._forked or gc.get_freeze_count():  # a process that froze objects itself: its choice
                return self._pool.submit(_contained, fn, *args)
            gc.freeze()
            try:
                return self._pool.submit(_contained, fn, *args)
            finally:
                self._forked = True
                gc.unfreeze()  # this process collects as before


@contextmanager
def worker_pool(workers: int, shared: Sequence[str] = ()) -> Iterator[Any]:
    """Worker processes that never outlive the report: on an error, Ctrl-C or SIGTERM the
    pending runs are cancelled and the workers killed before the exception goes on.

    ``shared``: modules imported here before the workers fork, so that they share them
    instead of each importing them again (matplotlib and SciPy: ~1 s of CPU per worker)."""
    if workers <= 1:
        with _InProcess() as serial:
            yield serial
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_worker_start)
    previous = signal.getsignal(signal.SIGTERM)
    in_main = _is_main_thread()
    if in_main:  # SIGTERM too cleans up, also when the library is used without the CLI
        signal.signal(signal.SIGTERM, interrupts.on_signal)
    try:
        for name in shared:  # before the first submit, which forks the workers
            importlib.import_module(name)
        yield _Workers(pool)
        pool.shutdown(wait=True)  # inside the try: interrupted here too, the workers are killed
    except BaseException:
        with interrupts.deferred():  # a second Ctrl-C does not stop the clean-up half-way
            processes = list(getattr(pool, "_processes", {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                if process.is_alive():
                    process.kill()
            for process in processes:
                process.join(timeout=5)
        raise
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)


def _is_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()
