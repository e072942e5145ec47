"""The MuJoCo plant (``--plant mujoco``, :mod:`twolink_pin.mujoco_plant`) against Pinocchio's,
against MuJoCo's own ``mj_step``, and each effect against its physics.

* the URDF compiled by MuJoCo is Pinocchio's arm: ``mj_fullM`` equals CRBA and ``qfrc_bias``
  RNEA's ``C q̇ + g`` at seeded states (twolink, UR5, Panda, Kinova, Z1), and MuJoCo reads the
  URDF's ranges as the toolkit does (a second reader);
* "MuJoCo's RK4" is what the docs say: ``mj_step`` with integrator RK4 and the law installed as
  ``mjcb_control`` (called at each of its four stages) gives the MuJoCo plant's run;
* the same law on both plants, every extra effect off: equal to 1e-8 rad (short runs here, the
  30-s runs of the twolink, the UR5 and the Panda × pd, computed-torque, adaptive, osc in
  ``test_mujoco_equality.py``); and every plant option of the Pinocchio plant acts the same on both;
* armature adds exactly its value to M's diagonal (Pinocchio's CRBA and MuJoCo's ``mj_fullM``);
  a turntable released against joint damping decays as ``exp(−d t / (I + a))`` on both plants;
  pressed into its soft limit by a constant torque it settles where ``solref``/``solimp`` say
  (MuJoCo's regularised constraint at rest: ``r = q̈₀ (1 − d) T² ζ²``); against ``frictionloss``
  it slides at ``(τ − F)/I`` above it and creeps at MuJoCo's regularised rate below it;
* a batch (``mujoco.batch``) equals its single runs.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ConstantTorque, ConstantTorqueGains, evaluate

from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.mujoco_model import arm_spec
from twolink_pin.mujoco_plant import MujocoPlant
from twolink_pin.plant import Plant
from twolink_pin.plant_options import PlantOptions
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.studies.batch import simulate_batch
from twolink_pin.trajectory import default_trajectory

ROD_INERTIA = 0.1
"""The turntable's inertia about its joint [kg·m²]: izz 0.02 + 2 kg × (0.2 m)²."""
TURNTABLE = """<?xml version="1.0"?>
<robot name="turntable">
  <link name="base_link"/>
  <link name="arm">
    <inertial>
      <origin xyz="0.2 0 0" rpy="0 0 0"/>
      <mass value="2"/>
      <inertia ixx="0.015" ixy="0" ixz="0" iyy="0.015" iyz="0" izz="0.02"/>
    </inertial>
  </link>
  <joint name="turn" type="revolute">
    <parent link="base_link"/>
    <child link="arm"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="50" velocity="10"/>
  </joint>
  <link name="tip"/>
  <joint name="tip_fixed" type="fixed">
    <parent link="arm"/>
    <child link="tip"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/>
  </joint>
</robot>
"""
"""One revolute joint about the vertical: gravity exerts no torque, ``I q̈ = τ`` exactly."""


@pytest.fixture(scope="module")
def turntable(tmp_path_factory: pytest.TempPathFactory) -> RobotModel:
    path = tmp_path_factory.mktemp("turntable") / "turntable.urdf"
    path.write_text(TURNTABLE)
    return load_robot(path)


def _release(robot: RobotModel, plant: Plant, q0: float, v0: float, torque: float, duration: float) -> object:
    """``robot`` started at ``(q0, v0)`` under a constant torque [N·m]."""
    trajectory = default_trajectory(robot)
    start = trajectory.sample(0.0)
    config = SimulationConfig(
        duration=duration, q0_offset=float(q0 - start.q[0]), v0_offset=float(v0 - start.v[0])
    )
    law = ConstantTorque(robot, ConstantTorqueGains(torque=torque))
    return simulate(law, plant, trajectory, config)


def _full_m(model: object, data: object) -> np.ndarray:
    nv = model.nv  # type: ignore[attr-defined]
    out = np.zeros((nv, nv))
    mujoco.mj_fullM(model, data, out)
    return out


