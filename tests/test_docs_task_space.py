"""docs/task_space.md, run: every command on the page is run here and every output line the
page quotes must be in what it prints; the page's code and trajectory file are the example's;
the tutorial's laws scale their gains where the built-in laws do (the robot's home).

Slow-ish: four UR5 runs of 16 s and a sweep of 8. ``compare`` and ``sweep`` run with ``--no-plot``:
what is checked here is what they print (the figures are tests/test_plotting.py's).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from docs_pages import blocks, commands, quoted_in

from twolink_pin.cli import main
from twolink_pin.controllers import load_controller
from twolink_pin.documents import load_toml
from twolink_pin.model import load_robot

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "task_space.md").read_text()
COMMANDS = commands(PAGE)


def test_the_page_runs_simulate_compare_and_sweep() -> None:
    verbs = [shlex.split(c)[1] for c, _ in COMMANDS]
    assert verbs.count("simulate") >= 2 and "compare" in verbs and "sweep" in verbs
    for robot in ("ur5", "panda"):  # each arm runs its own example square
        assert any(f"--robot {robot}" in c and f"examples/{robot}_square_pose.toml" in c for c, _ in COMMANDS)
    assert all(
        any(f"--robot {r}" in c and f"examples/{r}_square_pose.toml" in c for r in ("ur5", "panda"))
        for c, _ in COMMANDS
    )


@pytest.mark.slow
@pytest.mark.parametrize(("command", "quoted"), COMMANDS, ids=[shlex.split(c)[1] for c, _ in COMMANDS])
def test_every_command_prints_what_the_page_says(
    command: str,
    quoted: list[str],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    argv = shlex.split(command)
    assert argv[0] == "twolink-pin"
    argv = argv[1:]
    if "--out" in argv:  # the page's out/… folder, here in a temporary one
        i = argv.index("--out") + 1
        argv[i] = str(tmp_path / Path(argv[i]).name)
    if argv[0] in ("compare", "sweep"):  # the printed lines, not the figures (test_plotting's):
        argv.append("--no-plot")  # compare's 27 figures of two 16-s runs were half of this file's time
    monkeypatch.chdir(ROOT)
    assert main(argv) == 0
    printed = capsys.readouterr().out.splitlines()
    for line in quoted:
        assert quoted_in(line, printed), f"{line!r} is not in the output of {command!r}:\n" + "\n".join(
            printed
        )


def test_the_pages_code_is_the_examples() -> None:
    source = (ROOT / "examples" / "jacobian_transpose.py").read_text()
    python = [text for kind, text in blocks(PAGE) if kind == "python"]
    assert python
    for line in python[0].splitlines():
        if line.strip():
            assert line.strip() in source, line


def test_the_pages_square_is_the_example_file() -> None:
    page = load_toml(next(text for kind, text in blocks(PAGE) if kind == "toml"), "page")
    file = load_toml((ROOT / "examples" / "ur5_square_pose.toml").read_text(), "file")
    assert page == file


def test_the_tutorials_gains_are_scaled_at_the_robots_home_like_the_built_in_laws() -> None:
    """SlidingMode's K = 10 diag M(home) and pd's Kp = ω² diag M(home), M by Pinocchio's CRBA
    at the UR5's home (not its neutral configuration, where the inertias differ)."""
    ur5 = load_robot("ur5")
    M_home = pin.crba(ur5.model, ur5.model.createData(), ur5.home)
    M_neutral = pin.crba(ur5.model, ur5.model.createData(), pin.neutral(ur5.model))
    assert np.abs(np.diag(M_home) - np.diag(M_neutral)).max() > 0.1  # the choice matters here
    sliding = load_controller("examples/sliding_mode.py:SlidingMode")(ur5)
    pd = load_controller("pd")(ur5)
    np.testing.assert_allclose(np.asarray(sliding.gains.k).ravel(), 10.0 * np.diag(M_home), rtol=1e-12)
    np.testing.assert_allclose(np.asarray(pd.gains.kp).ravel() / 10.0**2, np.diag(M_home), rtol=1e-12)
