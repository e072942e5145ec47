"""What the CLI puts around a command so that user code cannot take it over.

* :func:`wall_clock_bound` — ``--timeout``: a law that never returns (sleeps, spins, waits
  on a lock) is stopped after the bound; the command ends with exit 1 naming the bound. A
  watchdog thread sends SIGUSR1 to the main thread, whose handler raises
  :class:`RunTimeout` where the program is (so ``with`` blocks clean up as for Ctrl-C; a
  blocking ``time.sleep`` is interrupted too). Code that blocks signals or loops inside C
  without returning to Python cannot be stopped this way.
* :func:`results_only_on_stdout` — with ``--json``, what the command's code (a law's
  ``print``) writes to ``sys.stdout`` goes to stderr, so stdout holds the JSON alone;
  :func:`twolink_pin.cli.output.emit` writes to the real stdout.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator

from twolink_pin.cli import output

DEFAULT_TIMEOUT = 86_400.0
"""Default ``--timeout`` [s]: one day, far beyond any run the bounds allow on one machine
(the longest single simulation, 10^7 steps, takes minutes), short of "forever"."""


class RunTimeout(BaseException):
    """The command ran past ``--timeout`` (a ``BaseException``, like ``KeyboardInterrupt``,
    so that a law's ``except Exception`` cannot swallow it)."""

    def __init__(self, seconds: float) -> None:
        super().__init__(seconds)
        self.seconds = seconds


@contextlib.contextmanager
def wall_clock_bound(seconds: float | None) -> Iterator[None]:
    """Raise :class:`RunTimeout` in the main thread once the block has run ``seconds`` of
    wall-clock time (None or 0: no bound; outside the main thread: no bound)."""
    if not seconds or threading.current_thread() is not threading.main_thread():
        yield
        return

    def expire(signum: int, frame: object) -> None:
        raise RunTimeout(seconds)

    previous = signal.signal(signal.SIGUSR1, expire)
    done = threading.Event()
    main_id = threading.main_thread().ident
    assert main_id is not None

    def watch() -> None:
        if not done.wait(seconds):
            with contextlib.suppress(OSError, ValueError):
                signal.pthread_kill(main_id, signal.SIGUSR1)

    watchdog = threading.Thread(target=watch, name="twolink-pin-timeout", daemon=True)
    watchdog.start()
    try:
        yield
    finally:
        done.set()
        watchdog.join()
        signal.signal(signal.SIGUSR1, previous)


@contextlib.contextmanager
def results_only_on_stdout(active: bool) -> Iterator[None]:
    """With ``active`` (``--json``), ``sys.stdout`` is stderr inside the block while
    :func:`~twolink_pin.cli.output.emit` writes the result to the real stdout."""
    if not active or sys.stderr is None or sys.stdout is None:
        yield
        return
    real = sys.stdout
    output.RESULT_STREAM = real
    sys.stdout = sys.stderr
    try:
        yield
    finally:
        if sys.stdout is sys.stderr:
            sys.stdout = real
        output.RESULT_STREAM = None


__all__ = ["DEFAULT_TIMEOUT", "RunTimeout", "results_only_on_stdout", "wall_clock_bound"]


OUTPUT_OPTIONS = ("save", "save_data", "out", "html", "write_urdf", "plot")
"""Destinations of the options that name something the command writes."""


def _named_paths(value: object) -> list[str]:
    values = value if isinstance(value, list) else [value]
    paths = []
    for text in values:
        if isinstance(text, str) and text:
            paths.append(text)
            location, sep, _ = text.rpartition(":")  # a law given as path/to/file.py:Class
            if sep and location.endswith(".py"):
                paths.append(location)
    return paths


def check_outputs_are_not_inputs(args: object, names: dict[str, str]) -> None:
    """Refuse, before any work, an output option naming a file the same command reads
    (``--save F`` where F is the log or the trajectory): the output would replace the input.
    Every other text argument that names an existing file counts as read.

    Raises:
        InvalidParameterError: an output and an input are the same file (links followed).
    """
    import os

    from twolink_pin.errors import InvalidParameterError

    given = vars(args)
    inputs = [
        (dest, path)
        for dest, value in given.items()
        if dest not in OUTPUT_OPTIONS and dest not in ("command", "argv", "func")
        for path in _named_paths(value)
    ]
    for dest in OUTPUT_OPTIONS:
        for out in _named_paths(given.get(dest)):
            if not os.path.exists(out):
                continue
            for source, path in inputs:
                try:
                    same = os.path.exists(path) and os.path.samefile(out, path)
                except OSError:
                    same = False
                if same:
                    raise InvalidParameterError(
                        names.get(dest, dest),
                        out,
                        f"a path other than the {names.get(source, source)} {path!r} it would replace "
                        "(the command reads that file)",
                    )
