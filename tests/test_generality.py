"""Nothing but the twolink's parameter map assumes the twolink: other URDF arms from
example-robot-data (with gravity) load, their dynamics identities hold, and the
controllers track joint-space trajectories on them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import (
    Adaptive,
    AdaptiveGains,
    ComputedTorque,
    InvalidURDFError,
    JointTrajectory,
    Plant,
    SimulationConfig,
    SlotineLiGains,
    load_robot,
    simulate,
)
from twolink_pin.dynamics import regressor
from twolink_pin.model import example_robot_urdf
from twolink_pin.model.base_parameters import BaseParameterMap
from twolink_pin.model.parameters import InertialParameterMap, inertial_parameters

ROBOTS = ["double_pendulum_description/urdf/double_pendulum.urdf", "asr_twodof_description/urdf/TwoDofs.urdf"]


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request: pytest.FixtureRequest):
    return load_robot(str(example_robot_urdf(request.param)))


def test_unknown_example_robot_is_named() -> None:
    with pytest.raises(InvalidURDFError, match=r"no_such_robot\.urdf"):
        example_robot_urdf("no_such_robot.urdf")


def test_a_urdf_by_path_lists_the_installed_robots_once_per_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A path is compared with every catalog robot's URDF; the distribution's ~1000 files are
    listed once, not once per robot and per load (0.1 s each: six per load before)."""
    import importlib.metadata

    from twolink_pin.model import catalog, robot_data

    listed = []
    files = importlib.metadata.files

    def counted(name: str) -> object:
        listed.append(name)
        return files(name)

    path = tmp_path / "my_pendulum.urdf"
    path.write_bytes(example_robot_urdf(ROBOTS[0]).read_bytes())
    monkeypatch.setattr(importlib.metadata, "files", counted)
    robot_data._located.cache_clear()  # what this process looked up before is forgotten
    robot_data._distribution_files.cache_clear()
    for _ in range(3):
        assert catalog.resolve(path)[1].name == "my_pendulum"
    assert catalog.resolve(example_robot_urdf(ROBOTS[0]))[1].name == "double_pendulum"
    assert listed == ["example-robot-data"]


def test_a_catalog_urdf_by_path_gets_its_profile_and_the_base_parameters(robot) -> None:
    """example-robot-data's file by path is the catalog's robot: its name, no gain presets, and
    p = β, the identifiable base parameters (4 for the horizontal arm, 6 under gravity)."""
    assert robot.name in ("double_pendulum", "asr_twodof") and robot.gain_presets == {}
    assert isinstance(robot.parameter_map, BaseParameterMap)
    assert robot.parameter_map.size == {"double_pendulum": 6, "asr_twodof": 4}[robot.name]


def test_a_urdf_outside_the_catalog_gets_the_generic_profile(tmp_path: Path) -> None:
    """A copy of the double pendulum's URDF elsewhere: named after its file, no presets, a home the
    loader chose (hanging: as dexterous as anywhere, at the middle of its unlimited joints: 0),
    its base parameters; p = π on request."""
    path = tmp_path / "my_pendulum.urdf"
    path.write_bytes(example_robot_urdf(ROBOTS[0]).read_bytes())
    robot = load_robot(path)
    assert robot.name == "my_pendulum" and robot.gain_presets == {}
    assert robot.profile.home_source.startswith("chosen")
    np.testing.assert_array_equal(robot.home, [0.0, 0.0])
    assert isinstance(robot.parameter_map, BaseParameterMap) and robot.parameter_map.size == 6
    full = load_robot(path, parameter_map=InertialParameterMap)
    assert full.parameter_map.size == 20
    np.testing.assert_array_equal(full.p, inertial_parameters(full.model))


def test_the_double_pendulum_feels_gravity_and_the_planar_arm_does_not() -> None:
    """Joints about x under gravity along −z (pendulum): |g(q)| > 0.1 N·m; the asr arm's joint axes
    are vertical: g(q) = 0 (to 1e-12)."""
    rng = np.random.default_rng(1)
    for relative, felt in zip(ROBOTS, (True, False)):
        robot = load_robot(str(example_robot_urdf(relative)))
        data = robot.create_data()
        worst = max(
            float(
                np.abs(pin.computeGeneralizedGravity(robot.model, data, rng.uniform(-3, 3, robot.nq))).max()
            )
            for _ in range(5)
        )
        assert (worst > 0.1) if felt else (worst < 1e-9), (relative, worst)


def test_polarised_regressor_includes_gravity_once(robot) -> None:
    """Y_π(q, v, w, a) π = M a + C(q, v) w + g(q), checked with Pinocchio's separate terms."""
    data = robot.create_data()
    rng = np.random.default_rng(2)
    pi = inertial_parameters(robot.model)
    for _ in range(20):
        q, v, w, a = rng.uniform(-2, 2, size=(4, robot.nv))
        M = pin.crba(robot.model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        C = pin.computeCoriolisMatrix(robot.model, data, q, v).copy()
        g = pin.computeGeneralizedGravity(robot.model, data, q).copy()
        np.testing.assert_allclose(
            regressor(robot.model, data, q, v, w, a) @ pi, M @ a + C @ w + g, atol=1e-10
        )


def _trajectory(robot) -> JointTrajectory:
    via = np.array([[0.0, 0.0], [0.6, -0.4], [0.2, 0.8], [0.0, 0.0]])[:, : robot.nv]
    return JointTrajectory.from_via_q((0.0, 1.0, 2.0, 3.0), via)


def test_computed_torque_tracks_on_another_robot(robot) -> None:
    controller = ComputedTorque(robot, SlotineLiGains(k=0.05, lam=10.0))
    result = simulate(
        controller, Plant(robot), _trajectory(robot), SimulationConfig(duration=8.0, q0_offset=(0.05, -0.05))
    )
    assert np.abs(result.e[result.t > 7.0]).max() < 1e-6  # from 0.05 rad: exponential convergence


def test_adaptive_with_twenty_parameters_keeps_v_non_increasing(robot) -> None:
    """V = ½ sᵀ M s + ½ p̃ᵀ Γ⁻¹ p̃ with all 20 of Pinocchio's parameters (gravity included)."""
    gains = AdaptiveGains(k=0.05, gamma=1.0, lam=10.0, initial_estimate=0.8)
    controller = Adaptive(robot, gains)
    result = simulate(
        controller, Plant(robot), _trajectory(robot), SimulationConfig(duration=2.0, q0_offset=(0.05, -0.05))
    )
    data = robot.create_data()
    s = result.edot + gains.lam * result.e
    p_err = result.p_hat - result.p_true
    V = np.array(
        [
            0.5 * s[k] @ pin.crba(robot.model, data, result.q[k]) @ s[k]
            + 0.5 * p_err[k] @ (p_err[k] * gains.gamma)
            for k in range(len(result.t))
        ]
    )
    assert np.diff(V).max() < 1e-9 * V[0]
