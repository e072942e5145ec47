"""The task-space laws' task inertia ``Λ = (J M⁻¹ Jᵀ)⁻¹`` (controllers/task_space.py): the exact
inverse away from singularities, the damped one below the threshold (closed forms on 2 × 2
matrices whose eigenvectors are (1, ±1)/√2), and every run of a batch as it is alone."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.controllers.task_space import SINGULAR_RATIO, SingularityWarning, TaskInertia
from twolink_pin.model import load_robot

EPS2 = SINGULAR_RATIO**2


def unit_pair(c: float, d: tuple[float, float] = (1.0, 1.0)) -> np.ndarray:
    """``D [[1, c], [c, 1]] D`` with ``D = diag(d)``: normalised eigenvalues ``1 ∓ c``."""
    D = np.diag(d)
    return D @ np.array([[1.0, c], [c, 1.0]]) @ D


def pair_inverse(low: float, high: float, d: tuple[float, float] = (1.0, 1.0)) -> np.ndarray:
    """``D⁻¹ U diag(low, high) Uᵀ D⁻¹`` with ``U``'s columns (1, −1)/√2 and (1, 1)/√2."""
    core = 0.5 * np.array([[low + high, high - low], [high - low, low + high]])
    Dinv = np.diag(1.0 / np.asarray(d))
    return Dinv @ core @ Dinv


def test_task_inertia_is_the_inverse_of_the_pandas_task_matrix() -> None:
    robot = load_robot("panda")
    data = robot.model.createData()
    q = robot.home
    J = pin.computeFrameJacobian(
        robot.model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )
    M = pin.crba(robot.model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    A = J @ np.linalg.solve(M, J.T)
    inertia = TaskInertia("osc")
    Lam = inertia(A[None], 0.0)[0]
    assert np.abs(Lam @ A - np.eye(6)).max() < 1e-10
    assert np.abs(Lam - Lam.T).max() <= 1e-12 * np.abs(Lam).max()
    assert inertia.damped == 0


def test_below_the_threshold_the_inertia_is_damped_with_the_closed_form() -> None:
    s = 0.5 * SINGULAR_RATIO  # the normalised matrix's smallest eigenvalue, 1 − c
    d = (2.0, 0.5)  # rows in different units
    inertia = TaskInertia("osc")
    with pytest.warns(
        SingularityWarning, match=r"osc: near a singularity at t = 0\.25 s .* 0\.0005 < 0\.001"
    ):
        Lam = inertia(unit_pair(1.0 - s, d)[None], 0.25)[0]
    high = 2.0 - s
    expected = pair_inverse(s / (s * s + (EPS2 - s * s)), high / (high * high), d)
    np.testing.assert_allclose(Lam, expected, rtol=1e-9)
    assert inertia.damped == 1


def block(pair: np.ndarray, corner: float = 1.0) -> np.ndarray:
    """``pair`` and a decoupled third row with ``corner`` on the diagonal, 3 × 3."""
    out = np.diag([1.0, 1.0, corner])
    out[:2, :2] = pair
    return out


def test_each_run_of_a_batch_is_computed_as_it_is_alone() -> None:
    # Far from the threshold; just above it but not certified by ‖B⁻¹‖_F (two eigenvalues of
    # 1.2 ε: B = a I + (1 − a) 11ᵀ); below it; and at the singularity (exactly singular: LU
    # stops, and the batch's inverse goes run by run).
    a = 1.2 * SINGULAR_RATIO
    matrices = [block(unit_pair(0.3, (3.0, 0.2))), a * np.eye(3) + (1 - a) * np.ones((3, 3))]
    matrices += [block(unit_pair(1 - 0.5 * SINGULAR_RATIO)), block(np.ones((2, 2)))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)
        inertia = TaskInertia("osc")
        batch = inertia(np.stack(matrices), 0.0)
        alone = [TaskInertia("osc")(m[None], 0.0)[0] for m in matrices]
    assert inertia.damped == 1
    for run, one in zip(batch, alone, strict=True):
        assert np.array_equal(run, one)
    np.testing.assert_allclose(batch[0], np.linalg.inv(matrices[0]), rtol=1e-12)
    sherman_morrison = np.eye(3) / a - (1 - a) / (a * (a + 3 * (1 - a))) * np.ones((3, 3))
    np.testing.assert_allclose(batch[1], sherman_morrison, rtol=1e-9)  # not damped
    np.testing.assert_allclose(
        batch[3], block(pair_inverse(0.0, 2.0 / (4.0 + EPS2)), 1 / (1 + EPS2)), atol=1e-9
    )  # ρ = ε
