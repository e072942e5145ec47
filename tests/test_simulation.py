"""Tests of twolink_pin.simulation: RK4 against the adaptive-step integrator, convergence in
dt, divergence detection, a law that misbehaves (raises, wrong shape, NaN), configuration
errors, and the read-only result with its torque-limit bookkeeping.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest_sim import ROBOT, TRAJECTORY, ConstantTorque, ConstantTorqueGains, run

from twolink_pin.controllers import (
    ComputedTorque,
    LawInput,
    LawOutput,
    PDFeedforward,
    PDGains,
    SlotineLiGains,
    Terms,
)
from twolink_pin.errors import ControllerError, InvalidParameterError, SimulationDivergedError
from twolink_pin.metrics import compute_metrics
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import DIVERGENCE_LIMIT, SimulationConfig, simulate

COMPARISON_DURATION = 3.0
"""[s]: the initial transient and most of one period; the adaptive-step runs cost ~3–6 s each."""

# --- RK4 against the adaptive-step method (DOP853, rtol 1e-9, atol 1e-11) --------------------


@pytest.mark.parametrize(
    ("name", "tolerance"),
    [
        # Measured 8e-9 rad.
        ("pd", 1e-7),
        # Measured 1.2e-7 rad: RK4's own global error, the fast mode K/M ≈ 400 1/s at K = 120
        # gives h K/M ≈ 0.4; see test_rk4_gap_to_adaptive_step_shrinks_like_dt_to_the_fourth.
        ("adaptive", 5e-7),
    ],
)
def test_rk4_and_adaptive_step_method_agree(name: str, tolerance: float) -> None:
    """Over 3 s, max |q_rk4 − q_dop853| is below the stated tolerance [rad]; p̂ agrees to 1e-4."""
    fixed = run(name, duration=COMPARISON_DURATION)
    adaptive = run(name, duration=COMPARISON_DURATION, method="adaptive")
    assert adaptive.method == "adaptive" and fixed.method == "rk4"
    np.testing.assert_array_equal(fixed.t, adaptive.t)
    np.testing.assert_allclose(fixed.q, adaptive.q, rtol=0, atol=tolerance)
    if fixed.p_hat is not None:
        assert adaptive.p_hat is not None
        np.testing.assert_allclose(fixed.p_hat, adaptive.p_hat, rtol=0, atol=1e-4)


def test_rk4_gap_to_adaptive_step_shrinks_like_dt_to_the_fourth() -> None:
    """Halving RK4's dt (1 ms -> 0.5 ms) divides its gap to DOP853 by ≈ 16 (> 10): RK4 is 4th order.

    Measured on the adaptive law: 1.17e-7 -> 6.2e-9 rad (ratio 18.7). The DOP853 solution
    itself moves by only 5e-12 rad when its tolerances are tightened 100-fold.
    """
    reference = run("adaptive", duration=COMPARISON_DURATION, method="adaptive")
    coarse = run("adaptive", duration=COMPARISON_DURATION)
    fine = run("adaptive", duration=COMPARISON_DURATION, dt=5e-4)
    gap_coarse = np.abs(coarse.q - reference.q).max()
    gap_fine = np.abs(fine.q[::2] - reference.q).max()
    assert gap_coarse / gap_fine > 10, (gap_coarse, gap_fine)


def test_smoothed_friction_with_adaptive_step_matches_exact_sgn_with_rk4() -> None:
    """adaptive-friction: DOP853 with tanh(q̇/1e-3) vs RK4 with exact sgn differ by < 1e-6 rad.

    The smoothing changes the friction only where |q̇| < a few mrad/s, which the arm
    crosses briefly; measured max |Δq| = 4.5e-8 rad and max |Δp̂| = 4e-6 over 3 s.
    """
    exact = run("adaptive-friction", duration=COMPARISON_DURATION)
    smooth = run(
        "adaptive-friction", duration=COMPARISON_DURATION, method="adaptive", friction_smoothing=1e-3
    )
    np.testing.assert_allclose(smooth.q, exact.q, rtol=0, atol=1e-6)
    assert smooth.p_hat is not None and exact.p_hat is not None
    np.testing.assert_allclose(smooth.p_hat, exact.p_hat, rtol=0, atol=1e-4)


def test_adaptive_step_method_refuses_exact_sgn_friction() -> None:
    """Exact sgn Coulomb friction stalls an adaptive-step integrator: InvalidParameterError up front."""
    controller, plant = make_scenario("adaptive-friction", ROBOT)
    with pytest.raises(InvalidParameterError, match=re.escape("friction.smoothing = 0.0 is invalid")) as info:
        simulate(controller, plant, TRAJECTORY, SimulationConfig(duration=1.0, method="adaptive"))
    assert info.value.name == "friction.smoothing"


# --- convergence in dt ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("signal", "tolerance"),
    [
        ("e", 1e-6),  # measured 1.2e-8
        ("edot", 1e-5),  # measured 4.6e-7
        # The trapezoid's O(dt²) error on the sharp initial torque transient: measured 6e-4.
        ("tau", 3e-3),
    ],
)
def test_halving_dt_barely_changes_the_metrics(signal: str, tolerance: float) -> None:
    """pd over 4 s: dt 1 ms -> 0.5 ms changes RMS and L2 of each signal by less than the stated relative tolerance."""
    coarse = compute_metrics(run("pd", duration=4.0))
    fine = compute_metrics(run("pd", duration=4.0, dt=5e-4))
    for kind in ("rms", "l2"):
        np.testing.assert_allclose(
            getattr(getattr(coarse, kind), signal),
            getattr(getattr(fine, kind), signal),
            rtol=tolerance,
            atol=0,
        )
    np.testing.assert_allclose(coarse.final_period_max_abs_e, fine.final_period_max_abs_e, rtol=1e-6, atol=0)


# --- divergence -------------------------------------------------------------------------------


def test_absurd_gain_diverges_with_the_controller_and_time_named() -> None:
    """K = 1e9 makes RK4 at dt = 1 ms unstable: SimulationDivergedError at t = dt naming 'computed-torque'
    (run anyway: the step check refuses it before the run, tests/test_step_check.py)."""
    controller = ComputedTorque(ROBOT, SlotineLiGains(k=(1e9, 1e9)))
    with pytest.raises(
        SimulationDivergedError, match=r"controller 'computed-torque' diverged at t = 0\.001 s"
    ) as info:
        simulate(controller, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=1.0, check_step=False))
    assert info.value.controller == "computed-torque"
    assert info.value.time == pytest.approx(1e-3, rel=1e-12)
    assert f"> {DIVERGENCE_LIMIT:g}" in info.value.detail


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_huge_torque_diverges_with_either_method(method: str) -> None:
    """τ = 1e9 N·m drives |q̇| past DIVERGENCE_LIMIT: SimulationDivergedError at some 0 < t <= 1 ms."""
    controller = ConstantTorque(ROBOT, ConstantTorqueGains(torque=1e9))
    with pytest.raises(SimulationDivergedError, match="controller 'test-constant-torque' diverged") as info:
        config = SimulationConfig(duration=1.0, method=method, check_step=False)  # the check would refuse it
        simulate(controller, Plant(ROBOT), TRAJECTORY, config)
    assert info.value.controller == "test-constant-torque"
    assert 0 < info.value.time <= 1e-3 + 1e-12


def test_stiff_gain_with_the_adaptive_method_stops_instead_of_hanging() -> None:
    """K = 1e9 makes DOP853's step collapse: the evaluation budget turns it into an error."""
    controller = ComputedTorque(ROBOT, SlotineLiGains(k=(1e9, 1e9)))
    with pytest.raises(SimulationDivergedError, match=r"diverged at t = .* s: .*(collapsed|state)") as info:
        simulate(controller, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.05, method="adaptive"))
    assert info.value.controller == "computed-torque"
    assert 0 < info.value.time <= 0.05


