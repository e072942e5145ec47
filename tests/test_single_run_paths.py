"""The single-run (N = 1) fast paths compute what the general path computes, bit for bit
(a rotation error's zero may differ in sign):
the rotation error of one run against its row of a batch of two, and
:mod:`twolink_pin.small_linalg` against ``numpy.linalg`` (the same LAPACK routine behind
less Python)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.controllers.task_space import rotation_error
from twolink_pin.small_linalg import inv, solve

EXAMPLES = settings(max_examples=200, deadline=None)
scales = st.sampled_from([0.0, 1e-10, 1e-7, 1e-4, 1e-2, 1.0, 3.0, np.pi - 1e-7])
# Components below 1e-100 are read as 0: a rotation that small has subnormal entries, which the
# batch's BLAS product (0.5 a + (-0.5) b summed with FMA) and the one run's floats (0.5 a − 0.5 b)
# round differently (hypothesis found offset [0, 2.2e-311, 0.5]); no arm's state lives there.
vectors = st.lists(st.floats(-1.0, 1.0).map(lambda x: x if abs(x) >= 1e-100 else 0.0), min_size=3, max_size=3)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@EXAMPLES
@given(axis=vectors, offset=vectors, scale=scales, base=st.floats(0.0, 3.0))
def test_one_run_rotation_error_is_its_row_of_a_batch(
    axis: list[float], offset: list[float], scale: float, base: float
) -> None:
    R_des = pin.exp3(base * np.asarray(axis))
    direction = np.asarray(offset)
    norm = np.linalg.norm(direction)
    R = pin.exp3(scale * direction / norm) @ R_des if norm > 1e-3 else R_des
    alone = rotation_error(R[None], R_des[None])
    batch = rotation_error(np.stack([R, R_des]), R_des[None])
    # bit for bit but for the sign of a zero: the batch's BLAS product adds +0 terms, the one
    # run's floats subtract 0 − 0 as written (hypothesis found [0, 1, -0] against [0, 1, 0])
    assert _same_bits(alone[0] + 0.0, batch[0] + 0.0)
    assert _same_bits(batch[1], np.zeros(3))  # no rotation: exactly zero


def test_rotation_error_is_the_log_of_the_relative_rotation() -> None:
    # A second method: Pinocchio's log3 on R R_dᵀ, to rounding (one run and near π).
    rng = np.random.default_rng(3)
    for angle in (1e-8, 0.3, 2.0, np.pi - 1e-8):
        axis = rng.normal(size=3)
        w = angle * axis / np.linalg.norm(axis)
        R_des = pin.exp3(rng.normal(size=3))
        R = pin.exp3(w) @ R_des
        np.testing.assert_allclose(rotation_error(R[None], R_des[None])[0], pin.log3(R @ R_des.T), atol=1e-9)


def test_small_linalg_is_numpy_linalg_bit_for_bit() -> None:
    rng = np.random.default_rng(4)
    A = rng.normal(size=(3, 7, 7)) + 7 * np.eye(7)
    B = rng.normal(size=(3, 7, 6))
    assert _same_bits(solve(A, B), np.linalg.solve(A, B))
    assert _same_bits(solve(A[:1], B[:1]), np.linalg.solve(A[:1], B[:1]))
    assert _same_bits(inv(A), np.linalg.inv(A))
    b32 = B.astype(np.float32)  # another dtype: numpy.linalg's own promotion
    assert _same_bits(solve(A, b32), np.linalg.solve(A, b32))


def test_small_linalg_raises_as_numpy_on_a_singular_matrix() -> None:
    singular = np.ones((1, 3, 3))
    with pytest.raises(np.linalg.LinAlgError, match="Singular matrix"):
        inv(singular)
    with pytest.raises(np.linalg.LinAlgError, match="Singular matrix"):
        solve(singular, np.ones((1, 3, 1)))
    # A NaN state is no singular matrix for LAPACK: NaN out, as numpy.linalg gives it
    nan = np.full((1, 3, 3), np.nan)
    assert (
        np.isnan(solve(nan, np.ones((1, 3, 1)))).all()
        == np.isnan(np.linalg.solve(nan, np.ones((1, 3, 1)))).all()
    )


@pytest.mark.parametrize("name", ["twolink", "panda"])
def test_one_run_saturated_acceleration_is_the_plants(name: str) -> None:
    # The engine's clip (maximum then minimum against rows) against Plant.acceleration
    # (numpy.clip through motor_torque): the same ABA input, so the same bits; torques
    # beyond the limits both ways, and a NaN passed through as NaN.
    from twolink_pin.model import load_robot
    from twolink_pin.plant import Plant
    from twolink_pin.simulation.forward import single_run_dynamics

    robot = load_robot(name)
    plant = Plant(robot, saturate=True)
    accel = single_run_dynamics(plant)
    rng = np.random.default_rng(5)
    for scale in (0.5, 3.0):
        q, v = rng.normal(size=(1, robot.nv)), rng.normal(size=(1, robot.nv))
        tau = scale * plant.limits * rng.choice([-1.0, 1.0], size=(1, robot.nv))
        assert _same_bits(accel(q, v, tau)[0], plant.acceleration(q[0], v[0], tau[0]))
    tau[0, 0] = np.nan
    assert np.isnan(accel(q, v, tau)).all() == np.isnan(plant.acceleration(q[0], v[0], tau[0])).all()
