"""How a control's value moves, and how a number is shown (no widget here).

A key press on a gain's slider must change something a person can see, in one press: the
gains of a control law matter by their ratio (twice the stiffness, half the damping), not
by a fixed amount, so a positive gain steps on a **logarithmic grid** of 20 rounded values a
decade, about 12 % apart (a decade in 20 presses). When the default is a preferred value
(:data:`PREFERRED`: 1, 1.1, 1.2, 1.4, 1.6, 1.8, 2, 2.2, 2.5, 2.8, 3, 3.5, 4, 4.5, 5, 5.5, 6,
7, 8, 9, times a power of ten: 350, 40, 0.025) the grid is those values (7 to 17 % apart);
otherwise it is the default times 10^(k/20), rounded to two significant digits (6 to 20 %
apart: 150 → 170, 190, 210). The default itself is a point of the grid, exact (a default
derived from the robot, ``159.99999999999997``, too), so that a press up and a press down
come back to it and the default's run is reproduced bit for bit. A drag lands on the same
grid.

Other values step linearly (:class:`Rule`): a signed gain by a twentieth of its default's
size, a fraction (0 < f <= 1) by 0.05, a count by 1, and a gain declared a multiple of
another (``gain(..., multiple_of="knot_interval")``: mpc's horizon) by that gain's value —
a whole number of knots.

The page's slider (Mantine's, in Viser's client) moves by ``value ± step`` on an arrow key
and by multiples of ``step`` from its low end on a drag; :func:`snapped` turns what it
sends into a grid value in the direction it moved (a press is one grid step whatever the
slider's step), and :func:`slider_step` / :func:`precision` give the slider the step and
decimals for the next press from where it is.

:func:`shown` writes a number to the digits that matter (``159.99999999999997`` as ``160``):
the page shows it so; the value that runs, its ``--json`` line and its command line keep
every digit.
"""

from __future__ import annotations

import math
from decimal import Decimal
from typing import NamedTuple

PREFERRED = tuple(float(m) for m in "1 1.1 1.2 1.4 1.6 1.8 2 2.2 2.5 2.8 3 3.5 4 4.5 5 5.5 6 7 8 9".split())
"""The log grid's values in one decade (times 10^k): rounded, about 10^(1/20) apart."""
SAME = 1e-9
"""Relative distance under which two values are one grid point (a default derived from the
robot, ``159.99999999999997``, is the grid's 160)."""
FRACTION_STEP = 0.05
"""The step of a fraction (0 < value <= 1)."""
SIGNED_SHARE = 20.0
"""A signed gain steps by its default's size over this (its slider spans ± 4 × the default)."""
TINY, HUGE = 1e-300, 1e300
"""The log grid's ends: a value outside them steps as typed (a gain refuses it anyway)."""
SHOWN_DIGITS = 6
"""Significant digits :func:`shown` keeps of a number whose shortest text is longer."""


class Rule(NamedTuple):
    """How one control's value steps."""

    kind: str
    """``"log"`` (the preferred-number grid), ``"linear"`` (by ``step``) or ``"multiple"``
    (whole multiples of the gain named ``of``, at least one)."""
    anchor: float = 1.0
    """A value that is a point of the log grid (the default)."""
    step: float = 1.0
    """The step of a linear rule."""
    of: str = ""
    """The gain whose value a multiple rule steps by."""


def _decimal(x: float) -> str:
    return f"{Decimal(repr(x)):f}"


def _on_preferred(x: float) -> bool:
    """Whether ``x`` > 0 is (to :data:`SAME`) a preferred value times a power of ten."""
    mantissa = x / 10.0 ** math.floor(math.log10(x))
    return any(abs(mantissa / m - 1) <= SAME for m in (*PREFERRED, 10.0))


def _two_digits(x: float) -> float:
    """``x`` rounded to two significant digits (as its decimal text reads: 170, 0.024)."""
    e = math.floor(math.log10(x)) - 1
    return float(f"{round(x / 10.0**e)}e{e}")


def _grid_near(x: float, anchor: float) -> list[float]:
    """The log grid's points around ``x``: the preferred values (:data:`PREFERRED`) when the
    anchor is one of them, else the anchor times 10^(k/20) rounded to two significant digits
    (a default of 150: 130, 150, 170, 190, …), the anchor itself exact either way (a default
    derived from the robot, 159.99999999999997, in place of the grid's 160)."""
    if not (anchor > 0 and math.isfinite(anchor)):
        anchor = 1.0
    if _on_preferred(anchor):
        decade = math.floor(math.log10(x))
        points = {float(f"{m!r}e{e}") for e in range(decade - 1, decade + 2) for m in PREFERRED}
        points |= {10.0 ** (decade + 2)}
        points = {p for p in points if abs(p / anchor - 1) > SAME}
    else:
        k = round(20 * math.log10(x / anchor))
        points = {_two_digits(anchor * 10.0 ** (j / 20)) for j in range(k - 25, k + 26) if j}
        points = {p for p in points if abs(math.log(p / anchor)) > math.log(10) / 40}
    return sorted({p for p in points if TINY <= p <= HUGE} | {anchor})


