"""A law that plans: the engine's discrete update of a law's state (``Controller.update`` every
``update_period`` seconds) against a second method, the engine's sampled-law mode."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from twolink_pin import Plant, SimulationConfig, load_robot, simulate, simulate_batch
from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput, StateVariable, gain
from twolink_pin.errors import ControllerError, InvalidParameterError
from twolink_pin.trajectory import default_trajectory

ROBOT = load_robot()
TRAJ = default_trajectory(ROBOT)
PERIOD = 0.01


@dataclass(frozen=True, eq=False)
class HoldGains(Gains):
    kp: Any = gain(200.0, per="joint", unit="N·m/rad", doc="stiffness")
    kd: Any = gain(30.0, per="joint", unit="N·m·s/rad", doc="damping")
    period: float = gain(PERIOD, unit="s", doc="update period")


class PlainPD(Controller[HoldGains], register=False):
    """τ = −Kp e − Kd ė, the state as measured (run sampled: held over the period)."""

    name = "plain-pd-test"
    title = "plain PD"
    Gains = HoldGains

    def compute(self, x: LawInput, terms: Any) -> LawOutput:
        g = self.gains
        return LawOutput(-g.kp * (x.q - x.q_des) - g.kd * (x.v - x.v_des))


class PlannedPD(PlainPD, register=False):
    """The same PD, its errors taken by update() every period and kept in z."""

    name = "planned-pd-test"

    def state_variables(self) -> tuple[StateVariable, ...]:
        nv = self.robot.nv
        return tuple(StateVariable(f"e{j + 1}", "rad", "plan") for j in range(nv)) + tuple(
            StateVariable(f"de{j + 1}", "rad/s", "plan") for j in range(nv)
        )

    def update_period(self) -> float | None:
        return self.gains.period

    def update(self, x: LawInput, terms: Any) -> np.ndarray:
        return np.concatenate([x.q - x.q_des, x.v - x.v_des], axis=1)

    def compute(self, x: LawInput, terms: Any) -> LawOutput:
        g, nv = self.gains, self.robot.nv
        tau = -g.kp * x.z[:, :nv] - g.kd * x.z[:, nv:]
        return LawOutput(tau, np.zeros_like(x.z))


def test_updates_equal_the_engine_s_sampled_law() -> None:
    """A PD whose errors are taken by update() every 10 ms and held in z, run with the law at
    every RK4 stage, equals the plain PD run as a sampled law (control period 10 ms): the
    same held torque, the same plant, so the same motion to rounding."""
    plant = Plant(ROBOT)
    planned = simulate(PlannedPD(ROBOT), plant, TRAJ, SimulationConfig(duration=0.5))
    held = simulate(PlainPD(ROBOT), plant, TRAJ, SimulationConfig(duration=0.5, control_period=PERIOD))
    np.testing.assert_allclose(planned.q, held.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(planned.tau_command, held.tau_command, rtol=0, atol=1e-9)
    # z is what update() measured at the last multiple of the period
    k = 37  # t = 0.037 s: the update at 0.03 s
    np.testing.assert_allclose(
        planned.state[k],
        np.concatenate([planned.e[30], planned.v[30] - planned.v_des[30]]),
        atol=1e-15,
    )


def test_a_batch_of_planning_runs_equals_its_single_runs() -> None:
    offsets = np.array([[0.1, -0.1], [0.0, 0.05], [-0.2, 0.0]])
    law, plant = PlannedPD(ROBOT), Plant(ROBOT)
    config = SimulationConfig(duration=0.3)
    batch = simulate_batch(law, plant, TRAJ, config, q0_offsets=offsets, record=True)
    for i, offset in enumerate(offsets):
        single = simulate(law, plant, TRAJ, SimulationConfig(duration=0.3, q0_offset=tuple(offset)))
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-13)


@pytest.mark.parametrize("period", [0.0015, 0.0005])
def test_a_period_that_is_not_a_multiple_of_the_step_is_refused(period: float) -> None:
    law = PlannedPD(ROBOT, HoldGains(period=period))
    with pytest.raises(
        InvalidParameterError,
        match=r"planned-pd-test: update period.*multiple of the simulation step dt = 0.001 s",
    ):
        simulate(law, Plant(ROBOT), TRAJ, SimulationConfig(duration=0.1))


class Raising(PlannedPD, register=False):
    name = "raising-update-test"

    def update(self, x: LawInput, terms: Any) -> np.ndarray:
        if x.t > 0.025:
            raise RuntimeError("the solver gave up")
        return super().update(x, terms)


class WrongShape(PlannedPD, register=False):
    name = "wrong-update-test"

    def update(self, x: LawInput, terms: Any) -> np.ndarray:
        return np.zeros(3)


def test_an_update_that_raises_fails_the_run_at_its_time() -> None:
    with pytest.raises(
        ControllerError, match=r"'raising-update-test' failed at t = 0.03 s: RuntimeError: the solver gave up"
    ):
        simulate(Raising(ROBOT), Plant(ROBOT), TRAJ, SimulationConfig(duration=0.1))


def test_an_update_of_the_wrong_shape_is_named() -> None:
    with pytest.raises(
        ControllerError, match=r"update must return the new state z.*\(1, 4\); got shape \(3,\)"
    ):
        simulate(WrongShape(ROBOT), Plant(ROBOT), TRAJ, SimulationConfig(duration=0.1))


def test_the_adaptive_method_refuses_a_law_that_replans() -> None:
    with pytest.raises(InvalidParameterError, match="a law that replans"):
        simulate(PlannedPD(ROBOT), Plant(ROBOT), TRAJ, SimulationConfig(duration=0.1, method="adaptive"))


def test_inverse_dynamics_derivatives_through_terms_match_rnea_and_finite_differences() -> None:
    """Terms.inverse_dynamics_derivatives on a believed model (masses 20 % off): τ equals
    pin.rnea on that model, ∂τ/∂q and ∂τ/∂v equal central differences of it, M is CRBA's."""
    import pinocchio as pin

    from twolink_pin.model.parameters import model_with_parameters
    from twolink_pin.simulation.terms import terms_for

    robot = load_robot("ur5")
    p = np.asarray(robot.p) * 1.2
    terms = terms_for(PlainPD(robot, model_parameters=p))
    rng = np.random.default_rng(0)
    q, v, a = (rng.uniform(-1, 1, (1, 3, 6)) for _ in range(3))
    d = terms.inverse_dynamics_derivatives(q, v, a)
    model = model_with_parameters(robot.model, robot.parameter_map, p)
    data = model.createData()
    h = 1e-6
    for k in range(3):
        tau = pin.rnea(model, data, q[0, k], v[0, k], a[0, k]).copy()
        np.testing.assert_allclose(d.tau[0, k], tau, atol=1e-10)
        for j in range(6):
            e = np.eye(6)[j] * h
            dq = (
                pin.rnea(model, data, q[0, k] + e, v[0, k], a[0, k])
                - pin.rnea(model, data, q[0, k] - e, v[0, k], a[0, k])
            ) / (2 * h)
            dv = (
                pin.rnea(model, data, q[0, k], v[0, k] + e, a[0, k])
                - pin.rnea(model, data, q[0, k], v[0, k] - e, a[0, k])
            ) / (2 * h)
            np.testing.assert_allclose(d.dtau_dq[0, k][:, j], dq, atol=1e-6)
            np.testing.assert_allclose(d.dtau_dv[0, k][:, j], dv, atol=1e-6)
        M = pin.crba(model, data, q[0, k])
        np.testing.assert_allclose(d.mass[0, k], np.triu(M) + np.triu(M, 1).T, atol=1e-12)
    assert not d.tau.flags.writeable
