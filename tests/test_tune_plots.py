"""The tuner's plot data (no page): at most POINTS samples a curve, a reference run resampled
on the latest run's times (exact for a straight line, NaN past its own end), the true
parameters as constant curves, seconds on a numeric (not a date) x scale."""

from __future__ import annotations

import numpy as np

from twolink_pin.tuning.plots import POINTS, X_SCALE, Curves, compose


def test_a_reference_is_resampled_on_the_latest_times_and_ends_where_it_ends() -> None:
    t = np.linspace(0.0, 8.0, 8001)
    latest = Curves(t, np.column_stack([np.sin(t), np.cos(t)]), ("e1", "e2"))
    short = np.linspace(0.0, 4.0, 333)
    previous = Curves(short, np.column_stack([2.0 * short, 1.0 - short]), ("e1", "e2"))
    data, series = compose(latest, {"previous": previous, "defaults": None})
    assert len(data) == len(series) == 5 and len(data[0]) <= POINTS
    grid = data[0]
    inside = grid <= 4.0
    np.testing.assert_allclose(data[3][inside], 2.0 * grid[inside], rtol=0, atol=1e-12)
    np.testing.assert_allclose(data[4][inside], 1.0 - grid[inside], rtol=0, atol=1e-12)
    assert np.isnan(data[3][~inside]).all() and (~inside).any()
    np.testing.assert_array_equal(data[1], np.sin(grid))
    assert [s["label"] for s in series] == ["t [s]", "e1", "e2", "e1 (previous)", "e2 (previous)"]
    assert X_SCALE == {"x": {"time": False}}


def test_true_parameters_are_constant_curves_beside_the_estimates() -> None:
    t = np.linspace(0.0, 1.0, 11)
    estimates = Curves(t, np.outer(t, [1.0, 2.0]), ("p1", "p2"), truth=np.array([3.0, 4.0]))
    data, series = compose(estimates)
    np.testing.assert_array_equal(data[3], np.full(11, 3.0))
    np.testing.assert_array_equal(data[4], np.full(11, 4.0))
    assert series[3]["label"] == "p1 true" and series[3]["dash"]


def test_a_law_state_is_drawn_one_panel_per_unit_as_the_law_declares_it() -> None:
    """mpc's state mixes seconds, a count, rad, rad/s and rad/s²: the page draws one panel per
    unit (as the report's state figure), each with the columns the law declares in that unit."""
    from types import SimpleNamespace

    from twolink_pin import Plant, SimulationConfig, load_robot, simulate
    from twolink_pin.controllers import ModelPredictive
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.tuning.plots import panels

    robot = load_robot()
    law = ModelPredictive(robot)
    result = simulate(law, Plant(robot), default_trajectory(robot), SimulationConfig(duration=0.03))
    drawn = panels(SimpleNamespace(result=result, task=None, robot=robot))  # type: ignore[arg-type]
    declared = law.state_variables()
    assert result.state is not None
    for unit in {v.unit for v in declared}:
        title = f"law state z [{unit}]" if unit else "law state z"
        columns = [i for i, v in enumerate(declared) if v.unit == unit]
        assert drawn[title].names == tuple(declared[i].name for i in columns)
        np.testing.assert_array_equal(drawn[title].columns, result.state[:, columns])
    assert len([title for title in drawn if title.startswith("law state")]) == len({v.unit for v in declared})
