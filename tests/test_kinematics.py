"""Tests of twolink_pin.kinematics: Pinocchio FK and Jacobian against the closed form and
finite differences; analytic IK on both branches, on the workspace boundary, and the
report's Table 1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.errors import UnreachableTargetError
from twolink_pin.kinematics import forward_kinematics, inverse_kinematics, jacobian, workspace
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.twolink import closed_form

ROBOT: RobotModel = load_robot()
L1, L2 = 0.38, 0.24
R_MIN, R_MAX = 0.14, 0.62

angles = st.lists(st.floats(min_value=-math.pi, max_value=math.pi), min_size=2, max_size=2).map(np.array)
EXAMPLES = settings(max_examples=60, deadline=None)


def _wrap(angle: np.ndarray) -> np.ndarray:
    """Angle(s) mapped to [−π, π) [rad]."""
    return (np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi


def test_workspace_is_the_report_annulus() -> None:
    """The reachable annulus is |L1 − L2| = 0.14 m <= r <= L1 + L2 = 0.62 m."""
    np.testing.assert_allclose(workspace(ROBOT), [R_MIN, R_MAX], rtol=0, atol=1e-15)


@EXAMPLES
@given(q=angles)
def test_pinocchio_fk_equals_closed_form(q: np.ndarray) -> None:
    """Pinocchio's end-effector frame position equals the report's eq. 1."""
    np.testing.assert_allclose(
        forward_kinematics(ROBOT, q), closed_form.forward_kinematics(q, L1, L2), rtol=0, atol=1e-14
    )


reachable = st.tuples(
    st.floats(min_value=R_MIN, max_value=R_MAX), st.floats(min_value=-math.pi, max_value=math.pi)
)


@EXAMPLES
@given(polar=reachable)
def test_fk_of_ik_is_target_on_both_branches(polar: tuple[float, float]) -> None:
    """FK(IK(x)) = x for both elbow branches of every target in the annulus; branch 0 has
    q2 >= 0 and branch 1 has q2 <= 0."""
    r, phi = polar
    target = np.array([r * math.cos(phi), r * math.sin(phi)])
    solutions = inverse_kinematics(ROBOT, target)
    assert solutions.shape == (2, 2)
    assert solutions[0, 1] >= 0
    assert solutions[1, 1] <= 0
    for q in solutions:
        np.testing.assert_allclose(forward_kinematics(ROBOT, q), target, rtol=0, atol=1e-12)


@pytest.mark.parametrize("r", [R_MIN, R_MAX])
@pytest.mark.parametrize("phi", np.linspace(-math.pi, math.pi, 13))
def test_branches_coincide_on_the_boundary(r: float, phi: float) -> None:
    """On the annulus boundary (r = 0.62 m stretched, r = 0.14 m folded) the two branches
    are the same configuration and both reach the target.

    Angles are compared modulo 2π (at r = 0.14 m the elbow is +π on one branch, −π on the
    other) to 1e-7 rad: acos near ±1 turns a 1e-16 rounding of cos q2 into ~3e-8 rad.
    """
    target = np.array([r * math.cos(phi), r * math.sin(phi)])
    branch0, branch1 = inverse_kinematics(ROBOT, target)
    np.testing.assert_allclose(_wrap(branch0 - branch1), [0.0, 0.0], rtol=0, atol=1e-7)
    np.testing.assert_allclose(abs(branch0[1]), 0.0 if r == R_MAX else math.pi, rtol=0, atol=1e-7)
    for q in (branch0, branch1):
        np.testing.assert_allclose(forward_kinematics(ROBOT, q), target, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    ("target", "r"),
    [((0.7, 0.0), 0.7), ((0.0, -0.05), 0.05), ((0.5, 0.5), math.hypot(0.5, 0.5))],
)
def test_unreachable_target_raises_with_target_and_range(target: tuple[float, float], r: float) -> None:
    """A target outside the annulus raises UnreachableTargetError naming the target, the
    valid range "0.14 <= r <= 0.62" and its own r; the error keeps the values."""
    with pytest.raises(UnreachableTargetError) as info:
        inverse_kinematics(ROBOT, target)
    message = str(info.value)
    assert f"target ({target[0]:.4g}, {target[1]:.4g}) m" in message
    assert "0.14 <= r <= 0.62" in message
    assert f"(r = {r:.4g} m)" in message
    assert info.value.target == target
    np.testing.assert_allclose([info.value.r_min, info.value.r_max], [R_MIN, R_MAX], rtol=0, atol=1e-15)


def test_unreachable_target_message_exact() -> None:
    """The exact text for (0.70, 0.00) m, as the style guide's example."""
    with pytest.raises(
        UnreachableTargetError,
        match=r"^target \(0\.7, 0\) m is outside the reachable "
        r"annulus 0\.14 <= r <= 0\.62 m \(r = 0\.7 m\)$",
    ):
        inverse_kinematics(ROBOT, (0.7, 0.0))


REPORT_TABLE_1 = [
    ((0.48, 0.1), [(-0.2936, 1.3587), (0.7044, -1.3587)]),
    ((0.38, 0.0), [(-0.6426, 1.8921), (0.6426, -1.8921)]),
    ((0.48, -0.1), [(-0.7044, 1.3587), (0.2936, -1.3587)]),
    ((0.58, 0.0), [(-0.2835, 0.7424), (0.2835, -0.7424)]),
]


@pytest.mark.parametrize(("target", "pairs"), REPORT_TABLE_1)
def test_ik_reproduces_report_table_1(target: tuple[float, float], pairs: list[tuple[float, float]]) -> None:
    """IK gives the report's Table 1 to its 4 decimals, both pairs in the report's order
    (first pair q2 >= 0). The third row's point is (0.48, −0.1): the report's text misprints
    it as (0.48, 0.1) and leaves it out of the table."""
    np.testing.assert_allclose(inverse_kinematics(ROBOT, target), pairs, rtol=0, atol=5e-5)


def test_third_via_point_as_printed_in_the_text_does_not_give_table_row_3() -> None:
    """IK of (0.48, +0.1) is row 1 of Table 1 and misses row 3 by 0.41 rad in q1: row 3
    belongs to (0.48, −0.1)."""
    solutions = inverse_kinematics(ROBOT, (0.48, 0.1))
    np.testing.assert_allclose(solutions, REPORT_TABLE_1[0][1], rtol=0, atol=5e-5)
    q1_gap = np.abs(solutions[:, 0] - np.array(REPORT_TABLE_1[2][1])[:, 0])
    assert np.all(q1_gap > 0.41), q1_gap


@EXAMPLES
@given(q=angles)
def test_jacobian_equals_finite_differences_of_fk(q: np.ndarray) -> None:
    """The planar Jacobian equals central differences of FK (step 1e-6 rad, error ~1e-12 m/rad)."""
    h = 1e-6
    numeric = np.column_stack(
        [
            (forward_kinematics(ROBOT, q + h * e) - forward_kinematics(ROBOT, q - h * e)) / (2 * h)
            for e in np.eye(2)
        ]
    )
    np.testing.assert_allclose(jacobian(ROBOT, q), numeric, rtol=0, atol=1e-9)
