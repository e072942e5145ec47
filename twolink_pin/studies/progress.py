"""The progress display of a long batch: what ``simulate_batch(progress=…)`` shows.

``progress`` is a callback ``progress(steps_done, steps_total)``, or:

* ``None`` (the default): a tqdm bar on stderr when stderr is a terminal, which appears
  only once the batch has run :data:`DELAY_S` seconds (a short batch prints nothing;
  a 1000-run batch of 30 s on a busy machine shows its rate and ETA instead of looking hung);
* ``True``: that bar whatever stderr is (a log file, a notebook), from the start;
* ``False``: nothing.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

DELAY_S = 2.0
"""Seconds a batch runs before the default display appears."""

Progress = Callable[[int, int], None] | bool | None
"""What ``simulate_batch`` accepts as ``progress``."""


def stderr_is_terminal() -> bool:
    """Whether ``sys.stderr`` is a terminal: where a progress bar is shown by default (a log
    file, a pipe or a notebook stays clean)."""
    stream = sys.stderr
    try:
        return bool(stream is not None and stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


@contextmanager
def progress_callback(progress: Progress, runs: int) -> Iterator[Callable[[int, int], None] | None]:
    """The engine's ``progress(steps_done, steps_total)`` for ``progress`` (see the module);
    the bar, if any, is closed on leaving."""
    if callable(progress) or progress is False:
        yield progress or None
        return
    stream = sys.stderr
    if progress is None and not stderr_is_terminal():
        yield None
        return
    from tqdm import tqdm

    bar = tqdm(
        total=None,
        unit="step",
        desc=f"{runs} run{'s' if runs != 1 else ''}",
        file=stream,
        dynamic_ncols=True,
        mininterval=0.5,
        delay=DELAY_S if progress is None else 0.0,
    )

    def update(done: int, total: int) -> None:
        if bar.total != total:
            bar.total = total
        bar.update(done - bar.n)

    try:
        yield update
    finally:
        bar.close()
