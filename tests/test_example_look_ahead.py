"""examples/look_ahead.py, the preview example of docs/writing_a_controller.md: its torque is the
closed form on the reference sampled ``ℓ`` ahead (``trajectory.sample`` and ``pin.rnea`` here, not
the law's preview and Terms), and with the plant's torque 10 ms late, looking 10 ms ahead makes
up for it (the last period's error at least 3 times smaller than looking at now)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from twolink_pin import Plant, SimulationConfig, default_trajectory, load_controller, load_robot, simulate
from twolink_pin.simulation import law_input, terms_for

LAW = str(Path(__file__).resolve().parents[1] / "examples" / "look_ahead.py") + ":LookAhead"
ROBOT = load_robot()


def test_the_torque_is_the_closed_form_on_the_reference_ahead() -> None:
    LookAhead = load_controller(LAW)
    lead = 0.013
    law = LookAhead(ROBOT, LookAhead.Gains(kp=(90.0, 60.0), kd=(19.0, 15.0), lead=lead))
    trajectory = default_trajectory(ROBOT)
    rng = np.random.default_rng(4)
    data = ROBOT.model.createData()
    for t in rng.uniform(0.0, 4.0, 5):
        now, ahead = trajectory.sample(t), trajectory.sample(t + lead)
        q, v = now.q + rng.uniform(-0.1, 0.1, 2), now.v + rng.uniform(-0.3, 0.3, 2)
        x = law_input(
            law, t, q[None], v[None], np.zeros((1, 0)), now.q[None], now.v[None], now.a[None], trajectory
        )
        tau = law.compute(x, terms_for(law)).tau[0]
        q_next = q + lead * v + 0.5 * lead**2 * now.a
        v_next = v + lead * now.a
        accel = (
            ahead.a
            + np.array([90.0, 60.0]) * (ahead.q - q_next)
            + np.array([19.0, 15.0]) * (ahead.v - v_next)
        )
        np.testing.assert_allclose(tau, pin.rnea(ROBOT.model, data, q, v, accel), rtol=0, atol=1e-10)


def test_looking_ahead_by_the_delay_makes_up_for_it() -> None:
    LookAhead = load_controller(LAW)
    plant = Plant(ROBOT, delay=10)  # the torque reaches the arm 10 steps (10 ms) late
    config = SimulationConfig(duration=5.0)
    errors = {}
    for lead in (0.0, 0.01):
        run = simulate(LookAhead(ROBOT, LookAhead.Gains(lead=lead)), plant, default_trajectory(ROBOT), config)
        errors[lead] = np.abs(run.e[run.t >= 1.0]).max()
    assert errors[0.01] < errors[0.0] / 3, errors
