"""Tests of twolink_pin.metrics against hand computations on synthetic results.

A :class:`SimulationResult` built directly from known signals: over whole periods the
RMS of A sin is A/√2 and its L2 norm A √(T/2) (the trapezoidal rule is exact to round-off
for a trigonometric polynomial sampled over whole periods).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest_sim import run

from twolink_pin.metrics import compute_metrics
from twolink_pin.simulation import SimulationResult

PERIOD = 4.0
DURATION = 12.0
DT = 1e-3
T = np.arange(round(DURATION / DT) + 1) * DT
OMEGA = 2 * np.pi / PERIOD
ZEROS = np.zeros((len(T), 2))


def _result(
    q: np.ndarray, v: np.ndarray, tau: np.ndarray, tau_command: np.ndarray | None = None
) -> SimulationResult:
    """A result with zero reference, so e = q and ė = q̇; limits (240, 40) N·m."""
    return SimulationResult(
        controller="synthetic",
        method="rk4",
        dt=DT,
        t=T,
        q=q,
        v=v,
        tau_command=tau if tau_command is None else tau_command,
        tau=tau,
        q_des=ZEROS,
        v_des=ZEROS,
        a_des=ZEROS,
        torque_limits=np.array([240.0, 40.0]),
        saturate=False,
        reference_period=PERIOD,
    )


def _sines(amplitudes: tuple[float, float]) -> np.ndarray:
    return np.stack([a * np.sin(OMEGA * T) for a in amplitudes], axis=1)


def test_rms_l2_and_max_of_sines_over_whole_periods() -> None:
    """e = (sin, 2 sin), ė = (3 cos, 0), τ = (10 sin, 5 cos): RMS = A/√2, L2 = A √(T/2), max = A."""
    cos = np.cos(OMEGA * T)
    q = _sines((1.0, 2.0))
    v = np.stack([3.0 * cos, np.zeros_like(T)], axis=1)
    tau = np.stack([10.0 * np.sin(OMEGA * T), 5.0 * cos], axis=1)
    metrics = compute_metrics(_result(q, v, tau))
    amplitudes = {"e": (1.0, 2.0), "edot": (3.0, 0.0), "tau": (10.0, 5.0)}
    for signal, amplitude in amplitudes.items():
        a = np.array(amplitude)
        np.testing.assert_allclose(getattr(metrics.rms, signal), a / np.sqrt(2), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(
            getattr(metrics.l2, signal), a * np.sqrt(DURATION / 2), rtol=1e-12, atol=1e-14
        )
        # The grid hits every quarter period (t = 1, 3, ... s), so the sampled max is A.
        np.testing.assert_allclose(getattr(metrics.max, signal), a, rtol=1e-12)


def test_rms_of_a_ramp_is_t_over_root_3() -> None:
    """e = t: RMS = T/√3, L2 = √(T³/3) (trapezoid error T dt²/6 on ∫t², relative 1e-8)."""
    q = np.stack([T, -T], axis=1)
    metrics = compute_metrics(_result(q, ZEROS, ZEROS))
    np.testing.assert_allclose(metrics.rms.e, DURATION / np.sqrt(3), rtol=1e-7)
    np.testing.assert_allclose(metrics.l2.e, np.sqrt(DURATION**3 / 3), rtol=1e-7)
    np.testing.assert_allclose(metrics.max.e, DURATION, rtol=1e-15)
    np.testing.assert_array_equal(metrics.rms.tau, 0.0)


def test_final_period_max_uses_only_the_last_period() -> None:
    """e = 10 sin before T − 4 s and 0.5 sin after: last-period max |e| = 0.5, whole-run max = 10."""
    amplitude = np.where(T < DURATION - PERIOD, 10.0, 0.5)[:, None]
    q = amplitude * _sines((1.0, -3.0))
    metrics = compute_metrics(_result(q, ZEROS, ZEROS))
    np.testing.assert_allclose(metrics.final_period_max_abs_e, [0.5, 1.5], rtol=1e-12)
    np.testing.assert_allclose(metrics.max.e, [10.0, 30.0], rtol=1e-12)


def test_metrics_use_the_applied_torque_not_the_command() -> None:
    """τ_command = 2 τ (as if saturated): the torque norms are those of the applied τ."""
    tau = _sines((10.0, 5.0))
    metrics = compute_metrics(_result(ZEROS, ZEROS, tau, tau_command=2 * tau))
    np.testing.assert_allclose(metrics.max.tau, [10.0, 5.0], rtol=1e-12)


def test_as_dict_is_json_ready_and_round_trips() -> None:
    """as_dict() holds plain lists that survive json and equal the arrays."""
    q = _sines((1.0, 2.0))
    metrics = compute_metrics(_result(q, q, q))
    data = json.loads(json.dumps(metrics.as_dict()))
    assert set(data) == {"rms", "l2", "max", "final_period_max_abs_e"}
    for kind in ("rms", "l2", "max"):
        assert set(data[kind]) == {"e", "edot", "tau"}
        np.testing.assert_array_equal(data[kind]["e"], getattr(metrics, kind).e)
    np.testing.assert_array_equal(data["final_period_max_abs_e"], metrics.final_period_max_abs_e)


def test_metrics_of_a_real_run_match_a_direct_computation() -> None:
    """On a 4-s pd run, RMS e = sqrt(trapezoid(e²)/T) and the last-period max is over t >= T − 4 s."""
    result = run("pd", duration=4.0)
    metrics = compute_metrics(result)
    e = result.e
    np.testing.assert_allclose(metrics.rms.e, np.sqrt(np.trapezoid(e**2, result.t, axis=0) / 4.0), rtol=1e-14)
    np.testing.assert_allclose(metrics.final_period_max_abs_e, np.abs(e).max(axis=0), rtol=0)
    assert metrics.final_period_max_abs_e == pytest.approx([0.1, 0.1], rel=1e-12)
