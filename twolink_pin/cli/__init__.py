"""``twolink-pin``: the command-line shell over the library.

=====================  ====================================================================================
``parser.py``          commands and options (``identify_parser.py``: those of ``identify`` and ``excite``;
                       ``optimal_parser.py``: ``optimize`` and ``trajectory --time-optimal``;
                       ``equations_parser.py``: ``equations``; ``sweep_options.py``: ``sweep``'s draws
                       and engine)
``common_options.py``  the options every family shares: the robot, the payload, the trajectory
``arguments.py``       the argument types that check numbers against their bounds
``commands/``          one module per family of commands, each command a thin shell over the library
``output.py``          text or JSON on stdout, the progress display on stderr
``guard.py``           around a command: ``--json`` stdout kept for the JSON, outputs ≠ inputs
``simulate_line.py``   the ``twolink-pin simulate …`` line that reproduces a run, bit for bit (``tune``)
=====================  ====================================================================================

Bad input gives one line on stderr and exit status 2; a failed run (a diverged
simulation, a law that raised, an optimisation that did not converge) exit status 1; Ctrl-C exit status 130, SIGTERM 143. An
unexpected exception (a bug) is one line with exit status 1, or its traceback with
``TWOLINK_PIN_DEBUG=1`` or ``twolink-pin --debug``; ``--debug`` also prints the traceback
of a law that raised.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import warnings
from collections.abc import Sequence
from typing import Any

# Loaded before a command runs, not on its first use (the law baseline's np.random.get_state,
# user_code): a Ctrl-C that lands inside numpy.random's extension-module initialisation is
# reported there as an unraisable error, not raised, and a long run went on. scipy.linalg,
# which pulled it in at start-up, is no longer imported there.
import numpy.random  # noqa: F401

from twolink_pin import interrupts
from twolink_pin.cli import guard
from twolink_pin.cli.parser import build_parser
from twolink_pin.errors import ControllerError, OptimizationError, SimulationDivergedError, TwolinkPinError
from twolink_pin.interrupts import Terminated
from twolink_pin.readiness import ready

_signalled = interrupts.received
"""The signals received while the command ran: whatever exception then reaches :func:`main`
(an import that turned the ``KeyboardInterrupt`` into an ``ImportError``, a library that
caught it), the outcome is the interrupt; long loops check it (:func:`interrupts.check`)."""


def _run(args: argparse.Namespace) -> int:
    """The command under its guards; an exception after a signal is the interrupt, whatever
    it turned into on its way (an ``ImportError`` from an interrupted import)."""
    from functools import partial

    from twolink_pin import user_code
    from twolink_pin.files import outputs_together
    from twolink_pin.simulation.deadline import bounded, per_run_limit, start_backstop

    start_backstop()  # its thread's memory held before any memory check counts what is left

    try:  # --timeout bounds each simulation (a law that never returns), not the whole command,
        # and each import and construction of a law (user_code.guarded); the command's files are
        # written all or none (files.outputs_together: committed before its summary is printed)
        with (
            per_run_limit(getattr(args, "timeout", None)),
            user_code.baseline(partial(bounded, stall=True)),
            user_code.exits_contained(),  # a law's os._exit: an error naming it, and the cleanup
            outputs_together(),
        ):
            with guard.results_only_on_stdout(bool(getattr(args, "json", False))):
                code = int(args.func(args))
    except BaseException:
        if _signalled:
            raise (Terminated if _signalled[-1] == signal.SIGTERM else KeyboardInterrupt)() from None
        raise
    return code  # a command may end on Ctrl-C by design (the live viewer): its status stands


MAX_LINE = 1000
"""Longest error line printed [characters]."""
MAX_PATH_TEXT = 4096
"""Longest path (or other text) accepted on the command line [characters]."""


def _option_names(parser: argparse.ArgumentParser, command: str) -> dict[str, str]:
    """dest → how the user spelled it (``--out``, ``CONTROLLER``) for ``command``'s options."""
    names: dict[str, str] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices[command]._actions:
                names[sub.dest] = (
                    sub.option_strings[0] if sub.option_strings else (sub.metavar or sub.dest).upper()
                )
    return names


