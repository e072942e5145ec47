"""twolink_pin/plotting/limits.py: several runs against one joint's range and one joint's effort
limit. Two twolink runs with made-up joint paths and torques (one past joint 2's range and above
joint 1's limit, one inside both): the worst joints found, the bounds drawn where the curves are,
each run's legend saying by how much it crossed, the file written."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twolink_pin import SimulationConfig, default_trajectory, load_robot, make_scenario, simulate
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import joint_limits
from twolink_pin.plotting import save_limits_figure
from twolink_pin.plotting.limits import _limits_figure, worst_joints

ROBOT = load_robot()
LIMITS = joint_limits(ROBOT)  # ±π rad; 240 and 40 N·m


@pytest.fixture(scope="module")
def runs() -> dict[str, object]:
    law, plant = make_scenario("pd", ROBOT)
    base = simulate(law, plant, default_trajectory(ROBOT), SimulationConfig(duration=0.2))
    t = base.t
    outside = replace(
        base,
        q=np.column_stack([0.1 * t, np.pi + 0.3 * np.sin(np.pi * t / t[-1])]),  # joint 2 past +π by 0.3
        tau_command=np.column_stack([300.0 * np.cos(t), 5.0 * t]),  # joint 1 above 240 N·m
    )
    inside = replace(
        base, q=np.column_stack([0.1 * t, 3.0 + 0 * t]), tau_command=np.column_stack([100 + 0 * t, t])
    )
    return {"crossing": outside, "within": inside}


def test_the_worst_joints_are_the_crossing_ones(runs: dict[str, object]) -> None:
    assert worst_joints(runs, LIMITS) == (1, 0)  # type: ignore[arg-type]


def test_the_figure_draws_the_bound_and_says_who_crossed(runs: dict[str, object], tmp_path: Path) -> None:
    fig = _limits_figure(runs, LIMITS, 1, 0, "test")  # type: ignore[arg-type]
    position, torque = fig.axes
    drawn = [line.get_ydata()[0] for line in position.get_lines() if line.get_linestyle() == ":"]
    assert drawn == pytest.approx([np.pi])  # the upper bound (the lower one is far from the data)
    labels = [t.get_text() for t in position.get_legend().get_texts()]
    assert labels[0] == "crossing: past the range by 0.3 rad"
    assert labels[1].startswith("within: inside it by 0.142 rad")
    torques = [t.get_text() for t in torque.get_legend().get_texts()]
    assert torques[:2] == ["crossing: peak 300 N·m", "within: peak 100 N·m"] and "240" in torques[2]
    path = save_limits_figure(runs, LIMITS, tmp_path / "limits.png")  # type: ignore[arg-type]
    assert path.stat().st_size > 10_000


def test_a_joint_out_of_range_is_refused(runs: dict[str, object], tmp_path: Path) -> None:
    with pytest.raises(
        InvalidParameterError, match="torque_joint = 2 is invalid: expected a joint index 0 … 1"
    ):
        save_limits_figure(runs, LIMITS, tmp_path / "x.png", torque_joint=2)  # type: ignore[arg-type]
