"""What the tuner does with a number typed into one of its boxes, without a browser: the
script's messages are taken once each and in order (a repeated message, a second tab, text
that is not the script's), a typed number is read as the gain boxes read theirs and refused
out of range naming what is expected; and the gain controls on a real Viser server (no
page): a slider's move lands on its grid, a typed value runs as typed, text that reads as
what a box shows changes nothing, and a horizon follows its knot interval in whole knots."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any, NamedTuple

import numpy as np
import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.typed import Channel, read_number


def message(page: str, *items: tuple[int, str, int, str]) -> str:
    return json.dumps({"page": page, "items": [list(item) for item in items]})


def test_each_typed_value_is_taken_once_in_order_whatever_the_messages_repeat() -> None:
    """The script sends its last few items each time (two may be sent within Viser's 50-ms
    throttle, only the last arriving): every item is taken once, in order, per page."""
    channel, taken = Channel(), []
    channel.register("kd joint 1 [N·m·s/rad]", lambda i, text: taken.append(("kd", i, text)))
    channel.register("push force [N]", lambda i, text: taken.append(("push", i, text)))
    assert channel.received(message("a", (1, "kd joint 1 [N·m·s/rad]", 0, "1e2"))) == 1
    both = message("a", (1, "kd joint 1 [N·m·s/rad]", 0, "1e2"), (2, "push force [N]", 2, "-5"))
    assert channel.received(both) == 1  # item 1 again: not taken twice
    assert channel.received(both) == 0
    assert channel.received(message("b", (1, "push force [N]", 0, "3"))) == 1  # another tab counts alone
    assert taken == [("kd", 0, "1e2"), ("push", 2, "-5"), ("push", 0, "3")]


@pytest.mark.parametrize(
    "text", ["", "not json", '{"page": "a"}', '{"page": "a", "items": [["x"]]}', "[1, 2]"]
)
def test_a_message_that_is_not_the_scripts_is_ignored(text: str) -> None:
    channel, taken = Channel(), []
    channel.register("x", lambda i, t: taken.append(t))
    assert channel.received(text) == 0 and taken == []


def test_a_typed_number_reads_exponent_notation_as_typed() -> None:
    assert read_number("payload [kg]", "1e3") == 1000.0
    assert read_number("payload [kg]", " 2.5E-1 ") == 0.25
    assert read_number("delay [steps]", "3", 0, 100_000, whole=True) == 3.0


@pytest.mark.parametrize(
    ("text", "low", "high", "whole", "above", "expected"),
    [
        ("-3", 0.001, 60.0, False, False, "expected a number from 0.001 to 60"),
        ("61", 0.001, 60.0, False, False, "expected a number from 0.001 to 60"),
        ("2.5", 0, 100_000, True, False, "expected a whole number from 0 to 100000"),
        ("0", 0.0, None, False, True, "expected a number > 0"),
        ("abc", 0.0, 1.0, False, False, "'abc' is not a number"),
        ("nan", None, None, False, False, "'nan' is not a finite float"),
    ],
)
def test_a_typed_number_out_of_range_is_refused_naming_the_box_and_what_is_expected(
    text: str, low: float | None, high: float | None, whole: bool, above: bool, expected: str
) -> None:
    with pytest.raises(InvalidParameterError) as raised:
        read_number("duration [s]", text, low, high, whole=whole, above_low=above)
    assert str(raised.value).startswith(f"duration [s] = {text!r} is invalid") and expected in str(
        raised.value
    )


# --- the gain controls on a real Viser server -------------------------------------------


class Event(NamedTuple):
    """A GUI event as a page's move delivers it (a client: not set by the server)."""

    client: Any
    target: Any


@pytest.fixture(scope="module")
def server() -> Iterator[Any]:
    import contextlib
    import io

    import viser

    with contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        yield server
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()


def controls(server: Any, gains_type: Any, values: dict[str, Any]) -> tuple[Any, list[int]]:
    """The gain controls of ``values`` and a list counting the runs they asked for."""
    from twolink_pin.tuning.gain_controls import GainControls
    from twolink_pin.tuning.knobs import knobs_of, matrices_of

    runs: list[int] = []
    made = GainControls(
        server.gui,
        knobs_of(gains_type, values),
        lambda: runs.append(1),
        matrices_of(gains_type, values),
        Channel(),
    )
    return made, runs


