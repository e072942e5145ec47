"""Reaching a scheduler and starting a LocalCluster (used by
:func:`~twolink_pin.studies.cluster.open_cluster`): a scheduler address that nothing answers,
or that answers with no Dask message, fails fast and says so (:func:`probe`,
:func:`handshake`); what Dask logs while a LocalCluster starts is kept rather than printed: a nanny that cannot spawn its worker (a
bad ``multiprocessing-method`` in the user's Dask configuration), a temporary folder that
cannot be made or workers that cannot start at the limit on processes (a fork or a thread
refused with ``EAGAIN``) is then one line naming the cause, not distributed's own tracebacks
and warnings on stderr (:func:`start_local`). Imports no Dask until called."""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import socket
import threading
from collections.abc import Iterator
from typing import Any
from urllib.parse import urlsplit

from twolink_pin import interrupts
from twolink_pin.studies.cluster_errors import ClusterError


@contextlib.contextmanager
def _startup_log() -> Iterator[list[logging.LogRecord]]:
    """While a LocalCluster starts: distributed's log records at WARNING and above are kept
    (the list yielded) instead of printed, so a nanny that cannot spawn its worker is one
    line naming the cause (:func:`_startup_cause`), not Dask's own tracebacks on stderr."""
    logger = logging.getLogger("distributed")
    records: list[logging.LogRecord] = []

    class _Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            records.append(record)

    saved = logger.handlers[:], logger.propagate
    logger.handlers, logger.propagate = [_Keep(logging.INFO)], False
    started = False
    try:
        yield records
        started = True
    finally:
        logger.handlers, logger.propagate = saved
        if started:  # a warning of a cluster that did start (a slow start, a deprecation) still shows
            for record in records:
                if record.levelno >= logging.WARNING:
                    logger.handle(record)


def _startup_cause(exc: BaseException, records: list[logging.LogRecord]) -> str:
    """The cause of a failed start: the first exception distributed logged (a nanny's
    ``ValueError: cannot find context for 'bogus'``), else ``exc`` itself."""
    for record in records:
        if record.exc_info and record.exc_info[1] is not None:
            inner = record.exc_info[1]
            return f"{type(inner).__name__}: {str(inner)[:300]}; {record.getMessage()[:120]}"
    return f"{type(exc).__name__}: {str(exc)[:300]}"


def _resource_cause(exc: BaseException, records: list[logging.LogRecord]) -> str | None:
    """The operating system's reason when a worker process or thread could not be created
    (fork or clone refused at the process limit: ``EAGAIN``, ``ENOMEM``; Python's "can't
    start new thread"), from ``exc`` or what distributed logged; else None."""
    seen = [exc] + [r.exc_info[1] for r in records if r.exc_info and r.exc_info[1] is not None]
    for first in seen:
        error: BaseException | None = first
        for _ in range(20):  # along its chain of causes (bounded: a chain can loop)
            if error is None:
                break
            if isinstance(error, OSError) and error.errno in (errno.EAGAIN, errno.ENOMEM):
                return error.strerror or os.strerror(error.errno)
            if isinstance(error, RuntimeError) and "can't start new thread" in str(error):
                return "can't start new thread"
            error = error.__cause__ or error.__context__
    for record in records:  # a worker that could not start a thread (twolink_pin_entry) left quietly
        if record.getMessage().endswith(f"exited with status {os.EX_TEMPFAIL}"):
            return "a worker process could not start its threads"
    return None


def _failed_start(
    address: str, workers: Any, exc: BaseException, records: list[logging.LogRecord]
) -> ClusterError:
    """The error of a LocalCluster that did not start: at the process limit one line naming
    the operating system's reason and what to do, else the cause distributed logged."""
    reason = _resource_cause(exc, records)
    if reason is None:
        return ClusterError(address, f"the LocalCluster did not start ({_startup_cause(exc, records)})")
    return ClusterError(
        address,
        f"the {workers} Dask worker process{'es' if workers != 1 else ''} could not start: {reason} "
        "(the limit on processes and threads reached?); try fewer workers, or run in-process "
        "(without --workers)",
    )


