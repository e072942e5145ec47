"""Joint stops (``--joint-stops``, :mod:`twolink_pin.simulation.stops`): a position range as a hard,
perfectly inelastic stop, against closed forms and a second computation.

* a pendulum released at rest falls into its stop: from then on it stays at the bound with zero
  velocity, its energy drops by the kinetic energy of its motion into the stop (closed form:
  ``m g l sin(q_stop)``), and without the stop the run's crossing comes when the closed-form fall
  time (a quadrature) says;
* the impact on a 6-joint arm: the stopped joint's velocity is zero after, the impulse acts at the
  stopped joints only (``M Δq̇`` zero elsewhere, with ``M`` from CRBA), and the kinetic energy lost is
  ``½ q̇_S^T (M⁻¹_SS)⁻¹ q̇_S`` with ``M⁻¹`` from numpy's inverse of CRBA (hypothesis);
* a run whose joints never reach a stop is the plain run bit for bit;
* the option reaches the plant, and is refused where it would do nothing.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ConstantTorque
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from twolink_pin.cli import main
from twolink_pin.cli.commands.common import run_spec
from twolink_pin.cli.parser import build_parser
from twolink_pin.limits import joint_limits
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.stops import JointStops
from twolink_pin.trajectory import default_trajectory

MASS, LENGTH, IYY, STOP = 2.0, 0.5, 0.01, 1.0
"""The pendulum: mass [kg] at LENGTH [m] from its joint, its own inertia [kg·m²], its upper stop [rad]."""
PENDULUM = f"""<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base_link"/>
  <link name="arm">
    <inertial>
      <origin xyz="{LENGTH} 0 0" rpy="0 0 0"/>
      <mass value="{MASS}"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="{IYY}" iyz="0" izz="{IYY}"/>
    </inertial>
  </link>
  <joint name="swing" type="revolute">
    <parent link="base_link"/>
    <child link="arm"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-{STOP}" upper="{STOP}" effort="50" velocity="10"/>
  </joint>
  <link name="tip"/>
  <joint name="tip_fixed" type="fixed">
    <parent link="arm"/>
    <child link="tip"/>
    <origin xyz="1 0 0" rpy="0 0 0"/>
  </joint>
</robot>
"""
"""About +y, q > 0 lowers the mass: U(q) = −m g l sin q with gravity along −z; released at q = 0
it falls into its upper stop at 1 rad, where gravity keeps pushing it."""
G = 9.81
INERTIA = MASS * LENGTH**2 + IYY
"""About the joint [kg·m²]."""


def _omega(q: np.ndarray | float) -> np.ndarray:
    """Closed form: the speed [rad/s] at ``q`` of the pendulum released at rest at 0."""
    return np.sqrt(2 * MASS * G * LENGTH * np.sin(q) / INERTIA)


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory: pytest.TempPathFactory) -> object:
    path = tmp_path_factory.mktemp("pendulum") / "pendulum.urdf"
    path.write_text(PENDULUM)
    return load_robot(path)


def _fall(robot: object, stops: bool) -> tuple[Plant, object]:
    trajectory = default_trajectory(robot)  # type: ignore[arg-type]
    start = trajectory.sample(0.0)
    config = SimulationConfig(duration=0.8, q0_offset=float(-start.q[0]), v0_offset=float(-start.v[0]))
    plant = Plant(robot, position_stops=stops)  # type: ignore[arg-type]
    return plant, simulate(ConstantTorque(robot), plant, trajectory, config)  # type: ignore[arg-type]


def test_a_falling_pendulum_stays_on_its_stop_and_loses_the_kinetic_energy_of_the_impact(
    pendulum: object,
) -> None:
    """Released at rest at q = 0 (τ = 0): after the impact q = 1 rad and q̇ = 0 exactly at every
    sample; the energy (Pinocchio's) is 0 before, −m g l sin 1 after: it dropped by the closed-form
    kinetic energy at the stop, ½ I ω(1)²; the last sample before the stop moves at ω(q) of the
    closed form."""
    plant, result = _fall(pendulum, stops=True)
    q, v = np.asarray(result.q)[:, 0], np.asarray(result.v)[:, 0]
    hit = int(np.argmax(q >= STOP))
    assert 0 < hit < len(q) - 100  # it hits, then rests for a while
    assert np.all(q[hit:] == STOP) and np.all(v[hit:] == 0.0)
    assert np.all(q <= STOP) and not result.crossings.position.crossed.any()
    energy = np.array([plant.energy(np.array([a]), np.array([b])) for a, b in zip(q, v)])
    np.testing.assert_allclose(energy[:hit], 0.0, rtol=0, atol=1e-9)  # RK4 conserves it before
    kinetic_at_stop = 0.5 * INERTIA * _omega(STOP) ** 2
    np.testing.assert_allclose(kinetic_at_stop, MASS * G * LENGTH * math.sin(STOP), rtol=1e-12)
    np.testing.assert_allclose(energy[hit:], -kinetic_at_stop, rtol=0, atol=1e-9)
    np.testing.assert_allclose(v[hit - 1], _omega(q[hit - 1]), rtol=1e-6)


def test_without_a_stop_the_crossing_comes_at_the_closed_form_fall_time(pendulum: object) -> None:
    """The same fall without stops passes the range: its recorded crossing is the first sample after
    t* = ∫₀¹ dq / ω(q) (quadrature of the closed form), and its excess the largest q − 1 of the run."""
    _, result = _fall(pendulum, stops=False)
    fall, _ = quad(lambda q: 1.0 / _omega(q), 0.0, STOP)
    crossing = result.crossings.position
    assert crossing.crossed[0]
    assert fall <= crossing.first_time[0] < fall + result.dt
    np.testing.assert_allclose(crossing.excess[0], np.asarray(result.q).max() - STOP, rtol=0, atol=0)


UR5 = load_robot("ur5")
UR5_LIMITS = joint_limits(UR5)


def _inverse_mass(q: np.ndarray) -> np.ndarray:
    """M⁻¹ by numpy from CRBA's upper triangle (a second method beside computeMinverse)."""
    mass = pin.crba(UR5.model, UR5.model.createData(), q)
    mass = np.triu(mass) + np.triu(mass, 1).T
    return np.linalg.inv(mass), mass


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-0.8, 0.8), min_size=6, max_size=6),
    st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6),
    st.sets(st.integers(0, 5), min_size=1, max_size=3),
    st.lists(st.booleans(), min_size=6, max_size=6),
)
def test_an_impact_acts_at_the_stopped_joints_only_and_takes_their_kinetic_energy(
    q_free: list[float], v_list: list[float], hit: set[int], upper: list[bool]
) -> None:
    """Joints ``hit`` of the UR5 just past a bound, any velocities: after the stop each of them is
    on its bound and not moving into it; ``M (q̇⁺ − q̇)`` is zero on every joint not stopped
    (an impulse at the stops only) and pushes each stopped joint out of its stop; the kinetic
    energy never grows, and its loss is ``½ q̇_S^T (M⁻¹_SS)⁻¹ q̇_S`` over the joints ``S`` stopped."""
    lower, upper_bounds = UR5_LIMITS.position_lower, UR5_LIMITS.position_upper
    q = np.array(q_free)
    for j in hit:
        q[j] = upper_bounds[j] + 1e-3 if upper[j] else lower[j] - 1e-3
    v = np.array(v_list)
    stops = JointStops(UR5_LIMITS, UR5.model)
    q_after, v_after = stops(q[None], v[None])
    q_after, v_after = q_after[0], v_after[0]
    for j in hit:
        assert q_after[j] == (upper_bounds[j] if upper[j] else lower[j])
        assert (v_after[j] <= 1e-12) if upper[j] else (v_after[j] >= -1e-12)
    others = [j for j in range(6) if j not in hit]
    np.testing.assert_array_equal(q_after[others], q[others])
    inverse, mass = _inverse_mass(q_after)
    impulse = mass @ (v_after - v)
    np.testing.assert_allclose(impulse[others], 0.0, rtol=0, atol=1e-9 * (1 + np.abs(v).max()))
    stopped = [j for j in hit if abs(impulse[j]) > 1e-9]
    for j in stopped:
        assert impulse[j] < 0 if upper[j] else impulse[j] > 0  # a stop pushes, never pulls
        assert v_after[j] == 0.0
    lost = 0.5 * v @ mass @ v - 0.5 * v_after @ mass @ v_after
    assert lost >= -1e-9
    if stopped:
        s = np.array(stopped)
        expected = 0.5 * v[s] @ np.linalg.solve(inverse[np.ix_(s, s)], v[s])
        np.testing.assert_allclose(lost, expected, rtol=1e-8, atol=1e-10)
    else:
        assert lost == pytest.approx(0.0, abs=1e-12)


