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
import signal
import threading
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
    """A simulation ran past its wall-clock bound (see module doc)."""

    def __init__(self, seconds: float) -> None:
        super().__init__(seconds)
        self.seconds = seconds


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
    (:func:`per_run_limit`) — or ``error(seconds)`` in its place, e.g. :func:`timed_out`
    naming the law; ``with`` gives the bound. No bound outside the main thread, without
    ``setitimer``, or when a bound is already armed (an enclosing simulation).

    Exact at every size: a bound so small (1e-9 s) that the alarm fires while it is being
    armed raises the same error from ``__enter__``, and once the block has ended the alarm
    raises nothing (the handler only raises while armed). A class, not a generator: a
    generator-based context manager has a gap between its ``yield`` and the block where an
    exception would escape both."""

    def __init__(self, error: Callable[[float], BaseException] | None = None) -> None:
        self.error = error
        self.seconds: float | None = None
        self.armed = False
        self.previous: Any = None

    def _expire(self, signum: int, frame: object) -> None:
        if self.armed:
            # Python ignores an exception raised where it cannot propagate (a gc callback, as
            # hypothesis and distributed install, or a __del__): fire again in 10 ms, so a
            # swallowed alarm still ends the block; __exit__ disarms before anything re-fires
            # outside it (the handler raises only while armed).
            signal.setitimer(signal.ITIMER_REAL, REFIRE)
            raise RunTimeout(self.seconds or 0.0)

    def _disarm(self) -> None:
        self.armed = False
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, self.previous)

    def _raise(self, exc: RunTimeout) -> BaseException:
        return exc if self.error is None else self.error(exc.seconds)

    def __enter__(self) -> float | None:
        seconds = _LIMIT.get()
        if (
            not seconds
            or threading.current_thread() is not threading.main_thread()
            or not hasattr(signal, "setitimer")
            or signal.getitimer(signal.ITIMER_REAL)[0] > 0
        ):
            return None
        self.seconds = seconds
        self.previous = signal.signal(signal.SIGALRM, self._expire)
        try:
            self.armed = True
            signal.setitimer(signal.ITIMER_REAL, seconds)
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
                raise self.error(exc.seconds) from None
            if kind is None:
                raise exc


def timed_out(controller: Controller, t: float, seconds: float) -> ControllerError:
    """The error of a run stopped by its bound: names the law (its name and class) and the bound."""
    return ControllerError(
        controller.name,
        t,
        f"the run did not finish within --timeout {seconds:g} s of wall-clock time (the law "
        f"{type(controller).__qualname__} may never return); give a larger --timeout for a longer run",
    )


__all__ = [
    "RunCancelled",
    "RunTimeout",
    "bounded",
    "per_run_limit",
    "run_limit",
    "run_watcher",
    "timed_out",
    "watched",
]
