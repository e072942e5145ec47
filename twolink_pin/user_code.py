"""User code outside ``compute``: importing a law's file and building the law, contained.

:func:`guarded` runs a law's import or its construction (``__init__``, ``scaled_gains``, its
gains' checks) so that what it does wrong is a
:class:`~twolink_pin.errors.ControllerSpecError` naming the law and **the user's file and
line** (never a module name of ours): an exception, ``sys.exit``, a ``MemoryError``, or —
when the command bounds user code (the CLI's ``--timeout``, through :func:`time_bound`) —
not returning in time. What it changes of the process is put back afterwards: the working
directory and NumPy's error handling, print options and global random state
(:func:`process_state`); the CLI also restores them before each simulation
(:func:`restore_baseline`), so that a law that changes them cannot move the outputs or change
the next run.

This module imports nothing of the package but its errors: the bound is given by the caller
(the CLI passes :func:`twolink_pin.simulation.deadline.bounded`).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import ControllerError, ControllerSpecError, TwolinkPinError

PACKAGE = Path(__file__).resolve().parent
"""This package's folder: frames in it are ours, not the user's."""

_BOUND: contextvars.ContextVar[Callable[..., Any] | None] = contextvars.ContextVar(
    "twolink_pin_user_code_bound", default=None
)
_BASELINE: contextvars.ContextVar[tuple[Any, ...] | None] = contextvars.ContextVar(
    "twolink_pin_user_code_baseline", default=None
)


class _TimedOut(Exception):
    """The bound's error (``bound(_TimedOut)``), made from its timeout: the seconds and whether
    the code made no progress for that long (the stall) rather than ran past ``--timeout``."""

    def __init__(self, timeout: Any) -> None:
        super().__init__(timeout)
        self.seconds = float(getattr(timeout, "seconds", timeout))
        self.stalled = bool(getattr(timeout, "stalled", False))


class HardExit(SystemExit):
    """``os._exit(code)`` called by user code while a command runs (:func:`exits_contained`):
    raised where it was called, so that the law is named and the command cleans up (staging
    files, workers) instead of the process ending at once with the law's status."""

    def __init__(self, code: object) -> None:
        super().__init__(code)


@contextlib.contextmanager
def exits_contained() -> Iterator[None]:
    """Inside the block, ``os._exit`` (and ``posix._exit``) called in this process's main thread
    raises :class:`HardExit` instead of ending the process: a law's ``os._exit(0)`` is an error
    naming the law (exit status 1), not a silent success with its staging folders left behind.
    A child process (``fork``: a ``multiprocessing`` worker ends with ``os._exit``), another
    thread and the code after the block get the real one."""
    import posix
    import threading

    real = os._exit
    pid = os.getpid()

    def contained_exit(code: int) -> None:
        if os.getpid() != pid or threading.current_thread() is not threading.main_thread():
            real(code)
        raise HardExit(code)

    os._exit = posix._exit = contained_exit  # type: ignore[assignment]
    try:
        yield
    finally:
        os._exit = posix._exit = real


def _state() -> tuple[Any, ...]:
    try:
        cwd: str | None = os.getcwd()
    except OSError:  # the folder was removed
        cwd = None
    return cwd, np.geterr(), np.get_printoptions(), np.random.get_state()  # noqa: NPY002  # the legacy global generator is what a law may have seeded


def _restore(state: tuple[Any, ...]) -> None:
    cwd, err, printing, random = state
    if cwd is not None:
        with contextlib.suppress(OSError):
            if os.getcwd() != cwd:
                os.chdir(cwd)
    np.seterr(**err)
    np.set_printoptions(**printing)
    np.random.set_state(random)  # noqa: NPY002  # the legacy global generator, put back


@contextlib.contextmanager
def process_state() -> Iterator[None]:
    """Put back the working directory and NumPy's global state (errors, printing, random)
    as they were when the block started."""
    state = _state()
    try:
        yield
    finally:
        _restore(state)


