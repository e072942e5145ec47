"""The signals a command has received (SIGINT, SIGTERM), for the loops that must act on them.

The CLI's handlers record each signal here and raise :class:`KeyboardInterrupt` (or
:class:`Terminated` for SIGTERM) where the program is. Library code a long loop calls may
catch that exception on its way (a Dask client call in progress, a callback wrapper): the
loop then calls :func:`check` between its steps, which raises it again, so Ctrl-C stops a
sweep on a cluster within one step of the loop however the first exception fared.

Some places drop an exception raised in them: ``os.fork``'s at-fork hooks (logging registers
some), finalisers. A signal that arrives while the report forks its workers was lost that way
(the report ran on to its end). Code that forks runs inside :func:`deferred`: the handlers
then only record the signal, and leaving the block raises it where the program is. Code that
starts worker processes a terminal's Ctrl-C would reach through the process group (a Dask
LocalCluster's) also runs inside :func:`spared_children`: they start with SIGINT blocked and
are stopped by their parent.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is so that every ``with`` block cleans up (staging
    folders removed, worker processes stopped) as for Ctrl-C."""


received: list[int] = []
"""The signals received while the command runs (emptied when a command starts)."""


def note(signum: int) -> None:
    """Record ``signum`` (called by the signal handlers)."""
    received.append(signum)


_deferring: list[int] = []
"""One entry per :func:`deferred` block being run (a forked child inherits its parent's)."""


def deferring() -> bool:
    """True inside :func:`deferred`: a handler records its signal and returns."""
    return bool(_deferring)


@contextmanager
def deferred() -> Iterator[None]:
    """Run the block with SIGINT and SIGTERM recorded, not raised; on leaving it, raise the
    last one received meanwhile (:class:`Terminated` or :class:`KeyboardInterrupt`)."""
    before = len(received)
    _deferring.append(1)
    try:
        yield
    finally:
        _deferring.pop()
    if not _deferring:
        check(since=before)


@contextmanager
def spared_children() -> Iterator[None]:
    """Run the block with SIGINT blocked in this thread. Threads started inside inherit the
    mask, and so do the processes they start, even across ``exec`` (a spawned Python keeps
    it): the workers that a terminal's Ctrl-C reaches through the process group never see
    it, and their parent, which then stops them, acts for them. A SIGINT that arrives
    meanwhile waits and is delivered when the block ends (run it inside :func:`deferred`)."""
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def on_signal(signum: int, frame: object) -> None:
    """The handler for SIGINT and SIGTERM while a command runs: record ``signum`` and raise
    it where the program is (:func:`check`), or, inside :func:`deferred`, only record it."""
    note(signum)
    if not _deferring:
        check()


def check(since: int = 0) -> None:
    """Raise :class:`Terminated` or :class:`KeyboardInterrupt` if a signal was received
    (after the first ``since`` entries of :data:`received`: a caller that marked where it
    started ignores the signals of an earlier, finished call in the same process)."""
    if len(received) > since:
        raise Terminated if received[-1] == signal.SIGTERM else KeyboardInterrupt


def result_of(future: Any, since: int, poll: float = 0.2) -> Any:
    """``future.result()``, checking every ``poll`` seconds [s] whether a signal was received
    after the first ``since`` entries of :data:`received` (:func:`check`): a KeyboardInterrupt
    raised where Python drops it (a gc callback, which distributed installs; a finaliser) would
    otherwise wait for the future's end (the report went on for 30 s after Ctrl-C on a loaded
    machine)."""
    while True:
        try:
            return future.result(timeout=poll)
        except TimeoutError:
            check(since=since)


__all__ = [
    "Terminated",
    "check",
    "deferred",
    "deferring",
    "note",
    "on_signal",
    "received",
    "result_of",
    "spared_children",
]
