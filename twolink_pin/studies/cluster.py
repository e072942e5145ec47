"""Dask for sweeps that outgrow one process: a scheduler to connect to, or a LocalCluster.

:func:`open_cluster` gives a :class:`DaskEngine`: connected to an existing scheduler
(``scheduler="tcp://HOST:PORT"``, checked to answer within ``timeout`` seconds), or
owning a ``LocalCluster`` of ``workers`` single-threaded worker processes on this machine,
the scheduler, the workers and the dashboard all bound to 127.0.0.1. :meth:`DaskEngine.run`
submits one task per item (a bounded window of them at a time, so that the client and the
scheduler hold O(workers) tasks, not O(items)), yields each result as it completes and,
whatever ends the iteration — the last result, an error, Ctrl-C, SIGTERM — cancels the
tasks still pending. Dask reschedules the tasks of a worker that dies; a task that killed
more than :data:`ALLOWED_FAILURES` workers in a row is a :class:`ClusterError`.

Dask is optional (``pip install 'twolink-pin[cluster]'``, :data:`INSTALL_HINT`): this
module imports only the standard library until a cluster is asked for.

This module knows nothing of sweeps: a task is ``fn(*args, progress=callback)``, where
``callback(done)`` reports how far the task is (the workers send it as Dask events,
at most every :data:`PROGRESS_INTERVAL` seconds).
"""

from __future__ import annotations

import contextlib
import importlib.util
import queue
import threading
import time
import uuid
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import urlsplit

from twolink_pin import interrupts
from twolink_pin.errors import InvalidParameterError
from twolink_pin.studies.cluster_errors import ClusterError, TaskTimeout, WorkerKilled
from twolink_pin.studies.cluster_startup import (
    handshake,
    kill_workers,
    probe,
    quiet_worker_deaths,
    quiet_worker_exit,
    start_local,
)

