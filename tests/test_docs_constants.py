"""The defaults docs/controllers.md states are the code's: each number quoted there is read
from the page and compared with the constant the code uses."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from twolink_pin.controllers import adaptive, computed_torque, impedance, osc, pd

PAGE = (Path(__file__).resolve().parents[1] / "docs" / "controllers.md").read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("symbol", "unit", "value"),
    [
        ("ω", "rad/s", pd.NATURAL_FREQUENCY),
        ("ω", "rad/s", impedance.STIFFNESS_FREQUENCY),
        ("ω", "rad/s", osc.TASK_FREQUENCY),
        ("ω_n", "rad/s", osc.POSTURE_FREQUENCY),
        ("ω_n", "rad/s", impedance.POSTURE_FREQUENCY),
        ("κ", "1/s", computed_torque.SLIDING_RATE),
        ("α", "1/s", adaptive.ADAPTATION_RATE),
        ("λ", "1/s", computed_torque.DEFAULT_LAMBDA),
    ],
)
def test_every_default_the_page_quotes_is_the_codes(symbol: str, unit: str, value: float) -> None:
    quoted = re.findall(rf"{symbol} = ([0-9.]+) {re.escape(unit)}", PAGE)
    assert quoted, f"docs/controllers.md quotes no {symbol} in {unit}"
    assert {float(x) for x in quoted} == {value}, f"{symbol}: page {quoted}, code {value}"
