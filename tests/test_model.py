"""Tests of twolink_pin.model: what load_robot reads from the URDF, and payloads.

The shipped URDF must give the report's parameters p = (3.4, 0.4, 0.3) kg·m², link lengths
(0.38, 0.24) m and motor limits (240, 40) N·m; a point-mass payload must change p exactly
as the closed form says.
"""

from __future__ import annotations

import importlib.metadata
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.dynamics import mass_matrix
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel, load_robot, twolink_urdf_path
from twolink_pin.model.parameters import InertialParameterMap, inertial_parameters
from twolink_pin.twolink import closed_form
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap

L1, L2 = 0.38, 0.24
REPORT_P = np.array([3.4, 0.4, 0.3])


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return load_robot()


def test_p_read_from_urdf_equals_report_values(robot: RobotModel) -> None:
    """p read from the shipped URDF is the report's (3.4, 0.4, 0.3) kg·m² to 1e-12."""
    assert isinstance(robot.parameter_map, TwoLinkLumpedMap)
    assert robot.parameter_map.names == ("p1", "p2", "p3")
    np.testing.assert_allclose(robot.p, REPORT_P, rtol=0, atol=1e-12)


def test_link_lengths_are_report_values(robot: RobotModel) -> None:
    """Joint 1 -> joint 2 is L1 = 0.38 m and joint 2 -> end effector is L2 = 0.24 m."""
    np.testing.assert_allclose(robot.link_lengths, [L1, L2], rtol=0, atol=1e-15)
    assert robot.ee_frame == "ee_link"


def test_torque_limits_are_report_values(robot: RobotModel) -> None:
    """The URDF effort limits are the report's motors: 240 N·m (base) and 40 N·m (elbow)."""
    np.testing.assert_allclose(robot.torque_limits, [240.0, 40.0], rtol=0, atol=0)


def test_model_arrays_are_read_only(robot: RobotModel) -> None:
    """p, link lengths and torque limits cannot be modified in place."""
    for array in (robot.p, robot.link_lengths, robot.torque_limits):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 0.0


@pytest.mark.parametrize("joint", [1, 2])
def test_urdf_inertias_are_physically_valid(robot: RobotModel, joint: int) -> None:
    """Each body in the Pinocchio model has mass > 0 and a rotational inertia about its
    centre of mass that is symmetric positive definite with principal moments obeying the
    triangle inequality (I_a + I_b >= I_c for every permutation)."""
    inertia = robot.model.inertias[joint]
    assert inertia.mass > 0
    about_com = np.asarray(inertia.inertia)
    np.testing.assert_allclose(about_com, about_com.T, rtol=0, atol=1e-15)
    moments = np.linalg.eigvalsh(about_com)
    assert np.all(moments > 0), moments
    total = moments.sum()
    for moment in moments:
        assert total - moment >= moment, moments


def test_urdf_inertials_are_the_documented_choice(robot: RobotModel) -> None:
    """The bodies are m1 = 10 kg at c1 = 0.19 m, Izz1 = 1.689 kg·m², and m2 = 125/19 kg at
    c2 = 0.12 m, Izz2 = 5.8/19 kg·m² (about the centre of mass), as docs/model.md derives."""
    body1, body2 = robot.model.inertias[1], robot.model.inertias[2]
    np.testing.assert_allclose(
        [body1.mass, body1.lever[0], body1.inertia[2, 2]], [10.0, 0.19, 1.689], rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        [body2.mass, body2.lever[0], body2.inertia[2, 2]], [125 / 19, 0.12, 5.8 / 19], rtol=0, atol=1e-12
    )


@settings(max_examples=30, deadline=None)
@given(m=st.floats(min_value=0.0, max_value=5.0, allow_nan=False))
def test_payload_changes_p_per_closed_form(m: float) -> None:
    """A point mass m [kg] at the end effector gives p1 += m (L1² + L2²), p2 += m L2²,
    p3 += m L1 L2."""
    loaded = load_robot(payload=m)
    expected = REPORT_P + m * np.array([L1**2 + L2**2, L2**2, L1 * L2])
    np.testing.assert_allclose(loaded.p, expected, rtol=0, atol=1e-12)
    assert loaded.payload == m


