"""The tutorial's law (examples/sliding_mode.py), tested like the built-in ones: its torque
against its closed form on the twolink, tracking, and a batch equal to single runs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from conftest_sim import ROBOT, TRAJECTORY, evaluate

from twolink_pin.controllers import load_controller
from twolink_pin.metrics import compute_metrics
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.studies.batch import simulate_batch
from twolink_pin.twolink import closed_form

SlidingMode = load_controller("examples/sliding_mode.py:SlidingMode")


def test_torque_is_slotine_li_plus_a_saturated_switching_term() -> None:
    """τ = M q̈_r + C q̇_r − K s − K_s sat(s/φ) with the report's closed-form M, C, at 50 states,
    inside and outside the boundary layer."""
    law = SlidingMode(ROBOT)
    g = law.gains
    rng = np.random.default_rng(5)
    p = np.asarray(ROBOT.p)
    inside = outside = 0
    for _ in range(50):
        q, v, e, edot, a = rng.uniform(-1, 1, (5, 2)) * np.array([[3.0], [5.0], [0.02], [0.1], [20.0]])
        q_des, v_des = q - e, v - edot
        s = edot + g.lam * e
        tau, _ = evaluate(law, q, v, q_des, v_des, a)
        w, a_r = v_des - g.lam * e, a - g.lam * edot
        model = closed_form.mass_matrix(q, p) @ a_r + closed_form.coriolis_matrix(q, v, p) @ w
        expected = model - g.k * s - g.ks * np.clip(s / g.phi, -1, 1)
        np.testing.assert_allclose(tau, np.ravel(expected), rtol=1e-12, atol=1e-10)
        inside += int(np.all(np.abs(s) < g.phi))
        outside += int(np.any(np.abs(s) > g.phi))
    assert inside > 0 and outside > 0  # both branches of sat were exercised


def test_it_tracks_the_reports_trajectory() -> None:
    """From the report's initial error (0.1 rad) the last-period error is below 1e-4 rad in 12 s."""
    result = simulate(SlidingMode(ROBOT), Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=12.0))
    assert compute_metrics(result).final_period_max_abs_e.max() < 1e-4
    np.testing.assert_allclose(np.abs(result.e[0]), 0.1, rtol=1e-12)


def test_a_batch_of_gains_equals_single_runs() -> None:
    """Three K_s values in one law object: each batch row is the single run with that K_s."""
    base = SlidingMode(ROBOT)
    ks = np.array([[1.0, 0.1], [5.0, 0.5], [0.2, 2.0]])
    batch = simulate_batch(
        SlidingMode(ROBOT, replace(base.gains, ks=ks)),
        Plant(ROBOT),
        TRAJECTORY,
        SimulationConfig(duration=0.5),
        record=True,
    )
    assert batch.q is not None
    for i in range(3):
        single = simulate(
            SlidingMode(ROBOT, replace(base.gains, ks=ks[i])),
            Plant(ROBOT),
            TRAJECTORY,
            SimulationConfig(duration=0.5),
        )
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-12)
