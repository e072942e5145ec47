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

A run that does not stop — a law whose ``compute`` sleeps or loops, so that no block ends —
would hold every later change back. Two bounds keep the page live: a superseded run that has
not stopped ``stuck_after`` seconds after the newer request, and a run that has shown no
progress for ``limit`` seconds (``tune --timeout``: ``work`` calls :meth:`LatestWins.alive`
after each block of samples; a run that never does, an adaptive-step one, counts from its
start), is **left behind**: a new worker thread takes the next
request at once, the old thread's outcome is never delivered, and :class:`RunAbandoned` is
raised in it asynchronously (which stops a loop in Python at its next bytecode, or a sleep
when it returns; code looping inside C cannot be stopped that way and goes on in the
background). ``on_abandoned`` says so (the page shows it); a run left behind at its limit is
delivered as :class:`RunTooLong`.
"""

from __future__ import annotations

import ctypes
import sys
import threading
import time
from collections.abc import Callable
from typing import Generic, TypeVar

from twolink_pin.errors import TwolinkPinError
from twolink_pin.simulation.deadline import RunCancelled

In = TypeVar("In")
Out = TypeVar("Out")

STUCK_AFTER = 2.0
"""A superseded run that has not stopped this long after the newer request is left behind [s]."""


class RunAbandoned(BaseException):
    """Raised asynchronously in a run left behind (a ``BaseException``: a law's
    ``except Exception`` does not swallow it)."""


class RunTooLong(TwolinkPinError):
    """A run that showed no progress for the session's limit (left behind, not stopped).

    Attributes:
        generation: The run's number.
        seconds: The limit [s].
    """

    def __init__(self, generation: int, seconds: float) -> None:
        self.generation, self.seconds = generation, seconds
        super().__init__(
            f"run {generation} made no progress for --timeout {seconds:g} s of wall-clock time (the law's "
            "compute may never return): it was left behind, and a change of a control starts a new run"
        )


def _raise_in(thread: threading.Thread) -> None:
    """Raise :class:`RunAbandoned` in ``thread`` at its next Python bytecode (CPython)."""
    ident = thread.ident
    set_async = getattr(getattr(ctypes, "pythonapi", None), "PyThreadState_SetAsyncExc", None)
    if ident is not None and set_async is not None and thread.is_alive():
        set_async(ctypes.c_ulong(ident), ctypes.py_object(RunAbandoned))


class LatestWins(Generic[In, Out]):
    """Run ``work(request)`` on a worker thread for the newest request only.

    Args:
        work: The job (a simulation); what it raises is its outcome too.
        deliver: Called on the worker thread with ``(generation, request, outcome)`` for the
            newest request's run (``outcome`` the value or the exception raised).
        stuck_after: A superseded run still in flight this long after the newer request is
            left behind [s] (module doc).
        limit: A run that showed no progress (:meth:`alive`) for this long is left behind
            and delivered as :class:`RunTooLong` [s] (None: no limit).
        on_abandoned: Called with ``(generation, seconds it ran)`` when a run is left behind,
            before the next run starts (with the session's lock held: it must not call back).
    """

    def __init__(
        self,
        work: Callable[[In], Out],
        deliver: Callable[[int, In, Out | Exception], None],
        stuck_after: float = STUCK_AFTER,
        limit: float | None = None,
        on_abandoned: Callable[[int, float], None] | None = None,
    ) -> None:
        self._work = work
        self._deliver = deliver
        self._stuck_after, self._limit, self._on_abandoned = stuck_after, limit, on_abandoned
        self._lock = threading.Condition()
        self._waiting: tuple[int, In] | None = None
        self._flight: tuple[int, In] | None = None  # the run in flight
        self._generation = 0
        self._closed = False
        self._running: dict[threading.Thread, int] = {}  # the worker's generation in flight
        self._started = 0.0  # when the run in flight started or last progressed (time.monotonic)
        self._superseded_at: float | None = None  # when a newer request came while it ran
        self.runs = 0
        """Runs started (a superseded request never starts)."""
        self.cancelled = 0
        """Runs that stopped with :class:`RunCancelled` (superseded while in flight)."""
        self.abandoned = 0
        """Runs left behind (stuck after a newer request, or past the limit)."""
        self._worker = self._start_worker()
        self._watchdog = threading.Thread(target=self._watch, name="twolink-pin-tune-watchdog", daemon=True)
        self._watchdog.start()

    def _start_worker(self) -> threading.Thread:
        thread = threading.Thread(target=self._loop, name="twolink-pin-tune-runs", daemon=True)
        self._worker = thread
        thread.start()
        return thread

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
            if self._busy and self._superseded_at is None:
                self._superseded_at = time.monotonic()
            self._lock.notify_all()
            return self._generation

    def superseded(self) -> bool:
        """Whether the run in flight on this thread is no longer wanted (a newer request,
        closed, or left behind)."""
        me = threading.current_thread()
        return self._closed or me is not self._worker or self._running.get(me) != self._generation

    def alive(self) -> None:
        """The run in flight on this thread made progress (a block of samples): its limit
        counts from now."""
        if threading.current_thread() is self._worker:
            self._started = time.monotonic()

    def close(self) -> None:
        """Stop: no further request starts, and the run in flight is superseded."""
        with self._lock:
            self._closed = True
            self._waiting = None
            self._lock.notify_all()

    def idle(self, timeout: float | None = None) -> bool:
        """Wait until no request is waiting or running; False on timeout."""
        with self._lock:
            return self._lock.wait_for(lambda: self._waiting is None and not self._busy, timeout)

    @property
    def _busy(self) -> bool:
        return self._worker in self._running

    def _watch(self) -> None:
        """Leave a stuck run behind (module doc)."""
        with self._lock:
            while not self._closed:
                now = time.monotonic()
                due: list[float] = []
                working = self._busy and self._flight is not None  # not yet delivering its outcome
                if working and self._superseded_at is not None:
                    due.append(self._superseded_at + self._stuck_after)
                if working and self._limit:
                    due.append(self._started + self._limit)
                if not due:
                    self._lock.wait()
                    continue
                if min(due) > now:
                    self._lock.wait(min(due) - now)
                    continue
                self._abandon(now)

    def _abandon(self, now: float) -> None:
        """(Lock held.) Leave the worker's run behind and start a new worker."""
        old = self._worker
        self._running.pop(old)
        assert self._flight is not None
        generation, request = self._flight
        seconds = now - self._started
        too_long = self._superseded_at is None  # at the limit, not superseded
        self.abandoned += 1
        self._superseded_at = None
        if self._on_abandoned is not None:  # before the next run starts: its page says so
            self._on_abandoned(generation, seconds)
        self._start_worker()
        _raise_in(old)
        if too_long:
            threading.Thread(
                target=self._say_too_long,
                args=(generation, request),
                name="twolink-pin-tune-limit",
                daemon=True,
            ).start()
        self._lock.notify_all()

    def _say_too_long(self, generation: int, request: In) -> None:
        with self._lock:
            current = generation == self._generation and not self._closed
        if current:
            self._deliver(generation, request, RunTooLong(generation, self._limit or 0.0))

    def _loop(self) -> None:
        me = threading.current_thread()
        try:
            self._serve(me)
        except RunAbandoned:  # left behind (raised asynchronously): this thread ends
            pass

    def _serve(self, me: threading.Thread) -> None:
        while True:
            with self._lock:
                self._lock.wait_for(
                    lambda: self._waiting is not None or self._closed or me is not self._worker
                )
                if self._closed or me is not self._worker:
                    return
                assert self._waiting is not None
                generation, request = self._waiting
                self._waiting = None
                self._running[me] = generation
                self._flight = (generation, request)
                self._started, self._superseded_at = time.monotonic(), None
                self.runs += 1
                self._lock.notify_all()
            outcome: Out | Exception
            try:
                outcome = self._work(request)
            except RunCancelled:
                with self._lock:
                    if me is self._worker:
                        self._flight = None
                    if self._running.pop(me, None) is not None:
                        self.cancelled += 1
                    self._lock.notify_all()
                continue
            except Exception as exc:  # the run's failure is its outcome (shown, the server stays up)
                outcome = exc
            try:
                with self._lock:
                    current = me is self._worker and generation == self._generation and not self._closed
                    if me is self._worker:
                        self._flight = None  # its work is done: never left behind while delivering
                if current:
                    self._deliver(generation, request, outcome)
            except Exception as exc:  # showing a run failed (stdout closed): say so, keep serving
                print(f"twolink-pin: run {generation} could not be shown: {exc}", file=sys.stderr, flush=True)
            finally:
                with self._lock:
                    self._running.pop(me, None)
                    self._lock.notify_all()


__all__ = ["STUCK_AFTER", "LatestWins", "RunAbandoned", "RunTooLong"]
