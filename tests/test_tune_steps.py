"""How a tuner control's value steps (``twolink_pin.tuning.steps``): a key press on a gain
changes it by a ratio a person sees in the metrics (6–20 %, never the old 1 %), comes back to
the default exactly, lands where the page's slider sends it (Mantine's ``value ± step``
rounded to the slider's decimals), and a horizon moves by whole knots; a number is shown to
the digits that matter."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.tuning.steps import (
    PREFERRED,
    Rule,
    grid_down,
    grid_up,
    precision,
    shown,
    slider_step,
    snapped,
)

POSITIVE = st.floats(min_value=1e-9, max_value=1e9, allow_nan=False, allow_infinity=False)


def press(rule: Rule, value: float, up: bool, of: float | None = None) -> float:
    """One arrow key on the page's slider at ``value``, as Mantine's slider computes it
    (``value ± step`` rounded to the slider's decimals), then as the tuner takes it."""
    step, decimals = slider_step(rule, value, of), precision(rule, value, of)
    sent = round(value + step if up else max(value - step, 0.0), decimals)
    return snapped(rule, value, sent, of)


def test_the_grid_is_twenty_rounded_values_a_decade_about_twelve_percent_apart() -> None:
    ratios = [b / a for a, b in zip(PREFERRED, (*PREFERRED[1:], 10.0), strict=True)]
    assert len(PREFERRED) == 20
    assert min(ratios) > 1.07 - 1e-12 and max(ratios) < 1.17 + 1e-12
    assert math.prod(ratios) == pytest.approx(10.0, rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(POSITIVE)
def test_a_key_press_without_an_anchor_changes_a_gain_by_seven_to_seventeen_percent(x: float) -> None:
    rule = Rule("log", anchor=1.0)
    up, down = grid_up(x), grid_down(x)
    assert up > x > down
    one = press(rule, grid_up(x), True)  # from a grid point: one grid step
    assert 1.07 - 1e-9 <= one / grid_up(x) <= 1.17 + 1e-9


@settings(max_examples=200, deadline=None)
@given(POSITIVE)
def test_up_then_down_comes_back_to_the_default_exactly(default: float) -> None:
    """The default is a point of the grid (159.99999999999997 too: mpc's derived weight), so
    the defaults' run can be had again from the keyboard, bit for bit."""
    rule = Rule("log", anchor=default)
    up = press(rule, default, True)
    assert up > default and press(rule, up, False) == default
    down = press(rule, default, False)
    assert down < default and press(rule, down, True) == default
    assert 1.06 - 1e-9 <= up / default <= 1.2 + 1e-9 and 1.06 - 1e-9 <= default / down <= 1.2 + 1e-9


def test_the_old_one_percent_step_is_gone_kp_350_goes_to_400() -> None:
    rule = Rule("log", anchor=350.0)  # a preferred value: the preferred grid
    assert _walk(rule, 350.0, 5) == [400.0, 450.0, 500.0, 550.0, 600.0]
    assert _walk(Rule("log", anchor=150.0), 150.0, 4) == [
        170.0,
        190.0,
        210.0,
        240.0,
    ]  # 150 · 10^(k/20), two digits
    derived = Rule("log", anchor=159.99999999999997)
    assert press(derived, 159.99999999999997, True) == 180.0
    assert press(derived, 180.0, False) == 159.99999999999997


def _walk(rule: Rule, value: float, presses: int) -> list[float]:
    out = []
    for _ in range(presses):
        value = press(rule, value, True)
        out.append(value)
    return out


@settings(max_examples=100, deadline=None)
@given(POSITIVE, st.floats(min_value=0.0, max_value=4.0))
def test_a_drag_lands_on_the_grid_point_nearest_where_it_was_let_go(x: float, share: float) -> None:
    rule = Rule("log", anchor=x)
    sent = share * 4 * x
    got = snapped(rule, x, sent)
    if sent == x or sent <= 0:
        assert got == sent
        return
    nearest = abs(math.log(got / sent)) <= math.log(1.2) / 2 + 1e-9  # half the widest gap
    if sent > x:
        assert got == grid_up(x, x) or (got > x and nearest)
    else:
        assert got == grid_down(x, x) or (got < x and nearest)


def test_a_horizon_steps_by_whole_knots_and_never_below_one() -> None:
    rule = Rule("multiple", anchor=0.2, of="knot_interval")
    h = 0.025
    values = [0.2]
    for _ in range(3):
        values.append(press(rule, values[-1], True, h))
    assert values == [0.2, 9 * h, 10 * h, 11 * h]
    assert all(v / h == round(v / h) for v in values)
    low = 0.2
    for _ in range(12):
        low = press(rule, low, False, h)
    assert low == h  # one knot: a horizon is never shorter
    assert snapped(rule, 0.2, 0.0, h) == h  # the slider's low end (Home): one knot


def test_a_fraction_and_a_signed_gain_step_linearly() -> None:
    fraction = Rule("linear", step=0.05)
    assert press(fraction, 0.95, True) == 1.0 and press(fraction, 0.95, False) == 0.9
    signed = Rule("linear", step=0.1)
    assert press(signed, -2.0, True) == -1.9


@pytest.mark.parametrize(
    ("x", "text"),
    [
        (159.99999999999997, "160"),
        (15.999999999999996, "16"),
        (0.1 + 0.2, "0.3"),
        (350.0, "350"),
        (0.025, "0.025"),
        (1e-300, "1e-300"),
        (123.4567, "123.4567"),
        (1 / 3, "0.333333"),
        (-2500.0, "-2500"),
    ],
)
def test_a_number_is_shown_to_the_digits_that_matter(x: float, text: str) -> None:
    assert shown(x) == text
    assert float(shown(x)) == pytest.approx(x, rel=5e-6)


def test_a_gain_declared_a_multiple_of_another_steps_by_that_gains_value() -> None:
    """mpc declares its horizon a multiple of its knot interval: the horizon's control steps
    by 0.025 s; a per-joint gain cannot be declared so (one value steps by one value)."""
    from twolink_pin.controllers.gains import gain, spec_of
    from twolink_pin.controllers.mpc import MPCGains
    from twolink_pin.tuning.knobs import knobs_of

    assert spec_of(MPCGains, "horizon").multiple_of == "knot_interval"
    knobs = {k.gain: k for k in knobs_of(MPCGains, {"horizon": 0.2, "knot_interval": 0.025})}
    assert knobs["horizon"].rule == Rule("multiple", anchor=0.2, of="knot_interval")
    assert knobs["horizon"].step == 0.025 and knobs["knot_interval"].rule.kind == "log"
    with pytest.raises(ValueError, match="a gain that is a multiple of another is a scalar gain"):
        gain(1.0, per="joint", multiple_of="knot_interval")
