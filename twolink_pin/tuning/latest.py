"""Latest wins: re-run a job in the background whenever its input changes.

:class:`LatestWins` keeps one slot for the newest request and one worker thread. A request
that arrives while a run is in flight replaces any request still waiting (nothing queues:
at most one run in flight and one waiting); when the in-flight run ends, its outcome is
delivered only if no newer request was made meanwhile, so a stale outcome never overwrites
a newer one. Every request gets a generation number (1, 2, …); the outcome of generation g
is delivered only while g is the newest.

The run in flight is cancelled, not waited for: ``work`` may ask :meth:`LatestWins.superseded`
(the tuner asks it after every block of samples the engine writes,
:func:`~twolink_pin.simulation.deadline.watched`) and stop by raising
:class:`~twolink_pin.simulation.deadline.RunCancelled`; a cancelled run is never delivered.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from typing import Generic, TypeVar

from twolink_pin.simulation.deadline import RunCancelled

In = TypeVar("In")
Out = TypeVar("Out")


class LatestWins(Generic[In, Out]):
    """Run ``work(request)`` on a worker thread for the newest request only.

    Args:
        work: The job (a simulation); what it raises is its outcome too.
        deliver: Called on the worker thread with ``(generation, request, outcome)`` for the
            newest request's run (``outcome`` the value or the exception raised).
    """

    def __init__(
        self,
        work: Callable[[In], Out],
        deliver: Callable[[int, In, Out | Exception], None],
    ) -> None:
        self._work = work
        self._deliver = deliver
        self._lock = threading.Condition()
        self._waiting: tuple[int, In] | None = None
        self._generation = 0
        self._closed = False
        self._running = 0
        self.runs = 0
        """Runs started (a superseded request never starts)."""
        self.cancelled = 0
        """Runs that stopped with :class:`RunCancelled` (superseded while in flight)."""
        self._thread = threading.Thread(target=self._loop, name="twolink-pin-tune-runs", daemon=True)
        self._thread.start()

    @property
    def generation(self) -> int:
        """The newest request's generation (0 before the first)."""
        return self._generation

    def submit(self, request: In) -> int:
        """Ask for a run of ``request``; returns its generation. A request still waiting
        is dropped (superseded)."""
        with self._lock:
            self._generation += 1
            self._waiting = (self._generation, request)
            self._lock.notify()
            return self._generation

    def superseded(self) -> bool:
        """Whether the run in flight is no longer wanted (a newer request, or closed)."""
        return self._closed or self._running != self._generation

    def close(self) -> None:
        """Stop: no further request starts, and the run in flight is superseded."""
        with self._lock:
            self._closed = True
            self._waiting = None
            self._lock.notify()

    def idle(self, timeout: float | None = None) -> bool:
        """Wait until no request is waiting or running; False on timeout."""
        with self._lock:
            return self._lock.wait_for(lambda: self._waiting is None and not self._busy, timeout)

    _busy = False

    def _loop(self) -> None:
        while True:
            with self._lock:
                self._lock.wait_for(lambda: self._waiting is not None or self._closed)
                if self._closed:
                    return
                assert self._waiting is not None
                generation, request = self._waiting
                self._waiting = None
                self._busy = True
                self._running = generation
                self.runs += 1
            outcome: Out | Exception
            try:
                outcome = self._work(request)
            except RunCancelled:
                with self._lock:
                    self.cancelled += 1
                    self._busy = False
                    self._lock.notify_all()
                continue
            except Exception as exc:  # the run's failure is its outcome (shown, the server stays up)
                outcome = exc
            try:
                with self._lock:
                    current = generation == self._generation and not self._closed
                if current:
                    self._deliver(generation, request, outcome)
            except Exception as exc:  # showing a run failed (stdout closed): say so, keep serving
                print(f"twolink-pin: run {generation} could not be shown: {exc}", file=sys.stderr, flush=True)
            finally:
                with self._lock:
                    self._busy = False
                    self._lock.notify_all()


__all__ = ["LatestWins"]
