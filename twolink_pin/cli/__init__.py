"""``twolink-pin``: the command-line shell over the library.

==============  ===================================================================
``parser.py``   commands and options
``arguments.py`` the argument types that check numbers against their bounds
``commands.py`` one function per command, each a thin shell over the library
``output.py``   text or JSON on stdout, the progress display on stderr
==============  ===================================================================

Bad input gives one line on stderr and exit status 2; a failed run (a diverged
simulation, a law that raised) exit status 1; Ctrl-C exit status 130, SIGTERM 143. An
unexpected exception (a bug) is one line with exit status 1, or its traceback with
``TWOLINK_PIN_DEBUG=1``.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Sequence

from twolink_pin.cli.parser import build_parser
from twolink_pin.errors import ControllerError, SimulationDivergedError, TwolinkPinError


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is so that every ``with`` block cleans up (staging
    folders removed, worker processes stopped) as for Ctrl-C."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``twolink-pin`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        return int(args.func(args))
    except (SimulationDivergedError, ControllerError) as exc:
        _say(f"twolink-pin: {exc}")
        return 1
    except TwolinkPinError as exc:
        _say(f"twolink-pin: error: {exc}")
        return 2
    except Terminated:
        _say("twolink-pin: terminated")
        return 143
    except KeyboardInterrupt:
        _say("twolink-pin: interrupted")
        return 130
    except BrokenPipeError:  # stdout closed by the reader (e.g. | head): nothing more to say
        _close_stdout()
        return 1
    except OSError as exc:  # stdout unwritable (a full disk or device): say so once, then be quiet
        _close_stdout()
        _say(f"twolink-pin: error: cannot write the output ({exc.strerror or exc})")
        return 1
    except Exception as exc:  # a bug of ours: one line that says so (TWOLINK_PIN_DEBUG=1 for the traceback)
        import os

        if os.environ.get("TWOLINK_PIN_DEBUG"):
            raise
        _say(
            f"twolink-pin: internal error: {type(exc).__name__}: {str(exc)[:500]} — please report it with the "
            "command line (TWOLINK_PIN_DEBUG=1 shows the traceback)"
        )
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _say(line: str) -> None:
    try:
        print(line, file=sys.stderr, flush=True)
    except OSError:
        pass


def _close_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's final flush cannot fail again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        if sys.stdout is not None:
            os.dup2(devnull, sys.stdout.fileno())
            sys.stdout = open(devnull, "w", closefd=False)  # lives until exit
    except (OSError, ValueError):
        pass


__all__ = ["build_parser", "main"]
