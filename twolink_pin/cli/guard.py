"""What the CLI puts around a command so that user code cannot take it over.

* ``--timeout`` — :data:`DEFAULT_TIMEOUT`; the bound applies to each simulation
  (:mod:`twolink_pin.simulation.deadline`): a law that never returns stops its run with an
  error naming the law and the bound, and ``compare`` keeps the other laws' results.
* :func:`results_only_on_stdout` — with ``--json``, what the command's code (a law's
  ``print``) writes to ``sys.stdout`` goes to stderr, so stdout holds the JSON alone;
  :func:`twolink_pin.cli.output.emit` writes to the real stdout.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator

from twolink_pin.cli import output

DEFAULT_TIMEOUT = 86_400.0
"""Default ``--timeout`` [s] per simulation: one day, far beyond any run the bounds allow on
one machine (the longest single simulation, 10^7 steps, takes minutes), short of "forever"."""
TUNE_TIMEOUT = 30.0
"""``tune``'s default ``--timeout`` [s]: a run that shows no progress (no block of samples) for
that long is left behind and shown as failed (:class:`~twolink_pin.tuning.latest.LatestWins`),
so that a law that never returns does not hold the page."""


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


__all__ = ["DEFAULT_TIMEOUT", "TUNE_TIMEOUT", "results_only_on_stdout"]


OUTPUT_OPTIONS = ("save", "save_data", "out", "html", "write_urdf", "plot", "latex", "python")
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