# --- configuration errors -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "name", "text"),
    [
        ({"duration": 0.0}, "duration", "duration = 0.0 is invalid: expected a finite value > 0 s"),
        ({"duration": -1.0}, "duration", "duration = -1.0 is invalid"),
        ({"duration": float("nan")}, "duration", "duration = nan is invalid"),
        ({"duration": float("inf")}, "duration", "duration = inf is invalid"),
        ({"dt": 0.0}, "dt", "dt = 0.0 is invalid: expected a finite value > 0 s"),
        ({"dt": -1e-3}, "dt", "dt = -0.001 is invalid"),
        ({"duration": 1.0, "dt": 2.0}, "dt", "dt = 2.0 is invalid: expected a step <= duration (1.0 s)"),
        ({"method": "euler"}, "method", "method = 'euler' is invalid: expected 'rk4' or 'adaptive'"),
        ({"rtol": 0.0}, "rtol", "rtol = 0.0 is invalid: expected a finite value > 0"),
        (
            {"q0_offset": (0.1, float("nan"))},
            "q0_offset",
            "q0_offset = (0.1, nan) is invalid: expected finite offsets",
        ),
        ({"q0_offset": "big"}, "q0_offset", "q0_offset = 'big' is invalid: expected finite offsets"),
        ({"control_period": 1.5e-3}, "control_period", "expected a whole multiple of dt = 0.001 s"),
        ({"control_period": 1e-3, "method": "adaptive"}, "control_period", "None with the adaptive method"),
    ],
)
def test_bad_config_is_refused_naming_the_value(kwargs: dict, name: str, text: str) -> None:
    """A bad SimulationConfig raises InvalidParameterError whose message holds the value received."""
    with pytest.raises(InvalidParameterError, match=re.escape(text)) as info:
        SimulationConfig(**kwargs)
    assert info.value.name == name