@pytest.mark.parametrize("name", ["twolink", "ur5", "panda", "kinova", "z1"])
def test_mujoco_compiles_pinocchios_arm_from_the_same_urdf(name: str) -> None:
    """M, C q̇ + g and the joints of MuJoCo's model equal Pinocchio's at seeded states; the ranges
    MuJoCo reads from the URDF are the toolkit's where the toolkit sees one."""
    robot = load_robot(name)
    plant = MujocoPlant(robot)
    model, pm = plant.mj_model, robot.model
    data, pdata = mujoco.MjData(model), pm.createData()
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, v = rng.uniform(-2, 2, pm.nv), rng.uniform(-2, 2, pm.nv)
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        M = pin.crba(pm, pdata, q)
        M = np.triu(M) + np.triu(M, 1).T
        scale = max(1.0, float(np.abs(M).max()))
        np.testing.assert_allclose(_full_m(model, data), M, rtol=0, atol=1e-12 * scale)
        bias = pin.nonLinearEffects(pm, pdata, q, v)
        np.testing.assert_allclose(
            data.qfrc_bias, bias, rtol=0, atol=1e-11 * max(1.0, float(np.abs(bias).max()))
        )
    spec = arm_spec(robot)  # MuJoCo's own reading of the URDF's <limit>
    lower, upper = plant.joint_limits.position_lower, plant.joint_limits.position_upper
    for j, joint in enumerate(spec.joints):
        if np.isfinite(lower[j]) and np.isfinite(upper[j]):
            assert tuple(joint.range) == pytest.approx((lower[j], upper[j]), abs=1e-12), joint.name


def test_armature_adds_exactly_its_value_to_the_diagonal_of_m_on_both_plants() -> None:
    """CRBA (Pinocchio, ``model.armature``) and ``mj_fullM`` (MuJoCo, ``dof_armature``) with the
    Panda's armature minus without: ``diag(a)`` and nothing else."""
    robot = load_robot("panda")
    armature = np.linspace(0.05, 0.35, robot.nv)
    q = np.random.default_rng(3).uniform(-1, 1, robot.nv)
    with_pin, without_pin = Plant(robot, armature=armature), Plant(robot)
    M = [pin.crba(p.model, p.model.createData(), q) for p in (with_pin, without_pin)]
    np.testing.assert_allclose(np.triu(M[0] - M[1]), np.diag(armature), rtol=0, atol=1e-14)
    full = []
    for plant in (MujocoPlant(robot, armature=armature), MujocoPlant(robot)):
        data = mujoco.MjData(plant.mj_model)
        data.qpos[:] = q
        mujoco.mj_forward(plant.mj_model, data)
        full.append(_full_m(plant.mj_model, data))
    np.testing.assert_allclose(full[0] - full[1], np.diag(armature), rtol=0, atol=1e-14)


@pytest.mark.parametrize("engine", ["pinocchio", "mujoco"])
def test_a_turntable_released_against_joint_damping_decays_at_the_rate_it_gives(
    turntable: RobotModel, engine: str
) -> None:
    """τ = 0, damping d, armature a: q̇(t) = q̇₀ exp(−d t / (I + a)) and q(t) = q₀ + q̇₀ (I + a)/d
    (1 − exp(…)), on each plant (RK4 at 1 ms: 1e-10 relative)."""
    d, a, v0 = 0.5, 0.05, 2.0
    plant = PlantOptions(engine=engine, armature=(a,), joint_damping=(d,)).plant(
        turntable, estimates_friction=False
    )
    result = _release(turntable, plant, 0.0, v0, 0.0, 1.0)
    t = result.t  # type: ignore[attr-defined]
    decay = np.exp(-d * t / (ROD_INERTIA + a))
    np.testing.assert_allclose(result.v[:, 0], v0 * decay, rtol=1e-10, atol=0)  # type: ignore[attr-defined]
    np.testing.assert_allclose(
        result.q[:, 0],
        v0 * (ROD_INERTIA + a) / d * (1 - decay),
        rtol=0,
        atol=1e-11,  # type: ignore[attr-defined]
    )