def _check_texts(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse, before any work, option values no file or name can have: empty, holding a NUL
    byte, or longer than :data:`MAX_PATH_TEXT` (paths and names reach the OS as they are)."""
    names = _option_names(parser, args.command)
    for dest, value in vars(args).items():
        values = value if isinstance(value, list) else [value]
        for text in values:
            if not isinstance(text, str) or dest in ("command", "argv"):
                continue
            problem = (
                "an empty value"
                if not text
                else "a NUL byte"
                if "\0" in text
                else f"too long ({len(text)} characters)"
                if len(text) > MAX_PATH_TEXT
                else None
            )
            if problem:
                shown = text if len(text) <= 80 else text[:60] + "…"
                parser.error(
                    f"argument {names.get(dest, dest)}: {shown!r} is {problem}; expected a path or name "
                    f"(1 to {MAX_PATH_TEXT} characters, no NUL)"
                )


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``twolink-pin`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    _check_texts(parser, args)
    try:
        guard.check_outputs_are_not_inputs(args, _option_names(parser, args.command))
    except TwolinkPinError as exc:
        parser.error(str(exc))
    ready("parsed")
    args.argv = list(sys.argv[1:] if argv is None else argv)
    previous: dict[int, Any] = {}
    del _signalled[:]
    if threading.current_thread() is threading.main_thread():
        previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, interrupts.on_signal)}
        if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # a background job ignores Ctrl-C
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, interrupts.on_signal)
    unraisable, sys.unraisablehook = sys.unraisablehook, _signal_in_a_finalizer(sys.unraisablehook)
    try:
        ready("running")
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning  # one line each, not Python's file:line and source
            return _run(args)
    except (SimulationDivergedError, ControllerError, OptimizationError) as exc:
        if isinstance(exc, ControllerError) and _debug(args):  # the law's own traceback
            import traceback

            traceback.print_exception(exc.__cause__ or exc, file=sys.stderr)
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
        if _debug(args):
            raise
        _say(
            f"twolink-pin: internal error: {type(exc).__name__}: {str(exc)[:500]} — please report it with the "
            "command line (TWOLINK_PIN_DEBUG=1 shows the traceback)"
        )
        return 1
    finally:
        sys.unraisablehook = unraisable
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _signal_in_a_finalizer(previous: Any) -> Any:
    """``sys.unraisablehook`` while a command runs: an interrupt raised by the signal handler
    inside a finalizer (a ``__del__``, a weakref callback), where Python can only print it as
    "Exception ignored in …" with a traceback, is dropped silently: the signal is recorded in
    :data:`_signalled` and the command's outcome stands. Everything else goes to ``previous``."""

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, (Terminated, KeyboardInterrupt)):
            return
        previous(unraisable)

    return hook


def _debug(args: argparse.Namespace) -> bool:
    """``--debug`` or ``TWOLINK_PIN_DEBUG=1``: tracebacks wanted."""
    import os

    return bool(getattr(args, "debug", False) or os.environ.get("TWOLINK_PIN_DEBUG"))


def _say(line: str) -> None:
    """``line`` on stderr; nothing if stderr is closed (never on stdout instead: with fd 2
    closed at start-up Python sets ``sys.stderr`` to None, and ``print(file=None)`` would
    write to stdout)."""
    if sys.stderr is None:
        return
    if len(line) > MAX_LINE:  # a long path or value echoed in a message: keep its start and end
        line = line[: MAX_LINE - 260] + " … " + line[-250:]
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """A warning raised while a command runs (a task-space law near a singularity, say), as one
    ``twolink-pin: warning: …`` line on stderr."""
    _say(f"twolink-pin: warning: {message}")


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