@pytest.mark.parametrize("name", ["q0_offset", "v0_offset"])
def test_offset_of_the_wrong_length_is_refused_by_simulate(name: str) -> None:
    """An offset with 3 values for a 2-joint arm: InvalidParameterError naming it and its value."""
    config = SimulationConfig(duration=1.0, **{name: (0.1, 0.1, 0.1)})
    with pytest.raises(
        InvalidParameterError,
        match=re.escape(f"{name} = (0.1, 0.1, 0.1) is invalid: expected one value, or 2 values"),
    ):
        simulate(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, config)


def test_one_offset_value_applies_to_every_joint() -> None:
    """q0_offset = 0.05 (a number) gives q(0) − q_d(0) = (0.05, 0.05) rad."""
    result = run("pd", duration=0.01, q0_offset=0.05)  # type: ignore[arg-type]
    np.testing.assert_allclose(result.e[0], (0.05, 0.05), rtol=0, atol=1e-15)


# --- a law that misbehaves ----------------------------------------------------------------------


class _Faulty(PDFeedforward, register=False):
    """PD that fails in a chosen way from t = 0.25 s."""

    mode = "raise"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        out = super().compute(x, terms)
        if x.t < 0.25:
            return out
        if self.mode == "raise":
            raise ZeroDivisionError("the law divided by zero")
        if self.mode == "nan":
            return LawOutput(out.tau * np.nan)
        return LawOutput(out.tau[:, :1])