@pytest.mark.parametrize(
    ("torque", "solref", "solimp"),
    [(10.0, None, None), (10.0, (0.05, 1.0), None), (20.0, (0.03, 0.8), (0.8, 0.9, 0.001, 0.5, 2.0))],
)
def test_a_joint_pressed_into_its_soft_limit_settles_where_solref_and_solimp_say(
    turntable: RobotModel, torque: float, solref: tuple[float, float] | None, solimp: tuple[float, ...] | None
) -> None:
    """At rest in the limit, MuJoCo's constraint force holds ``τ`` and its reference acceleration
    ``−K d r`` equals the regularisation's share ``q̈₀ R / A``, ``R/A = (1 − d)/d``; with
    ``K = 1/(dmax² T² ζ²)`` and ``d = dmax`` beyond the width: ``r = q̈₀ (1 − dmax) T² ζ²``
    (``q̈₀ = τ / I``)."""
    options = PlantOptions(engine="mujoco", solref=solref, solimp=solimp)
    plant = options.plant(turntable, estimates_friction=False)
    result = _release(turntable, plant, 0.9, 0.0, torque, 2.0)
    T, zeta = solref or (0.02, 1.0)
    dmax = (solimp or (0.9, 0.95))[1]
    r = torque / ROD_INERTIA * (1 - dmax) * T**2 * zeta**2
    assert r > 0.001  # beyond solimp's width: d = dmax
    q = result.q[:, 0]  # type: ignore[attr-defined]
    assert q[-1] - 1.0 == pytest.approx(r, rel=1e-6)
    assert abs(result.v[-1, 0]) < 1e-9  # type: ignore[attr-defined]


def test_dry_friction_slides_above_its_value_and_creeps_below_it(turntable: RobotModel) -> None:
    """``frictionloss`` F: τ = 3 F slides at (τ − F)/I; τ = F/2 creeps at MuJoCo's regularised rate
    ``q̈₀ (1 − d0)/d0 / B`` (d0 = solimp[0] at zero slip, B = 2/(dmax T), the defaults)."""
    F = 1.0
    plant = PlantOptions(engine="mujoco", frictionloss=(F,)).plant(turntable, estimates_friction=False)
    sliding = _release(turntable, plant, -0.9, 0.0, 3 * F, 0.4)
    v = sliding.v[:, 0]  # type: ignore[attr-defined]
    slope = (v[-1] - v[200]) / (0.4 - 0.2)
    assert slope == pytest.approx(2 * F / ROD_INERTIA, rel=1e-8)
    creeping = _release(turntable, plant, 0.0, 0.0, F / 2, 0.3)
    d0, dmax, T = 0.9, 0.95, 0.02
    creep = (F / 2) / ROD_INERTIA * (1 - d0) / d0 / (2 / (dmax * T))
    assert creeping.v[-1, 0] == pytest.approx(creep, rel=1e-6)  # type: ignore[attr-defined]


def test_mujocos_own_rk4_with_the_law_as_control_callback_gives_the_plants_run() -> None:
    """``mj_step`` (integrator RK4) with ``pd`` installed as ``mjcb_control``: MuJoCo calls it at
    t, t + dt/2 (twice) and t + dt with the reference of that instant; its run equals the MuJoCo
    plant's (the engine's RK4 on ``mj_forward``) to rounding over 1 s."""
    robot = load_robot()
    trajectory = default_trajectory(robot)
    spec = RunSpec(law="pd", plant=PlantOptions(engine="mujoco"), simulation=SimulationConfig(duration=1.0))
    controller, plant = spec.build(robot)
    ours = simulate(controller, plant, trajectory, spec.simulation)
    model = plant.mj_model
    model.opt.timestep = 1e-3
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = ours.q[0], ours.v[0]
    calls = []

    def law(m: object, d: object) -> None:
        half = round(d.time / 5e-4)  # type: ignore[attr-defined]
        ref = trajectory.sample(half * 5e-4)
        tau, _ = evaluate(controller, d.qpos.copy(), d.qvel.copy(), ref.q, ref.v, ref.a)  # type: ignore[attr-defined]
        d.qfrc_applied[:] = tau  # type: ignore[attr-defined]
        calls.append(half)

    mujoco.set_mjcb_control(law)
    try:
        q = [data.qpos.copy()]
        for _ in range(1000):
            mujoco.mj_step(model, data)
            q.append(data.qpos.copy())
    finally:
        mujoco.set_mjcb_control(None)
    assert calls[:8] == [0, 1, 1, 2, 2, 3, 3, 4]  # the stages: t, t + dt/2 twice, t + dt
    np.testing.assert_allclose(np.array(q), ours.q, rtol=0, atol=1e-12)


