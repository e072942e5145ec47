"""A wall-clock bound per simulation: a law that never returns stops its run, not the program.

:func:`per_run_limit` sets the bound (the CLI's ``--timeout``) for the simulations started
inside it; the engine (:func:`~twolink_pin.simulation.engine.integrate`, and the adaptive-step
integrator) runs each simulation inside :func:`bounded`, which arms ``SIGALRM``
(``signal.setitimer``) for the bound and, when it fires, raises :class:`RunTimeout` where
the program is — in the law's busy loop, in its ``time.sleep`` — which the engine turns into
a :class:`~twolink_pin.errors.ControllerError` naming the law and the bound. So ``compare``
records that law's run as failed and keeps the others' results, as for a law that raises.

:class:`RunTimeout` is a ``BaseException`` (like ``KeyboardInterrupt``): a law's
``except Exception`` cannot swallow it.

Where it does not apply: outside the main thread (Python delivers signals to the main
thread only) — a Dask worker runs its tasks in worker threads, so a sweep on Dask workers
is not bounded per run (an in-process sweep is, per chunk of runs: one chunk is one
simulation of N runs); on a platform without ``setitimer`` (Windows); and code that blocks
signals or loops inside C without returning to Python.

A second, cooperative hook: :func:`watched` hands every block of samples the fixed-step
engine writes to a callable (in the thread that runs the simulation), which may raise
:class:`RunCancelled` to stop the run there — the tuner (:mod:`twolink_pin.tuning`) cancels a
superseded run this way and streams the part already simulated.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from twolink_pin.errors import ControllerError

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller

_LIMIT: contextvars.ContextVar[float | None] = contextvars.ContextVar("twolink_pin_run_limit", default=None)
_WATCHER: contextvars.ContextVar[Callable[[Any], None] | None] = contextvars.ContextVar(
    "twolink_pin_run_watcher", default=None
)


class RunCancelled(Exception):
    """A run stopped by its watcher (:func:`watched`): its result is no longer wanted."""


@contextlib.contextmanager
def watched(hook: Callable[[Any], None] | None) -> Iterator[None]:
    """Call ``hook(block)`` with each block of samples (:class:`~twolink_pin.simulation.engine.Samples`,
    views: copy to keep) of the fixed-step simulations started inside the block; the hook
    may raise :class:`RunCancelled` to stop the run."""
    token = _WATCHER.set(hook)
    try:
        yield
    finally:
        _WATCHER.reset(token)


def run_watcher() -> Callable[[Any], None] | None:
    """The hook in force (:func:`watched`; None: none)."""
    return _WATCHER.get()


class RunTimeout(BaseException):
    """A simulation ran past its wall-clock bound (see module doc), or made no progress for
    :data:`STALL` seconds (``stalled``)."""

    def __init__(self, seconds: float, stalled: bool = False) -> None:
        super().__init__(seconds)
        self.seconds = seconds
        self.stalled = stalled


STALL = 600.0
"""Seconds a bounded block (a simulation, a law's import or build) may go without progress —
no call of the law returning, no block of steps done — when its bound is longer (the default
``--timeout`` is a day): a law that sleeps or spins forever ends its run in 10 to 20 minutes,
not the next day. 600 s is a hundred times the slowest single call of a law here (an ``mpc``
replan of 900 knots, the longest horizon 4 GB hold, takes 5 s) and longer than any law's import
(a machine-learning framework's, some 30 s); ``--timeout 0`` waits forever."""
BACKSTOP_GRACE = 10.0
"""Seconds past a bound (or past twice :data:`STALL` without progress) after which the
backstop thread ends the process: the alarm that should have stopped the block was ignored,
blocked or disarmed by the law (:func:`_watch`)."""
BACKSTOP_TICK = 1.0
"""Seconds between two looks of the backstop thread."""
PROGRESS = [0]
"""Calls of a law that returned, and blocks of steps done (:func:`note_progress`)."""


def note_progress() -> None:
    """Count one step of progress of the bounded block (a law's call returned): what tells a
    slow run from a stalled one (:data:`STALL`)."""
    PROGRESS[0] += 1


@contextlib.contextmanager
def per_run_limit(seconds: float | None) -> Iterator[None]:
    """Bound every simulation started inside the block to ``seconds`` of wall-clock time
    (None or 0: no bound)."""
    token = _LIMIT.set(float(seconds) if seconds else None)
    try:
        yield
    finally:
        _LIMIT.reset(token)


def run_limit() -> float | None:
    """The bound [s] in force (None: none)."""
    return _LIMIT.get()


REFIRE = 0.01
"""Seconds after an alarm that the alarm fires again while the block has not ended (an
exception raised inside a gc callback or ``__del__`` is printed and dropped by Python)."""


class bounded:
    """Raise :class:`RunTimeout` inside the block once it has run for the bound in force
    (:func:`per_run_limit`), or — with ``stall`` and a bound longer than :data:`STALL` — once it
    has made no progress (:func:`note_progress`) for :data:`STALL` to twice that; or ``error(timeout)`` in
    its place, e.g. :func:`timed_out` naming the law. ``with`` gives the bound. No bound outside
    the main thread, without ``setitimer``, or when a bound is already armed (an enclosing
    simulation).

    Exact at every size: a bound so small (1e-9 s) that the alarm fires while it is being
    armed raises the same error from ``__enter__``, and once the block has ended the alarm
    raises nothing (the handler only raises while armed). A class, not a generator: a
    generator-based context manager has a gap between its ``yield`` and the block where an
    exception would escape both. A law that ignores, blocks or disarms the alarm is met by a
    backstop thread that ends the process (:func:`start_backstop`)."""

    def __init__(
        self, error: Callable[[RunTimeout], BaseException] | None = None, *, stall: bool = False
    ) -> None:
        self.error = error
        self.stall = stall
        """Whether the block's progress is counted (:func:`note_progress`: a law's calls), so
        that :data:`STALL` applies; off for work that reports none (a symbolic derivation)."""
        self.seconds: float | None = None
        self.armed = False
        self.previous: Any = None
        self.started = 0.0
        self.seen = 0
        self.raised: RunTimeout | None = None

    def _expire(self, signum: int, frame: object) -> None:
        if not self.armed:
            return
        if self.raised is None:
            seconds = self.seconds or 0.0
            remaining = seconds - (time.monotonic() - self.started)
            if (
                self.stall and seconds > STALL and remaining > 1e-3
            ):  # a look at the progress, not the bound yet
                if PROGRESS[0] != self.seen:
                    self.seen = PROGRESS[0]
                    signal.setitimer(signal.ITIMER_REAL, min(STALL, remaining))
                    return
                self.raised = RunTimeout(STALL, stalled=True)
            else:
                self.raised = RunTimeout(seconds)
        # Python ignores an exception raised where it cannot propagate (a gc callback, as
        # hypothesis and distributed install, or a __del__): fire again in 10 ms, so a
        # swallowed alarm still ends the block; __exit__ disarms before anything re-fires
        # outside it (the handler raises only while armed).
        signal.setitimer(signal.ITIMER_REAL, REFIRE)
        raise self.raised

    def _disarm(self) -> None:
        self.armed = False
        _WATCHED[0] = None
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, self.previous)

    def _raise(self, exc: RunTimeout) -> BaseException:
        return exc if self.error is None else self.error(exc)

    def __enter__(self) -> float | None:
        seconds = _LIMIT.get()
        if (
            not seconds
            or threading.current_thread() is not threading.main_thread()
            or not hasattr(signal, "setitimer")
            or signal.getitimer(signal.ITIMER_REAL)[0] > 0
        ):
            return None
        self.seconds, self.started, self.seen = seconds, time.monotonic(), PROGRESS[0]
        start_backstop()  # before the alarm: an alarm that fires while a thread starts would escape
        _WATCHED[0] = self
        self.previous = signal.signal(signal.SIGALRM, self._expire)
        try:
            self.armed = True
            signal.setitimer(signal.ITIMER_REAL, min(seconds, STALL) if self.stall else seconds)
        except RunTimeout as exc:  # fired while being armed
            self._disarm()
            raise self._raise(exc) from None
        return seconds

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: Any) -> None:
        if self.seconds is None:
            return
        try:
            self._disarm()
        except RunTimeout as late:  # fired as the block ended, before the disarm took
            self._disarm()
            if kind is None:
                exc = late
        if isinstance(exc, RunTimeout):
            if self.error is not None:
                raise self.error(exc) from None
            if kind is None:
                raise exc