@contextlib.contextmanager
def baseline(bound: Callable[..., Any] | None = None) -> Iterator[None]:
    """The command's frame: the process state now is what :func:`restore_baseline` puts back
    (and what the block ends with); ``bound(error)`` (a context manager factory that raises
    ``error(seconds)`` when user code runs past the command's bound) bounds :func:`guarded`."""
    state = _state()
    tokens = _BASELINE.set(state), _BOUND.set(bound)
    try:
        yield
    finally:
        _BASELINE.reset(tokens[0])
        _BOUND.reset(tokens[1])
        _restore(state)


def restore_baseline() -> None:
    """Put back the state :func:`baseline` recorded (nothing outside one): before each run."""
    state = _BASELINE.get()
    if state is not None:
        _restore(state)


def location(exc: BaseException) -> str:
    """``file:line`` of the deepest frame of ``exc``'s traceback outside this package (the
    user's code), or ``""``."""
    found = ""
    for frame in traceback.extract_tb(exc.__traceback__):
        path = Path(frame.filename)
        if path.is_absolute() and PACKAGE not in path.resolve().parents and "importlib" not in frame.filename:
            found = f"{frame.filename}:{frame.lineno}"
    return found


def location_of(exc: BaseException) -> str:
    """``file:line`` in the user's code where ``exc`` arose: a syntax error's own file and line
    (its traceback holds only importlib's frames), else :func:`location`."""
    if isinstance(exc, SyntaxError) and exc.filename and exc.lineno:
        return f"{exc.filename}:{exc.lineno}"
    return location(exc)


def _raised(exc: BaseException) -> str:
    if isinstance(exc, SyntaxError):  # its place is the file's line, not a frame (location_of)
        return f"raised {type(exc).__name__}: {exc.msg}"
    if isinstance(exc, HardExit):
        return f"called os._exit({exc.code!r})"
    if isinstance(exc, SystemExit):
        return f"called sys.exit({exc.code!r})"
    if isinstance(exc, MemoryError):
        return f"ran out of memory (MemoryError{': ' + str(exc) if str(exc) else ''})"
    return f"raised {type(exc).__name__}: {str(exc)[:300]}"


@contextlib.contextmanager
def guarded(reference: str, what: str, *, timed: bool = True) -> Iterator[None]:
    """Run user code (``what``: ``"importing path/to/law.py"``, ``"building it on twolink"``):
    its failures are a :class:`ControllerSpecError` naming ``reference``, what it did and
    where (file and line) — except running past the command's bound, a
    :class:`~twolink_pin.errors.ControllerError` as when ``compute`` does (a failed run, exit
    status 1); the process state is put back afterwards (module docstring).

    Ctrl-C and SIGTERM pass through; so do the package's own errors (a gain out of bounds).
    ``timed=False``: not under the command's bound (a law of this package: its build is ours,
    not user code, and ``--timeout`` bounds its runs only)."""
    bound = _BOUND.get() if timed else None
    with process_state():
        try:
            with bound(_TimedOut) if bound is not None else contextlib.nullcontext():
                yield
        except _TimedOut as exc:  # a run stopped by its bound, as in compute: exit 1, not bad input
            where = location(exc.__context__) if exc.__context__ is not None else ""
            raise ControllerError(
                reference,
                float("nan"),
                (
                    f"{what} did not return within {exc.seconds:g} s (no progress; --timeout 0 waits forever)"
                    if exc.stalled
                    else f"{what} did not finish within --timeout {exc.seconds:g} s"
                )
                + (f" (it was at {where})" if where else ""),
            ) from None
        except (KeyboardInterrupt, TwolinkPinError):
            raise
        except BaseException as exc:
            if type(exc).__name__ in ("Terminated", "RunTimeout"):  # a signal, an enclosing bound
                raise
            where = location_of(exc)
            raise ControllerSpecError(
                reference, f"{what} {_raised(exc)}" + (f" at {where}" if where else "")
            ) from exc


__all__ = [
    "HardExit",
    "baseline",
    "exits_contained",
    "guarded",
    "location",
    "location_of",
    "process_state",
    "restore_baseline",
]
