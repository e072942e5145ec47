"""The server's end of what the page's script sends of a number box's typed text
(:mod:`.typed_js`): each box that takes numbers is registered here by its label with what to
do with a text typed into it (its ``take``); :class:`Channel` reads the script's messages
and calls it once per typed value, in order.

:func:`read_number` reads a typed number as the gain boxes read theirs
(:func:`~twolink_pin.tuning.knobs.parse_typed`: exponent notation as typed) and checks it
against the box's range, naming what is expected: ``duration [s] = '-3' is invalid: expected
a number from 0.001 to 60``."""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Callable
from typing import Any

from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.knobs import parse_typed

Take = Callable[[int, str], None]
"""What a box does with a text typed into it: ``(index of the input in its row, text)``."""
PAGES = 256
"""Pages (tabs, reloads) whose last message number is remembered."""


def read_number(
    label: str,
    text: str,
    low: float | None = None,
    high: float | None = None,
    whole: bool = False,
    above_low: bool = False,
) -> float:
    """The number typed as ``text`` into the box ``label``, within ``[low, high]``.

    Args:
        whole: Only a whole number is taken (a count).
        above_low: ``low`` itself is refused (a value that must be > low).

    Raises:
        InvalidParameterError: text that is no number, or a number out of range, naming the
            box, the text and what is expected.
    """
    x = float(parse_typed(label, text, None))
    sign = ">" if above_low else ">="
    if low is not None and high is not None and not above_low:
        expected = f"a {'whole ' if whole else ''}number from {low:g} to {high:g}"
    else:
        parts = ([f"{sign} {low:g}"] if low is not None else []) + (
            [f"<= {high:g}"] if high is not None else []
        )
        expected = f"a {'whole ' if whole else ''}number {' and '.join(parts)}".rstrip()
    too_low = low is not None and (x <= low if above_low else x < low)
    if too_low or (high is not None and x > high) or (whole and x != math.floor(x)):
        raise InvalidParameterError(label, text, expected)
    return x


class Channel:
    """The boxes that take typed numbers, and the hidden box their texts arrive in."""

    def __init__(self) -> None:
        self._takes: dict[str, Take] = {}
        self._seen: dict[str, int] = {}
        self._lock = threading.Lock()

    def register(self, label: str, take: Take) -> None:
        """Send what is typed into the box labelled ``label`` to ``take``."""
        self._takes[label] = take

    def labels(self) -> tuple[str, ...]:
        """The labels of the registered boxes."""
        return tuple(self._takes)

    def received(self, message: str) -> int:
        """Take the items of one message of the script that were not taken yet (a message
        repeats the last few); returns how many were new. A message that is not the
        script's (no JSON, other keys) is ignored."""
        try:
            data = json.loads(message)
            page, items = str(data["page"]), list(data["items"])
        except (ValueError, KeyError, TypeError):
            return 0
        new: list[tuple[str, int, str]] = []
        with self._lock:  # held while the boxes take them: in the order typed
            last = self._seen.get(page, 0)
            for item in items:
                try:
                    n, label, index, text = int(item[0]), str(item[1]), int(item[2]), str(item[3])
                except (ValueError, TypeError, IndexError):
                    continue
                if n > last:
                    last = n
                    new.append((label, index, text))
            self._seen.pop(page, None)
            self._seen[page] = last
            while len(self._seen) > PAGES:
                self._seen.pop(next(iter(self._seen)))
            for label, index, text in new:
                take = self._takes.get(label)
                if take is not None:
                    take(index, text)
        return len(new)

    def attach(self, handle: Any) -> None:
        """Read the hidden text box ``handle`` (its updates from a page)."""

        def on_update(event: Any) -> None:
            if event.client is not None:
                self.received(str(handle.value))

        handle.on_update(on_update)


__all__ = ["PAGES", "Channel", "Take", "read_number"]
