"""What an optimal reference is measured by (twolink_pin.trajectory.optimal_measures): the
distance from the via points' convex hull against closed forms, and the end effector's
excursion along a reference that stays on its via points' polyline."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twolink_pin.model import load_robot
from twolink_pin.trajectory import read_trajectory_file
from twolink_pin.trajectory.optimal_measures import HULL_TOLERANCE, hull_distance, hull_excursion

SQUARE = np.array(
    [[0.45, 0.1, 0.4], [0.45, -0.1, 0.4], [0.45, -0.1, 0.2], [0.45, 0.1, 0.2], [0.45, 0.1, 0.4]]
)
"""The UR5's 20-cm square (examples/ur5_square_pose.toml), the first corner again at the end."""


@pytest.mark.parametrize(
    ("point", "distance"),
    [
        ((0.45, 0.0, 0.3), 0.0),  # inside the square
        ((0.45, 0.1, 0.2), 0.0),  # a corner
        ((0.30, 0.0, 0.3), 0.15),  # off its plane, over its middle: the plane's distance
        ((0.45, 0.3, 0.3), 0.2),  # in its plane, beside an edge
        ((0.45, 0.4, 0.6), np.hypot(0.3, 0.2)),  # in its plane, beyond a corner
        ((-0.047, 0.0, 0.45), np.hypot(0.497, 0.05)),  # behind the base: the plane, then above the top edge
    ],
)
def test_the_distance_from_a_square_is_the_closed_form(point: tuple[float, ...], distance: float) -> None:
    assert hull_distance(SQUARE, np.array(point)) == pytest.approx(distance, abs=HULL_TOLERANCE)


def test_the_distance_from_a_segment_and_from_one_point() -> None:
    """A degenerate hull: a vertical segment (the Panda's fold) and a single point."""
    segment = np.array([[0.32, 0.0, 0.15], [0.32, 0.0, 0.45]])
    assert hull_distance(segment, np.array([0.32, 0.0, 0.3])) == pytest.approx(0.0, abs=HULL_TOLERANCE)
    assert hull_distance(segment, np.array([0.12, 0.0, 0.3])) == pytest.approx(0.2, abs=HULL_TOLERANCE)
    assert hull_distance(segment, np.array([0.32, 0.0, 0.55])) == pytest.approx(0.1, abs=HULL_TOLERANCE)
    assert hull_distance(segment[:1], np.array([0.32, 0.3, 0.55])) == pytest.approx(0.5, abs=HULL_TOLERANCE)


def test_a_reference_along_its_square_stays_in_its_hull() -> None:
    """The via-pose reference follows straight edges between its corners (SE(3) interpolation,
    its IK to 1e-9 m): its largest distance from the hull is within the IK's error."""
    robot = load_robot("ur5")
    poses = read_trajectory_file(
        Path(__file__).resolve().parents[1] / "examples" / "ur5_square_pose.toml", robot
    )
    excursion = hull_excursion(robot, poses, poses.via_q)
    assert excursion.distance <= 1e-5