def test_a_run_that_never_reaches_a_stop_is_the_plain_run_bit_for_bit() -> None:
    """The twolink's report run stays far inside ±π: with stops it is the same run, bit for bit."""
    robot = load_robot()
    controller, plain = make_scenario("computed-torque", robot)
    trajectory = default_trajectory(robot)
    config = SimulationConfig(duration=0.3)
    stopped = Plant(robot, position_stops=True)
    a = simulate(controller, plain, trajectory, config)
    b = simulate(controller, stopped, trajectory, config)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.tau_command, b.tau_command)
    assert b.position_stops and not a.position_stops


def test_the_option_reaches_the_plant() -> None:
    """The pattern of tests/test_run_spec.py: argv → run_spec → build → the plant it changes."""
    args = build_parser().parse_args(["simulate", "pd", "--joint-stops"])
    assert run_spec(args, "pd").build(load_robot()).plant.position_stops is True
    args = build_parser().parse_args(["simulate", "pd"])
    assert run_spec(args, "pd").build(load_robot()).plant.position_stops is False


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--robot", "double_pendulum"], ("--joint-stops", "position range", "joint1, joint2")),
        (["--method", "adaptive"], ("--joint-stops", "rk4", "adaptive")),
    ],
)
def test_joint_stops_that_would_do_nothing_are_refused(
    capsys: pytest.CaptureFixture[str], argv: list[str], words: tuple[str, ...]
) -> None:
    """No joint of the double pendulum has a range; the adaptive integrator has no steps to stop
    between: one line naming the option, exit 2."""
    code = main(["simulate", "pd", "--duration", "0.01", "--joint-stops", *argv])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    for word in words:
        assert word in err


def test_a_pendulum_past_its_range_is_named_on_stderr(
    pendulum: object, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without stops the run says so: a warning naming the joint, the time and the excess (a
    start 1.5 rad from the reference, which starts at 0: 0.5 rad past the range at t = 0); with
    them the run starts on its stop and says nothing."""
    urdf = str(Path(pendulum.urdf_path))  # type: ignore[attr-defined]
    argv = ["simulate", "pd", "--robot", urdf, "--duration", "0.05", "--q0-offset", "1.5"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert (
        "twolink-pin: warning: pd: joint 1 (swing) passed its position range [-1, 1] rad at t = 0 s, by up to 0.5 rad"
        in err
    )
    assert "--joint-stops makes the range a hard stop" in err
    assert main([*argv, "--joint-stops"]) == 0
    assert "warning" not in capsys.readouterr().err
