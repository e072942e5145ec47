"""A docs page's commands and the output it quotes, compared with what the commands print.

A page quotes what a command printed on the machine it was written on. Another CPU or other
versions of the solvers (a fresh ``pip install`` takes the newest allowed) move the last
printed digit (``mpc``'s RMS error printed 0.03248 on an AMD EPYC where the page says
0.03249): the quoted lines are compared as **text with numbers**, the words exactly, each
number to :data:`RTOL` relative plus half a unit of the last digit the page prints. The
claims the pages make are differences of several per cent (a law 13 % better, a joint
0.162 rad past its range): 0.1 % is far finer than any of them, and wider than the spread
between machines seen (2e-4 relative). Integers printed as integers (a joint's number, a
count of iterations) must be equal.
"""

from __future__ import annotations

import re

BLOCK = re.compile(r"```(\w*)\n(.*?)```", re.S)
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
RTOL = 1e-3
"""Relative tolerance of a quoted number against the printed one (module docstring)."""


def blocks(page: str) -> list[tuple[str, str]]:
    """The page's fenced blocks as ``(language, text)``."""
    return [(m.group(1), m.group(2)) for m in BLOCK.finditer(page)]


def commands(page: str) -> list[tuple[str, list[str]]]:
    """Each ``sh`` block's command with the ``text`` block right after it (the quoted output)."""
    found = blocks(page)
    out = []
    for (kind, text), (next_kind, quoted) in zip(found, [*found[1:], ("", "")], strict=True):
        if kind == "sh":
            assert next_kind == "text", f"no quoted output after {text!r}"
            out.append((text.strip(), quoted.strip("\n").splitlines()))
    return out


def _unit(text: str) -> float:
    """Half a unit of the last digit ``text`` (a number as printed) shows."""
    mantissa, _, exponent = text.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def close(quoted: str, printed: str) -> bool:
    """Whether the printed number agrees with the quoted one (module docstring)."""
    a, b = float(quoted), float(printed)
    if not re.search(r"[.eE]", quoted):  # an integer: a joint's number, a count
        return a == b
    return abs(a - b) <= RTOL * max(abs(a), abs(b)) + _unit(quoted)


def _pattern(line: str) -> tuple[re.Pattern[str], list[str]]:
    texts = NUMBER.split(line)
    numbers = NUMBER.findall(line)
    body = "".join(
        re.escape(t) + (f"({NUMBER.pattern})" if i < len(numbers) else "") for i, t in enumerate(texts)
    )
    return re.compile(body), numbers


def quoted_in(line: str, printed: list[str], whole: bool = True) -> bool:
    """Whether ``line`` (quoted by the page) is one of the ``printed`` lines (``whole``) or in
    one of them, its words exactly and its numbers within the tolerance (module docstring)."""
    pattern, numbers = _pattern(line)
    for candidate in printed:
        found = pattern.fullmatch(candidate) if whole else pattern.search(candidate)
        if found is not None and all(close(q, p) for q, p in zip(numbers, found.groups(), strict=True)):
            return True
    return False