def move(made: Any, label: str, sent: float) -> None:
    """The page's slider ``label`` sends ``sent``."""
    slider = next(s for s in made.sliders if s.label == label)
    slider.value = sent
    made._moved(Event(client=object(), target=slider))


def test_a_key_press_on_a_derived_gain_runs_the_next_grid_value_and_back_the_exact_default(
    server: Any,
) -> None:
    """mpc's weight_q of joint 2 is 159.99999999999997 (derived from the robot): its box
    shows 160; → runs 180, ← runs the default again to the last bit."""
    from twolink_pin.controllers.mpc import MPCGains

    made, runs = controls(server, MPCGains, {"weight_q": [1600.0, 159.99999999999997]})
    label = "weight_q joint 2 [N·m/rad]"
    slider = next(s for s in made.sliders if s.label == label)
    assert made.typed["weight_q"].value == "1600, 160"
    move(made, label, round(159.99999999999997 + float(slider.step), int(slider.precision)))
    assert made.gains()["weight_q"] == (1600.0, 180.0) and len(runs) == 1
    move(made, label, round(180.0 - float(slider.step), int(slider.precision)))
    assert made.gains()["weight_q"] == (1600.0, 159.99999999999997) and len(runs) == 2


def test_text_that_reads_as_the_box_shows_changes_nothing_and_typed_values_run_as_typed(server: Any) -> None:
    from twolink_pin.controllers.mpc import MPCGains

    made, runs = controls(server, MPCGains, {"weight_q": [1600.0, 159.99999999999997]})
    box = made.typed["weight_q"]
    box.value = "1600, 160"  # Enter on the box as shown: the exact value keeps running
    made._typed(Event(client=object(), target=box), "weight_q")
    assert runs == [] and made.gains()["weight_q"] == (1600.0, 159.99999999999997)
    made._typed_into_slider(1, 0, "1.6e2")  # the slider's own box: typed 160 runs 160
    assert made.gains()["weight_q"] == (1600.0, 160.0) and len(runs) == 1
    made._typed_into_slider(1, 0, "160")  # the same value again: no second run
    assert len(runs) == 1
    made._typed_into_slider(0, 0, "1e5")  # beyond the slider's end: the end moves
    assert made.gains()["weight_q"] == (1e5, 160.0) and float(made.sliders[0].max) >= 1e5
    made._typed_into_slider(0, 0, "-")
    assert (
        "refused**: weight_q joint 1 = '-' is invalid" in made.errors["weight_q"].content and len(runs) == 2
    )


def test_a_horizon_steps_by_one_knot_and_follows_its_knot_interval_in_whole_knots(server: Any) -> None:
    from twolink_pin.controllers.mpc import MPCGains

    made, runs = controls(server, MPCGains, {"horizon": 0.2, "knot_interval": 0.025})
    horizon = next(s for s in made.sliders if s.label == "horizon [s]")
    assert float(horizon.step) == 0.025
    move(made, "horizon [s]", round(0.2 + 0.025, int(horizon.precision)))
    assert made.gains()["horizon"] == 9 * 0.025
    made._typed_into_slider(1, 0, "0.03")  # knot_interval: 0.225 s is 7.5 knots of 0.03 s
    gains = made.gains()
    assert gains["knot_interval"] == 0.03 and gains["horizon"] == 8 * 0.03  # rounded half to even: 8
    assert float(horizon.step) == 0.03
    assert "horizon rounded to 8 × knot_interval = 0.24 (was 0.225)" in made.errors["horizon"].content
    assert len(runs) == 2


def test_a_full_matrix_keeps_its_off_diagonal_terms_when_its_diagonal_steps(server: Any) -> None:
    from twolink_pin.controllers import CONTROLLERS

    full = [[150.0, 20.0, 0.0], [20.0, 150.0, 0.0], [0.0, 0.0, 80.0]]
    made, _ = controls(server, CONTROLLERS["osc"].Gains, {"kp": full})
    x = next(s for s in made.sliders if s.label == "kp axis x [1/s²]")
    move(made, "kp axis x [1/s²]", round(150.0 + float(x.step), int(x.precision)))
    np.testing.assert_array_equal(
        np.reshape(made.gains()["kp"], (3, 3)), [[170, 20, 0], [20, 150, 0], [0, 0, 80]]
    )  # 150 · 10^(1/20) = 168 → 170