_WATCHED: list[bounded | None] = [None]
"""The bounded block that runs now (one at a time: an enclosing bound is not re-armed)."""
_BACKSTOP: list[threading.Thread] = []


def start_backstop() -> None:
    """Start the process's backstop thread once (:func:`_watch`); the CLI starts it with the
    command, so that its stack and its allocator's arena (some 70 MB of address space) are
    held before any memory check (``mpc``'s horizon) counts what is left."""
    if not _BACKSTOP:
        thread = threading.Thread(target=_watch, name="twolink-pin-backstop", daemon=True)
        _BACKSTOP.append(thread)
        thread.start()


def _watch() -> None:
    """The backstop thread, for the life of the process: every :data:`BACKSTOP_TICK` seconds it
    looks at the bounded block that runs (:data:`_WATCHED`). When that block is
    :data:`BACKSTOP_GRACE` past its bound, or has made no progress for twice :data:`STALL` and
    the grace (the alarm looks at the progress every :data:`STALL` seconds), the alarm did not
    stop it — the law ignored, blocked or disarmed ``SIGALRM``: say so naming the law, remove
    the command's staging files, end its child processes and the process (exit status 1)."""
    block, seen, since = None, 0, 0.0
    while True:
        time.sleep(BACKSTOP_TICK)
        now, current = time.monotonic(), _WATCHED[0]
        if current is not block:
            block, seen, since = current, PROGRESS[0], now
        if block is None or not block.armed:
            continue
        if PROGRESS[0] != seen:
            seen, since = PROGRESS[0], now
        seconds = block.seconds or 0.0
        late = now - block.started > seconds + BACKSTOP_GRACE
        stalled = block.stall and seconds > STALL and now - since > 2 * STALL + BACKSTOP_GRACE
        if (late or stalled) and _WATCHED[0] is block and block.armed:
            _end_process(block._raise(RunTimeout(seconds) if late else RunTimeout(STALL, stalled=True)))


