"""What Dask logs while a LocalCluster starts, kept rather than printed (used by
:func:`~twolink_pin.studies.cluster.open_cluster`): a nanny that cannot spawn its worker (a
bad ``multiprocessing-method`` in the user's Dask configuration) or a temporary folder that
cannot be made is then one line naming the cause, not distributed's own tracebacks and
warnings on stderr. Imports no Dask."""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator


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
