"""Tests of twolink_pin.limits: every limit read once from the model (checked against the
URDF's own XML and the maker's data), and a reference checked against each kind (checked
against closed forms and an independent evaluation of the polynomial's derivatives)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from numpy.polynomial import polynomial as P

from twolink_pin import load_robot
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import (
    ACCELERATION,
    EFFORT,
    KINDS,
    POSITION,
    VELOCITY,
    JointLimits,
    check_limits,
    joint_limits,
    kind_named,
)
from twolink_pin.trajectory import JointTrajectory, build_trajectory, default_trajectory
from twolink_pin.twolink import closed_form

TWOLINK = load_robot()


def _urdf_limits(robot) -> dict[str, dict[str, float]]:
    """Each joint's ``<limit>`` attributes read from the URDF file by ElementTree."""
    root = ET.parse(robot.urdf_path).getroot()
    out = {}
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if limit is not None and joint.get("type") in ("revolute", "continuous", "prismatic"):
            attrs = {k: float(v) for k, v in limit.attrib.items()}
            # a continuous joint has no range, whatever it says; nor has lower == upper (the
            # URDF's default 0 and 0: load_robot's documented convention)
            if joint.get("type") == "continuous" or attrs.get("lower", 0.0) == attrs.get("upper", 0.0):
                attrs.pop("lower", None), attrs.pop("upper", None)
            out[joint.get("name")] = attrs
    return out


@pytest.mark.parametrize("name", ["twolink", "ur5", "panda", "kinova", "z1", "double_pendulum"])
def test_limits_are_the_urdf_s_own(name: str) -> None:
    """Position range, velocity and effort of every joint equal the URDF's ``<limit>``
    attributes as ElementTree reads them (0 or absent: none, reported as None)."""
    robot = load_robot(name)
    limits = joint_limits(robot)
    urdf = _urdf_limits(robot)
    data = limits.as_dict()
    for j, joint in enumerate(limits.joint_names):
        attrs = urdf.get(joint, {})
        for key, attr in (("velocity", "velocity"), ("effort", "effort")):
            expected = attrs.get(attr, 0.0)
            assert data[key][j] == (expected if expected > 0 else None), (joint, key)
        if "lower" in attrs and "upper" in attrs:
            assert data["position_lower"][j] == pytest.approx(attrs["lower"], abs=1e-12)
            assert data["position_upper"][j] == pytest.approx(attrs["upper"], abs=1e-12)
        else:
            assert data["position_lower"][j] is None and data["position_upper"][j] is None


def test_acceleration_limits_come_from_the_profile() -> None:
    """The Panda's acceleration limits are Franka's data sheet's (15, 7.5, 10, 12.5, 15, 20,
    20 rad/s²); the twolink has none, and its JSON leaves the key out."""
    panda = joint_limits(load_robot("panda"))
    np.testing.assert_array_equal(panda.acceleration, [15, 7.5, 10, 12.5, 15, 20, 20])
    assert panda.as_dict()["acceleration"] == [15, 7.5, 10, 12.5, 15, 20, 20]
    twolink = joint_limits(TWOLINK)
    assert not twolink.given(ACCELERATION).any() and "acceleration" not in twolink.as_dict()


@pytest.mark.parametrize(
    ("field", "value"),
    [("velocity", 0.0), ("velocity", -1.0), ("effort", math.nan), ("acceleration", 0.0)],
)
def test_zero_negative_or_nan_limits_are_refused_naming_the_joint(field: str, value: float) -> None:
    base = joint_limits(TWOLINK)
    values = {k: np.array(getattr(base, k)) for k in ("velocity", "acceleration", "effort")}
    values[field][1] = value
    with pytest.raises(InvalidParameterError, match=f"{field} limit of joint 'joint2'"):
        JointLimits(base.joint_names, base.position_lower, base.position_upper, **values)


def test_a_range_upside_down_is_refused() -> None:
    base = joint_limits(TWOLINK)
    with pytest.raises(InvalidParameterError, match="position range of joint 'joint1'"):
        JointLimits(base.joint_names, [1.0, -1.0], [0.0, 1.0], base.velocity, base.acceleration, base.effort)


@pytest.mark.parametrize("fraction", [0.0, -0.5, 1.5, math.nan, math.inf, True])
def test_limit_scale_outside_zero_one_is_refused(fraction: float) -> None:
    with pytest.raises(InvalidParameterError, match="limit scale"):
        joint_limits(TWOLINK).scaled(fraction)


def test_scaled_limits_keep_the_position_range() -> None:
    limits = joint_limits(load_robot("panda"))
    half = limits.scaled(0.5)
    np.testing.assert_array_equal(half.velocity, 0.5 * limits.velocity)
    np.testing.assert_array_equal(half.acceleration, 0.5 * limits.acceleration)
    np.testing.assert_array_equal(half.effort, 0.5 * limits.effort)
    np.testing.assert_array_equal(half.position_lower, limits.position_lower)


