"""The ``twolink-pin`` console script: signal handlers first, the package second.

Importing :mod:`twolink_pin` (Pinocchio, NumPy, SciPy) takes seconds on a busy machine;
an interrupt during that import used to end in a ``KeyboardInterrupt`` traceback. This
module imports nothing heavy: its first statements install the SIGINT and SIGTERM
handlers, and everything after — the package import, argument parsing, the command, the
interpreter's shutdown — runs under them, so Ctrl-C (SIGINT) or ``kill`` (SIGTERM) at any
instant gives one line (``twolink-pin: interrupted`` / ``twolink-pin: terminated``) and exit
status 130 / 143. ``python -m twolink_pin_entry`` runs the same code as the console
script; ``twolink_pin.cli.main`` stays the library-level entry (``python -m
twolink_pin.cli``), which is covered only once the package is imported.

A signal that arrives before the interpreter runs this module's first line (while
Python itself starts) ends the process as the operating system does (exit −2 / −15).
"""

from __future__ import annotations

import os
import signal
import sys

INTERRUPTED, TERMINATED = 130, 143
"""Exit statuses for SIGINT and SIGTERM (128 + the signal number, as shells report)."""


class _Terminated(KeyboardInterrupt):
    """SIGTERM before the CLI has installed its own handler."""


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def _terminate(signum: int, frame: object) -> None:
    raise _Terminated


def _say(line: str) -> None:
    if sys.stderr is None:  # fd 2 closed at start-up: never print on stdout instead
        return
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _ready(stage: str) -> None:
    """As :func:`twolink_pin.readiness.ready`, without importing the package."""
    path = os.environ.get("TWOLINK_PIN_READY_FILE")
    if path:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
            try:
                os.write(fd, f"{stage}\n".encode())
            finally:
                os.close(fd)
        except OSError:
            pass


def _settle(code: int) -> None:
    """From here on a signal ends the process at once with ``code``: the command has
    finished (its output written or not), and a late Ctrl-C during the interpreter's shutdown
    must neither print a traceback nor change the outcome."""

    def done(signum: int, frame: object) -> None:
        with_streams_flushed()
        os._exit(code)

    def with_streams_flushed() -> None:
        for stream in (sys.stdout, sys.stderr):
            try:
                if stream is not None:
                    stream.flush()
            except (OSError, ValueError):
                pass

    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            signal.signal(signum, done)
        except (OSError, ValueError):
            pass


def main() -> int:
    """Run ``twolink-pin`` with the process's arguments; returns the exit status."""
    signal.signal(signal.SIGINT, _interrupt)
    signal.signal(signal.SIGTERM, _terminate)
    try:
        _ready("started")
        from twolink_pin.cli import main as cli_main

        code = cli_main()
    except KeyboardInterrupt as exc:  # during the import or the argument parsing
        code = TERMINATED if _is_term(exc) else INTERRUPTED
        _settle(code)
        _say("twolink-pin: terminated" if code == TERMINATED else "twolink-pin: interrupted")
        return code
    except SystemExit as exc:  # argparse's --help and usage errors
        _settle(exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1)
        raise
    _settle(code)
    return code


def _is_term(exc: BaseException) -> bool:
    return isinstance(exc, _Terminated) or type(exc).__name__ == "Terminated"


if __name__ == "__main__":
    sys.exit(main())
