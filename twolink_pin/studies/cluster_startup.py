"""Reaching a scheduler and starting a LocalCluster (used by
:func:`~twolink_pin.studies.cluster.open_cluster`): a scheduler address that nothing answers,
or that answers with no Dask message, fails fast and says so (:func:`_probe`,
:func:`_handshake`); what Dask logs while a LocalCluster starts is kept rather than printed: a nanny that cannot spawn its worker (a
bad ``multiprocessing-method`` in the user's Dask configuration) or a temporary folder that
cannot be made is then one line naming the cause, not distributed's own tracebacks and
warnings on stderr. Imports no Dask."""

from __future__ import annotations

import contextlib
import logging
import socket
import threading
from collections.abc import Iterator
from urllib.parse import urlsplit

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
    logger.handlers, logger.propagate = [_Keep(logging.WARNING)], False
    started = False
    try:
        yield records
        started = True
    finally:
        logger.handlers, logger.propagate = saved
        if started:  # a warning of a cluster that did start (a slow start, a deprecation) still shows
            for record in records:
                logger.handle(record)


def _startup_cause(exc: BaseException, records: list[logging.LogRecord]) -> str:
    """The cause of a failed start: the first exception distributed logged (a nanny's
    ``ValueError: cannot find context for 'bogus'``), else ``exc`` itself."""
    for record in records:
        if record.exc_info and record.exc_info[1] is not None:
            inner = record.exc_info[1]
            return f"{type(inner).__name__}: {str(inner)[:300]}; {record.getMessage()[:120]}"
    return f"{type(exc).__name__}: {str(exc)[:300]}"


def _probe(address: str, timeout: float) -> None:
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


def _handshake(address: str, timeout: float) -> None:
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