@pytest.mark.parametrize(
    ("mode", "error", "text"),
    [
        (
            "raise",
            ControllerError,
            "controller 'pd' failed at t = 0.25 s: ZeroDivisionError: the law divided by zero",
        ),
        ("shape", ControllerError, "LawOutput.tau must have shape (1, 2), got shape (1, 1)"),
    ],
)
def test_a_misbehaving_law_is_named_with_the_simulated_time(mode: str, error: type, text: str) -> None:
    """A law that raises, returns NaN or the wrong shape stops the run with ControllerError naming
    the law and the time of the evaluation (the shape is checked at the first evaluation it changes:
    the engine validates the first output, then trusts the shapes, so a later change surfaces as
    numpy's broadcast error or a non-finite state — here the torque of shape (1, 1) broadcasts)."""
    law = _Faulty(ROBOT, PDGains(kp=(350.0, 300.0), kd=(40.0, 50.0)))
    law.mode = mode
    if mode == "shape":  # wrong from the start: caught by the first-output check
        law.compute = lambda x, terms: LawOutput(np.zeros((1, 1)))  # type: ignore[method-assign]
        text = text.replace("0.25", "0")
    with pytest.raises(error, match=re.escape(text)) as info:
        simulate(law, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.5))
    assert info.value.controller == "pd"


def test_a_law_returning_nan_stops_the_run_naming_the_law_and_the_time() -> None:
    """NaN torques from t = 0.25 s: the run stops at t = 0.25 s (the first sample whose state or
    torque is not finite), naming the law; the message says the law's torque is the likely cause."""
    law = _Faulty(ROBOT, PDGains(kp=(350.0, 300.0), kd=(40.0, 50.0)))
    law.mode = "nan"
    with pytest.raises((ControllerError, SimulationDivergedError)) as info:
        simulate(law, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.5))
    assert info.value.controller == "pd"  # type: ignore[union-attr]
    assert info.value.time == pytest.approx(0.25, abs=1.5e-3)  # type: ignore[union-attr]
    assert "torque" in str(info.value)


def test_a_law_returning_a_bare_array_is_told_to_return_law_output() -> None:
    """compute must return LawOutput; a bare ndarray is refused at the first evaluation, t = 0."""
    law = PDFeedforward(ROBOT)
    law.compute = lambda x, terms: np.zeros((1, 2))  # type: ignore[method-assign,assignment,return-value]
    with pytest.raises(
        ControllerError, match=re.escape("compute returned ndarray; return LawOutput(tau)")
    ) as info:
        simulate(law, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.1))
    assert info.value.time == 0.0


# --- the result -------------------------------------------------------------------------------

ARRAYS = ("t", "q", "v", "tau_command", "tau", "q_des", "v_des", "a_des", "torque_limits")


@pytest.mark.parametrize("name", ["pd", "adaptive"])
def test_result_arrays_have_the_documented_shapes(name: str) -> None:
    """N = duration/dt + 1 samples, (N, nv) signals, p̂ (N, 3) for adaptive and None for pd."""
    result = run(name, duration=1.0)
    n = 1001
    np.testing.assert_allclose(result.t, np.arange(n) * 1e-3, rtol=0, atol=1e-12)
    assert result.duration == pytest.approx(1.0, rel=1e-12)
    for attr in ("q", "v", "tau_command", "tau", "q_des", "v_des", "a_des", "e", "edot"):
        assert getattr(result, attr).shape == (n, 2), attr
    assert result.torque_limits.shape == (2,)
    assert result.controller == name and result.reference_period == 4.0 and result.robot == "twolink"
    if name == "pd":
        assert result.p_hat is None and result.p_true is None and result.p_error is None
        assert result.parameter_names == ()
    else:
        assert result.p_hat is not None and result.p_hat.shape == (n, 3)
        assert result.parameter_names == ("p1", "p2", "p3")
        np.testing.assert_allclose(result.p_hat[0], 0.5 * np.asarray(ROBOT.p), rtol=1e-15)
        np.testing.assert_allclose(result.p_true, ROBOT.p, rtol=0)


@pytest.mark.parametrize("attr", [*ARRAYS, "p_hat", "p_true"])
def test_result_arrays_are_read_only(attr: str) -> None:
    """Writing into any array of a result raises ValueError."""
    array = getattr(run("adaptive", duration=1.0), attr)
    with pytest.raises(ValueError, match="read-only"):
        array[0] = 0.0