def _both(robot: RobotModel, law: str, duration: float, **plant: object) -> tuple[object, object]:
    runs = []
    for engine in ("pinocchio", "mujoco"):
        spec = RunSpec(
            law=law,
            plant=PlantOptions(engine=engine, **plant),
            simulation=SimulationConfig(duration=duration),  # type: ignore[arg-type]
        )
        controller, built = spec.build(robot)
        runs.append(simulate(controller, built, default_trajectory(robot), spec.simulation))
    return runs[0], runs[1]


@pytest.mark.parametrize(
    ("robot", "law"),
    [("twolink", "pd"), ("twolink", "adaptive"), ("ur5", "computed-torque"), ("panda", "osc")],
)
def test_the_same_law_on_both_plants_is_the_same_run(robot: str, law: str) -> None:
    """Every extra effect off, RK4 at the run's dt: the joint trajectories agree to 1e-8 rad (1 s
    here; 30 s in test_mujoco_equality.py)."""
    ideal, mj = _both(load_robot(robot), law, 1.0)
    assert np.abs(ideal.q - mj.q).max() <= 1e-8  # type: ignore[attr-defined]


def test_armature_and_damping_on_both_plants_are_the_same_run() -> None:
    """The effects both plants have give the same motion on both (computed-torque on the UR5)."""
    ideal, mj = _both(load_robot("ur5"), "computed-torque", 1.0, armature="arm", joint_damping=(0.5,))
    assert np.abs(ideal.q - mj.q).max() <= 1e-8  # type: ignore[attr-defined]
    assert np.abs(ideal.q - _both(load_robot("ur5"), "computed-torque", 1.0)[0].q).max() > 1e-4  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    ("options", "config"),
    [
        ({"saturate": True}, {"q0_offset": 0.5}),
        ({"wrench": Wrench((0.0, 20.0, 0.0, 0.0, 0.0, 1.0), 0.2, 0.6)}, {}),
        ({"payload_step": PayloadStep(2.0, 0.5)}, {}),
        ({"sensor_noise": SensorNoise(0.001, 0.01, seed=3)}, {}),
        ({"delay": 3}, {}),
        ({}, {"control_period": 0.005}),
        ({"friction": "on"}, {}),
        ({"friction": "on", "friction_smoothing": 0.01}, {"method": "adaptive"}),
    ],
    ids=[
        "saturate",
        "wrench",
        "payload-step",
        "sensor-noise",
        "delay",
        "control-period",
        "friction",
        "adaptive",
    ],
)
def test_every_option_of_the_pinocchio_plant_acts_the_same_on_mujoco(
    options: dict[str, object], config: dict[str, object]
) -> None:
    """pd on the twolink for 1 s with one option on: the MuJoCo plant's run is the Pinocchio
    plant's to 1e-8 rad (and the option changed the run)."""
    robot = load_robot()
    runs = {}
    for engine in ("pinocchio", "mujoco"):
        spec = RunSpec(
            law="pd",
            plant=PlantOptions(engine=engine, **options),  # type: ignore[arg-type]
            simulation=SimulationConfig(duration=1.0, **config),  # type: ignore[arg-type]
        )
        controller, plant = spec.build(robot)
        runs[engine] = simulate(controller, plant, default_trajectory(robot), spec.simulation)
    assert np.abs(runs["pinocchio"].q - runs["mujoco"].q).max() <= 1e-8
    plain = _both(robot, "pd", 1.0)[0]
    if config.get("method") != "adaptive":
        assert np.abs(plain.q - runs["mujoco"].q).max() > 1e-6  # type: ignore[attr-defined]


@pytest.mark.parametrize("integrator", ["rk4", "implicitfast"])
def test_a_mujoco_batch_equals_its_single_runs(integrator: str) -> None:
    """Three runs of adaptive on the twolink in one ``mujoco.batch`` (the law once for the three)
    equal the three single runs (``MjData``) to 1e-12 rad."""
    robot = load_robot()
    spec = RunSpec(
        law="adaptive",
        plant=PlantOptions(engine="mujoco", integrator=integrator, frictionloss="arm", armature="arm"),
        simulation=SimulationConfig(duration=0.5),
    )
    controller, plant = spec.build(robot)
    trajectory = default_trajectory(robot)
    offsets = np.array([[0.1, -0.1], [0.3, 0.2], [-0.2, 0.05]])
    batch = simulate_batch(controller, plant, trajectory, spec.simulation, q0_offsets=offsets, record=True)
    for i, offset in enumerate(offsets):
        config = SimulationConfig(duration=0.5, q0_offset=tuple(offset))
        single = simulate(controller, plant, trajectory, config)
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-12)  # type: ignore[index]


