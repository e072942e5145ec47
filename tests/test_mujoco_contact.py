"""Contact on the MuJoCo plant (twolink_pin.mujoco_contact), against independent constructions:

* a static push ``τ = ĝ + Jᵀ F`` into a surface reads ``F`` at the sensor (statics, 1 %), the
  penetration is ``|F| / K`` (the stiffness mapped onto ``solref``: Hooke), and the two plants
  read the same force (2 %);
* a bounce against a damped wall loses energy and leaves at the Pinocchio plant's speed (the
  damping mapped), and an undamped one keeps it;
* with friction the tangential force never leaves Coulomb's cone;
* a batch equals its single runs.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ROBOT
from test_contact import EXAMPLES, WALL_X, Push, PushGains, at, held, wall

from twolink_pin.contact import Scene, Surface, read_scene
from twolink_pin.contact_metrics import contact_metrics
from twolink_pin.model import load_robot
from twolink_pin.mujoco_contact import IMPEDANCE, contact_parameters
from twolink_pin.plant_options import PlantOptions
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.studies.batch import simulate_batch
from twolink_pin.trajectory import read_trajectory_file

pytest.importorskip("mujoco")


def _plant(robot, scene: Scene, engine: str):  # type: ignore[no-untyped-def]
    return PlantOptions(scene=scene, engine=engine).plant(robot, estimates_friction=False)


@pytest.mark.parametrize("robot_name", ["twolink", "panda"])
def test_a_static_push_reads_the_force_on_both_plants(robot_name: str) -> None:
    """τ = ĝ + Jᵀ F into the surface, the motion damped: at rest each plant's sensor reads F
    (1 %), the penetration is |F|/K (1 %), and the plants agree (2 %)."""
    robot = ROBOT if robot_name == "twolink" else load_robot("panda")
    if robot_name == "twolink":
        scene, q0, force = wall(friction=0.3), at(WALL_X - 0.025, -0.05), (15.0, 0.0, 0.0)
    else:  # a table 1 cm below the Panda's tip at home, pressed down with 20 N
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, robot.home)
        z = float(data.oMf[robot.ee_frame_id].translation[2]) - 0.03
        scene = Scene((Surface((0.3, 0.0, z), (0.0, 0.0, 1.0), 5000.0, 100.0, 0.5, name="table"),))
        q0, force = robot.home, (0.0, 0.0, -20.0)
    config = SimulationConfig(duration=2.0, q0_offset=0.0)
    read = {}
    for engine in ("pinocchio", "mujoco"):
        law = Push(robot, PushGains(force=force, kd=4.0))
        result = simulate(law, _plant(robot, scene, engine), held(q0), config)
        assert result.wrench is not None and result.penetration is not None
        read[engine] = result.wrench[-1, :3]
        size = float(np.linalg.norm(force))
        np.testing.assert_allclose(read[engine], force, rtol=0, atol=0.01 * size)
        stiffness = scene.surfaces[0].stiffness
        np.testing.assert_allclose(result.penetration[-1], size / stiffness, rtol=0.01)
    np.testing.assert_allclose(read["mujoco"], read["pinocchio"], rtol=0, atol=0.02 * np.linalg.norm(force))


def test_the_scenes_stiffness_and_damping_map_onto_solref() -> None:
    """solref's direct form (−s, −c) with s = K (1−d) Â and c = B (1−d) Â: MuJoCo's contact
    stiffness k d / R = (s/d²) d / ((1−d) Â / d) is K again (and c/d / R is B)."""
    surface = Surface((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 3000.0, 40.0)
    inverse_mass = 0.37
    (s, c), solimp = contact_parameters(surface, inverse_mass)
    d = IMPEDANCE
    assert solimp[:2] == (d, d)
    R = (1 - d) / d * inverse_mass
    assert (s / d**2) * d / R == pytest.approx(-3000.0, rel=1e-12)
    assert (c / d) / R == pytest.approx(-40.0, rel=1e-12)
    own = dataclasses.replace(surface, solref=(0.02, 1.0), solimp=(0.9, 0.95, 0.001, 0.5, 2.0))
    assert contact_parameters(own, inverse_mass) == ((0.02, 1.0), (0.9, 0.95, 0.001, 0.5, 2.0))


def _bounce(damping: float, engine: str) -> tuple[float, float]:
    """The twolink (horizontal: its energy is kinetic) thrown at the wall with no torque: its
    energy [J] before and after the first contact."""
    plant = _plant(ROBOT, wall(damping=damping), engine)
    law = Push(ROBOT, PushGains(force=(0.0, 0.0, 0.0)))
    q0 = at(0.45, 0.0)
    J = pin.computeFrameJacobian(
        ROBOT.model, ROBOT.model.createData(), q0, ROBOT.ee_frame_id, pin.LOCAL_WORLD_ALIGNED
    )
    v0 = np.linalg.solve(J[:2], np.array([0.4, 0.05]))  # towards the wall at 0.4 m/s
    config = SimulationConfig(duration=0.8, q0_offset=(0.0, 0.0), v0_offset=tuple(v0))
    run = simulate(law, plant, held(q0), config)
    assert run.penetration is not None
    energy = np.array([plant.energy(q, v) for q, v in zip(run.q, run.v, strict=True)])
    edges = np.flatnonzero(np.diff((run.penetration > 0).astype(int)))
    assert len(edges) >= 2
    return float(energy[edges[0]]), float(energy[edges[1] + 1])


def test_a_bounce_loses_the_pinocchio_plants_energy_on_mujoco() -> None:
    """Undamped, the bounce gives the energy back (0.5 %); damped (20 N·s/m), it loses energy,
    as much as on the Pinocchio plant (5 % of the loss: the added mass d/(1−d) and the sensor's
    half step apart)."""
    before, after = _bounce(0.0, "mujoco")
    assert after == pytest.approx(before, rel=5e-3)
    before, after = _bounce(20.0, "mujoco")
    p_before, p_after = _bounce(20.0, "pinocchio")
    assert after < before
    assert before - after == pytest.approx(p_before - p_after, rel=0.05)


def test_the_tangential_force_stays_within_the_friction_cone_on_mujoco() -> None:
    """hybrid slides along a wall with μ = 0.2 on MuJoCo: at every sample |f_t| <= μ f_n (MuJoCo's
    elliptic cone, to its solver's tolerance), and the contact slides at the cone's edge."""
    scene = read_scene(EXAMPLES / "wall.toml")
    trajectory = read_trajectory_file(EXAMPLES / "wall_slide.toml", ROBOT)
    spec = RunSpec(
        law="hybrid",
        plant=PlantOptions(scene=scene, engine="mujoco"),
        simulation=SimulationConfig(duration=3.5, q0_offset=0.0),
    )
    result = simulate(*spec.build(ROBOT), trajectory, spec.simulation)
    assert result.wrench is not None and result.contact_normal is not None
    F = result.wrench[:, :3]
    n = result.contact_normal
    normal = -(F @ n)
    tangential = np.linalg.norm(F - np.outer(F @ n, n), axis=1)
    mu = scene.surfaces[0].friction
    assert np.all(tangential <= mu * normal * (1 + 1e-6) + 1e-9)
    sliding = np.abs(result.v).max(axis=1) > 0.1
    assert (tangential[sliding & (normal > 1)] > 0.9 * mu * normal[sliding & (normal > 1)]).any()


def test_a_batch_against_a_wall_equals_its_single_runs_on_mujoco() -> None:
    """N runs on one ``mujoco.batch.Batch`` read the same contacts as each run alone."""
    scene = read_scene(EXAMPLES / "wall.toml")
    trajectory = read_trajectory_file(EXAMPLES / "wall_slide.toml", ROBOT)
    config = SimulationConfig(duration=1.5, q0_offset=0.0)
    spec = RunSpec(law="hybrid", plant=PlantOptions(scene=scene, engine="mujoco"), simulation=config)
    controller, plant = spec.build(ROBOT)
    offsets = np.array([[0.0, 0.0], [0.03, -0.02]])
    batch = simulate_batch(controller, plant, trajectory, config, q0_offsets=offsets, record=True)
    assert batch.contact_metrics is not None and batch.q is not None
    for i, offset in enumerate(offsets):
        single = simulate(controller, plant, trajectory, dataclasses.replace(config, q0_offset=tuple(offset)))
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-9)
        metrics = contact_metrics(single, ROBOT)
        assert metrics is not None
        np.testing.assert_allclose(list(batch.contact_metrics.run(i)), list(metrics), rtol=1e-9, atol=1e-12)


def test_a_contact_too_stiff_for_the_step_fails_on_mujoco_naming_the_limit() -> None:
    """MuJoCo's contact integrated by the engine's RK4 has the Pinocchio plant's stability limit:
    a 10⁹ N/m wall fails the run when the contact starts, naming the limit (never a blow-up)."""
    from twolink_pin.errors import ContactError

    law = Push(ROBOT, PushGains(force=(20.0, 0.0, 0.0), kd=20.0))
    plant = _plant(ROBOT, wall(stiffness=1e9, damping=0.0), "mujoco")
    with pytest.raises(ContactError, match=r"surface 'wall' at t = 0\.") as err:
        simulate(law, plant, held(at(0.52, 0.0)), SimulationConfig(duration=2.0, q0_offset=0.0))
    assert "largest stable stiffness at --dt 0.001 s" in str(err.value)


def test_a_payload_step_in_contact_keeps_the_sensors_reading_on_mujoco() -> None:
    """A payload picked up while hybrid presses on the wall (t = 1.5 s): MuJoCo's model after the
    step takes over from the last state, so the sensor reads the contact through the switch (no
    sample of zero force while the ball is pressed in)."""
    from twolink_pin.disturbances import PayloadStep

    scene = read_scene(EXAMPLES / "wall.toml")
    trajectory = read_trajectory_file(EXAMPLES / "wall_slide.toml", ROBOT)
    plant = PlantOptions(scene=scene, engine="mujoco", payload_step=PayloadStep(0.5, 1.5))
    config = SimulationConfig(duration=1.8, q0_offset=0.0)
    result = simulate(*RunSpec(law="hybrid", plant=plant, simulation=config).build(ROBOT), trajectory, config)
    assert result.wrench is not None and result.penetration is not None
    pressed = (result.t > 1.2) & (result.t < 1.8)
    assert (result.penetration[pressed] > 1e-3).all()
    assert (result.wrench[pressed, 0] > 5.0).all()  # f_n = −n·F on the wall (normal −x)
