"""The signals a command has received (SIGINT, SIGTERM), for the loops that must act on them.

The CLI's handlers record each signal here and raise :class:`KeyboardInterrupt` (or
:class:`Terminated` for SIGTERM) where the program is. Library code a long loop calls may
catch that exception on its way (a Dask client call in progress, a callback wrapper): the
loop then calls :func:`check` between its steps, which raises it again, so Ctrl-C stops a
sweep on a cluster within one step of the loop however the first exception fared.
"""

from __future__ import annotations

import signal


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is so that every ``with`` block cleans up (staging
    folders removed, worker processes stopped) as for Ctrl-C."""


received: list[int] = []
"""The signals received while the command runs (emptied when a command starts)."""


def note(signum: int) -> None:
    """Record ``signum`` (called by the signal handlers)."""
    received.append(signum)


def check() -> None:
    """Raise :class:`Terminated` or :class:`KeyboardInterrupt` if a signal was received."""
    if received:
        raise Terminated if received[-1] == signal.SIGTERM else KeyboardInterrupt


__all__ = ["Terminated", "check", "note", "received"]
