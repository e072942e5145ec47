"""Defaults from the arm's whole inertia (issue 50 §1): at the home pose every robot-derived gain
puts the closed loop's modes at the stated rates — the generalised eigenvalues of (K, M(q₀)),
M from Pinocchio's CRBA here, and the eigenvalues of the whole closed loop linearised by
:mod:`twolink_pin.simulation.step_check` (a second method) — on every catalog arm and on random
arms (2–7 joints, masses and inertias over four decades, offset centres of mass). The twolink's
report gains are unchanged."""

from __future__ import annotations

import functools
import sys
import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.controllers import PID, ComputedTorque, Impedance, PDFeedforward, PDGravity, WrongModel
from twolink_pin.controllers.computed_torque import MODE_SPREAD, SLIDING_RATE
from twolink_pin.controllers.impedance import POSTURE_FREQUENCY
from twolink_pin.controllers.pd import NATURAL_FREQUENCY
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.model.catalog import names
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig
from twolink_pin.simulation.step_check import initial_law_input, linearise
from twolink_pin.trajectory import Trajectory, TrajectorySample
from twolink_pin.twolink.reference import REPORT_GAINS

sys.path.insert(0, str(Path(__file__).parent))
from random_arms import write_random_arm

W, KAPPA = NATURAL_FREQUENCY, SLIDING_RATE


class Hold(Trajectory):
    """A constant reference at ``q`` [rad]."""

    def __init__(self, q: np.ndarray) -> None:
        self.q, self.t0, self.period = np.asarray(q, dtype=float), 0.0, 1.0

    @property
    def nv(self) -> int:
        return int(self.q.size)

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        shape = (self.nv,) if np.ndim(t) == 0 else (np.size(t), self.nv)
        zero = np.zeros(shape)
        return TrajectorySample(np.broadcast_to(self.q, shape).copy(), zero, zero.copy(), zero.copy())


def _inertia(robot: RobotModel) -> np.ndarray:
    M = pin.crba(robot.model, robot.model.createData(), robot.home)
    return np.triu(M) + np.triu(M, 1).T


def _modes(K: np.ndarray, M: np.ndarray) -> np.ndarray:
    return scipy.linalg.eigvalsh(np.asarray(K)[0], M)


def _check_modes(robot: RobotModel) -> None:
    """Every derived gain's modes against M(q₀) (module docstring)."""
    M = _inertia(robot)
    pd, pid = PDFeedforward(robot).gains, PID(robot).gains
    np.testing.assert_allclose(_modes(pd.kp, M), W**2, rtol=1e-9)
    np.testing.assert_allclose(_modes(pd.kd, M), 2 * W, rtol=1e-9)
    np.testing.assert_allclose(_modes(PDGravity(robot).gains.kp, M), W**2, rtol=1e-9)
    # M s³ + Kd s² + Kp s + Ki = M (s + ω)³: every pole at −ω
    for gain, value in ((pid.kd, 3 * W), (pid.kp, 3 * W**2), (pid.ki, W**3)):
        np.testing.assert_allclose(_modes(gain, M), value, rtol=1e-9)
    joint_wise = np.clip(scipy.linalg.eigvalsh(np.diag(np.diag(M)), M), 1.0, MODE_SPREAD) * KAPPA
    for law in (ComputedTorque, WrongModel):
        modes = _modes(law(robot).gains.k, M)
        np.testing.assert_allclose(modes, joint_wise, rtol=1e-8)
        assert KAPPA * (1 - 1e-9) <= modes.min() and modes.max() <= MODE_SPREAD * KAPPA * (1 + 1e-9)
    if len(Impedance(robot).rows) < robot.nv:  # a posture task: its modes at ω_n
        np.testing.assert_allclose(_modes(Impedance(robot).gains.kp_null, M), POSTURE_FREQUENCY**2, rtol=1e-9)


def _closed_loop_at_home(robot: RobotModel) -> np.ndarray:
    """``pd``'s closed loop linearised at rest at home (the step check's central differences of
    the law and Pinocchio's RNEA derivatives of the plant): its matrix A."""
    law, plant = PDFeedforward(robot), Plant(robot)
    x = initial_law_input(law, plant, Hold(robot.home), SimulationConfig(q0_offset=0.0))
    return linearise(law, plant, x).A


@functools.cache
def _folder() -> Path:
    return Path(tempfile.mkdtemp(prefix="twolink-pin-arms-"))


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), joints=st.integers(2, 7))
def test_random_arms_have_their_home_modes_at_the_stated_rates(seed: int, joints: int) -> None:
    robot = load_robot(write_random_arm(_folder(), seed, joints))
    M = _inertia(robot)
    assert np.linalg.cond(M) > 1.0  # coupled (a diagonal gain would put modes elsewhere)
    _check_modes(robot)
    # PD + feedforward at rest on the exact model: (s + ω)² on every mode, i.e. (A + ω I)² = 0
    # (its eigenvalues, a double root, would spread by √ of the differences' error); the central
    # differences of g(q) (up to 1e3 N·m here) are good to ~1e-7 N·m/rad, which M⁻¹ of a 10-g
    # link (1e-4 kg·m²) makes ~1e-3 1/s² in A, and (A + ωI)² multiplies it by entries up to ~ω²:
    # 1e-3 ω² (seed 859780, 6 joints, reached 1.6e-4 ω²); a design off by one mode leaves ~ω²
    A = _closed_loop_at_home(robot)
    shifted = A + W * np.eye(len(A))
    assert np.abs(shifted @ shifted).max() <= 1e-3 * W**2
    np.testing.assert_allclose(np.linalg.eigvals(A).real, -W, rtol=0, atol=0.05 * W)


@pytest.mark.parametrize("name", [n for n in names() if n != "twolink"])
def test_every_catalog_arm_has_its_home_modes_at_the_stated_rates(name: str) -> None:
    _check_modes(load_robot(name))


def test_the_twolink_keeps_the_reports_gains() -> None:
    """The course report's gains, as diagonal matrices: the same torques, bit for bit."""
    robot = load_robot("twolink")
    pd = PDFeedforward(robot).gains
    np.testing.assert_array_equal(pd.kp[0], np.diag(REPORT_GAINS["pd"]["kp"]))
    np.testing.assert_array_equal(pd.kd[0], np.diag(REPORT_GAINS["pd"]["kd"]))
    np.testing.assert_array_equal(
        ComputedTorque(robot).gains.k[0], np.diag(REPORT_GAINS["computed-torque"]["k"])
    )


def test_a_diagonal_design_on_a_coupled_arm_puts_a_mode_far_above_its_rate() -> None:
    """Why (the issue's measurement, a random arm of strongly coupled inertia): K = κ diag M(q₀)
    has a mode above κ by the coupling; the default's are within [κ, 20 κ]."""
    robot = load_robot(write_random_arm(_folder(), 7, 7))
    M = _inertia(robot)
    assert _modes(KAPPA * np.diag(np.diag(M))[None], M).max() > 2 * KAPPA
    assert _modes(ComputedTorque(robot).gains.k, M).max() <= MODE_SPREAD * KAPPA * (1 + 1e-9)