def _end_process(error: BaseException) -> None:
    """The backstop's last resort (:func:`_watch`), from its thread: one line on
    stderr, the staging files removed, the children ended, exit status 1."""
    import sys

    from twolink_pin.files import remove_staging

    line = (
        f"twolink-pin: {error}; the alarm that stops it (SIGALRM) was ignored, blocked or disarmed by the law: "
        "the process was ended"
    )
    try:
        print(line[:1000], file=sys.stderr, flush=True)
    except (OSError, ValueError, AttributeError):
        pass
    remove_staging()
    entry = sys.modules.get("twolink_pin_entry")
    end_children = getattr(entry, "_end_children", None)
    if end_children is not None:
        end_children()
    os._exit(1)  # a thread's call: the real one (user_code.exits_contained contains the main thread's)


def timed_out(controller: Controller, t: float, timeout: RunTimeout) -> ControllerError:
    """The error of a run stopped by its bound (``timeout``): names the law (its name and
    class) and the bound, or the time it made no progress for."""
    law = type(controller).__qualname__
    if timeout.stalled:
        return ControllerError(
            controller.name,
            t,
            f"the run made no progress for {timeout.seconds:g} s of wall-clock time: no call of the law "
            f"{law} returned (it may never return); --timeout 0 waits forever",
        )
    return ControllerError(
        controller.name,
        t,
        f"the run did not finish within --timeout {timeout.seconds:g} s of wall-clock time (the law "
        f"{law} may never return); give a larger --timeout for a longer run",
    )


__all__ = [
    "RunCancelled",
    "RunTimeout",
    "bounded",
    "note_progress",
    "per_run_limit",
    "run_limit",
    "run_watcher",
    "start_backstop",
    "timed_out",
    "watched",
]
