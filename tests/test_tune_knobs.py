"""The tuner's controls without a page: a full matrix gain comes back from its controls with
its off-diagonal terms (and runs as ``simulate`` runs it), a typed value reads as typed
(exponent notation included) or is refused with the text typed, and what a box shows reads
back to the same numbers."""

from __future__ import annotations

import numpy as np
import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.knobs import format_typed, gains_from, knobs_of, matrices_of, parse_typed

FULL = [[150.0, 20.0, 0.0], [20.0, 150.0, 0.0], [0.0, 0.0, 80.0]]


def _osc() -> type:
    from twolink_pin.controllers import CONTROLLERS

    return CONTROLLERS["osc"].Gains


def test_a_full_matrix_gain_round_trips_through_its_controls() -> None:
    """Diagonal sliders + the kept matrix give back the 9 numbers row by row; moving a
    diagonal slider changes that entry only; the scale multiplies every entry."""
    gains = {"kp": FULL, "kd": (20 * np.eye(3)).tolist()}
    knobs = knobs_of(_osc(), gains)
    matrices = matrices_of(_osc(), gains)
    out = gains_from(knobs, {}, matrices)
    np.testing.assert_array_equal(np.reshape(out["kp"], (3, 3)), FULL)
    assert out["kd"] == (20.0, 20.0, 20.0)  # a diagonal stays k numbers (the command line's short form)
    moved = gains_from(knobs, {1: 170.0, 3: 2.0}, matrices)
    expected = 2.0 * np.array(FULL)
    expected[1, 1] = 2.0 * 170.0
    np.testing.assert_array_equal(np.reshape(moved["kp"], (3, 3)), expected)


def test_the_matrix_the_controls_give_runs_as_the_law_reads_it() -> None:
    """The 9 numbers the controls give, read by the law's own gain parser, are the matrix
    (a second reader: the one ``simulate --gain`` uses)."""
    from twolink_pin.model import load_robot
    from twolink_pin.run_spec import make_scenario

    gains = {"kp": FULL, "kd": (20 * np.eye(3)).tolist()}
    values = gains_from(knobs_of(_osc(), gains), {}, matrices_of(_osc(), gains))
    law = make_scenario("osc", load_robot("panda"), gains=values).controller
    np.testing.assert_array_equal(np.reshape(law.gains.kp, (3, 3)), FULL)


@pytest.mark.parametrize(
    ("text", "count", "matrix", "expected"),
    [
        ("1e308", None, False, 1e308),
        ("1e-300", None, False, 1e-300),
        ("-2.5E3", None, False, -2500.0),
        ("120", 2, False, [120.0, 120.0]),
        ("350, 300", 2, False, [350.0, 300.0]),
        ("[350 300]", 2, False, [350.0, 300.0]),
        ("150, 20, 0; 20, 150, 0; 0, 0, 80", 3, True, FULL),
    ],
)
def test_a_typed_value_reads_as_typed(text: str, count: int | None, matrix: bool, expected: object) -> None:
    np.testing.assert_array_equal(parse_typed("kp", text, count, matrix), expected)


@pytest.mark.parametrize(
    ("text", "count", "matrix", "why"),
    [
        ("NaN", None, False, "'NaN' is not a finite float"),
        ("1e999", None, False, "'1e999' is not a finite float"),
        ("abc", 2, False, "'abc' is not a number"),
        ("", None, False, "expected one number"),
        ("1, 2, 3", 2, False, "expected 1 or 2 numbers, got 3"),
        ("1, 2, 3, 4", 3, True, "expected 1, 3 or 9 numbers"),
    ],
)
def test_a_typed_value_that_is_no_gain_is_refused_naming_the_text(
    text: str, count: int | None, matrix: bool, why: str
) -> None:
    with pytest.raises(InvalidParameterError) as raised:
        parse_typed("kp", text, count, matrix)
    assert f"kp = {text!r} is invalid" in str(raised.value) and why in str(raised.value)


def test_what_a_box_shows_is_the_value_to_six_digits_and_short_values_exactly() -> None:
    """A box shows each number to at most 7 significant digits: what it shows reads back to
    the value within 5e-6 relative (6 digits rounded: half a unit of the 6th digit of a mantissa ≥ 1), and exactly when the value's shortest
    text is that short (a typed value, a grid value, the course's gains)."""
    rng = np.random.default_rng(0)
    for value in (rng.normal(size=()) * 1e3, rng.normal(size=7) * 1e-5, rng.normal(size=(3, 3)), 1e308):
        text = format_typed(value)
        shape = np.shape(value)
        count = None if not shape else shape[0]
        back = parse_typed("g", text, count, matrix=len(shape) == 2)
        np.testing.assert_allclose(back, value, rtol=5e-6, atol=0)
        for token in text.replace(";", ",").split(","):
            digits = token.strip().lower().partition("e")[0].replace("-", "").replace(".", "").strip("0")
            assert len(digits) <= 7, text
    for exact in (350.0, 0.025, 1e-300, 1e308, 123.4567, -2500.0):
        assert parse_typed("g", format_typed(exact), None) == exact
    assert format_typed(FULL) == "150, 20, 0; 20, 150, 0; 0, 0, 80"
    assert format_typed([1600.0, 159.99999999999997]) == "1600, 160"  # mpc's derived weight_q
