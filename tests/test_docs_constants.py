"""The defaults docs/controllers.md states are the code's: each number quoted there is read
from the page and compared with the constant the code uses. And what the README and
writing_a_controller.md list is what the code has: every command, every gain bound."""

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


ROOT = Path(__file__).resolve().parents[1]


def test_the_readmes_command_table_lists_every_command() -> None:
    """Issue 38 §9: ``robots`` was missing from the README's table."""
    from twolink_pin.cli.parser import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction").choices
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    listed = re.findall(r"^\| `twolink-pin ([a-z-]+)", readme, re.MULTILINE)
    assert sorted(set(listed)) == sorted(commands)


def test_writing_a_controller_documents_every_gain_bound() -> None:
    """Issue 38 §9: ``bound="nonnegative"`` (the adaptive laws' initial estimate, robust's β)
    was used and not documented; the page names every bound ``gain()`` takes."""
    from twolink_pin.controllers.gains import BOUNDS, SHAPES

    page = (ROOT / "docs" / "writing_a_controller.md").read_text(encoding="utf-8")
    for bound in BOUNDS:
        assert f'"{bound}"' in page, bound
    for shape in SHAPES:
        assert f'"{shape}"' in page, shape


def test_info_write_urdf_says_how_to_believe_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 38 §9: the message names ``--model FILE`` beside ``--robot FILE``, and the line it
    suggests runs."""
    from twolink_pin.cli import main

    urdf = tmp_path / "heavier.urdf"
    assert main(["info", "--payload", "0.5", "--write-urdf", str(urdf)]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert f"--model {urdf}" in line and f"--robot {urdf}" in line
    assert main(["simulate", "computed-torque", "--model", str(urdf), "--duration", "0.05"]) == 0
