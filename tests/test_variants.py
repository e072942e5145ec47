"""Payload variants written as URDF (yourdfpy) agree with the in-Pinocchio payload."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin import InvalidParameterError, InvalidURDFError, load_robot, twolink_urdf_path
from twolink_pin.model.payload import POINT_MASS_INERTIA, payload_urdf, write_payload_urdf
from twolink_pin.twolink.closed_form import mass_matrix
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap


@settings(max_examples=10, deadline=None)
@given(mass=st.floats(min_value=0.05, max_value=5.0))
def test_written_payload_urdf_gives_the_same_p_as_load_robot(tmp_path_factory, mass: float) -> None:
    """Second method: the yourdfpy-edited file and Pinocchio's added inertia give equal p."""
    path = write_payload_urdf(twolink_urdf_path(), mass, tmp_path_factory.mktemp("v") / "pl.urdf")
    from_file = load_robot(
        path, parameter_map=TwoLinkLumpedMap
    )  # a file outside the catalog: generic profile
    in_memory = load_robot(payload=mass)
    # The written point mass carries POINT_MASS_INERTIA about its centre (adds to p1, p2).
    np.testing.assert_allclose(from_file.p, in_memory.p, atol=3 * POINT_MASS_INERTIA)
    l1, l2 = 0.38, 0.24
    expected = np.array([3.4 + mass * (l1**2 + l2**2), 0.4 + mass * l2**2, 0.3 + mass * l1 * l2])
    np.testing.assert_allclose(from_file.p, expected, atol=1e-8)
    q = np.array([0.3, -1.1])
    data = from_file.create_data()
    import pinocchio as pin

    np.testing.assert_allclose(pin.crba(from_file.model, data, q), mass_matrix(q, expected), atol=1e-8)


def test_payload_must_be_positive() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"payload = -1\.0 is invalid: expected a finite mass > 0 kg"
    ):
        payload_urdf(twolink_urdf_path(), -1.0)


def test_a_link_with_mass_carries_the_sum_of_its_body_and_the_payload(tmp_path: Path) -> None:
    """Issue 28 §5: a link with an <inertial> of its own (the UR5's tool0) is no refusal: the
    body read back is Pinocchio's sum of the link's body and a point mass at its origin."""
    import pinocchio as pin

    from twolink_pin.model import load_robot

    out = tmp_path / "heavier_link2.urdf"
    out.write_text(payload_urdf(twolink_urdf_path(), 1.0, link="link2"))
    before, after = load_robot(twolink_urdf_path()).model, load_robot(out).model
    expected = before.inertias[2] + pin.Inertia(1.0, np.zeros(3), np.zeros((3, 3)))
    np.testing.assert_allclose(
        after.inertias[2].toDynamicParameters(), expected.toDynamicParameters(), rtol=1e-12, atol=1e-12
    )


def test_unknown_link_is_named() -> None:
    with pytest.raises(InvalidURDFError, match="link 'gripper': no such link"):
        payload_urdf(twolink_urdf_path(), 1.0, link="gripper")