def start_local(address: str, options: dict[str, Any]) -> tuple[Any, Any]:
    """A LocalCluster of ``options`` and a client of it, or :class:`ClusterError` naming
    the cause. Ctrl-C and SIGTERM are held while it starts: Dask cannot close a cluster that
    is half started (its exit hook then fails on a worker still starting, with a traceback),
    so the signal is raised once it has started, and the cluster is then stopped. Its
    worker processes start with SIGINT blocked: a Ctrl-C sent to the process group stops
    them through this process, not in the middle of their imports with a traceback each."""
    from multiprocessing import resource_tracker

    from distributed import Client, LocalCluster

    # The tracker unblocks SIGINT in the thread that starts it (after blocking it for its own
    # start): started here first, it cannot undo spared_children in Dask's threads below.
    resource_tracker.ensure_running()
    cluster = client = None
    records: list[logging.LogRecord] = []
    try:
        with _startup_log() as records, interrupts.deferred(), interrupts.spared_children():
            cluster = LocalCluster(**options)
            client = Client(cluster, set_as_default=False)
        return cluster, client
    except BaseException as exc:
        if cluster is not None:
            with interrupts.deferred():  # a second Ctrl-C does not stop the clean-up half-way
                if not isinstance(exc, Exception):
                    kill_workers(cluster)
                if client is not None:
                    with contextlib.suppress(Exception):
                        client.close(timeout=5)
                with contextlib.suppress(Exception):
                    cluster.close(timeout=10)
        if not isinstance(exc, Exception):
            raise
        raise _failed_start(address, options.get("n_workers"), exc, records) from None


class _SlowExit(logging.Filter):
    """Drops a nanny's "Worker process still alive after 4.0 seconds, killing"."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("Worker process still alive after")


class _Deaths(logging.Filter):
    """Drops a nanny's "Restarting worker" and the scheduler's "… marked as failed because N
    workers died …": the command's one line names the law and the runs that killed them."""

    def filter(self, record: logging.LogRecord) -> bool:
        text = record.getMessage()
        return not (text.startswith("Restarting worker") or "workers died while trying to run" in text)


@contextlib.contextmanager
def quiet_worker_deaths() -> Iterator[None]:
    """While an owned LocalCluster runs the work: a worker killed by what it runs is the
    command's error (:class:`~twolink_pin.studies.cluster_errors.WorkerKilled`), not log lines."""
    quiet = _Deaths()
    loggers = [logging.getLogger(name) for name in ("distributed.nanny", "distributed.scheduler")]
    for logger in loggers:
        logger.addFilter(quiet)
    try:
        yield
    finally:
        for logger in loggers:
            logger.removeFilter(quiet)


@contextlib.contextmanager
def quiet_worker_exit() -> Iterator[None]:
    """While a LocalCluster closes after its work: a worker process that is slow to exit (a
    loaded machine; a teardown that does not return) is killed by its nanny after 4 s, and
    the nanny's warning that says so is dropped: the results are complete, and a success
    prints nothing on stderr."""
    logger, quiet = logging.getLogger("distributed.nanny"), _SlowExit()
    logger.addFilter(quiet)
    try:
        yield
    finally:
        logger.removeFilter(quiet)


def kill_workers(cluster: Any) -> None:
    """Kill a LocalCluster's worker processes at once, their nannies' complaints silenced
    (a task they are in can take minutes)."""
    import os
    import signal

    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    for nanny in list(getattr(cluster, "workers", {}).values()):
        with contextlib.suppress(Exception):
            pid = nanny.pid
            if pid:
                os.kill(pid, signal.SIGKILL)


def probe(address: str, timeout: float) -> None:
    """Fail fast if nothing listens at ``address`` (Dask itself would retry until its timeout)."""
    parts = urlsplit(address)
    assert parts.hostname is not None and parts.port is not None
    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=timeout):
            pass
    except TimeoutError:
        raise ClusterError(
            address, f"no answer within {timeout:g} s; is the scheduler running there?"
        ) from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise ClusterError(
            address,
            f"cannot be reached ({reason}); start one with `dask scheduler` (see docs/cluster.md) or check the address",
        ) from None


def handshake(address: str, timeout: float) -> None:
    """Fail within ``timeout`` if what listens at ``address`` is no Dask scheduler: Dask's
    own connect waits for the peer's handshake without a time limit."""
    import asyncio

    from distributed.comm import connect
    from distributed.security import Security

    failure: list[BaseException] = []

    async def probe() -> None:
        args = Security().get_connection_args("client")
        comm = await asyncio.wait_for(connect(address, timeout=timeout, **args), timeout)
        await comm.close()

    def run() -> None:
        try:
            asyncio.run(probe())
        except BaseException as exc:  # reported to the caller's thread below
            failure.append(exc)

    thread = threading.Thread(target=run, name="twolink-pin-handshake", daemon=True)
    thread.start()
    thread.join(timeout + 1.0)
    if thread.is_alive() or (failure and isinstance(failure[0], (TimeoutError, asyncio.TimeoutError))):
        raise ClusterError(
            address, f"cannot connect within {timeout:g} s: it does not answer as a Dask scheduler"
        )
    if failure and not isinstance(failure[0], OSError):  # it answered, with no Dask message
        # (Dask reads the first bytes as a frame length: an SSH or HTTP greeting asks for exabytes)
        raise ClusterError(
            address,
            "answers, but not as a Dask scheduler (what it sent is no Dask message); check the host and port",
        )
    if failure:
        raise ClusterError(address, f"cannot connect ({type(failure[0]).__name__}: {failure[0]})")