def test_require_names_the_joints_without_the_limit() -> None:
    limits = joint_limits(load_robot("double_pendulum"))
    with pytest.raises(InvalidParameterError, match=r"velocity limit of joint 'joint1'.*joint1, joint2"):
        limits.require(VELOCITY, "retime under it")
    joint_limits(TWOLINK).require(VELOCITY, "retime under it")  # the twolink has them


def test_as_dict_round_trips() -> None:
    limits = joint_limits(load_robot("kinova"))
    back = JointLimits.from_mapping(limits.joint_names, limits.as_dict())
    for kind in KINDS:
        for a, b in zip(limits.bounds(kind), back.bounds(kind)):
            np.testing.assert_array_equal(a, b)


def test_kind_named() -> None:
    assert kind_named("effort") is EFFORT
    with pytest.raises(InvalidParameterError, match="jerk"):
        kind_named("jerk")


def test_the_report_reference_against_closed_forms() -> None:
    """On the report's reference: the effort peak is the closed-form torque's, the velocity
    and acceleration peaks are those of the polynomial's own derivatives (numpy's polyder
    of its coefficients) on a 10x finer grid, and every margin is limit − peak."""
    traj = build_trajectory(TWOLINK)
    check = check_limits(TWOLINK, traj)
    assert check.within_limits
    t = np.linspace(0.0, traj.period, 40001)
    coefficients = np.asarray(traj.coefficients)
    for kind, order in ((VELOCITY, 1), (ACCELERATION, 2)):
        values = np.stack([P.polyval(t, P.polyder(c, order)) for c in coefficients], axis=1)
        np.testing.assert_allclose(check.of(kind.name).peak, np.abs(values).max(axis=0), rtol=1e-6)
    ref = traj.sample(check.motion.t)
    tau = np.array(
        [
            closed_form.mass_matrix(q, TWOLINK.p) @ a + closed_form.coriolis_matrix(q, v, TWOLINK.p) @ v
            for q, v, a in zip(ref.q, ref.v, ref.a)
        ]
    )
    effort = check.of("effort")
    np.testing.assert_allclose(effort.peak, np.abs(tau).max(axis=0), rtol=0, atol=1e-9)
    np.testing.assert_allclose(effort.margin, [240, 40] - effort.peak, rtol=0, atol=1e-12)
    velocity = check.of("velocity")
    np.testing.assert_allclose(velocity.margin, 10.0 - velocity.peak, rtol=0, atol=1e-12)
    assert check.summary()["acceleration"]["limit"] == [None, None]


def test_a_swing_past_the_range_is_caught_between_via_points() -> None:
    """Via points inside the twolink's ±π range whose polynomial overshoots between them:
    the position check's margin is negative at the overshoot, and the top verdict false."""
    via = np.array([[0.0, 0.0], [2.5, 0.0], [3.1, 0.0], [0.0, 0.0]])
    traj = JointTrajectory.from_via_q([0.0, 1.0, 1.5, 3.0], via)
    grid = np.linspace(0.0, 3.0, 30001)
    q_max = traj.sample(grid).q[:, 0].max()
    assert q_max > math.pi  # the overshoot lies between the via points
    check = check_limits(TWOLINK, traj)
    position = check.of("position")
    assert position.margin[0] < 0 and not position.within_limits and not check.within_limits
    assert position.peak[0] == pytest.approx(q_max, abs=1e-5)
    assert position.limit[0] == pytest.approx(3.14159265)
    assert position.margin[0] == pytest.approx(3.14159265 - q_max, abs=1e-5)


def test_velocity_past_a_catalog_limit_is_caught() -> None:
    """The Kinova's 0.63 rad/s limits: its default swing scaled 1.2x in time-compression
    (period 4 s → 3 s) moves faster than its limits: the velocity check says so."""
    robot = load_robot("kinova")
    base = default_trajectory(robot)
    fast = JointTrajectory.from_via_q(np.asarray(base.times) * 0.75, np.asarray(base.via_q))
    check = check_limits(robot, fast)
    velocity = check.of("velocity")
    assert not velocity.within_limits
    peak = np.abs(fast.sample(np.linspace(0, fast.period, 30001)).v).max(axis=0)
    np.testing.assert_allclose(velocity.peak, peak, rtol=1e-5)
    np.testing.assert_allclose(velocity.margin, joint_limits(robot).velocity - velocity.peak, atol=1e-12)


def test_position_kind_reads_positions() -> None:
    assert POSITION.order == 0 and not POSITION.symmetric and EFFORT.order is None