def grid_up(x: float, anchor: float = 1.0) -> float:
    """The log grid's next value above ``x`` > 0."""
    return min(p for p in _grid_near(x, anchor) if p > x * (1 + SAME))


def grid_down(x: float, anchor: float = 1.0) -> float:
    """The log grid's next value below ``x`` > 0."""
    return max(p for p in _grid_near(x, anchor) if p < x * (1 - SAME))


def grid_nearest(x: float, anchor: float = 1.0) -> float:
    """The log grid's value nearest ``x`` > 0 (in ratio)."""
    return min(_grid_near(x, anchor), key=lambda p: abs(math.log(p / x)))


def _multiple(x: float, of: float) -> float:
    return max(1, round(x / of)) * of


def snapped(rule: Rule, now: float, sent: float, of: float | None = None) -> float:
    """The value a slider at ``now`` takes when it sends ``sent``: one grid step in the
    direction it moved when ``sent`` is within one step of ``now`` (an arrow key sends
    ``now ± step``, the step being the distance to the next value up), else the grid point
    nearest ``sent`` (a drag), at least one step away; ``sent`` itself when it did not move,
    at 0 (a slider's low end: the law says whether 0 is allowed) or for a value the grid has
    no point for.

    Args:
        of: The value of the gain a multiple rule steps by.
    """
    if sent == now or not math.isfinite(sent):
        return sent
    up = sent > now
    if rule.kind == "multiple" and of is not None and of > 0:
        k = max(1, round(now / of))
        near = _multiple(sent, of)
        return max(near, (k + 1) * of) if up else min(near, max(1, k - 1) * of)
    if rule.kind == "linear" or not TINY <= sent <= HUGE or not (now == 0 or TINY <= now <= HUGE):
        return sent
    if now == 0:  # the log grid has no 0: up from there by the slider's own step
        return grid_nearest(sent, rule.anchor)
    above, below = grid_up(now, rule.anchor), grid_down(now, rule.anchor)
    key = (above - now) * (1 + SAME) + 0.5 * 10.0 ** -precision(rule, now)
    if abs(sent - now) <= key:  # an arrow key (value ± the step up, rounded): one grid step
        return above if up else below
    near = grid_nearest(sent, rule.anchor)  # a drag: the grid point nearest where it ended
    return max(near, above) if up else min(near, below)


def slider_step(rule: Rule, value: float, of: float | None = None) -> float:
    """The slider's step at ``value``: the distance to the next value up (an arrow key
    sends ``value ± step``; :func:`snapped` makes it one grid step either way)."""
    if rule.kind == "multiple" and of is not None and of > 0:
        return of
    if rule.kind == "log" and TINY <= value <= HUGE / 10:
        return grid_up(value, rule.anchor) - value
    return rule.step


def decimals(x: float) -> int:
    """Digits after the point of ``x``'s shortest exact text (``0.025`` → 3, ``350.0`` → 0)."""
    if not math.isfinite(x) or x == 0:
        return 0
    text = _decimal(x)
    return len(text.partition(".")[2].rstrip("0"))


def precision(rule: Rule, value: float, of: float | None = None) -> int:
    """Decimals a slider at ``value`` shows and rounds an arrow key's value to: those of its
    value shown (:func:`shown`, at most 4 significant digits) and of its neighbours on the
    grid (so that a key's ``value ± step`` is not rounded back)."""
    step = slider_step(rule, value, of)
    candidates = [float(f"{value:.4g}"), value + step, max(value - step, 0.0)]
    if rule.kind == "log" and TINY * 10 <= value <= HUGE / 10:
        candidates += [grid_up(value, rule.anchor), grid_down(value, rule.anchor)]
    return min(12, max(decimals(float(f"{x:.4g}")) if x else 0 for x in [*candidates, step]))


def shown(x: float) -> str:
    """``x`` to the digits that matter: its shortest text when that has at most
    :data:`SHOWN_DIGITS` + 1 significant digits (``0.025``, ``1e-300``, ``123.4567``), else
    rounded to :data:`SHOWN_DIGITS` (``159.99999999999997`` → ``160``); ``350``, not ``350.0``."""
    x = float(x)
    text = repr(x)
    mantissa = text.lower().partition("e")[0].replace("-", "").replace(".", "").strip("0")
    if len(mantissa) > SHOWN_DIGITS + 1:
        text = f"{x:.{SHOWN_DIGITS}g}"
    if "e" not in text and text.endswith(".0"):
        text = text[:-2]
    return text


__all__ = [
    "FRACTION_STEP",
    "PREFERRED",
    "SIGNED_SHARE",
    "Rule",
    "decimals",
    "grid_down",
    "grid_nearest",
    "grid_up",
    "precision",
    "shown",
    "slider_step",
    "snapped",
]
