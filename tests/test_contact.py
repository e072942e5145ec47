"""Contact with a scene's surfaces (twolink_pin.contact), the force sensor and the force laws.

Each against an independent construction:

* a static push ``τ = ĝ + Jᵀ F`` into a surface reads ``F`` at the sensor (statics);
* a bounce without damping keeps the arm's energy (the spring stores ½ k δ² and gives it back),
  and with damping loses some at every contact, never gains; a pendulum dropped on a floor
  likewise;
* with friction the tangential force never leaves Coulomb's cone ``|f_t| <= μ f_n``;
* the joint-space stiffness is the contact torque's derivative (finite differences);
* RK4's largest stable stiffness is ``m (2√2/h)²`` without damping (its stability function);
* ``hybrid`` on a stiff wall holds the commanded force (its PI's steady state);
* a batch equals its single runs (every law that runs against a surface, metrics included).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ROBOT, ConstantTorque, pendulum

from twolink_pin.contact import (
    CompliantContact,
    Scene,
    Surface,
    joint_stiffness,
    largest_stable_stiffness,
    read_scene,
)
from twolink_pin.contact.stability import largest_stable_step, rk4_amplification
from twolink_pin.contact_metrics import contact_metrics
from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput, Terms, gain
from twolink_pin.errors import ContactError, InvalidParameterError
from twolink_pin.kinematics import solve_position
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.plant_options import PlantOptions
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.studies.batch import simulate_batch
from twolink_pin.trajectory import ForceReference, JointTrajectory, read_trajectory_file, with_force

EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[1] / "examples"
WALL_X = 0.55
"""The test wall: the plane x = 0.55 m facing the twolink (normal −x)."""


def wall(stiffness: float = 1000.0, damping: float = 20.0, friction: float = 0.0, **scene: Any) -> Scene:
    return Scene((Surface((WALL_X, 0.0, 0.0), (-1.0, 0.0, 0.0), stiffness, damping, friction),), **scene)


def at(x: float, y: float) -> np.ndarray:
    """The twolink's configuration [rad] with the end effector's frame at (x, y) [m] (elbow q2 > 0)."""
    return solve_position(ROBOT, np.array([x, y]), np.array([0.0, 0.8]))


def held(q: np.ndarray, force: ForceReference | None = None, period: float = 10.0) -> JointTrajectory:
    """A reference that holds ``q`` [rad], carrying ``force``."""
    trajectory = JointTrajectory.from_via_q((0.0, period), np.array([q, q]))
    return with_force(trajectory, force) if force is not None else trajectory


@dataclass(frozen=True, eq=False)
class PushGains(Gains):
    force: Any = gain(0.0, per="axis", unit="N", bound="any")
    kd: Any = gain(0.0, per="joint", unit="N·m·s/rad", bound="nonnegative")


class Push(Controller, register=False):
    """``τ = ĝ(q) + J(q)ᵀ F − K_d q̇``: a constant force ``F`` [N] at the end effector, gravity
    compensated, the motion damped."""

    name = "test-push"
    title = "constant push (tests)"
    Gains = PushGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        J = terms.frame(x.q, x.v).jacobian[:, :3]
        return LawOutput(terms.gravity(x.q) + np.vecmat(self.gains.force, J) - self.gains.kd * x.v)


# -- the scene ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("normal", (0.0, 0.0, 0.0), "non-zero direction"),
        ("normal", (math.nan, 0.0, 1.0), "finite"),
        ("normal", (math.inf, 0.0, 1.0), "finite"),
        ("stiffness", -1.0, "stiffness in (0"),
        ("stiffness", 0.0, "stiffness in (0"),
        ("damping", -0.1, "damping in [0"),
        ("friction", -0.2, "Coulomb coefficient"),
        ("size", (0.3, -0.1, 0.1), "each > 0"),
        ("solimp", (0.9, 0.95, 0.001, 0.5, 0.5), "power >= 1"),
    ],
)
def test_a_bad_surface_is_refused_naming_the_value(field: str, value: Any, expected: str) -> None:
    values = {"point": (0.5, 0.0, 0.0), "normal": (-1.0, 0.0, 0.0), field: value}
    with pytest.raises(InvalidParameterError, match=f"surface 'wall': {field}") as err:
        Surface(**values)
    assert expected in str(err.value)


def test_the_normal_is_normalised_and_the_scene_survives_json() -> None:
    surface = Surface((0.5, 0.0, 0.0), (-2.0, 0.0, 0.0))
    assert surface.normal == (-1.0, 0.0, 0.0)
    options = PlantOptions(scene=wall(friction=0.3))
    spec = RunSpec(law="pd", plant=options)
    import json

    again = RunSpec.from_dict(json.loads(json.dumps(spec.as_dict())))
    assert again.plant.scene == options.scene


def test_a_scene_file_names_its_bad_key(tmp_path: Any) -> None:
    path = tmp_path / "scene.toml"
    path.write_text("[[surface]]\npoint = [0.5, 0, 0]\nnormal = [-1, 0, 0]\ndamping = -3\n")
    with pytest.raises(InvalidParameterError, match=r"scene\.toml: surface 'wall': damping"):
        read_scene(path)
    path.write_text('[[surface]]\npoint = [0.5, 0, 0]\nnormal = [-1, 0, 0]\ncolour = "red"\n')
    with pytest.raises(InvalidParameterError, match=r"surface\[0\].colour"):
        read_scene(path)
    assert read_scene(EXAMPLES / "wall.toml").surfaces[0].stiffness == 1000.0


# -- the contact's physics ------------------------------------------------------------------------


@pytest.mark.parametrize("robot_name", ["twolink", "panda"])
def test_a_static_push_reads_the_force_at_the_sensor(robot_name: str) -> None:
    """τ = ĝ + Jᵀ F into the surface, the motion damped: at rest the sensor reads F (1 %)."""
    robot = ROBOT if robot_name == "twolink" else load_robot("panda")
    if robot_name == "twolink":
        scene, q0, force = wall(friction=0.3), at(WALL_X - 0.025, -0.05), (15.0, 0.0, 0.0)
    else:  # a table 1 cm below the Panda's tip at home, pressed down with 20 N
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, robot.home)
        z = float(data.oMf[robot.ee_frame_id].translation[2]) - 0.03
        scene = Scene((Surface((0.3, 0.0, z), (0.0, 0.0, 1.0), 5000.0, 100.0, 0.5, name="table"),))
        q0, force = robot.home, (0.0, 0.0, -20.0)
    law = Push(robot, PushGains(force=force, kd=4.0))
    result = simulate(law, Plant(robot, scene=scene), held(q0), SimulationConfig(duration=3.0, q0_offset=0.0))
    assert result.wrench is not None
    np.testing.assert_allclose(result.wrench[-1, :3], force, rtol=0, atol=0.01 * np.linalg.norm(force))
    assert result.penetration is not None and result.penetration[-1] > 0


def test_a_bounce_without_damping_keeps_the_energy_and_with_damping_loses_some() -> None:
    """Thrown at the wall with no torque (the twolink is horizontal: its energy is kinetic): out of
    contact the energy stays; through an undamped contact the spring gives it back (2e-5); every
    damped or rubbing contact takes some (more than 1e-4 of it) and none gives any."""
    plant = Plant(ROBOT, scene=wall(damping=0.0))
    law = Push(ROBOT, PushGains(force=(0.0, 0.0, 0.0)))  # no torque at all
    q0 = at(0.45, 0.0)
    J = pin.computeFrameJacobian(
        ROBOT.model, ROBOT.model.createData(), q0, ROBOT.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
    )
    v0 = np.linalg.solve(J[:2], np.array([0.4, 0.05]))  # towards the wall at 0.4 m/s
    config = SimulationConfig(duration=1.5, q0_offset=(0.0, 0.0), v0_offset=tuple(v0))
    elastic = simulate(law, plant, held(q0), config)
    energy = np.array([plant.energy(q, v) for q, v in zip(elastic.q, elastic.v, strict=True)])
    free = elastic.penetration == 0
    assert not free.all() and free[0] and free[-1]
    # to RK4's error where the contact starts and ends (the force's derivative jumps there)
    np.testing.assert_allclose(energy[free], energy[0], rtol=2e-5)
    for damping, friction in ((20.0, 0.0), (0.0, 0.5), (20.0, 0.5)):
        lossy = dataclasses.replace(plant, scene=wall(damping=damping, friction=friction))
        run = simulate(law, lossy, held(q0), config)
        e = np.array([lossy.energy(q, v) for q, v in zip(run.q, run.v, strict=True)])
        inside = run.penetration > 0
        edges = np.flatnonzero(np.diff(inside.astype(int)))  # contact starts and ends
        assert len(edges) >= 2
        before = [e[k] for k in edges[::2]]
        after = [e[k + 1] for k in edges[1::2]]
        for b, a in zip(before, after, strict=False):
            assert a < b - 1e-4 * b  # every bounce loses energy
        assert np.all(np.diff(e[~inside]) <= 1e-6 * e[0])  # never any gain, in contact or out


def test_a_pendulum_dropped_on_a_floor_loses_energy_at_every_bounce() -> None:
    """The double pendulum (gravity in its plane) falls from near its top onto a floor with no
    torque: its energy ½ q̇ᵀMq̇ + U(q) is kept between contacts (1e-8 J) and drops through every
    one, never rising."""
    robot = pendulum()
    floor = Scene((Surface((0.0, 0.0, -0.02), (0.0, 0.0, 1.0), 2000.0, 5.0, name="floor"),))
    plant = Plant(robot, scene=floor)
    run = simulate(
        ConstantTorque(robot), plant, held(np.array([0.3, 0.0])), SimulationConfig(3.0, q0_offset=0.0)
    )
    energy = np.array([plant.energy(q, v) for q, v in zip(run.q, run.v, strict=True)])
    inside = run.penetration > 0
    edges = np.flatnonzero(np.diff(inside.astype(int)))
    assert len(edges) >= 6  # three bounces at least
    for start, end in zip(edges[::2], edges[1::2], strict=False):
        assert energy[end + 1] < energy[start] - 1e-3  # a bounce loses energy
    free = np.diff(energy[~inside])
    assert np.all(free <= 1e-8)  # never any gain
    assert np.all(np.abs(free[np.diff(np.flatnonzero(~inside)) == 1]) <= 1e-8)  # kept in flight


def test_the_tangential_force_stays_within_the_friction_cone() -> None:
    """hybrid slides along a wall with μ = 0.2: at every sample |f_t| <= μ f_n."""
    scene = read_scene(EXAMPLES / "wall.toml")
    trajectory = read_trajectory_file(EXAMPLES / "wall_slide.toml", ROBOT)
    spec = RunSpec(
        law="hybrid",
        plant=PlantOptions(scene=scene),
        simulation=SimulationConfig(duration=3.5, q0_offset=0.0),
    )
    result = simulate(*spec.build(ROBOT), trajectory, spec.simulation)
    assert result.wrench is not None and result.contact_normal is not None
    F = result.wrench[:, :3]
    n = result.contact_normal
    normal = -(F @ n)
    tangential = np.linalg.norm(F - np.outer(F @ n, n), axis=1)
    mu = scene.surfaces[0].friction
    assert np.all(tangential <= mu * normal + 1e-12)
    sliding = np.abs(result.v).max(axis=1) > 0.1
    assert (tangential[sliding & (normal > 1)] > 0.9 * mu * normal[sliding & (normal > 1)]).any()


def test_the_joint_stiffness_is_the_contact_torques_derivative() -> None:
    """K_q = k Jᵀ n nᵀ J: at the edge of contact (f → 0) dτ_c/dq = −K_q (finite differences)."""
    scene = wall(stiffness=2000.0, damping=0.0)
    contact = CompliantContact(ROBOT, scene, 1)
    q = at(WALL_X - scene.radius + 1e-7, 0.05)  # just inside
    h = 1e-7
    derivative = np.column_stack(
        [
            (
                contact((q + h * e)[None], np.zeros((1, 2))).tau[0]
                - contact((q - h * e)[None], np.zeros((1, 2))).tau[0]
            )
            / (2 * h)
            for e in np.eye(2)
        ]
    )
    np.testing.assert_allclose(derivative, -joint_stiffness(ROBOT, scene, q).stiffness, rtol=1e-4, atol=1e-6)


def test_the_largest_stable_stiffness_is_rk4s() -> None:
    """Without damping: m (2√2 / h)² (RK4's imaginary-axis limit); with it, the boundary of
    |R(s h)| = 1 for the spring's eigenvalues, and the largest step inverts it."""
    assert largest_stable_stiffness(2.0, 0.0, 1e-3) == pytest.approx(
        2.0 * (2 * math.sqrt(2) / 1e-3) ** 2, rel=1e-9
    )
    k = largest_stable_stiffness(5.0, 300.0, 2e-3)
    roots = np.roots([5.0, 300.0, k])
    assert np.max(rk4_amplification(roots * 2e-3)) == pytest.approx(1.0, abs=1e-9)
    assert largest_stable_step(5.0, 300.0, k) == pytest.approx(2e-3, rel=1e-9)
    assert largest_stable_stiffness(1.0, 3000.0, 1e-3) == 0.0  # b h / m beyond the real-axis limit


def test_a_contact_too_stiff_for_the_step_fails_at_that_time_naming_the_limit() -> None:
    law = Push(ROBOT, PushGains(force=(20.0, 0.0, 0.0), kd=20.0))
    plant = Plant(ROBOT, scene=wall(stiffness=1e9, damping=0.0))
    with pytest.raises(ContactError, match=r"surface 'wall' at t = 0\.") as err:
        simulate(law, plant, held(at(0.52, 0.0)), SimulationConfig(duration=2.0, q0_offset=0.0))
    assert "largest stable stiffness at --dt 0.001 s" in str(err.value)


def test_a_start_inside_a_surface_is_refused_with_the_penetration() -> None:
    with pytest.raises(InvalidParameterError, match="mm inside surface 'wall'"):
        simulate(
            Push(ROBOT),
            Plant(ROBOT, scene=wall()),
            held(at(0.545, 0.0)),
            SimulationConfig(duration=0.1, q0_offset=0.0),
        )


# -- the force laws -------------------------------------------------------------------------------


def test_hybrid_on_a_stiff_wall_holds_the_commanded_force() -> None:
    """At rest against a wall of 10⁵ N/m the PI leaves no force error: f_n = f_d (1e-3)."""
    spec = RunSpec(law="hybrid", plant=PlantOptions(scene=wall(stiffness=1e5, damping=200.0, friction=0.2)))
    trajectory = held(at(0.52, -0.05), ForceReference.constant(12.0))
    result = simulate(*spec.build(ROBOT), trajectory, SimulationConfig(duration=4.0, q0_offset=0.0))
    assert result.normal_force is not None
    np.testing.assert_allclose(result.normal_force[-200:], 12.0, rtol=1e-3)


def test_a_force_law_without_a_surface_or_a_reference_is_refused() -> None:
    spec = RunSpec(law="force")
    with pytest.raises(InvalidParameterError, match="controls a contact force"):
        simulate(
            *spec.build(ROBOT),
            held(at(0.5, 0.0), ForceReference.constant(5.0)),
            SimulationConfig(duration=0.1, q0_offset=0.0),
        )
    spec = RunSpec(law="force", plant=PlantOptions(scene=wall()))
    with pytest.raises(InvalidParameterError, match="force' column"):
        simulate(*spec.build(ROBOT), held(at(0.5, 0.0)), SimulationConfig(duration=0.1, q0_offset=0.0))
    spec = RunSpec(law="pd")
    with pytest.raises(InvalidParameterError, match="force reference without one"):
        simulate(
            *spec.build(ROBOT),
            held(at(0.5, 0.0), ForceReference.constant(5.0)),
            SimulationConfig(duration=0.1, q0_offset=0.0),
        )


@pytest.mark.parametrize("law", ["hybrid", "force", "impedance"])
def test_a_batch_against_a_wall_equals_its_single_runs(law: str) -> None:
    scene = read_scene(EXAMPLES / "wall.toml")
    trajectory = read_trajectory_file(EXAMPLES / "wall_slide.toml", ROBOT)
    config = SimulationConfig(duration=2.0, q0_offset=0.0)
    spec = RunSpec(law=law, plant=PlantOptions(scene=scene), simulation=config)
    controller, plant = spec.build(ROBOT)
    offsets = np.array([[0.0, 0.0], [0.03, -0.02], [-0.02, 0.04]])
    batch = simulate_batch(controller, plant, trajectory, config, q0_offsets=offsets, record=True)
    assert batch.contact_metrics is not None and batch.q is not None
    for i, offset in enumerate(offsets):
        single = simulate(controller, plant, trajectory, dataclasses.replace(config, q0_offset=tuple(offset)))
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-9)
        metrics = contact_metrics(single, ROBOT)
        assert metrics is not None
        np.testing.assert_allclose(list(batch.contact_metrics.run(i)), list(metrics), rtol=1e-9, atol=1e-12)