INSTALL_HINT = "pip install 'twolink-pin[cluster]'"
"""How to install Dask for ``--workers`` / ``--scheduler``."""
DEFAULT_PORT = 8786
"""Dask's scheduler port, used when an address gives none."""
CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a scheduler to answer, and for it to have a worker."""
MAX_WORKERS = 64
"""Largest LocalCluster (worker processes on this machine)."""
PROTOCOLS = ("tcp", "tls")
"""Schemes of a scheduler address (``tls://`` needs distributed's security configuration)."""
PROGRESS_INTERVAL = 0.5
"""Least interval between two progress events of one task [s]."""
ALLOWED_FAILURES = 3
"""Dask's default ``distributed.scheduler.allowed-failures``: a task whose workers died
while running it more than this many times fails with ``KilledWorker``."""


def available() -> bool:
    """Whether ``distributed`` (Dask's scheduler and workers) is installed."""
    try:
        return importlib.util.find_spec("distributed") is not None
    except (ImportError, ValueError):  # a broken or blocked installation
        return False


def require_dask() -> None:
    """Raise :class:`ClusterError` with the install command if Dask is missing."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise ClusterError(
            "(none)",
            f"Dask is not installed; --workers and --scheduler need the cluster extra: {INSTALL_HINT}",
        ) from None


def scheduler_address(text: str) -> str:
    """``text`` as a scheduler address ``tcp://HOST:PORT`` or ``tls://HOST:PORT``.

    A bare ``HOST:PORT`` is ``tcp://``; a missing port is Dask's :data:`DEFAULT_PORT`.

    Raises:
        InvalidParameterError: another scheme, no host, a port outside 1..65535, or a
            path, query or user name in the address.
    """
    expected = "tcp://HOST:PORT or tls://HOST:PORT (a Dask scheduler's address)"
    if not isinstance(text, str) or not text.strip() or any(c.isspace() for c in text.strip()):
        raise InvalidParameterError("scheduler", text, expected)
    raw = text.strip()
    if "://" not in raw:
        raw = "tcp://" + raw
    try:
        parts = urlsplit(raw)
        port = parts.port
    except ValueError:
        raise InvalidParameterError("scheduler", text, expected) from None
    if (
        parts.scheme not in PROTOCOLS
        or not parts.hostname
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username is not None
        or port == 0
    ):
        raise InvalidParameterError("scheduler", text, expected)
    host = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
    return f"{parts.scheme}://{host}:{port or DEFAULT_PORT}"


LOCAL_WORKER = "TWOLINK_PIN_LOCAL_WORKER"
"""Environment variable set in the LocalCluster's worker processes."""


def dask_setup(worker: Any) -> None:
    """Preload hook of workers (Dask calls it when the worker starts with ``--preload`` of a
    module that has it: this one, or :mod:`twolink_pin.studies.sweep`, which re-exports it so
    that the sweep's code is imported before the first task): in a LocalCluster's workers,
    leave Ctrl-C to the client, which kills them (a terminal sends SIGINT to the whole
    process group)."""
    import os
    import signal

    if os.environ.get(LOCAL_WORKER) == "1" and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _call(fn: Callable[..., Any], topic: str, index: int, args: tuple[Any, ...]) -> tuple[str, Any]:
    """The task run on a worker: ``(worker address, fn(*args, progress=...))``."""
    from distributed import get_worker

    worker = get_worker()
    last = [0.0]

    def progress(done: int) -> None:
        now = time.monotonic()
        if now - last[0] >= PROGRESS_INTERVAL:
            last[0] = now
            worker.log_event(topic, [index, int(done)])

    return str(worker.address), fn(*args, progress=progress)


class _Reports:
    """The running tasks' progress reports, which arrive on Dask's thread as events of the
    run's topic: runs done per task, and when each task's first report came (it is running)."""

    def __init__(self) -> None:
        self.partial: dict[int, int] = {}
        self.started: dict[int, float] = {}  # task -> when its first report arrived [monotonic s]
        self.lock = threading.Lock()

    def on_event(self, event: Any) -> None:
        """A worker's ``(index, runs done)`` event."""
        index, runs = event[1]
        with self.lock:
            self.partial[int(index)] = max(self.partial.get(int(index), 0), int(runs))
            self.started.setdefault(int(index), time.monotonic())  # its first report: running

    def snapshot(self) -> dict[int, int]:
        """``{index: runs done}`` of the running tasks."""
        with self.lock:
            return dict(self.partial)

    def forget(self, index: int) -> None:
        """Task ``index`` has finished."""
        with self.lock:
            self.partial.pop(index, None)
            self.started.pop(index, None)

    def late(self, limit_s: float) -> list[int]:
        """The tasks running for longer than ``limit_s`` [s]."""
        now = time.monotonic()
        with self.lock:
            return [i for i, t0 in self.started.items() if now - t0 > limit_s]


@dataclass
class DaskEngine:
    """A Dask client (and the LocalCluster it owns, if any); see the module docstring."""

    client: Any
    """The ``distributed.Client``."""
    address: str
    """The scheduler's address."""
    description: str
    """``LocalCluster of N workers at ADDRESS`` or ``scheduler ADDRESS``."""
    cluster: Any = None
    """The LocalCluster this engine started (closed with it), or None."""
    dashboard: str | None = None
    """The dashboard's URL, if the scheduler serves one (bokeh installed)."""
    _pending: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def slots(self) -> int:
        """Worker threads now in the cluster (tasks that can run at once), >= 1."""
        try:
            return max(1, sum(self.client.nthreads().values()))
        except Exception:  # the scheduler went away: the next wait says so
            return 1

    def run(
        self,
        fn: Callable[..., Any],
        items: Sequence[tuple[Any, ...]],
        *,
        name: str = "task",
        progress: Callable[[dict[int, int]], None] | None = None,
        window: int | None = None,
        limit_s: float | None = None,
    ) -> Generator[tuple[int, str, Any], None, None]:
        """``fn(*items[i], progress=...)`` on the cluster: ``(i, worker address, result)``
        as each task completes (in any order).

        Args:
            fn: A module-level function (pickled by reference: the workers import it).
            items: The tasks' arguments.
            name: Label of the tasks (their keys, the dashboard, messages).
            progress: Called in this thread with ``{i: done}`` of the running tasks, as the
                workers report them (at least every :data:`PROGRESS_INTERVAL` s while
                waiting).
            window: Most tasks submitted at once (default 2 per worker thread + 2).
            limit_s: Wall-clock bound of one task [s] from its first progress report (a task
                should report ``progress(0)`` when its work starts); past it,
                :class:`TaskTimeout` (None: no bound). A worker thread cannot be interrupted:
                the caller stops the workers (a LocalCluster's are killed on the error).

        Raises:
            ClusterError: a task killed too many workers, a worker cannot
                import the code, or the scheduler dropped the tasks.
            TaskTimeout: a task ran past ``limit_s``.
            Exception: what a task raised (a twolink-pin error arrives whole).
        """
        token = uuid.uuid4().hex[:12]
        topic = f"twolink-pin-{name}-{token}"
        done_queue: queue.Queue[Any] = queue.Queue()
        reports = _Reports()
        self.client.subscribe_topic(topic, reports.on_event)
        index_of: dict[str, int] = {}
        next_item = 0
        finished = 0
        refreshed = time.monotonic()
        limit = window or 2 * self.slots + 2
        try:
            while finished < len(items):
                while next_item < len(items) and len(self._pending) < limit:
                    key = f"{name}-{token}-{next_item}"
                    self._submit(fn, topic, next_item, items[next_item], key, done_queue)
                    index_of[key] = next_item
                    next_item += 1
                try:
                    future = done_queue.get(timeout=PROGRESS_INTERVAL)
                except queue.Empty:
                    future = None
                interrupts.check()  # a Ctrl-C that a Dask call caught on its way still stops the loop
                if window is None and time.monotonic() - refreshed > 5.0:  # workers come and go
                    limit, refreshed = 2 * self.slots + 2, time.monotonic()
                if future is None and self.client.status in ("closing", "closed"):
                    raise ClusterError(
                        self.address, f"lost the connection to the scheduler during the {name}"
                    )
                if limit_s is not None:
                    self._check_bound(reports, limit_s, name)
                if future is None or future.key not in self._pending:
                    if progress is not None:
                        progress(reports.snapshot())
                    continue
                index = index_of.pop(future.key)
                del self._pending[future.key]
                reports.forget(index)
                if future.status in ("cancelled", "error"):
                    raise self._failure(future, index, name)
                worker, result = future.result()
                future.release()
                finished += 1
                yield index, worker, result
        finally:
            self.cancel()
            with contextlib.suppress(Exception):
                self.client.unsubscribe_topic(topic)

    def _submit(
        self, fn: Callable[..., Any], topic: str, index: int, args: tuple[Any, ...], key: str, done: Any
    ) -> None:
        """Submit task ``index`` (``fn(*args)``, reporting on ``topic``) under ``key``; its
        future is pending until it is put on the queue ``done`` when it ends."""
        future = self.client.submit(_call, fn, topic, index, args, key=key, pure=False, retries=0)
        self._pending[key] = future
        future.add_done_callback(done.put)

    def _failure(self, future: Any, index: int, name: str) -> BaseException:
        """The error of task ``index`` that was cancelled or raised: the scheduler dropped it,
        it killed too many workers, a worker cannot import the code, or what it raised."""
        from distributed import KilledWorker

        if future.status == "cancelled":
            return ClusterError(
                self.address,
                f"the scheduler dropped the {name} tasks (was it restarted, or did another client cancel them?)",
            )
        exc = future.exception()
        if isinstance(exc, KilledWorker):
            deaths = int(getattr(exc, "allowed_failures", ALLOWED_FAILURES)) + 1
            last = getattr(getattr(exc, "last_worker", None), "address", "?")
            error: ClusterError = WorkerKilled(self.address, name, index, deaths, str(last))
        elif isinstance(exc, ImportError):
            error = ClusterError(
                self.address,
                f"a worker cannot import the code ({exc}): install the same twolink-pin on every worker",
            )
        else:
            return exc
        error.__cause__ = exc
        return error

    def _check_bound(self, reports: _Reports, limit_s: float, name: str) -> None:
        """Raise :class:`TaskTimeout` for the first task running for longer than ``limit_s``."""
        late = reports.late(limit_s)
        if late:
            raise TaskTimeout(self.address, name, min(late), limit_s, owned=self.cluster is not None)

    def cancel(self) -> None:
        """Cancel every task still pending (idempotent)."""
        futures = list(self._pending.values())
        self._pending.clear()
        if futures:
            with contextlib.suppress(Exception):
                self.client.cancel(futures, force=True)

    def close(self, kill: bool = False) -> None:
        """Cancel pending tasks, close the client and the LocalCluster if it owns one.

        With ``kill`` (an error, Ctrl-C, SIGTERM) the LocalCluster's worker processes are
        killed at once rather than asked to finish the task they are in (a chunk can take
        minutes); their nannies' complaints are silenced.
        """
        if kill and self.cluster is not None:
            self._pending.clear()  # the tasks die with the workers
            kill_workers(self.cluster)
        self.cancel()
        with contextlib.suppress(Exception):
            self.client.close(timeout=5)
        if self.cluster is not None:
            with contextlib.suppress(Exception), quiet_worker_exit():
                self.cluster.close(timeout=10)


def engine_for(client: Any) -> DaskEngine:
    """A :class:`DaskEngine` on a ``distributed.Client`` the caller owns (and closes)."""
    address = str(client.scheduler.address)
    return DaskEngine(client, address, f"scheduler {address}", dashboard=_dashboard(client.dashboard_link))


def _dashboard(link: str | None) -> str | None:
    if not link or importlib.util.find_spec("bokeh") is None:
        return None  # the scheduler serves no dashboard pages without bokeh
    return str(link)


@contextlib.contextmanager
def open_cluster(
    scheduler: str | None = None,
    workers: int | None = None,
    timeout: float = CONNECT_TIMEOUT,
    preload: Sequence[str] = (),
) -> Iterator[DaskEngine]:
    """A :class:`DaskEngine` on ``scheduler``, or on a new LocalCluster of ``workers``
    processes; closed (pending tasks cancelled, the LocalCluster stopped) on exit.

    Args:
        scheduler: Address of a running scheduler (see :func:`scheduler_address`).
        workers: Worker processes of a LocalCluster on 127.0.0.1, 1 to :data:`MAX_WORKERS`
            (one thread each).
        timeout: Seconds for the scheduler to answer and to have at least one worker, > 0.
        preload: Modules a LocalCluster's workers import when they start (the code their
            tasks run; each may have a ``dask_setup`` hook, see :func:`dask_setup`); default
            this one.

    Raises:
        InvalidParameterError: both or neither of ``scheduler`` and ``workers``, or a bad value.
        ClusterError: Dask is not installed, the scheduler cannot be reached or has no
            worker, or the LocalCluster does not start.
    """
    _check_cluster_options(scheduler, workers, timeout)
    address = scheduler_address(scheduler) if scheduler is not None else "127.0.0.1 (LocalCluster)"
    require_dask()
    if scheduler is not None:
        engine = _remote_engine(address, timeout)
    else:
        assert workers is not None
        engine = _local_engine(address, workers, preload)
    client = engine.client
    # an owned LocalCluster's worker killed by a task is the command's error, not Dask's log lines
    quiet = quiet_worker_deaths() if engine.cluster is not None else contextlib.nullcontext()
    try:
        try:
            client.wait_for_workers(1, timeout=timeout)
        except (TimeoutError, OSError):
            raise ClusterError(
                engine.address,
                f"has no worker after {timeout:g} s; start some with `dask worker {engine.address}`",
            ) from None
        with quiet:
            yield engine
    except BaseException:
        engine.close(kill=True)
        raise
    else:
        engine.close()


def _check_cluster_options(scheduler: str | None, workers: int | None, timeout: float) -> None:
    """Raise unless exactly one of ``scheduler`` and ``workers`` is given, ``workers`` is 1 to
    :data:`MAX_WORKERS` and ``timeout`` a number of seconds > 0."""
    if (scheduler is None) == (workers is None):
        raise InvalidParameterError(
            "scheduler/workers", (scheduler, workers), "exactly one of a scheduler address and a worker count"
        )
    if not (isinstance(timeout, (int, float)) and not isinstance(timeout, bool) and 0 < timeout < 1e6):
        raise InvalidParameterError("timeout", timeout, "a number of seconds > 0")
    if workers is not None and not (
        isinstance(workers, int) and not isinstance(workers, bool) and 1 <= workers <= MAX_WORKERS
    ):
        raise InvalidParameterError("workers", workers, f"a whole number from 1 to {MAX_WORKERS}")


def _remote_engine(address: str, timeout: float) -> DaskEngine:
    """An engine on the running scheduler at ``address``, checked to answer within ``timeout`` [s]."""
    from distributed import Client

    probe(address, timeout)
    handshake(address, timeout)
    try:
        client = Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ClusterError(address, f"cannot connect within {timeout:g} s ({exc})") from None
    return DaskEngine(client, address, f"scheduler {address}", dashboard=_dashboard(client.dashboard_link))


def _local_engine(address: str, workers: int, preload: Sequence[str]) -> DaskEngine:
    """An engine owning a new LocalCluster of ``workers`` single-threaded processes, all bound
    to 127.0.0.1, whose workers import ``preload`` (default this module) when they start."""
    cluster, client = start_local(
        address,
        dict(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            scheduler_port=0,
            dashboard_address="127.0.0.1:0",
            preload=list(preload) or [__name__],
            env={LOCAL_WORKER: "1"},
        ),
    )
    return DaskEngine(
        client,
        str(cluster.scheduler_address),
        f"LocalCluster of {workers} worker{'s' if workers != 1 else ''} at {cluster.scheduler_address}",
        cluster=cluster,
        dashboard=_dashboard(cluster.dashboard_link),
    )


__all__ = [
    "CONNECT_TIMEOUT",
    "DEFAULT_PORT",
    "INSTALL_HINT",
    "MAX_WORKERS",
    "ClusterError",
    "DaskEngine",
    "TaskTimeout",
    "available",
    "engine_for",
    "open_cluster",
    "require_dask",
    "scheduler_address",
]
