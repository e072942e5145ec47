"""docs/control_within_limits.md, run: every command on the page is run here and every output
line the page quotes must be in what it prints (stdout, or stderr for the run the page shows
failing); the page's path is the example file; and demo (b) is checked from the runs its
``compare`` made: qp-osc keeps every joint inside its range, every velocity, acceleration and
commanded torque within its limit, where osc takes joint 4 past its range and asks joint 6 for
more than its effort limit.

Slow-ish: two 2.5-s Panda runs (one with its limits binding for 0.7 s) and one that fails at
0.12 s. ``compare`` runs with ``--no-plot``: what is checked here is what it prints and its runs
(the figures are scripts/docs_images.py's, their code tests/test_plotting_limits.py's).
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.documents import load_toml
from twolink_pin.limits import ACCELERATION, EFFORT, POSITION, VELOCITY, joint_limits
from twolink_pin.model import load_robot

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "control_within_limits.md").read_text()
BLOCK = re.compile(r"```(\w*)\n(.*?)```", re.S)


def _blocks() -> list[tuple[str, str]]:
    return [(m.group(1), m.group(2)) for m in BLOCK.finditer(PAGE)]


def _commands() -> list[tuple[str, list[str]]]:
    """Each ``sh`` block's command with the ``text`` block right after it (the quoted output)."""
    blocks = _blocks()
    out = []
    for (kind, text), (next_kind, quoted) in zip(blocks, [*blocks[1:], ("", "")], strict=True):
        if kind == "sh":
            assert next_kind == "text", f"no quoted output after {text!r}"
            out.append((text.strip(), quoted.strip("\n").splitlines()))
    return out


COMMANDS = _commands()


def test_the_page_compares_osc_and_qp_osc_on_its_example_path() -> None:
    verbs = [shlex.split(c)[1:3] for c, _ in COMMANDS]
    assert ["compare", "osc"] in verbs and ["simulate", "qp-osc"] in verbs
    assert all("--robot panda" in c and "examples/panda_fold_pose.toml" in c for c, _ in COMMANDS)
    page = load_toml(next(text for kind, text in _blocks() if kind == "toml"), "page")
    assert page == load_toml((ROOT / "examples" / "panda_fold_pose.toml").read_text(), "file")


def _run(command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[int, dict[str, Any]]:
    """The page's command through ``main``, its output folder in ``tmp_path``, ``compare``
    without figures; and the runs ``compare`` made (each law's result as it was tabulated)."""
    import twolink_pin.studies.comparison as comparison

    argv = shlex.split(command)[1:]
    if "--out" in argv:
        i = argv.index("--out") + 1
        argv[i] = str(tmp_path / Path(argv[i]).name)
    if argv[0] == "compare":
        argv.append("--no-plot")
    runs: dict[str, Any] = {}
    tabulate = comparison.run_comparison

    def keeping(runner: Any, names: Any, progress: Any = None, on_result: Any = None) -> Any:
        def kept(name: str, result: Any) -> None:
            runs[name] = result
            if on_result is not None:
                on_result(name, result)

        return tabulate(runner, names, progress, kept)

    monkeypatch.setattr(comparison, "run_comparison", keeping)
    monkeypatch.chdir(ROOT)
    return main(argv), runs


@pytest.mark.slow
@pytest.mark.parametrize(("command", "quoted"), COMMANDS, ids=[shlex.split(c)[1] for c, _ in COMMANDS])
def test_every_command_prints_what_the_page_says(
    command: str,
    quoted: list[str],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    fails = any("failed at t =" in line for line in quoted)
    status, runs = _run(command, tmp_path, monkeypatch)
    out, err = capsys.readouterr()
    assert status == (1 if fails else 0), err
    printed = (err if fails else out).splitlines()
    for line in quoted:
        assert any(line in p for p in printed) if fails else line in printed, (
            f"{line!r} is not in the output of {command!r}:\n" + "\n".join(printed)
        )
    if runs:
        _check_demo(runs)


def _check_demo(runs: dict[str, Any]) -> None:
    """Demo (b) from compare's own runs: qp-osc inside every limit (positions and commanded
    torques exactly, velocities and accelerations to RK4's rounding: 1e-6 rad/s, and a central
    difference of the recorded velocity to 1e-6 rad/s²); osc past joint 4's range by more than
    0.1 rad and above joint 6's effort limit."""
    limits = joint_limits(load_robot("panda", payload=3.0))
    qp, osc = runs["qp-osc"], runs["osc"]
    assert limits.excess(POSITION, qp.q).max() < 0
    assert limits.excess(EFFORT, qp.tau_command).max() < 0
    assert limits.excess(VELOCITY, qp.v).max() < 1e-6
    accel = (qp.v[2:] - qp.v[:-2]) / (qp.t[2:] - qp.t[:-2])[:, None]
    assert limits.excess(ACCELERATION, accel).max() < 1e-6
    assert limits.excess(POSITION, osc.q)[:, 3].max() > 0.1  # the elbow past its range
    assert limits.excess(EFFORT, osc.tau_command)[:, 5].max() > 5.0  # joint 6 above its 12 N·m
    assert np.abs(osc.v).max(axis=0)[0] > 2 * limits.velocity[0]  # and the base twice its speed