def test_mujocos_implicitfast_holds_the_law_over_the_step_and_converges_to_rk4() -> None:
    """``implicitfast`` evaluates the law once per step (as ``--control-period dt``): its run is
    first order in dt, 10× closer to the RK4 run at dt/10."""
    robot = load_robot()
    trajectory = default_trajectory(robot)
    reference = _both(robot, "pd", 0.5)[1]
    gaps = []
    for dt in (1e-3, 1e-4):
        spec = RunSpec(
            law="pd",
            plant=PlantOptions(engine="mujoco", integrator="implicitfast"),
            simulation=SimulationConfig(duration=0.5, dt=dt),
        )
        controller, plant = spec.build(robot)
        run = simulate(controller, plant, trajectory, spec.simulation)
        stride = round(1e-3 / dt)
        gaps.append(np.abs(run.q[::stride] - reference.q).max())  # type: ignore[attr-defined]
    assert 5 < gaps[0] / gaps[1] < 20


@pytest.mark.parametrize("name", ["twolink", "panda"])
def test_a_payload_is_the_same_point_mass_on_both_plants(name: str) -> None:
    """``--payload`` (the robot's) and a picked-up payload step: MuJoCo's model after the step
    gives Pinocchio's M and C q̇ + g."""
    robot = load_robot(name, payload=1.5)
    options = PlantOptions(engine="mujoco", payload_step=PayloadStep(2.0, 0.5))
    after = options.plant(robot, estimates_friction=False).after_payload()
    assert isinstance(after, MujocoPlant) and after.carried == 2.0
    model, data = after.mj_model, mujoco.MjData(after.mj_model)
    q, v = np.random.default_rng(0).uniform(-1, 1, (2, robot.nv))
    data.qpos[:], data.qvel[:] = q, v
    mujoco.mj_forward(model, data)
    M = pin.crba(after.model, after.model.createData(), q)
    np.testing.assert_allclose(_full_m(model, data), np.triu(M) + np.triu(M, 1).T, rtol=0, atol=1e-12)
    bias = pin.nonLinearEffects(after.model, after.model.createData(), q, v)
    np.testing.assert_allclose(data.qfrc_bias, bias, rtol=0, atol=1e-11)


def test_a_law_that_believes_the_effects_has_them_in_its_model() -> None:
    """``believed_effects``: computed torque's ``τ = M q̈_r + C q̇_r + g − K s`` with the plant's
    armature in its M is the law without it plus ``diag(a) q̈_r`` (fixed gains; the UR5 at a
    random state), adaptive-friction's believed viscous friction gains the joint damping; the
    option is refused without an effect to believe."""
    robot = load_robot("ur5")
    rng = np.random.default_rng(5)
    q, v, q_des, v_des, a_des = rng.uniform(-1, 1, (5, robot.nv))
    gains = (("k", 10.0), ("lam", 5.0))
    plant = PlantOptions(armature="arm")
    taus = []
    for believed in (False, True):
        spec = RunSpec(law="computed-torque", gains=gains, plant=plant, believed_effects=believed)
        taus.append(evaluate(spec.build(robot).controller, q, v, q_des, v_des, a_des)[0])
    a_r = a_des - 5.0 * (v - v_des)
    np.testing.assert_allclose(taus[1] - taus[0], 0.1 * a_r, rtol=0, atol=1e-12)
    twolink = load_robot()
    spec = RunSpec(
        law="adaptive-friction", plant=PlantOptions(joint_damping=(0.5, 0.25)), believed_effects=True
    )
    believed = spec.build(twolink).controller.friction  # type: ignore[attr-defined]
    assert believed.viscous == pytest.approx((0.4 + 0.5, 0.2 + 0.25))
    with pytest.raises(InvalidParameterError, match="--believe-effects"):
        RunSpec(law="pd", believed_effects=True).check_effective(twolink)
