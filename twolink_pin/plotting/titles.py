"""A figure's title as plain text: what the figure says it shows, carried in its file.

:func:`~twolink_pin.plotting._save.save_figure` writes :func:`shown_title` into each figure file
(a PNG's ``Title`` text chunk, a PDF's or SVG's ``Title``): the report captions its figures
with it, where they were bare file names. Mathtext (``$\\dot\\theta_{1}$``), which only
matplotlib draws, becomes plain Unicode (``θ̇₁``).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from matplotlib.figure import Figure


def shown_title(fig: Figure) -> str:
    """What ``fig`` says it shows: its suptitle, else its first panel's title, on one line
    (written into the file as its ``Title``: the report's captions read it back)."""
    suptitle = fig._suptitle  # type: ignore[attr-defined]  # the Text of fig.suptitle, or None
    texts = [suptitle.get_text()] if suptitle is not None else []
    texts += [ax.get_title() for ax in fig.axes]
    return " ".join(_plain_math(next((t for t in texts if t and t.strip()), "")).split())


_GREEK = {
    name: chr(code)
    for name, code in (
        ("alpha", 0x3B1), ("beta", 0x3B2), ("gamma", 0x3B3), ("delta", 0x3B4), ("epsilon", 0x3B5),
        ("theta", 0x3B8), ("lambda", 0x3BB), ("mu", 0x3BC), ("pi", 0x3C0), ("sigma", 0x3C3),
        ("tau", 0x3C4), ("phi", 0x3C6), ("omega", 0x3C9), ("Delta", 0x394), ("Lambda", 0x39B),
    )
}  # fmt: skip
_ACCENTS = {"dddot": "\u20db", "ddot": "\u0308", "dot": "\u0307", "hat": "\u0302", "tilde": "\u0303"}
_SUBSCRIPTS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def _plain_math(text: str) -> str:
    """``text`` with its mathtext (``$\\dot\\theta_{1}$``) as plain Unicode (``θ̇₁``), for a
    caption that is not drawn by matplotlib."""

    def accented(mark: str) -> Callable[[re.Match[str]], str]:
        return lambda m: m.group(1).strip("{}") + mark

    def plain(math: str) -> str:
        for name, mark in _ACCENTS.items():  # \dot\theta, \hat{p}: the letter, then its mark
            math = re.sub(rf"\\{name}\s*(\\[A-Za-z]+|\{{[^{{}}]*\}}|\w)", accented(mark), math)
        math = re.sub(r"\\([A-Za-z]+)", lambda m: _GREEK.get(m.group(1), m.group(1)), math)
        math = re.sub(
            r"_\{([^{}]*)\}|_(\w)", lambda m: (m.group(1) or m.group(2)).translate(_SUBSCRIPTS), math
        )
        return math.replace("{", "").replace("}", "")

    return re.sub(r"\$([^$]*)\$", lambda m: plain(m.group(1)), text)


__all__ = ["shown_title"]
