"""The ``twolink-pin`` console script: signal handlers first, the package second.

Importing :mod:`twolink_pin` (Pinocchio, NumPy, SciPy) takes seconds on a busy machine;
an interrupt during that import used to end in a ``KeyboardInterrupt`` traceback (or, inside
NumPy's import, an ``ImportError`` that hides it). This module imports nothing heavy. Its
first statements install SIGINT and SIGTERM handlers that, until the command starts, end
the process at once with one line (``twolink-pin: interrupted`` / ``twolink-pin:
terminated``) and exit status 130 / 143: while the package loads and the arguments are
parsed there is nothing to clean up (no output, no worker). From the command's start
:func:`twolink_pin.cli.main` raises ``KeyboardInterrupt`` where the program is, so that
staging files are removed and workers stopped, and reports the interrupt whatever exception
it turned into. When the command has finished, a late signal cannot change its outcome: the
process runs the exit handlers and ends with the command's status (the interpreter's own
finalisation, during which Python restores the default handlers, is skipped).

``python -m twolink_pin_entry`` runs the same code as the console script;
``twolink_pin.cli.main`` stays the library-level entry (``python -m twolink_pin.cli``, covered
only once the package is imported). A signal that arrives before the interpreter reaches this
module's first line ends the process as the operating system does (exit −2 / −15).
"""

from __future__ import annotations

import os
import signal
import sys

INTERRUPTED, TERMINATED = 130, 143
"""Exit statuses for SIGINT and SIGTERM (128 + the signal number, as shells report)."""


def _flush() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):
            pass


def _say(line: str) -> None:
    if sys.stderr is None:  # fd 2 closed at start-up: never print on stdout instead
        return
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _leave_at_once(signum: int, frame: object) -> None:
    """Before the command starts: nothing to clean up, so say it and go."""
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_IGN)
    _say("twolink-pin: terminated" if signum == signal.SIGTERM else "twolink-pin: interrupted")
    _flush()
    os._exit(TERMINATED if signum == signal.SIGTERM else INTERRUPTED)


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


def _finish(code: int) -> None:
    """End the process with ``code``, the command's outcome: exit handlers run (with a
    signal then ending the process at once with ``code``), streams flushed, and no
    interpreter finalisation left for a signal to land in."""

    def done(signum: int, frame: object) -> None:
        _flush()
        os._exit(code)

    for s in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(s) is not signal.SIG_IGN:
            signal.signal(s, done)
    try:
        import atexit

        atexit._run_exitfuncs()
    finally:
        _flush()
        os._exit(code)


def main() -> int:
    """Run ``twolink-pin`` with the process's arguments. Ends the process (it never returns)."""
    signal.signal(signal.SIGTERM, _leave_at_once)
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # a background job ignores Ctrl-C
        signal.signal(signal.SIGINT, _leave_at_once)
    code = 1
    try:
        _ready("started")
        from twolink_pin.cli import main as cli_main

        code = cli_main()
    except SystemExit as exc:  # argparse's --help and usage errors (already printed)
        if isinstance(exc.code, int) or exc.code is None:
            code = exc.code or 0
        else:
            _say(str(exc.code))
    except KeyboardInterrupt:  # raised by a handler of the command that outlived it
        code = INTERRUPTED
        _say("twolink-pin: interrupted")
    _finish(code)
    return code  # not reached


if __name__ == "__main__":
    sys.exit(main())