@settings(max_examples=30, deadline=None)
@given(
    m=st.floats(min_value=0.0, max_value=5.0, allow_nan=False),
    q=st.lists(st.floats(min_value=-math.pi, max_value=math.pi), min_size=2, max_size=2),
)
def test_payload_mass_matrix_equals_closed_form_with_new_p(m: float, q: list[float]) -> None:
    """CRBA's M(q) of the payload model equals the report's closed-form M(q) with the
    payload-shifted p."""
    loaded = load_robot(payload=m)
    q_arr = np.array(q)
    p_new = REPORT_P + m * np.array([L1**2 + L2**2, L2**2, L1 * L2])
    np.testing.assert_allclose(
        mass_matrix(loaded.model, loaded.create_data(), q_arr),
        closed_form.mass_matrix(q_arr, p_new),
        rtol=0,
        atol=1e-12,
    )


@pytest.mark.parametrize(
    ("payload", "text"),
    [
        (-1.0, "payload = -1.0 is invalid: expected a finite mass >= 0 kg"),
        (float("nan"), "payload = nan is invalid: expected a finite mass >= 0 kg"),
        (float("inf"), "payload = inf is invalid: expected a finite mass >= 0 kg"),
    ],
)
def test_bad_payload_raises_naming_the_value(payload: float, text: str) -> None:
    """A negative or non-finite payload raises InvalidParameterError whose message names the
    value and the valid range; the error keeps the value."""
    with pytest.raises(InvalidParameterError) as info:
        load_robot(payload=payload)
    assert str(info.value) == text
    assert info.value.name == "payload"
    assert info.value.value is payload


def test_urdf_copied_outside_the_package_loads(tmp_path: Path) -> None:
    """A copy of the URDF in an arbitrary directory loads and gives the same model."""
    copy = tmp_path / "elsewhere" / "arm.urdf"
    copy.parent.mkdir()
    shutil.copyfile(twolink_urdf_path(), copy)
    loaded = load_robot(copy, parameter_map=TwoLinkLumpedMap)
    assert loaded.urdf_path == copy
    assert loaded.name == "arm" and loaded.gain_presets == {}  # not the catalog's file: generic profile
    np.testing.assert_allclose(loaded.p, REPORT_P, rtol=0, atol=1e-12)
    np.testing.assert_allclose(loaded.link_lengths, [L1, L2], rtol=0, atol=1e-15)


def _double_pendulum_urdf() -> Path | None:
    """The double pendulum of example-robot-data, located from the installed distribution.

    example-robot-data 6 ships as a cmeel wheel with no ``example_robot_data`` Python
    module, so the file is found among the distribution's files.
    """
    try:
        from example_robot_data import getModelPath
    except ImportError:
        pass
    else:  # pragma: no cover - older example-robot-data with its Python loader
        path = Path(getModelPath("double_pendulum_description/urdf/double_pendulum.urdf"))
        return path / "double_pendulum_description/urdf/double_pendulum.urdf"
    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        return None
    for file in files:
        if str(file).endswith("double_pendulum_description/urdf/double_pendulum.urdf"):
            return Path(str(file.locate()))
    return None


def test_example_robot_data_double_pendulum_loads_with_inertial_map() -> None:
    """example-robot-data's double pendulum (joints about x, not a planar-z 2R arm) loads
    with InertialParameterMap when asked, and its p is Pinocchio's stacked inertial parameters π."""
    path = _double_pendulum_urdf()
    if path is None or not path.is_file():
        pytest.skip("example-robot-data's double_pendulum.urdf not found (pip install example-robot-data)")
    pendulum = load_robot(path, parameter_map=InertialParameterMap)
    assert pendulum.nv == 2
    assert not TwoLinkLumpedMap.applies_to(pendulum.model)
    assert isinstance(pendulum.parameter_map, InertialParameterMap)
    assert pendulum.p.shape == (20,)
    np.testing.assert_allclose(pendulum.p, inertial_parameters(pendulum.model), rtol=0, atol=0)
    np.testing.assert_allclose(
        pendulum.parameter_map.matrix, np.eye(20), rtol=0, atol=0
    )  # identity map: Y_p = Y_π
    np.testing.assert_allclose(pendulum.p[[0, 10]], [0.26703, 0.33238], rtol=0, atol=1e-12)  # link masses