def test_result_reference_and_initial_state() -> None:
    """q_des etc. are the trajectory on the grid; q(0) − q_d(0) = q0_offset, q̇(0) = q̇_d(0)."""
    result = run("pd", duration=1.0)
    reference = TRAJECTORY.sample(result.t)
    np.testing.assert_allclose(result.q_des, reference.q, rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.v_des, reference.v, rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.a_des, reference.a, rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.e[0], (0.1, -0.1), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.edot[0], 0.0, rtol=0, atol=1e-15)


def test_saturation_clips_the_applied_torque_but_reports_the_command() -> None:
    """saturate=True, q(0) − q_d(0) = (1, −1) rad: |τ| <= limits (240, 40) N·m always while τ_command exceeds them.

    The first command is −Kp e(0) = (−350, 300) N·m, so both joints exceed at t = 0 by
    (110, 260) N·m; the run still converges (|e(1 s)| < 0.01 rad).
    """
    result = run("pd", duration=1.0, saturate=True, q0_offset=(1.0, -1.0))
    limits = np.array([240.0, 40.0])
    np.testing.assert_array_equal(result.torque_limits, limits)
    assert result.saturate
    assert np.all(np.abs(result.tau) <= limits)
    np.testing.assert_array_equal(result.tau, np.clip(result.tau_command, -limits, limits))
    assert np.all(np.abs(result.tau_command).max(axis=0) > limits)
    np.testing.assert_array_equal(result.limit_exceeded, [True, True])
    assert result.first_exceeded_at == [0.0, 0.0]
    np.testing.assert_allclose(result.limit_excess, [110.0, 260.0], rtol=1e-9)
    assert np.abs(result.e[-1]).max() < 0.01


def test_without_saturation_limit_flags_reflect_the_commanded_torque() -> None:
    """saturate=False: τ = τ_command, limit_exceeded and first_exceeded_at follow |τ_command| > limit."""
    for offset in ((1.0, -1.0), (0.1, -0.1)):
        result = run("pd", duration=1.0, q0_offset=offset)
        assert not result.saturate
        np.testing.assert_array_equal(result.tau, result.tau_command)
        over = np.abs(result.tau_command) > result.torque_limits
        np.testing.assert_array_equal(result.limit_exceeded, over.any(axis=0))
        expected = [float(result.t[np.flatnonzero(col)[0]]) if col.any() else None for col in over.T]
        assert result.first_exceeded_at == expected
    assert run("pd", duration=1.0, q0_offset=(1.0, -1.0)).first_exceeded_at == [0.0, 0.0]
    assert run("pd", duration=1.0).first_exceeded_at == [None, None]


def test_saturated_and_unsaturated_runs_differ_only_once_a_limit_is_hit() -> None:
    """Below the limits saturation is inactive: the default pd run is identical with and without it."""
    plain, clipped = run("pd", duration=1.0), run("pd", duration=1.0, saturate=True)
    np.testing.assert_array_equal(plain.q, clipped.q)
    np.testing.assert_array_equal(plain.tau, clipped.tau)


def test_a_stiff_law_with_the_adaptive_method_is_recognised_from_its_pace() -> None:
    """λ = 1e5 holds DOP853's step at a fraction of dt by stability: the run's pace, projected to
    its end, exceeds the evaluation budget, so it ends early in simulated time (not after the
    whole budget, at t ≈ 22 s of 30) naming the step it is down to."""
    from twolink_pin import make_scenario

    controller, plant = make_scenario("computed-torque", ROBOT, lam=1e5)
    with pytest.raises(SimulationDivergedError, match=r"collapsed to about .* s \(.* steps per dt") as info:
        simulate(controller, plant, TRAJECTORY, SimulationConfig(duration=30.0, method="adaptive"))
    assert 0 < info.value.time < 1.0
