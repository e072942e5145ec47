"""JSON and TOML input documents parsed with bounds: nesting depth and repeated keys.

Python's parsers recurse once per nesting level: a file of ten thousand ``[`` ends in a
``RecursionError`` (a traceback) rather than a refusal. :func:`load_json` and
:func:`load_toml` count the nesting first (outside strings and comments) and refuse a
document deeper than :data:`MAX_NESTING`; JSON objects that repeat a key are refused too
(the last one would silently win; TOML refuses them itself). Every refusal is an
:class:`~twolink_pin.errors.InputFileError` naming the file, the line and the bound.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from twolink_pin.errors import InputFileError

MAX_NESTING = 32
"""Deepest nesting of arrays and objects/tables accepted in an input document (every file
twolink-pin reads needs at most 4)."""


def nesting(text: str, toml: bool = False) -> tuple[int, int]:
    """(Deepest nesting of ``[``/``{`` outside strings and comments, the line where it is
    first reached). Stops counting once past :data:`MAX_NESTING`."""
    depth = deepest = 0
    line = at = 1
    quote = ""
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
        if quote:
            if c == "\\" and quote in ('"', '"""'):
                i += 2
                continue
            if text.startswith(quote, i):
                i += len(quote)
                quote = ""
                continue
        elif c in "\"'" and (toml or c == '"'):
            triple = c * 3
            quote = triple if toml and text.startswith(triple, i) else c
            i += len(quote)
            continue
        elif c == "#" and toml:
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        elif c in "[{":
            depth += 1
            if depth > deepest:
                deepest, at = depth, line
                if deepest > MAX_NESTING:
                    break
        elif c in "]}":
            depth -= 1
        i += 1
    return deepest, at


def _check_depth(text: str, where: str, toml: bool) -> None:
    deepest, line = nesting(text, toml)
    if deepest > MAX_NESTING:
        raise InputFileError(
            where,
            f"nests arrays or tables more than {MAX_NESTING} deep (line {line}); expected a flat document "
            f"(at most {MAX_NESTING} levels)",
        )


def _unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    seen: dict[str, Any] = {}
    for key, value in pairs:
        if key in seen:
            raise ValueError(f"the key {key!r} appears twice in one object")
        seen[key] = value
    return seen


def load_json(text: str, where: str) -> Any:
    """``text`` parsed as JSON, nesting bounded and repeated keys refused.

    Raises:
        InputFileError: deeper than :data:`MAX_NESTING`, a key repeated in an object, or not JSON.
    """
    _check_depth(text, where, toml=False)
    try:
        return json.loads(text, object_pairs_hook=_unique)
    except json.JSONDecodeError as err:
        raise InputFileError(where, f"is not valid JSON: {err}") from None
    except ValueError as err:  # a repeated key
        raise InputFileError(where, f"is ambiguous: {err}; expected each key once") from None
    except RecursionError:  # pragma: no cover  # the depth check comes first
        raise InputFileError(where, f"nests more than Python can parse (bound {MAX_NESTING})") from None


def load_toml(text: str, where: str) -> Any:
    """``text`` parsed as TOML, nesting bounded.

    Raises:
        InputFileError: deeper than :data:`MAX_NESTING`, or not TOML.
    """
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib

    _check_depth(text, where, toml=True)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputFileError(where, f"is not valid TOML: {err}") from None
    except RecursionError:  # pragma: no cover  # the depth check comes first
        raise InputFileError(where, f"nests more than Python can parse (bound {MAX_NESTING})") from None


__all__ = ["MAX_NESTING", "load_json", "load_toml", "nesting"]
