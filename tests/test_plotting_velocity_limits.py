"""twolink_pin/plotting/velocity_limits.py: several runs against one joint's velocity and effort
limits. Two twolink runs with made-up velocities and torques (one past joint 2's 10-rad/s and
40-N·m limits, one inside both): the limits drawn at ±limit, the curves the runs' own, each
run's legend saying by how much it crossed or its peak, the file written, a bad joint refused."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twolink_pin import SimulationConfig, default_trajectory, load_robot, make_scenario, simulate
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import joint_limits
from twolink_pin.plotting import save_velocity_limits_figure
from twolink_pin.plotting.velocity_limits import _figure

ROBOT = load_robot()
LIMITS = joint_limits(ROBOT)  # 10 rad/s; 240 and 40 N·m


@pytest.fixture(scope="module")
def runs() -> dict[str, object]:
    law, plant = make_scenario("pd", ROBOT)
    base = simulate(law, plant, default_trajectory(ROBOT), SimulationConfig(duration=0.1))
    t = base.t
    fast = replace(
        base,
        v=np.column_stack([t, 10.5 * np.sin(np.pi * t / t[-1])]),
        tau_command=np.column_stack([t, 50 + 0 * t]),
    )
    slow = replace(base, v=np.column_stack([t, 9.0 + 0 * t]), tau_command=np.column_stack([t, -30 + 0 * t]))
    return {"fast": fast, "slow": slow}


def test_the_figure_draws_the_limits_and_says_who_crossed(runs: dict[str, object], tmp_path: Path) -> None:
    fig = _figure(runs, LIMITS, 1, "test")  # type: ignore[arg-type]
    velocity, torque = fig.axes
    dotted = sorted(line.get_ydata()[0] for line in velocity.get_lines() if line.get_linestyle() == ":")
    assert dotted == pytest.approx([-10.0, 10.0])
    curves = [line for line in velocity.get_lines() if line.get_linestyle() == "-"]
    np.testing.assert_array_equal(curves[0].get_ydata(), runs["fast"].v[:, 1])  # type: ignore[attr-defined]
    labels = [t.get_text() for t in velocity.get_legend().get_texts()]
    assert labels == ["fast: past it by 0.5 rad/s", "slow: peak 9 rad/s"]
    torques = [t.get_text() for t in torque.get_legend().get_texts()]
    assert torques == ["fast: past it by 10 N·m", "slow: peak 30 N·m"]
    path = save_velocity_limits_figure(runs, LIMITS, tmp_path / "v.png", joint=1)  # type: ignore[arg-type]
    assert path.stat().st_size > 10_000


def test_a_joint_out_of_range_is_refused(runs: dict[str, object], tmp_path: Path) -> None:
    with pytest.raises(InvalidParameterError, match="joint = 2 is invalid: expected a joint index 0 … 1"):
        save_velocity_limits_figure(runs, LIMITS, tmp_path / "x.png", joint=2)  # type: ignore[arg-type]
