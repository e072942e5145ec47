"""The argument types of ``twolink-pin``: numbers checked against their bounds, gain ranges.

Each raises :class:`argparse.ArgumentTypeError` with the value and what was expected, which
the parser turns into one line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable
from typing import Any

NUMBER = re.compile(r"^-((\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|inf|infinity|nan)$", re.IGNORECASE)
"""A negative number in any float spelling (``-1``, ``-.5``, ``-1e-3``, ``-inf``): a value (which
the option's type then checks), not an option."""
MAX_TEXT = 200
"""Longest option value echoed back in an error message."""


def _shown(text: str) -> str:
    return repr(text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + "…")


def finite(text: str) -> float:
    """A finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {_shown(text)}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {_shown(text)}")
    return value


def bounded(low: float, high: float, *, low_open: bool = False, unit: str = "") -> Callable[[str], float]:
    """A finite number in ``[low, high]`` (``(low, high]`` with ``low_open``)."""

    def parse(text: str) -> float:
        value = finite(text)
        ok = (value > low if low_open else value >= low) and value <= high
        if not ok:
            left = "(" if low_open else "["
            raise argparse.ArgumentTypeError(
                f"expected a number in {left}{low:g}, {high:g}]{' ' + unit if unit else ''}, got {_shown(text)}"
            )
        return value

    return parse


def whole(low: int, high: int) -> Callable[[str], int]:
    """A whole number in ``[low, high]``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {_shown(text)}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(
                f"expected a whole number from {low} to {high}, got {_shown(text)}"
            )
        return value

    return parse


MAX_DURATION = 1e6
"""Largest simulated time accepted on the command line [s] (the step count is bounded too)."""
MAX_OFFSET = 100.0
"""Largest initial offset accepted on the command line [rad]."""
MAX_GAIN = 1e12
"""Largest gain accepted on the command line (any unit)."""


def gain_range(text: str) -> Any:
    """``NAME=LO:HI`` as a :class:`~twolink_pin.studies.sweep.GainRange`, both bounds within
    ±:data:`MAX_GAIN`; ``NAME=WORD`` (a word, no number: a gain of choices such as ``mpc``'s
    ``on_infeasible=fail``) as the text itself, a gain fixed for every run."""
    from twolink_pin.errors import InvalidParameterError
    from twolink_pin.studies.sweep import GainRange

    name, _, value = text.partition("=")
    if (
        name.strip() and value.strip().isidentifier()
    ):  # a word: fixed (the law checks it is one of its choices)
        return text
    try:
        parsed = GainRange.parse(text)
    except InvalidParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    if max(abs(parsed.low), abs(parsed.high)) > MAX_GAIN:
        raise argparse.ArgumentTypeError(f"expected LO and HI within ±{MAX_GAIN:g}, got {_shown(text)}")
    return parsed


def port(text: str) -> int:
    """A TCP port, 0..65535 (0: any free port)."""
    return whole(0, 65535)(text)
