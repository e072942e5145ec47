"""``trajectory --save FILE``: any robot's reference written as a trajectory file, read back by
the reader ``--trajectory`` and ``--reference`` use, gives the same motion (q, q̇, q̈ at 400
instants over two periods, to 1e-12)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.trajectory import default_trajectory, read_trajectory_file

FIXTURES = Path(__file__).parent / "fixtures"


@pytest.mark.parametrize(
    ("robot", "given", "suffix"),
    [("twolink", None, ".json"), ("ur5", None, ".toml"), ("ur5", "ur5_excitation.json", ".toml")],
)
def test_saved_reference_reads_back_as_the_same_motion(
    tmp_path: Path, robot: str, given: str | None, suffix: str
) -> None:
    model = load_robot(robot)
    out = tmp_path / f"reference{suffix}"
    args = ["trajectory", "--robot", robot, "--save", str(out), "--json"]
    if given:
        args += ["--trajectory", str(FIXTURES / given)]
    assert main(args) == 0
    original = read_trajectory_file(FIXTURES / given, model) if given else default_trajectory(model)
    again = read_trajectory_file(out, model)
    t = np.linspace(0.0, 2 * original.period, 400)
    a, b = original.sample(t), again.sample(t)
    assert again.period == original.period
    for x, y in zip((a.q, a.v, a.a), (b.q, b.v, b.a)):
        np.testing.assert_allclose(y, x, rtol=0, atol=1e-12 * max(1.0, float(np.abs(x).max())))


def test_save_refuses_another_suffix_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "reference.csv"
    assert main(["trajectory", "--save", str(out)]) == 2
    assert "--save" in capsys.readouterr().err and not out.exists()
